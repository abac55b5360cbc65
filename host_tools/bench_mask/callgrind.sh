#!/bin/sh
# SPDX-License-Identifier: MIT
# callgrind.sh [BUILD_DIR] [extra sl-bench-mask args...]
#
# Instructions per azimuth and per rotation of each detection stage (threshold, mask update
# incl. end of rotation, detection from the mask, tracking) and of all four together, for
# n = 4, 16, 32 (the sl-bench-mask-n<N> variants), counted by valgrind's callgrind. The
# bench switches collection on around one stage for the measured rotations only
# (--collect-atstart=no + CALLGRIND_TOGGLE_COLLECT), so building the scene and the warm-up
# rotations are not counted. Use a RelWithDebInfo build:
#   cmake -S . -B build/detect-rel -DCMAKE_BUILD_TYPE=RelWithDebInfo
#   cmake --build build/detect-rel --target sl-bench-mask-n4 sl-bench-mask-n16 sl-bench-mask-n32
#   host_tools/bench_mask/callgrind.sh build/detect-rel
set -eu
build=${1:-build/detect-rel}
[ $# -gt 0 ] && shift
command -v valgrind >/dev/null || { echo "callgrind.sh: valgrind not installed" >&2; exit 2; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_cgm.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
printf '%-4s %-8s %14s %8s %12s %14s\n' n stage instructions azimuths instr/az instr/rotation
# Full 512-bin ROI for n = 4, 16, 32; then n = 16 thresholding and masking only the bins
# detection reads (--detect-bins).
for run in 4 16 32 16d; do
    n=${run%d}
    extra=""
    [ "$run" = 16d ] && extra="--detect-bins"
    bench="$build/host_tools/bench_mask/sl-bench-mask-n$n"
    [ -x "$bench" ] || { echo "callgrind.sh: $bench not built" >&2; exit 2; }
    "$bench" $extra "$@" | sed -n '1,2p' | sed "s/^/# /"
    for stage in thresh mask detect track all; do
        valgrind --tool=callgrind --collect-atstart=no \
            --callgrind-out-file="$tmp/cg.$n.$stage" \
            "$bench" $extra --collect "$stage" "$@" >"$tmp/log.$n.$stage" 2>"$tmp/err.$n.$stage" || {
                cat "$tmp/log.$n.$stage" "$tmp/err.$n.$stage" >&2; exit 1; }
        ir=$(awk '/^(summary|totals):/ {print $2; exit}' "$tmp/cg.$n.$stage")
        az=$(awk '/^azimuths:/ {print $2; exit}' "$tmp/log.$n.$stage")
        [ -n "$ir" ] && [ -n "$az" ] && [ "$az" -gt 0 ] || {
            echo "callgrind.sh: could not parse totals ($ir) or azimuths ($az)" >&2; exit 1; }
        per=$(awk -v a="$ir" -v b="$az" 'BEGIN {printf "%.0f", a / b}')
        rot=$(awk -v a="$ir" -v b="$az" 'BEGIN {printf "%.0f", a / b * 400}')
        printf '%-4s %-8s %14s %8s %12s %14s\n' "$run" "$stage" "$ir" "$az" "$per" "$rot"
    done
done
