#!/bin/sh
# SPDX-License-Identifier: MIT
# realtime_equals_fast.sh SL_SIM SHADOWLEAND OUT_DIR SRC_DIR
# --realtime (paced by the FFT timestamps: 20 rotations at 4 Hz, ~5 s) writes exactly the
# frames and targets of the as-fast-as-possible run: the pipeline runs on the radar's clock.
set -u
SL_SIM=$1; DAEMON=$2; OUT=$3; SRC=$4
rm -rf "$OUT"; mkdir -p "$OUT"
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" --rotations 20 -o "$OUT/s.colossus" --quiet || exit 1
"$DAEMON" --board paper-sim --input "$OUT/s.colossus" --can-log "$OUT/fast.log" --targets-out "$OUT/fast.jsonl" -q || exit 1
"$DAEMON" --board paper-sim --input "$OUT/s.colossus" --realtime --can-log "$OUT/rt.log" --targets-out "$OUT/rt.jsonl" -q || exit 1
[ -s "$OUT/fast.log" ] || { echo "FAIL: empty log"; exit 1; }
cmp "$OUT/fast.log" "$OUT/rt.log" && cmp "$OUT/fast.jsonl" "$OUT/rt.jsonl" || { echo "FAIL: --realtime differs"; exit 1; }
n=$(grep -c " 5C0#" "$OUT/fast.log")
[ "$n" -gt 0 ] || { echo "FAIL: no PoleLean frame to compare"; exit 1; }
echo "realtime == fast: $(wc -l < "$OUT/fast.log") frames ($n PoleLean)"
