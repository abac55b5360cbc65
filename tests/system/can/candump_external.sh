#!/bin/sh
# SPDX-License-Identifier: MIT
# candump_external.sh ROUNDTRIP_EXE PYTHON SRC_DIR OUT_DIR
# The candump log writer/reader round trip, then the written file through can-utils'
# log2long (must accept every line: it exits 1 on the first line it cannot parse) and
# python-can's CanutilsLogReader (field-by-field comparison).
set -eu
exe=$1; py=$2; src=$3; out=$4
mkdir -p "$out"
"$exe" "$out/rt.log" "$out/rt.expect" 5000
n=$(wc -l < "$out/rt.log")
if command -v log2long >/dev/null 2>&1; then
    log2long < "$out/rt.log" > "$out/rt.long" || { echo "FAIL: log2long rejected the log"; exit 1; }
    m=$(wc -l < "$out/rt.long")
    [ "$n" -eq "$m" ] || { echo "FAIL: log2long printed $m lines for $n frames"; exit 1; }
    # Spot check: the ids log2long printed are the ids of the log, in order.
    awk '{print $3}' "$out/rt.log" | sed 's/#.*//' > "$out/ids.log"
    awk '{print $3}' "$out/rt.long" > "$out/ids.long"
    cmp -s "$out/ids.log" "$out/ids.long" || { echo "FAIL: log2long ids differ"; diff "$out/ids.log" "$out/ids.long" | head; exit 1; }
    echo "log2long: accepted all $n lines, ids identical"
else
    echo "log2long not installed (Debian can-utils): that part skipped"
fi
"$py" "$src/check_pycan.py" "$out/rt.log" "$out/rt.expect"
