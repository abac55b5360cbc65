#!/bin/sh
# SPDX-License-Identifier: MIT
# sl-sim -> capture + truth -> sl-eval run (core decoder + estimator); and the realistic
# experiment at its smallest size. Usage: cli_roundtrip.sh SL_SIM SL_EVAL SCENES_DIR WORKDIR
set -eu
SIM=$1; EVAL=$2; SCENES=$3; WORK=$4
mkdir -p "$WORK"
"$SIM" "$SCENES/paper_pass_p10.ini" -o "$WORK/p10.colossus" --rotations 12 --threads 2 --quiet
test -s "$WORK/p10.colossus"
head -1 "$WORK/p10.gt.csv" | grep -q '^rotation,azimuth,nominal,pole,'
# 12 rotations x 400 azimuths x (22 + 14 + 3768) bytes + the configuration message
size=$(wc -c < "$WORK/p10.colossus")
test $(( (size - 12 * 400 * 3804) )) -gt 20
test $(( (size - 12 * 400 * 3804) )) -lt 200
out=$("$EVAL" run "$WORK/p10.colossus" "$WORK/p10.gt.csv" --board paper-sim --raw)
echo "$out"
echo "$out" | grep -q 'bbox extraction (detection pipeline not used)'
echo "$out" | grep -q '4800 FFT rows, 12 rotations'
# raw bounds: the quantisation bias is positive
echo "$out" | grep -Eq 'error mean [0-9]'
# the core pipeline on the same capture (12 rotations at 1 m/s: n_eff 1)
out=$("$EVAL" run "$WORK/p10.colossus" "$WORK/p10.gt.csv" --scene "$SCENES/paper_pass_p10.ini" --extract pipeline)
echo "$out"
echo "$out" | grep -q '^core pipeline (sl_pipeline: mask + detection + corrections + alpha; n_eff from motion)'
echo "$out" | grep -Eq 'pole 0: rotations 12, truth rows [0-9]+, detected [1-9]'
# a bad scene is rejected with the key in the message
printf '[scene]\nboard = paper-sim\n[pole.a]\nx_m = 1\ny_m = 0\nradius = 2\n' > "$WORK/bad.ini"
if "$SIM" "$WORK/bad.ini" -o "$WORK/bad.colossus" --quiet 2> "$WORK/bad.err"; then exit 1; fi
grep -q 'pole.a.radius: unknown key' "$WORK/bad.err"
# realistic, smallest size: runs end to end and prints the five angles
out=$("$EVAL" realistic --positions 1 --reps 1 --frames 2 --calib 2 --range-bins 128 --quiet)
echo "$out"
test "$(echo "$out" | grep -cE '^ *[+-][0-9]+ +\|')" -eq 5
echo OK
