#!/bin/sh
# SPDX-License-Identifier: MIT
# callgrind.sh [BENCH] [extra sl-bench-proto args...]
#
# Instructions per azimuth of the decoder + scan assembly (and of the decoder alone),
# counted by valgrind's callgrind over the measured function only (sl_bench_run, via
# --toggle-collect), so building the test stream is not counted. Parses callgrind's
# "summary:"/"totals:" line and the bench's "azimuths:" line. Use a RelWithDebInfo build:
#   cmake -S . -B build/proto-rel -DCMAKE_BUILD_TYPE=RelWithDebInfo
#   cmake --build build/proto-rel --target sl-bench-proto
#   host_tools/bench_proto/callgrind.sh build/proto-rel/host_tools/bench_proto/sl-bench-proto
# Default stream: 4 rotations x 400 azimuths x 3768 8-bit bins, one chunk size per run.
set -eu
bench=${1:-build/proto-rel/host_tools/bench_proto/sl-bench-proto}
[ $# -gt 0 ] && shift
command -v valgrind >/dev/null || { echo "callgrind.sh: valgrind not installed" >&2; exit 2; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_cg.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
printf '%-14s %-8s %14s %10s %12s\n' mode chunk instructions azimuths "instr/azimuth"
for mode in scan proto; do
    for chunk in 65536 1448; do
        valgrind --tool=callgrind --toggle-collect=sl_bench_run \
            --callgrind-out-file="$tmp/cg.$mode.$chunk" \
            "$bench" --rotations 4 --repeat 1 --mode "$mode" --chunk "$chunk" "$@" \
            >"$tmp/log.$mode.$chunk" 2>"$tmp/err.$mode.$chunk" || {
                cat "$tmp/err.$mode.$chunk" >&2; exit 1; }
        ir=$(awk '/^(summary|totals):/ {print $2; exit}' "$tmp/cg.$mode.$chunk")
        az=$(awk '/^azimuths:/ {print $2; exit}' "$tmp/log.$mode.$chunk")
        [ -n "$ir" ] && [ -n "$az" ] && [ "$az" -gt 0 ] || {
            echo "callgrind.sh: could not parse totals ($ir) or azimuths ($az)" >&2; exit 1; }
        per=$(awk -v a="$ir" -v b="$az" 'BEGIN {printf "%.0f", a / b}')
        label=$mode; [ "$mode" = scan ] && label="decoder+scan"; [ "$mode" = proto ] && label="decoder"
        printf '%-14s %-8s %14s %10s %12s\n' "$label" "$chunk" "$ir" "$az" "$per"
    done
done
