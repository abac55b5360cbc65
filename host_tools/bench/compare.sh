#!/bin/sh
# SPDX-License-Identifier: MIT
# compare.sh [BUILD_DIR] CAPTURE [--board NAME] [--loop N] [--repeat N] [sl-bench args...]
#
# Side by side in one run, on the same capture (read whole into memory by both, then
# --loop N copies): sl-bench (the C pipeline, firmware configuration, 64 KiB chunks) and
# reference_numpy.py (a straightforward NumPy implementation of the same front-end steps:
# parse messages, ROI copy, threshold, n-frame consistency, run extraction). The NumPy side
# gets the pipeline's own parameters (masked bins as its ROI, threshold, n, near band, widest
# search window) from sl-bench's output. Prints both MB/s (best of --repeat) and the ratio;
# exits 1 when the C pipeline is less than 10x faster. Wall clock: run it on an idle machine.
#   host_tools/bench/compare.sh build/pipe-rel capture.colossus --board robotcar-leaf --loop 8
set -eu
build=${1:?usage: compare.sh BUILD_DIR CAPTURE [--board NAME] [--loop N] [--repeat N] [args]}
cap=${2:?usage: compare.sh BUILD_DIR CAPTURE [args]}
shift 2
here=$(dirname "$0")
bench="$build/host_tools/bench/sl-bench"
py=${PYTHON:-/usr/bin/python3}
[ -x "$bench" ] || { echo "compare.sh: $bench not built" >&2; exit 2; }
"$py" -c 'import numpy' 2>/dev/null || {
    echo "compare.sh: $py has no numpy (Debian python3-numpy: scripts/deps.sh test)" >&2; exit 2; }
loop=1
repeat=5
args=""
while [ $# -gt 0 ]; do
    case "$1" in
    --loop) loop=$2; shift 2 ;;
    --repeat) repeat=$2; shift 2 ;;
    *) args="$args $1"; shift ;;
    esac
done
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_cmp.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
# shellcheck disable=SC2086
"$bench" "$cap" --loop "$loop" --repeat "$repeat" $args >"$tmp/c.txt"
val() { awk -v k="$1:" '$1 == k {print $2; exit}' "$2"; }
c_mbs=$(val MB_per_s "$tmp/c.txt")
bins=$(awk '/^missing:/ {for (i = 1; i < NF; i++) if ($i == "mask_bins:") print $(i + 1)}' "$tmp/c.txt")
n=$(awk '/^missing:/ {for (i = 1; i < NF; i++) if ($i == "n:") print $(i + 1)}' "$tmp/c.txt")
near=$(awk '/^detect_window:/ {print $3}' "$tmp/c.txt")
win=$(awk '/^detect_window:/ {print $5}' "$tmp/c.txt")
thr=$(echo "$args" | awk '{for (i = 1; i < NF; i++) if ($i == "--threshold") print $(i + 1)}')
[ -n "$thr" ] || thr=40
"$py" "$here/reference_numpy.py" "$cap" --loop "$loop" --repeat "$repeat" --roi "$bins" \
    --n "$n" --near "$near" --win "$win" --threshold "$thr" >"$tmp/py.txt"
py_mbs=$(val MB_per_s "$tmp/py.txt")
grep -E '^(capture|board|sizeof_pipeline|bytes|rotations|azimuths):' "$tmp/c.txt"
echo "parameters: masked bins $bins, n $n, near $near, window $win, threshold $thr"
echo "C pipeline (sl-bench):      $c_mbs MB/s"
echo "NumPy (reference_numpy.py): $py_mbs MB/s"
awk -v c="$c_mbs" -v p="$py_mbs" 'BEGIN {
    r = c / p; printf "ratio: %.1fx (target >= 10x)\n", r; exit !(r >= 10) }'
