#!/bin/sh
# SPDX-License-Identifier: MIT
# check_tables.sh SL_TABLES BOARDS_DIR WORK: regenerate every board's tables into WORK and
# fail on any difference from the committed boards/<name>/sl_board_*.{c,h}.
set -eu
GEN=$1; BOARDS=$2; WORK=$3
rm -rf "$WORK"; mkdir -p "$WORK"
n=0; bad=0
for ini in "$BOARDS"/*/board.ini; do
    name=$(basename "$(dirname "$ini")")
    mkdir -p "$WORK/$name"
    "$GEN" "$ini" --out "$WORK/$name" --no-png
    for f in "$WORK/$name"/sl_board_* "$WORK/$name"/shadowlean.dbc; do
        if ! diff -u "$BOARDS/$name/$(basename "$f")" "$f"; then
            echo "STALE: boards/$name/$(basename "$f") differs from a fresh sl-tables run"
            bad=1
        fi
        n=$((n + 1))
    done
done
[ $n -ge 9 ] || { echo "expected tables for at least 3 boards, got $n files"; exit 1; }
[ $bad -eq 0 ] || exit 1
echo "check_tables: $n generated files identical to the committed ones"
