#!/bin/sh
# SPDX-License-Identifier: MIT
# bad_boards.sh SL_TABLES BAD_DIR WORK: every bad/*.ini must be rejected (exit 1) with a
# message containing the text in its first line "; expect: <text>".
set -eu
GEN=$1; BAD=$2; WORK=$3
mkdir -p "$WORK"
n=0
for ini in "$BAD"/*.ini; do
    want=$(sed -n '1s/^; expect: //p' "$ini")
    set +e
    out=$("$GEN" "$ini" --out "$WORK" --no-png 2>&1)
    rc=$?
    set -e
    if [ $rc -ne 1 ]; then echo "FAIL $ini: exit $rc (want 1): $out"; exit 1; fi
    case "$out" in
        *"$want"*) echo "ok   $(basename "$ini"): $out" ;;
        *) echo "FAIL $ini: message '$out' lacks '$want'"; exit 1 ;;
    esac
    n=$((n + 1))
done
[ $n -ge 5 ] || { echo "too few bad boards ($n)"; exit 1; }
