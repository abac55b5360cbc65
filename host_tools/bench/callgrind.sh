#!/bin/sh
# SPDX-License-Identifier: MIT
# callgrind.sh [BUILD_DIR] CAPTURE [sl-bench args...]
#
# Instructions of the whole pipeline (sl_pipeline_feed over CAPTURE, 64 KiB chunks unless
# --chunk is given) per azimuth and per rotation, and of the latency path (from the feed of
# the message that completes a rotation to the on_rotation callback), counted by valgrind's
# callgrind. sl-bench toggles collection itself (--collect-atstart=no +
# CALLGRIND_TOGGLE_COLLECT from valgrind/callgrind.h): pipeline init, reading the capture and
# the pre-pass over message boundaries are not counted. Latency in microseconds is the
# instruction count at an ASSUMED 1 instruction per ns (1 GHz at IPC 1, a conservative
# figure for an aarch64 companion computer: Cortex-A53 1.2-1.5 GHz, IPC ~0.7-1; A72 higher).
# Use a RelWithDebInfo build:
#   cmake -S . -B build/pipe-rel -DCMAKE_BUILD_TYPE=RelWithDebInfo
#   cmake --build build/pipe-rel --target sl-bench
#   host_tools/bench/callgrind.sh build/pipe-rel capture.colossus --board robotcar-leaf
# BENCH=sl-bench-host selects the host-default build of the same program.
set -eu
build=${1:?usage: callgrind.sh BUILD_DIR CAPTURE [args]}
cap=${2:?usage: callgrind.sh BUILD_DIR CAPTURE [args]}
shift 2
bench="$build/host_tools/bench/${BENCH:-sl-bench}"
[ -x "$bench" ] || { echo "callgrind.sh: $bench not built" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "callgrind.sh: valgrind not installed" >&2; exit 2; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_cgb.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM

for mode in run latency; do
    valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$tmp/cg.$mode" \
        "$bench" "$cap" --callgrind "$mode" "$@" >"$tmp/log.$mode" 2>"$tmp/err.$mode" || {
            cat "$tmp/log.$mode" "$tmp/err.$mode" >&2; exit 1; }
done
ir=$(awk '/^(summary|totals):/ {print $2; exit}' "$tmp/cg.run")
az=$(awk '/^azimuths:/ {print $2; exit}' "$tmp/log.run")
rot=$(awk '/^rotations:/ {print $2; exit}' "$tmp/log.run")
lir=$(awk '/^(summary|totals):/ {print $2; exit}' "$tmp/cg.latency")
lrot=$(awk '/^latency_rotations:/ {print $2; exit}' "$tmp/log.latency")
[ -n "$ir" ] && [ -n "$az" ] && [ "$az" -gt 0 ] && [ -n "$rot" ] && [ "$rot" -gt 0 ] || {
    echo "callgrind.sh: could not parse totals ($ir), azimuths ($az), rotations ($rot)" >&2; exit 1; }
grep -E '^(capture|board|config|sizeof_pipeline|bytes|messages|chunk|targets|missing|detect|tilt):' "$tmp/log.run"
# Cost per 3D tilt fit: sl_tilt_fit's inclusive instructions / fits (with --speed-mm-s).
fits=$(awk '/^tilt:/ {print $5; exit}' "$tmp/log.run")
if [ -n "$fits" ] && [ "$fits" -gt 0 ] && command -v callgrind_annotate >/dev/null; then
    fit_ir=$(callgrind_annotate --inclusive=yes "$tmp/cg.run" 2>/dev/null |
        awk '/sl_tilt_fit[^_]/ || /sl_tilt_fit$/ {gsub(",", "", $1); print $1; exit}')
    [ -n "$fit_ir" ] && awk -v a="$fit_ir" -v f="$fits" -v z="$az" 'BEGIN {
        printf "tilt_fit_instructions: %.0f per fit (%d fits; %.1f per azimuth on average)\n", a / f, f, a / z }'
fi
echo "instructions: $ir"
awk -v a="$ir" -v z="$az" -v r="$rot" 'BEGIN {
    printf "instructions_per_azimuth: %.0f\n", a / z
    printf "instructions_per_rotation: %.0f   (total / %d rotations; %.0f per 400 azimuths)\n", a / r, r, a / z * 400 }'
if [ -n "$lir" ] && [ -n "$lrot" ] && [ "$lrot" -gt 0 ]; then
    awk -v a="$lir" -v r="$lrot" 'BEGIN {
        printf "latency_instructions: %.0f   (mean over %d rotations)\n", a / r, r
        printf "latency_us_at_1GHz_IPC1: %.1f\n", a / r / 1000 }'
fi
