#!/bin/sh
# SPDX-License-Identifier: MIT
# The forward model of a pole's return on the radar's physics: scenes/cts350x_physics.ini
# (the measured CTS350-X lobe applied coherently, frozen physical speckle, the elevation
# pattern, knife-edge diffraction, the sensor's value scale) rendered for 24 rotations, and
# `sl-eval run --extract model` (the core's sensor model learned from the scene's isolated
# returns, the core's fit over the rotations summed as one frozen draw): every pole is
# fitted, every lean within 2.5 deg of the truth and within 3 of its stated sigmas + 0.5 deg
# (a lean the data cannot pin down says so in its sigma, never as a confident number).
# Usage: physics_model_extraction.sh SL_SIM SL_EVAL SCENE WORKDIR
set -eu
sim=$1 eval=$2 scene=$3 work=$4
mkdir -p "$work"
cap="$work/physics.colossus"
"$sim" "$scene" -o "$cap" --gt "$work/physics.gt.csv" --rotations 24 -q
"$eval" run "$cap" "$work/physics.gt.csv" --scene "$scene" --extract model > "$work/model.txt"
cat "$work/model.txt"
grep -q "range response: learned from the capture" "$work/model.txt" || {
    echo "FAIL: the range response was not learned from the scene's isolated returns"; exit 1; }
awk '
/^pole [0-9]+: fits/ {
    poles++
    for (i = 1; i <= NF; i++) {
        if ($i == "max") maxerr = $(i + 1)
        if ($i == "signal") nosig = $(i + 1)
    }
    n = split($0, w, " ")
    beyond = w[n]
    if (nosig + 0 != 0) { print "FAIL: a pole without signal: " $0; bad = 1 }
    if (maxerr + 0 > 2.5) { print "FAIL: error beyond 2.5 deg: " $0; bad = 1 }
    if (beyond + 0 != 0) { print "FAIL: an estimate beyond 3 sigma + 0.5 deg: " $0; bad = 1 }
}
END {
    if (poles != 3) { print "FAIL: " poles " poles fitted, want 3"; bad = 1 }
    exit bad
}' "$work/model.txt"
echo "physics_model_extraction: 3 poles within 2.5 deg and 3 sigma + 0.5 deg"
