#!/bin/sh
# SPDX-License-Identifier: MIT
# dbc_decode.sh SL_DBC GEN_FRAMES PYTHON SRC_DIR BOARD OUT_DIR N SEED
# Generate the board's DBC, encode N random messages with the core into a candump log,
# decode every frame with python3-canmatrix and compare with the encoder's inputs.
set -eu
dbc=$1; gen=$2; py=$3; src=$4; board=$5; out=$6; n=$7; seed=$8
mkdir -p "$out"
"$dbc" "$board" --out "$out/$board.dbc"
"$gen" "$board" "$n" "$seed" "$out/$board.log" "$out/$board.expect"
"$py" "$src/check_dbc_decode.py" "$out/$board.dbc" "$out/$board.log" "$out/$board.expect"
