#!/bin/sh
# SPDX-License-Identifier: MIT
# driveby_tilt_robotcar.sh SL_EVAL FITS_WITHIN_SIGMA_PY OUT_DIR
# Issue 12's drive-by on robotcar-leaf (noise-free, 1 m/s, psi 10 deg in 8 directions, the
# pole 2 and 3 m either side of the path: 32 passes). Abeam this board's chassis shadow
# reaches 3.07 m on the ground and its near exclusion is 2.7 m, so a pole is seen only while
# it is inside that band (2-3 m of travel, 8-13 rotations at 1 m/s). Asserts: every pass
# tracks its pole (before the noise-free passes stopped applying the board's elongation
# table, the paper bench's 0.74-0.81 m cut off every smear-free return: no track on any
# pass); at least 12 FITTED; every FITTED fit along the passes within 3 of its stated
# sigmas (a pass with few observations may be FITTED with a wide sigma, never a confident
# wrong one). Measured: 16 FITTED, 16 AMBIGUOUS; 7 of 32 within 1 deg / 10 deg; FITTED fits
# at most 1.27 sigma off.
set -u
EVAL=$1; CHECK=$2; OUT=$3
mkdir -p "$OUT"
"$EVAL" driveby --board robotcar-leaf --speeds 1 --psi 10 --offset 2 --offset -2 --offset 3 \
    --offset -3 --obs-log "$OUT/fits.jsonl" > "$OUT/driveby.txt" 2>&1 ||
    { cat "$OUT/driveby.txt"; exit 1; }
cat "$OUT/driveby.txt"
passes=$(awk '$5 == "|" && $1 ~ /^[0-9]/' "$OUT/driveby.txt" | wc -l)
[ "$passes" -eq 32 ] || { echo "FAIL: $passes passes, want 32"; exit 1; }
lost=$(awk '$5 == "|" && $1 ~ /^[0-9]/ && $6 == "no"' "$OUT/driveby.txt")
[ -z "$lost" ] || { echo "FAIL: passes without a track:"; echo "$lost"; exit 1; }
fitted=$(awk '$5 == "|" && $1 ~ /^[0-9]/ && $6 == "FITTED"' "$OUT/driveby.txt" | wc -l)
[ "$fitted" -ge 12 ] || { echo "FAIL: $fitted of 32 passes FITTED, want >= 12"; exit 1; }
python3 "$CHECK" "$OUT/fits.jsonl" --max-sigmas 3 || { echo "FAIL: a FITTED fit outside 3 sigma"; exit 1; }
echo "driveby_tilt_robotcar: 32 passes tracked, $fitted FITTED, every FITTED fit within 3 sigma: OK"
