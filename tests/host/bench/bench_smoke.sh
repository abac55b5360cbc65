#!/bin/sh
# SPDX-License-Identifier: MIT
# bench_smoke.sh SL_SIM SL_BENCH SCENE WORKDIR: a 14-rotation simulated pass at 1 m/s through
# sl-bench with the motion input (1000 mm/s) and the simulator's beam spread; checks the
# report's fields, the 64 KiB RAM budget of the firmware build and that targets are found.
set -eu
sim=$1 bench=$2 scene=$3 dir=$4
mkdir -p "$dir"
cap="$dir/smoke.colossus"
"$sim" "$scene" -o "$cap" --rotations 14 --threads 1 --quiet
out=$("$bench" "$cap" --board paper-sim --repeat 1 --speed-mm-s 1000 --beam-cdeg 1200)
echo "$out"
val() { echo "$out" | awk -v k="$1:" '$1 == k {print $2; exit}'; }
fail() { echo "bench_smoke: $*" >&2; exit 1; }
[ "$(val rotations)" = 14 ] || fail "expected 14 rotations"
[ "$(val azimuths)" = 5600 ] || fail "expected 5600 azimuths"
[ "$(val sizeof_pipeline)" -le 65536 ] || fail "sizeof(sl_pipeline_t) above 64 KiB"
[ "$(val targets)" -ge 8 ] || fail "expected the pole in most rotations"
[ -n "$(val MB_per_s)" ] && [ -n "$(val latency_us_mean)" ] || fail "missing throughput/latency"
# Without the motion input (fixed n = 16) the moving pole is never stable.
out=$("$bench" "$cap" --board paper-sim --repeat 1 --beam-cdeg 1200)
[ "$(echo "$out" | awk '$1 == "targets:" {print $2}')" = 0 ] || fail "targets without motion input"
echo "bench_smoke: OK"
