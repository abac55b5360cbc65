#!/bin/sh
# SPDX-License-Identifier: MIT
# Regenerates the documentation's pictures in docs/img from a host build:
#   tests/host/view/make_docs_img.sh BUILD_DIR [OUT_DIR=docs/img] [WORK_DIR=BUILD_DIR/docs-img-work]
# Needs sl-sim, sl-calib, sl-view in BUILD_DIR and the Oxford Radar RobotCar scans in
# $SL_OXFORD_DIR (default: the build's SL_OXFORD_RADAR_DIR from its CMakeCache.txt).
# Takes about a minute.
set -eu
B=$(cd "$1" && pwd)
SRC=$(cd "$(dirname "$0")/../../.." && pwd)
OUT=${2:-$SRC/docs/img}
W=${3:-$B/docs-img-work}
OX=${SL_OXFORD_DIR:-$(sed -n 's/^SL_OXFORD_RADAR_DIR:PATH=//p' "$B/CMakeCache.txt")}
SIM=$B/host_tools/sim/sl-sim
CAL=$B/host_tools/calib/sl-calib
VIEW=$B/host_tools/view/sl-view
mkdir -p "$OUT" "$W"

# 1. Elongation d from a simulated calibration pass (110 positions, 1 cm apart).
"$SIM" "$SRC/tests/host/view/scenes/elong_pass.ini" -o "$W/pass.colossus" --gt "$W/pass.gt.csv" -q
"$CAL" elongation "$W/pass.colossus" --truth "$W/pass.gt.csv" --board paper-sim \
    --out-ini "$W/pass_d.ini" --png "$OUT/calib_elongation_sim.png" --csv "$W/pass_d.csv"

# 2. Three leaning poles in the simulated vehicle's shadow, without and with that d.
"$SIM" "$SRC/tests/host/view/scenes/three_poles.ini" -o "$W/three.colossus" --gt "$W/three.gt.csv" -q
"$VIEW" "$W/three.colossus" --board paper-sim --truth "$W/three.gt.csv" \
    --out "$OUT/view_sim_three_poles_no_d.png" \
    --title "sl-view: sl-sim scene, three 6 cm poles in the shadow of paper-sim (theta 26 deg), no elongation correction"
"$VIEW" "$W/three.colossus" --board paper-sim --truth "$W/three.gt.csv" \
    --elongation "$W/pass_d.ini" --out "$OUT/view_sim_three_poles.png" \
    --title "sl-view: sl-sim scene, three 6 cm poles in the shadow of paper-sim (theta 26 deg), d calibrated on an sl-sim pass"

# 3. The real Oxford scans: shadow calibration and the calibrated shadow on the last scan.
"$CAL" shadow "$OX" --board robotcar-leaf --out-ini "$W/robotcar-leaf_calib.ini" \
    --png "$OUT/calib_shadow_oxford.png" --csv "$W/robotcar-leaf_calib.csv" | tee "$W/robotcar-leaf_calib.txt"
"$VIEW" "$OX" --board robotcar-leaf --calib "$W/robotcar-leaf_calib.ini" --roi-m 9 \
    --out "$OUT/view_oxford_calibrated.png" \
    --title "sl-view: real Oxford RobotCar scan (CTS350-X on a Nissan LEAF), shadow calibrated by sl-calib on 11 scans"
echo "pictures in $OUT, work files in $W"
