#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_guest.sh DAEMON CAPTURE SHORT_CAPTURE MOTION_FRAMES OUTDIR BOARD: runs INSIDE user-mode Linux
# (tests/support/vm/uml_run.sh, vcan0 up). `candump -L vcan0` records the bus while:
#   run 1: shadowleand --board BOARD --input CAPTURE --can vcan0 --can-log daemon_fast.log (as fast as
#          possible; --motion-can none);
#   run 2: shadowleand --input SHORT_CAPTURE --realtime --can vcan0 --can-log daemon_rt.log
#          while VehicleMotion frames (MOTION_FRAMES: one cansend argument per line, E2E
#          counters 0..14) go onto vcan0 every 50 ms, replayed by ONE canplayer process per
#          pass (a cansend process per frame is slow enough in a guest on a loaded host to
#          leave gaps beyond the receiver's 500 ms timeout: every frame then only
#          resynchronises); VehicleMotion is read from vcan0 (the default: the --can
#          interface). The daemon is stopped (SIGINT, exit 0) once 2 rotations used the motion
#          input, by its own --targets-out, not by time (or at the capture's end).
# Marker frames 7FF#... (SYNC / MID / END) delimit the runs in candump's recording without
# timing assumptions (the same trick as tests/system/can/uml_sink_guest.sh).
set -u
daemon=$1; cap=$2; short=$3; motion=$4; out=$5; board=$6
. "$(dirname "$0")/../../support/vm/candump_guest.sh"
candump_start "$out/candump.log" vcan0
candump_mark 53594E43 || exit 1                               # "SYNC"
"$daemon" --board "$board" --input "$cap" --can vcan0 --can-log "$out/daemon_fast.log" \
    --targets-out "$out/targets_fast.jsonl" --motion-can none --stats-every 0 \
    2> "$out/daemon_fast.err"
rc=$?
echo "run 1 (fast): exit $rc"; cat "$out/daemon_fast.err"
[ $rc -eq 0 ] || exit 1
candump_mark 4D4944 || exit 1                                 # "MID"
awk '{ printf "(%d.%06d) vcan0 %s\n", (NR * 50000) / 1000000, (NR * 50000) % 1000000, $1 }' \
    "$motion" > "$out/motion.pass.log"
rm -f "$out/motion.pass"
( while :; do
      canplayer -I "$out/motion.pass.log"
      : > "$out/motion.pass"
  done ) &
sender=$!
"$daemon" --board "$board" --input "$short" --realtime --can vcan0 --can-log "$out/daemon_rt.log" \
    --targets-out "$out/targets_rt.jsonl" 2> "$out/daemon_rt.err" &
dpid=$!
used() { _n=$(grep -c '"motion_valid":true' "$out/targets_rt.jsonl" 2>/dev/null); echo "${_n:-0}"; }
i=0
while [ "$(used)" -lt 2 ] && [ $i -lt 2400 ] && kill -0 $dpid 2>/dev/null; do
    sleep 0.05; i=$((i + 1))
done
kill -INT $dpid 2>/dev/null
wait $dpid
rc=$?
kill $sender; wait $sender 2>/dev/null
echo "run 2 (realtime, VehicleMotion on vcan0): exit $rc"; cat "$out/daemon_rt.err"
[ $rc -eq 0 ] || exit 1
candump_mark 454E44 || exit 1                                 # "END"
candump_stop
exit 0
