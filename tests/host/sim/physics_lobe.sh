#!/bin/sh
# SPDX-License-Identifier: MIT
# scenes/cts350x_physics.ini rendered by sl-sim and measured by sl-calib response (the core's
# learner, the tool of the real scans): every offset whose drop in the CTS350-X lobe is at
# most 40 values is reproduced within 1 value.
# Usage: physics_lobe.sh SL_SIM SL_CALIB SCENE WORKDIR
set -eu
sim=$1 calib=$2 scene=$3 work=$4
mkdir -p "$work"
"$sim" "$scene" -o "$work/cts350x_physics.colossus" -q
"$calib" response "$work/cts350x_physics.colossus" --board paper-sim -q --max-diff 1 --down-to 40
