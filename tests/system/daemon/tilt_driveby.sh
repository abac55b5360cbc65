#!/bin/sh
# SPDX-License-Identifier: MIT
# tilt_driveby.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# 3D tilt while driving: `shadowleand --input CAPTURE --motion V` on simulated drive-bys
# (paper-sim, noise-free) emits PoleTilt frames that canmatrix decodes with the board's DBC,
# and the last FITTED frame of every pole matches the simulator's truth (psi, phi_deg).
# Scenes: scenes/driveby_two_poles.ini (1 m/s, one pole leaning towards the path, one leaning
# away, both sides), the same at 3 m/s, and scenes/driveby_curve.ini (1.5 m/s turning at
# 10 deg/s: --motion 1.5,10). Without --motion the same capture gives no
# PoleTilt frame.
# Tolerances: the issue's, |Tilt error| <= 1 deg, direction within 10 deg (the observations
# are the detection group's union extent at its centre azimuth: sl_tiltobs.h); on
# scenes/driveby_realistic.ini (the same drive-by as the sensor reports it: log magnitude,
# noise floor, leakage, smear tail, speckle) the realistic bounds, 2 deg / 20 deg,
# and no LeanWarning above the true lean's level (lean_warning_sides.py).
set -u
SL_SIM=$1; D=$2; PY=$3; SRC=$4; OUT=$5
rm -rf "$OUT"; mkdir -p "$OUT"
ROOT="$SRC/../../.."
DBC="$ROOT/boards/paper-sim/shadowlean.dbc"
fail=0
PSI_TOL=1; PHI_TOL=10
run() { # name speed scene [--ambiguous-ok]
    "$SL_SIM" "$3" -o "$OUT/$1.colossus" --quiet || return 1
    "$D" --board paper-sim --input "$OUT/$1.colossus" --motion "$2" --can-log "$OUT/$1.log" -q \
        ${EXTRA:-} || return 1
    echo "== $1 (--motion $2)"
    "$PY" "$SRC/tilt_vs_truth.py" "$DBC" "$OUT/$1.log" "$OUT/$1.gt.csv" --psi-tol $PSI_TOL \
        --phi-tol $PHI_TOL ${4:-} || return 1
}
run slow 1.0 "$ROOT/scenes/driveby_two_poles.ini" || fail=1
sed 's/^speed_mps = 1.0/speed_mps = 3.0/; s/^rotations = 48/rotations = 24/; s/^y_m = -6.0/y_m = -8.0/' \
    "$ROOT/scenes/driveby_two_poles.ini" > "$OUT/fast.ini"
grep -q '^speed_mps = 3.0' "$OUT/fast.ini" || { echo "FAIL: scene edit"; exit 1; }
# At 3 m/s the pole leaning away is seen on 8 rotations only: its fit may stay AMBIGUOUS (the
# mirror hypothesis fits as well), which is the right answer when the truth is one of its two
# readings (the AMBIGUOUS frame and the MIRROR frame after it; tilt_vs_truth.py also checks
# that they come in pairs).
run fast 3.0 "$OUT/fast.ini" --ambiguous-ok || fail=1
# A curved path (scenes/driveby_curve.ini: 1.5 m/s turning at 10 deg/s), one pole either side.
run curve 1.5,10 "$ROOT/scenes/driveby_curve.ini" || fail=1
# The sensor's output: the range profile refines each target from one rotation's rows of
# neighbouring azimuths (sl_profile.h, "While moving"); measured 0.1 / 0.2 deg, 2 / 1 deg.
PSI_TOL=2; PHI_TOL=20
run realistic 1.0 "$ROOT/scenes/driveby_realistic.ini" || fail=1
# ... and its LeanWarning never above the true lean's level by more than 3 sigma: the pole
# leaning 10 deg away from the path never raises DANGER (before the range profile while
# moving it did, on 9 frames at Lean +16.95). Every PoleLean frame's in-plane Lean within
# 4 LeanSigma of the simulator's alpha at its azimuth (lean_sigma_vs_truth.py; before the
# bounds' own uncertainty, sl_profile.h "Uncertainty of the bounds", up to 9.6 sigmas
# forwards and 14 reversing; measured now 2.5 and 3.2, 1 of 49 reversing frames beyond 3).
"$PY" "$SRC/lean_warning_sides.py" "$DBC" "$OUT/realistic.log" 10 -10 || fail=1
"$PY" "$SRC/lean_sigma_vs_truth.py" "$DBC" "$OUT/realistic.log" "$OUT/realistic.gt.csv" --max-sigmas 4 || fail=1
# The tail slope as calibration data: the exit log states the slope this stream self-fitted;
# a second start from it (--tail-slope) gives the same bounds' quality from the first rotation.
"$D" --board paper-sim --input "$OUT/realistic.colossus" --motion 1.0 2> "$OUT/realistic.err" || fail=1
slope=$(sed -n 's/.*tail slope \([0-9.]*\) values\/bin (self-fitted.*/\1/p' "$OUT/realistic.err" | tail -1)
echo "== self-fitted tail slope: ${slope:-none}"
[ -n "$slope" ] || { cat "$OUT/realistic.err"; echo "FAIL: no tail slope in the exit log"; fail=1; }
EXTRA="--tail-slope ${slope:-3}" run prior 1.0 "$ROOT/scenes/driveby_realistic.ini" || fail=1
"$PY" "$SRC/lean_warning_sides.py" "$DBC" "$OUT/prior.log" 10 -10 || fail=1
"$PY" "$SRC/lean_sigma_vs_truth.py" "$DBC" "$OUT/prior.log" "$OUT/prior.gt.csv" --max-sigmas 4 || fail=1
# The same drive-by reversing (from 7.5 m past the poles, --motion -1.0): the profile's slots
# follow the tracks backwards too (measured 10.1 / 10.5 deg, 1 / 2 deg).
sed 's/^y_m = -6.0/y_m = 7.5/; s/^speed_mps = 1.0/speed_mps = -1.0/' \
    "$ROOT/scenes/driveby_realistic.ini" > "$OUT/reverse.ini"
grep -q '^speed_mps = -1.0' "$OUT/reverse.ini" || { echo "FAIL: scene edit"; exit 1; }
run reverse -1.0 "$OUT/reverse.ini" || fail=1
"$PY" "$SRC/lean_warning_sides.py" "$DBC" "$OUT/reverse.log" 10 -10 || fail=1
"$PY" "$SRC/lean_sigma_vs_truth.py" "$DBC" "$OUT/reverse.log" "$OUT/reverse.gt.csv" --max-sigmas 4 || fail=1
# The realistic drive-by on the sensor's value scale (output.log_quantity = power: 0.5 dB per
# value, exponential noise; the effects' dB halved so their values per bin stay): no
# LeanWarning above the true lean's level and every PoleLean frame within 4 of its LeanSigma
# of the truth. Its 3D fits are not held to the realistic bounds on this scale
# (docs/RESULTS.md, limitations).
sed 's/^normalize = none/normalize = none\nlog_quantity = power/; s/^smear_decay_db = 3.3/smear_decay_db = 1.65\nspeckle_db = 1.0/' \
    "$ROOT/scenes/driveby_realistic.ini" > "$OUT/power.ini"
grep -q '^log_quantity = power' "$OUT/power.ini" && grep -q '^speckle_db = 1.0' "$OUT/power.ini" ||
    { echo "FAIL: scene edit"; exit 1; }
"$SL_SIM" "$OUT/power.ini" -o "$OUT/power.colossus" --quiet || fail=1
"$D" --board paper-sim --input "$OUT/power.colossus" --motion 1.0 --can-log "$OUT/power.log" -q || fail=1
echo "== power (the sensor's value scale, --motion 1.0)"
"$PY" "$SRC/lean_warning_sides.py" "$DBC" "$OUT/power.log" 10 -10 || fail=1
"$PY" "$SRC/lean_sigma_vs_truth.py" "$DBC" "$OUT/power.log" "$OUT/power.gt.csv" --max-sigmas 4 || fail=1
# No motion input: no PoleTilt frame (the demo and Oxford frames stay as they were).
"$D" --board paper-sim --input "$OUT/slow.colossus" --can-log "$OUT/still.log" -q || fail=1
n=$(grep -c " 5C4#" "$OUT/still.log")
[ "$n" -eq 0 ] || { echo "FAIL: $n PoleTilt frames without a motion input"; fail=1; }
exit $fail
