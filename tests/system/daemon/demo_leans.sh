#!/bin/sh
# SPDX-License-Identifier: MIT
# demo_leans.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# The demo's scene (scenes/demo_three_poles.ini: a parked vehicle, noise-free, so every
# rotation is quantised the same way) through the daemon: every pole's decoded PoleLean lean
# within 1.0 deg of the simulator's truth (issue 11), from the first frame sent for it to the
# last (lean_vs_truth.py --all-frames).
set -u
SL_SIM=$1; DAEMON=$2; PY=$3; SRC=$4; OUT=$5
rm -rf "$OUT"; mkdir -p "$OUT"
"$SL_SIM" "$SRC/../../../scenes/demo_three_poles.ini" -o "$OUT/scene.colossus" --threads 1 --quiet || exit 1
"$DAEMON" --board paper-sim --input "$OUT/scene.colossus" --can-log "$OUT/can.log" -q || {
    echo "FAIL: shadowleand exit status $?"; exit 1; }
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
"$PY" "$SRC/lean_vs_truth.py" "$DBC" "$OUT/can.log" "$OUT/scene.gt.csv" --tol 1.0 --all-frames || exit 1
