#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_test.sh UML_RUN SHADOWLEAND SL_SIM PYTHON SRC_DIR OUT_DIR
# Real SocketCAN inside user-mode Linux (tests/support/vm/uml_run.sh): shadowleand --input CAPTURE
# --can vcan0 --can-log OUT while `candump -L vcan0` records (uml_guest.sh); on the host:
# the recording equals the --can-log output field by field, the real-time run took
# VehicleMotion from vcan0, and the fast run's frames match its targets (DBC decode).
# Exit 77 (ctest skip) when linux.uml is not installed.
set -u
uml_run=$1; daemon=$2; sim=$3; py=$4; src=$(cd "$5" && pwd); out=$6
rm -rf "$out"; mkdir -p "$out"; out=$(cd "$out" && pwd)
dbc="$src/../../../boards/paper-sim/shadowlean.dbc"
"$sim" "$src/scenes/static_four_poles.ini" -o "$out/scene.colossus" --quiet || exit 1
"$sim" "$src/scenes/static_four_poles.ini" --rotations 40 -o "$out/short.colossus" --quiet || exit 1
"$py" "$src/motion_frames.py" "$dbc" 0.10 0 > "$out/motion.txt" || exit 1
SL_UML_TIMEOUT=${SL_UML_TIMEOUT:-150} sh "$uml_run" "$out/vm" sh "$src/uml_guest.sh" "$daemon" \
    "$out/scene.colossus" "$out/short.colossus" "$out/motion.txt" "$out"
rc=$?
[ $rc -eq 0 ] || exit $rc
"$py" "$src/uml_compare.py" "$out" 300 || exit 1
"$py" "$src/check_can_vs_targets.py" "$dbc" "$out/daemon_fast.log" "$out/targets_fast.jsonl" \
    --rotations 24 --min-poles 4 || exit 1
