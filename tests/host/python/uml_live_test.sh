#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_live_test.sh UML_RUN PYTHON SRC OUT: the Python package on live SocketCAN inside
# user-mode Linux (uml_live_guest.sh), then on the host: every frame of the daemon's log
# received, CRC and counters clean (--check), and each decoded line equal to the offline
# decode of the same log (`python3 -m shadowlean decode`) except the receive time.
# Exit 77 (skip) without linux.uml.
set -u
uml_run=$1; py=$2; src=$(cd "$3" && pwd); out=$4
log="$src/tests/system/daemon/golden/demo_three_poles.candump"
dbc="$src/boards/paper-sim/shadowlean.dbc"
rm -rf "$out"; mkdir -p "$out"
sh "$uml_run" "$out" sh "$src/tests/host/python/uml_live_guest.sh" "$py" "$src/python" "$dbc" "$log" "$out"
rc=$?
[ $rc -eq 0 ] || { echo "FAIL: guest exit status $rc"; cat "$out/live.err" 2>/dev/null; exit $rc; }
PYTHONPATH="$src/python" "$py" -m shadowlean decode "$log" --dbc "$dbc" --check > "$out/offline.out" ||
    { echo "FAIL: offline decode"; exit 1; }
# Frame lines without their time stamp; the E2E table as it is.
grep -v -e "(unknown id)" -e "^unknown ids: " "$out/live.out" | cut -d' ' -f2- > "$out/live.cmp"
cut -d' ' -f2- "$out/offline.out" > "$out/offline.cmp"
if ! cmp -s "$out/live.cmp" "$out/offline.cmp"; then
    echo "FAIL: live decode differs from the offline decode"; diff "$out/offline.cmp" "$out/live.cmp" | head; exit 1
fi
n=$(grep -c "crc=ok" "$out/live.out")
echo "uml_live: $n frames received on vcan0, decoded and verified as offline"
[ "$n" -eq "$(grep -c . "$log")" ] || { echo "FAIL: $n frames, the log has $(grep -c . "$log")"; exit 1; }
