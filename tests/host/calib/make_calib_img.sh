#!/bin/sh
# SPDX-License-Identifier: MIT
# make_calib_img.sh BUILD_DIR: regenerates docs/img/calib_lower_body.png (docs/CALIBRATION.md, "Measuring
# a vehicle") with the shipped tools: sl-sim on tests/host/calib/data/lower_body_empty.ini,
# then sl-calib shadow --png. Run from anywhere; writes only that picture.
set -eu
B=$1
SRC=$(cd "$(dirname "$0")/../../.." && pwd)
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$B/host_tools/sim/sl-sim" "$SRC/tests/host/calib/data/lower_body_empty.ini" -o "$T/lower_body_empty.colossus" --quiet
# The picture's title names the input file only (never a machine path).
(cd "$T" && "$B/host_tools/calib/sl-calib" shadow lower_body_empty.colossus --board paper-sim \
    --png "$SRC/docs/img/calib_lower_body.png" > /dev/null)
echo "wrote docs/img/calib_lower_body.png"
