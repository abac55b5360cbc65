#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_live_guest.sh PYTHON PYPATH DBC LOG OUTDIR: runs INSIDE user-mode Linux (uml_run.sh,
# vcan0 up). `python3 -m shadowlean live` listens on vcan0 (python-can's socketcan
# interface on a real kernel CAN stack); a marker frame (7FF#53594E43, not in the DBC, not
# counted) is sent until the listener has printed one, so no frame of the log is sent
# before it listens (no timing assumption); then canplayer sends the daemon's log as fast
# as it can and the listener stops after that many frames of the DBC (--count), --check.
set -u
py=$1; pypath=$2; dbc=$3; log=$4; out=$5
n=$(grep -c . "$log")
PYTHONPATH=$pypath PYTHONDONTWRITEBYTECODE=1 "$py" -m shadowlean live --dbc "$dbc" \
    --channel vcan0 --count "$n" --check > "$out/live.out" 2> "$out/live.err" &
pid=$!
i=0
while ! grep -q "(unknown id)" "$out/live.out" 2>/dev/null; do
    i=$((i + 1))
    if [ $i -gt 1200 ] || ! kill -0 $pid 2>/dev/null; then
        echo "the listener never received the marker frame"; cat "$out/live.err"; kill $pid 2>/dev/null; exit 1
    fi
    cansend vcan0 7FF#53594E43
    sleep 0.05
done
canplayer -t -I "$log" vcan0=can0 || { echo "canplayer failed"; kill $pid; exit 1; }
wait $pid
rc=$?
echo "listener exit status $rc"
exit $rc
