#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_live_guest.sh PYTHON PYPATH DBC LOG MOTION OUTDIR: runs INSIDE user-mode Linux
# (uml_run.sh, vcan0 up). Twice, `python3 -m shadowlean live` (python-can's socketcan
# interface on a real kernel CAN stack, E2E Profile 11 check) listens on vcan0 and a marker
# frame (7FF#53594E43, not in the DBC, not counted) is sent until the listener has printed
# one, so no frame is sent before it listens (no timing assumption); then canplayer sends
# the frames as fast as it can and the listener stops after that many frames of the DBC
# (--count):
#   1. the daemon's log LOG, --check (live.out, live.rc);
#   2. the VehicleMotion frames of MOTION (one cansend argument and its expected Profile 11
#      status per line), --check --max-delta-counter 2 (motion.out, motion.rc).
set -u
py=$1; pypath=$2; dbc=$3; log=$4; motion=$5; out=$6

listen() { # NAME FRAMES [live options...]: listener output in OUT/NAME.out, status in NAME.rc
    name=$1; n=$2; shift 2
    PYTHONPATH=$pypath PYTHONDONTWRITEBYTECODE=1 "$py" -m shadowlean live --dbc "$dbc" \
        --channel vcan0 --count "$n" "$@" > "$out/$name.out" 2> "$out/$name.err" &
    pid=$!
    i=0
    while ! grep -q "(unknown id)" "$out/$name.out" 2>/dev/null; do
        i=$((i + 1))
        if [ $i -gt 1200 ] || ! kill -0 $pid 2>/dev/null; then
            echo "the $name listener never received the marker frame"; cat "$out/$name.err"
            kill $pid 2>/dev/null; return 1
        fi
        cansend vcan0 7FF#53594E43
        sleep 0.05
    done
}

listen live "$(grep -c . "$log")" --check || exit 1
canplayer -t -I "$log" vcan0=can0 || { echo "canplayer failed"; kill $pid; exit 1; }
wait $pid
echo $? > "$out/live.rc"
echo "demo listener exit status $(cat "$out/live.rc")"

awk '{ printf "(%d.%06d) can0 %s\n", NR / 1000, (NR % 1000) * 1000, $1 }' "$motion" > "$out/motion.log"
listen motion "$(grep -c . "$motion")" --check --max-delta-counter 2 || exit 1
canplayer -t -I "$out/motion.log" vcan0=can0 || { echo "canplayer failed"; kill $pid; exit 1; }
wait $pid
echo $? > "$out/motion.rc"
echo "VehicleMotion listener exit status $(cat "$out/motion.rc")"
exit 0
