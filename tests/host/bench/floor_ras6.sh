#!/bin/sh
# SPDX-License-Identifier: MIT
# floor_ras6.sh SL_REPLAY SL_BENCH_HOST BOREAS_DIR WORK: the RAS6 scan repeated as 24
# rotations on the paper-sim board (same azimuths, encoder and bin size), benched with the
# sensor model learning the floor and with it off. Asserts that the occupied thresholds of
# the bands inside the shadow rose to the learned floor's mean + 10 dB (the scan's floor
# median is 43-44 values at 2-6 m, above the board's threshold of 40), and that detection
# then starts at most half the runs it starts at the fixed threshold.
set -eu
REPLAY=$1; BENCH=$2; DATA=$3; WORK=$4
png=$(ls "$DATA"/*.png 2>/dev/null | head -1)
[ -n "$png" ] || { echo "floor_ras6: no scan in $DATA (set SL_BOREAS_RT_DIR)"; exit 1; }
rm -rf "$WORK"; mkdir -p "$WORK/scans/radar"
t=1733239501859565
for i in $(seq 0 23); do cp "$png" "$WORK/scans/radar/$((t + i * 250000)).png"; done
"$REPLAY" from-oxford "$WORK/scans" --out "$WORK/ras6.colossus" --bin-size-m 0.0438 >/dev/null
"$BENCH" "$WORK/ras6.colossus" --board paper-sim > "$WORK/learn.txt"
"$BENCH" "$WORK/ras6.colossus" --board paper-sim --no-learn > "$WORK/fixed.txt"
grep -E "^(model|detect):" "$WORK/learn.txt" "$WORK/fixed.txt"
# model: ... floor_dB/threshold F0/T0 F1/T1 ...: the first two bands (inside the shadow)
thr=$(sed -n 's/^model: .* floor_dB\/threshold //p' "$WORK/learn.txt")
set -- $thr
for band in "$1" "$2"; do
    f=${band%/*}; t=${band#*/}
    [ "$f" != "-" ] || { echo "FAIL: no floor learned in a shadow band ($band)"; exit 1; }
    # the threshold is the smallest value whose power is >= floor + 10 dB (0.5 dB per value)
    want=$(awk -v f="$f" 'BEGIN { v = int(2 * (f + 10)); if (v < 40) v = 40; print v }')
    awk -v t="$t" -v w="$want" 'BEGIN { exit !(t >= w - 1 && t <= w + 1) }' ||
        { echo "FAIL: band threshold $t, want about $want for a floor of $f dB"; exit 1; }
done
runs() { sed -n 's/^detect: runs \([0-9]*\) .*/\1/p' "$1"; }
rl=$(runs "$WORK/learn.txt"); rf=$(runs "$WORK/fixed.txt")
[ $((2 * rl)) -le "$rf" ] || { echo "FAIL: runs $rl with the learned floor, $rf at the fixed threshold"; exit 1; }
echo "floor_ras6: thresholds $1 $2 (floor dB/value), runs $rl learned vs $rf fixed"
