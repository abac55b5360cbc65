#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_live_test.sh UML_RUN PYTHON SRC OUT: the Python package as an AUTOSAR E2E Profile 11
# receiver on live SocketCAN inside user-mode Linux (uml_live_guest.sh), then on the host:
#   - the demo: every frame of the daemon's log received, every one accepted by the Profile
#     11 check (--check, exit 0), and each decoded line equal to the offline decode of the
#     same log (`python3 -m shadowlean decode`) except the receive time;
#   - VehicleMotion frames built with Profile 11 by the test (motion_fault_frames.py, the
#     AUTOSAR library chaining of p11_frames.py): good ones OK or OK_SOME_LOST, repetitions
#     REPEATED, a jump beyond the max delta counter 2 WRONG_SEQUENCE, corrupted CRCs ERROR,
#     frame by frame as the generator says (the listener's first frame is INITIAL), and
#     --check fails (exit 1) because of them.
# Exit 77 (skip) without linux.uml.
set -u
uml_run=$1; py=$2; src=$(cd "$3" && pwd); out=$4
log="$src/tests/system/daemon/golden/demo_three_poles.candump"
dbc="$src/boards/paper-sim/shadowlean.dbc"
rm -rf "$out"; mkdir -p "$out"
"$py" "$src/tests/system/daemon/motion_fault_frames.py" "$dbc" > "$out/motion.txt" ||
    { echo "FAIL: motion_fault_frames.py"; exit 1; }
sh "$uml_run" "$out" sh "$src/tests/host/python/uml_live_guest.sh" "$py" "$src/python" "$dbc" "$log" \
    "$out/motion.txt" "$out"
rc=$?
[ $rc -eq 0 ] || { echo "FAIL: guest exit status $rc"; cat "$out/live.err" "$out/motion.err" 2>/dev/null; exit $rc; }
[ "$(cat "$out/live.rc")" = 0 ] || { echo "FAIL: the demo's frames did not all pass the Profile 11 check"; cat "$out/live.err"; exit 1; }
PYTHONPATH="$src/python" "$py" -m shadowlean decode "$log" --dbc "$dbc" --check > "$out/offline.out" ||
    { echo "FAIL: offline decode"; exit 1; }
# Frame lines without their time stamp; the E2E table as it is.
grep -v -e "(unknown id)" -e "^unknown ids: " "$out/live.out" | cut -d' ' -f2- > "$out/live.cmp"
cut -d' ' -f2- "$out/offline.out" > "$out/offline.cmp"
if ! cmp -s "$out/live.cmp" "$out/offline.cmp"; then
    echo "FAIL: live decode differs from the offline decode"; diff "$out/offline.cmp" "$out/live.cmp" | head; exit 1
fi
n=$(grep -c "crc=ok" "$out/live.out")
echo "uml_live: $n frames received on vcan0, all accepted by the Profile 11 check, decoded as offline"
[ "$n" -eq "$(grep -c . "$log")" ] || { echo "FAIL: $n frames, the log has $(grep -c . "$log")"; exit 1; }
# VehicleMotion: the status of every frame, in order (no e2e= tail: OK).
[ "$(cat "$out/motion.rc")" = 1 ] || { echo "FAIL: --check accepted faulty VehicleMotion frames (exit $(cat "$out/motion.rc"))"; exit 1; }
grep " VehicleMotion .*ctr=" "$out/motion.out" |
    awk '{ s = "OK"; for (i = 1; i <= NF; i++) if ($i ~ /^e2e=/) s = substr($i, 5); print s }' > "$out/motion.got"
awk 'NR == 1 { print "INITIAL"; next } { print $2 }' "$out/motion.txt" > "$out/motion.want"
if ! cmp -s "$out/motion.want" "$out/motion.got"; then
    echo "FAIL: Profile 11 statuses differ (want, got):"; paste "$out/motion.want" "$out/motion.got"; exit 1
fi
echo "uml_live: $(grep -c . "$out/motion.got") VehicleMotion frames classified as built: $(sort "$out/motion.got" | uniq -c | tr -s ' ' | tr '\n' ';')"
