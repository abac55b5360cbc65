#!/bin/sh
# SPDX-License-Identifier: MIT
# realtime_stall.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# Root cause of the flaky daemon_gs_usb_output_in_vm ("Status frame outside a rotation
# group" under CPU load), reproduced deterministically: a --realtime capture replay whose
# daemon is stopped (SIGSTOP) for 1.5 s, longer than the 1 s idle-Status period, then
# continued. The daemon is behind schedule, not the capture late: it must catch up with no
# idle Status between the rotations (check_can_vs_targets.py without --idle-ok), every
# rotation's frames complete.
set -u
SL_SIM=$1; DAEMON=$2; PY=$3; SRC=$4; OUT=$5
rm -rf "$OUT"; mkdir -p "$OUT"
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" -o "$OUT/s.colossus" --rotations 12 --quiet || exit 1
"$DAEMON" --board paper-sim --input "$OUT/s.colossus" --realtime --can-log "$OUT/can.log" \
    --targets-out "$OUT/t.jsonl" 2> "$OUT/d.err" &
DPID=$!
i=0
while [ "$(grep -c ' 5C2#' "$OUT/can.log" 2>/dev/null || echo 0)" -lt 2 ] && [ $i -lt 200 ]; do
    sleep 0.05; i=$((i + 1))
done
kill -STOP $DPID
sleep 1.5
kill -CONT $DPID
wait $DPID; rc=$?
[ $rc -eq 0 ] || { cat "$OUT/d.err"; echo "FAIL: exit status $rc"; exit 1; }
"$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$OUT/can.log" "$OUT/t.jsonl" --rotations 12 \
    || { echo "FAIL: an idle Status while the daemon caught up"; exit 1; }
echo "realtime_stall: OK"
