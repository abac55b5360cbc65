#!/bin/sh
# SPDX-License-Identifier: MIT
# driveby_tilt_gross.sh SL_EVAL FITS_WITHIN_SIGMA_PY OUT_DIR
# Poles of 5 deg leaning along the path at 45 / 225 deg, 3-4 m either side, 1 and 2 m/s,
# noise-free (12 passes of `sl-eval driveby`). Far out (4.4-5 m) the paper's rendering (each
# azimuth scaled to its brightest bin, the threshold at 16 % of it) leaves the dim lower end
# of a return leaning away below the threshold: r2 up to 4 bins short, alpha 2-7 deg low at
# a stated 0.5-0.9 deg, a handful of rotations per pass. Those observations do not make the
# fit INCONSISTENT; they pulled three FITTED passes 1.01-1.57 deg off. A FITTED fit drops a
# gross outlier (sl_tiltobs.h, "Outlier rejection"): asserts every pass FITTED
# within the issue's bounds (`--check`: 1.0 deg / 10 deg), at least one such drop, and every
# FITTED fit along the passes within 3 of its stated sigmas (`--obs-log`).
set -u
EVAL=$1; FWS=$2; OUT=$3
mkdir -p "$OUT"
"$EVAL" driveby --psi 5 --speeds 1,2 --phi 45 --phi 225 --offset -3 --offset -4 --offset 4 \
    --check --dump --obs-log "$OUT/obs.jsonl" > "$OUT/driveby.txt" 2>&1
rc=$?
grep -E '\| |^driveby:' "$OUT/driveby.txt"
[ "$rc" -eq 0 ] || { echo "FAIL: a pass is not FITTED within the bounds (sl-eval --check: $rc)"; exit 1; }
drops=$(sed -n 's/.* gross \([0-9]*\)$/\1/p' "$OUT/driveby.txt" | awk '{ s += $1 } END { print s + 0 }')
[ "$drops" -ge 1 ] || { echo "FAIL: no gross outlier dropped (the passes no longer hold any?)"; exit 1; }
python3 "$FWS" "$OUT/obs.jsonl" || exit 1
echo "driveby_tilt_gross: 12 passes within the bounds, $drops gross outliers dropped: OK"
