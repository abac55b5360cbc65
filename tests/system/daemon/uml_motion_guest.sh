#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_motion_guest.sh DAEMON CAPTURE MOTION_FRAMES OUTDIR: runs INSIDE user-mode Linux
# (tests/support/vm/uml_run.sh, vcan0 up). shadowleand replays CAPTURE in real time with --can vcan0
# (VehicleMotion read from vcan0) while MOTION_FRAMES (motion_fault_frames.py: Profile 11
# frames that are OK, OK_SOME_LOST, ERROR, REPEATED and WRONG_SEQUENCE in sequence) go onto
# vcan0 every 20 ms (canplayer), from the daemon's first rotation until 4 rotations used the
# motion input AND the whole file (every kind of fault) was sent at least once (a slow guest
# on a loaded host may need many rotations for one pass: the stop must not depend on how
# fast cansend runs); then the sender stops (a reception timeout: the window must fall back
# to the board's n); 6 rotations later (1.5 s of radar time, beyond the 500 ms timeout) one
# more pass goes out, whose first frame follows a gap (one NO_NEW_DATA, then INITIAL), and
# 6 rotations after it ended the daemon is stopped with SIGINT (exit 0). Ordering by the
# daemon's own output files and by canplayer's exit, not by timing.
set -u
daemon=$1; cap=$2; motion=$3; out=$4
"$daemon" --board paper-sim --input "$cap" --realtime --can vcan0 --can-log "$out/motion.log" \
    --targets-out "$out/motion.jsonl" 2> "$out/motion.err" &
dpid=$!
used() { _n=$(grep -c '"motion_valid":true' "$out/motion.jsonl" 2>/dev/null); echo "${_n:-0}"; }
i=0
while [ ! -s "$out/motion.jsonl" ] && [ $i -lt 400 ]; do sleep 0.05; i=$((i + 1)); done
# One pass of the file as a candump log 20 ms apart, replayed by ONE canplayer process per
# pass: a cansend process per frame is slow enough in a guest on a loaded host to leave
# gaps beyond the receiver's 500 ms timeout, which restarts the counter sequence (a
# repetition or a jump after a gap is not one), and the counts asserted on the host would
# depend on the host's load.
awk '{ printf "(%d.%06d) vcan0 %s\n", (NR * 20000) / 1000000, (NR * 20000) % 1000000, $1 }' \
    "$motion" > "$out/motion.pass.log"
rm -f "$out/motion.pass"
( while :; do
      canplayer -I "$out/motion.pass.log"
      : > "$out/motion.pass"
  done ) &
sender=$!
i=0
while { [ "$(used)" -lt 4 ] || [ ! -e "$out/motion.pass" ]; } && [ $i -lt 1800 ] &&
    kill -0 $dpid 2>/dev/null; do
    sleep 0.05; i=$((i + 1))
done
kill $sender; wait $sender 2>/dev/null
echo "sender stopped after $(used) rotations with motion"
# The fallback to static: wait (by the daemon's output, not by time) until 6 more rotations
# are out -- more than the 500 ms motion timeout at 4 Hz -- then stop the daemon cleanly.
rots() { _n=$(grep -c '"type":"rotation"' "$out/motion.jsonl" 2>/dev/null); echo "${_n:-0}"; }
six_more() {
    r0=$(rots); i=0
    while [ "$(rots)" -lt $((r0 + 6)) ] && [ $i -lt 1200 ] && kill -0 $dpid 2>/dev/null; do
        sleep 0.05; i=$((i + 1))
    done
}
six_more
canplayer -I "$out/motion.pass.log"
echo "one more pass sent after the gap"
six_more
kill -INT $dpid 2>/dev/null
wait $dpid
rc=$?
echo "shadowleand exit $rc"; cat "$out/motion.err"
echo "$rc" > "$out/motion.rc"
exit 0
