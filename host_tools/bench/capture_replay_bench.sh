#!/bin/sh
# SPDX-License-Identifier: MIT
# capture_replay_bench.sh SHADOWLEAND SL_REPLAY OXFORD_DIR OUT_DIR [MIN_MB]
#
# Whole-process capture replay, side by side in one run on the same file: the daemon
# (`shadowleand --board robotcar-leaf --input CAPTURE --can-log /dev/null`) and the NumPy
# reference (host_tools/bench/reference_numpy.py CAPTURE --repeat 1). The capture is the 11
# real Oxford RobotCar scans (`sl-replay from-oxford`) repeated until it is at least MIN_MB
# MB (default 200; 1 MB = 1e6 bytes). It is read once beforehand so both runs read it from
# the page cache. Each process runs under /usr/bin/time -v (peak RSS) between two readings
# of the wall clock (date +%s%N); the script prints both, GB/s of the whole process (file
# bytes / wall time), user + system CPU seconds (time -v, 10 ms steps; less sensitive to
# a loaded machine than the wall clock) and the speed ratio. The daemon must report every
# byte read.
# Each side runs RUNS times (default 3, alternating); the best wall time of each is shown.
# Measured wall time: run it on an idle machine and use an optimised build
# (cmake --build --preset host-release --target shadowleand sl-replay). No time threshold
# is asserted; the printed figures are the measurement. It fails when the daemon does not
# report every byte read or its peak RSS exceeds 64 MiB.
set -eu
D=${1:?usage: capture_replay_bench.sh SHADOWLEAND SL_REPLAY OXFORD_DIR OUT_DIR [MIN_MB]}
R=${2:?}; OX=${3:?}; OUT=${4:?}; MIN_MB=${5:-200}
here=$(dirname "$0")
py=${PYTHON:-/usr/bin/python3}
[ -x /usr/bin/time ] || { echo "capture_replay_bench.sh: /usr/bin/time missing (Debian: time)" >&2; exit 2; }
"$py" -c 'import numpy' 2>/dev/null || { echo "capture_replay_bench.sh: $py has no numpy" >&2; exit 2; }
mkdir -p "$OUT"
"$R" from-oxford "$OX" --out "$OUT/oxford.colossus" > /dev/null
one=$(wc -c < "$OUT/oxford.colossus")
copies=$(( (MIN_MB * 1000000 + one - 1) / one ))
: > "$OUT/big.colossus"
i=0
while [ $i -lt $copies ]; do cat "$OUT/oxford.colossus" >> "$OUT/big.colossus"; i=$((i + 1)); done
bytes=$(wc -c < "$OUT/big.colossus")
cat "$OUT/big.colossus" > /dev/null # into the page cache
echo "capture: $OUT/big.colossus, $bytes bytes ($copies x the 11 Oxford scans)"

rss() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }
cpu() { awk -F': ' '/User time|System time/ { s += $2 } END { printf "%.2f", s }' "$1"; } # 10 ms steps
now_ns() { date +%s%N; } # wall clock around each whole process (finer than time -v's 10 ms)

# Best (shortest wall) of RUNS runs each, alternating (RUNS=3 unless set).
RUNS=${RUNS:-3}
ds=""; ns=""
r=0
while [ $r -lt "$RUNS" ]; do
    t0=$(now_ns)
    /usr/bin/time -v -o "$OUT/daemon.time.$r" "$D" --board robotcar-leaf --input "$OUT/big.colossus" \
        --can-log /dev/null 2> "$OUT/daemon.err" || { cat "$OUT/daemon.err"; echo "FAIL: shadowleand"; exit 1; }
    t1=$(now_ns)
    /usr/bin/time -v -o "$OUT/numpy.time.$r" "$py" "$here/reference_numpy.py" "$OUT/big.colossus" --repeat 1 \
        > "$OUT/numpy.out" 2>&1 || { cat "$OUT/numpy.out"; echo "FAIL: reference_numpy.py"; exit 1; }
    t2=$(now_ns)
    grep -q "input $OUT/big.colossus (raw): $bytes bytes read, $bytes stream bytes" "$OUT/daemon.err" ||
        { cat "$OUT/daemon.err"; echo "FAIL: the daemon did not read every byte"; exit 1; }
    d1=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f", (b - a) / 1e9 }')
    n1=$(awk -v a="$t1" -v b="$t2" 'BEGIN { printf "%.4f", (b - a) / 1e9 }')
    if [ -z "$ds" ] || awk -v x="$d1" -v y="$ds" 'BEGIN { exit !(x < y) }'; then ds=$d1; cp "$OUT/daemon.time.$r" "$OUT/daemon.time"; fi
    if [ -z "$ns" ] || awk -v x="$n1" -v y="$ns" 'BEGIN { exit !(x < y) }'; then ns=$n1; cp "$OUT/numpy.time.$r" "$OUT/numpy.time"; fi
    r=$((r + 1))
done
dr=$(rss "$OUT/daemon.time"); nr=$(rss "$OUT/numpy.time")
dc=$(cpu "$OUT/daemon.time"); nc=$(cpu "$OUT/numpy.time")
awk -v b="$bytes" -v ds="$ds" -v ns="$ns" -v dr="$dr" -v nr="$nr" -v dc="$dc" -v nc="$nc" 'BEGIN {
    printf "%-22s %9s %11s %12s %9s\n", "whole process (best)", "wall [s]", "wall GB/s", "peak RSS", "CPU [s]"
    printf "%-22s %9.3f %11.2f %8.1f MiB %9.2f\n", "shadowleand --input", ds, b / ds / 1e9, dr / 1024, dc
    printf "%-22s %9.3f %11.2f %8.1f MiB %9.2f\n", "reference_numpy.py", ns, b / ns / 1e9, nr / 1024, nc
    printf "ratio (numpy wall / shadowleand wall): %.1fx\n", ns / ds
}'
# Memory is not timing: the daemon streams, whatever the capture's size.
[ "$dr" -le 65536 ] || { echo "FAIL: shadowleand peak RSS $dr KiB > 64 MiB"; exit 1; }
