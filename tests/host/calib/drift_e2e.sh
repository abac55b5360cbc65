#!/bin/sh
# SPDX-License-Identifier: MIT
# drift_e2e.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR [PART_B_INI EXPECT_DEG]
# Theta drift watch end to end: one capture of the paper-sim vehicle, 40 rotations as its
# board says (theta 26 deg, tests/host/calib/data/drift_a.ini), then 60 rotations loaded (body
# 4.4 cm lower: theta 28 deg, drift_b.ini), two leaning poles throughout. The daemon with the
# nominal board must raise Health Fault bit THETA_DRIFT within 48 rotations of the step
# (sl_drift.h's stated bound: the mask's window 16 + 2 samples per sector x 8 sectors +
# persistence 8), never before it, keep it, and end with ThetaDrift +2.0 deg
# (+-0.5). The first part alone: no THETA_DRIFT (no false alarm) and a valid estimate.
# With PART_B_INI / EXPECT_DEG: another second part (default drift_b.ini, +2.0), e.g. the
# body rising (drift_c24.ini, -2.0; drift_c20.ini, -6.0: the ground start beyond the
# masked range, read from the watched row's raw tail), same bound.
set -u
SL_SIM=$1; DAEMON=$2; PY=$3; SRC=$4; OUT=$5; PART_B=${6:-drift_b.ini}; EXPECT=${7:-2.0}
D="$SRC/data"
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
rm -rf "$OUT"; mkdir -p "$OUT"
fail() { echo "FAIL: $*"; exit 1; }
"$SL_SIM" "$D/drift_a.ini" -o "$OUT/a.colossus" --quiet || fail "sl-sim a"
"$SL_SIM" "$D/$PART_B" -o "$OUT/b.colossus" --quiet || fail "sl-sim b"
cat "$OUT/a.colossus" "$OUT/b.colossus" > "$OUT/drift.colossus"
"$DAEMON" --board paper-sim --input "$OUT/drift.colossus" --can-log "$OUT/drift.log" 2> "$OUT/drift.txt" ||
    fail "shadowleand exit status $?"
grep "drift watch" "$OUT/drift.txt"
"$PY" "$SRC/drift_health.py" "$DBC" "$OUT/drift.log" 40 48 --expect-deg "$EXPECT" || fail "THETA_DRIFT"
"$DAEMON" --board paper-sim --input "$OUT/a.colossus" --can-log "$OUT/a.log" 2> "$OUT/a.txt" ||
    fail "shadowleand (a) exit status $?"
grep "drift watch" "$OUT/a.txt"
grep -q "drift watch: estimate [+-]0\.[0-4]" "$OUT/a.txt" || fail "no valid estimate near 0 before the step"
"$PY" "$SRC/drift_health.py" "$DBC" "$OUT/a.log" -1 0 || fail "false alarm without a step"
echo "drift end to end: OK"
