#!/bin/sh
# SPDX-License-Identifier: MIT
# The fit of the sensor model as the daemon's extraction on the radar's physics:
# scenes/cts350x_physics.ini (the measured CTS350-X lobe applied coherently, frozen physical
# speckle, the elevation pattern, knife-edge diffraction, sixteen isolated posts outside the
# shadow, the sensor's value scale) rendered for 32 rotations on the paper-sim board, whose
# prior is an ideal one-bin response: `shadowleand --extract fit` must learn the lobe from
# the stream (the exit log says "learned from the stream") and every PoleLean frame with
# Quality VALID or FILTERED must lie within 3 of its LeanSigma of the truth, over at least 10
# such frames (lean_sigma_vs_truth.py). Never a confident number the data do not hold.
# Usage: physics_fit.sh SL_SIM DAEMON PYTHON3 SRC_DIR WORKDIR
set -eu
sim=$1 daemon=$2 py=$3 src=$4 work=$5
root=$src/../../..
mkdir -p "$work"
"$sim" "$root/scenes/cts350x_physics.ini" -o "$work/physics.colossus" --gt "$work/physics.gt.csv" \
    --rotations 32 -q
"$daemon" --board paper-sim --input "$work/physics.colossus" --extract fit \
    --can-log "$work/fit.log" 2> "$work/fit.err" || { cat "$work/fit.err"; echo "FAIL: daemon"; exit 1; }
grep "sensor model" "$work/fit.err"
grep -q "range response learned from the stream" "$work/fit.err" || {
    echo "FAIL: the range response was not learned from the stream"; exit 1; }
"$py" "$src/lean_sigma_vs_truth.py" "$root/boards/paper-sim/shadowlean.dbc" "$work/fit.log" \
    "$work/physics.gt.csv" --max-sigmas 3 > "$work/sigmas.txt" || { cat "$work/sigmas.txt"; exit 1; }
tail -1 "$work/sigmas.txt"
n=$(sed -n 's/^lean_sigma_vs_truth: \([0-9]*\) PoleLean frames compared.*/\1/p' "$work/sigmas.txt")
[ "${n:-0}" -ge 10 ] || { echo "FAIL: only ${n:-0} PoleLean frames compared (10 needed)"; exit 1; }
echo "physics_fit: OK"
