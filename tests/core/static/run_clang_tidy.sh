#!/bin/sh
# SPDX-License-Identifier: MIT
# run_clang_tidy.sh CLANG_TIDY CONFIG INCLUDE_DIR SRC...: every core source with the
# checks in CONFIG, firmware configuration; exit 1 on any finding (printed).
set -eu
TIDY=$1; CONFIG=$2; INC=$3; shift 3
out=$(for f in "$@"; do
    "$TIDY" -quiet --config-file="$CONFIG" "$f" -- -std=c11 -I"$INC" \
        -DSL_CFG_MASK_BINS=160 -DSL_CFG_MASK_FRAMES_MAX=16 2>/dev/null || true
done)
n=$(printf '%s\n' "$out" | grep -cE '(warning|error): ' || true)
if [ "$n" -ne 0 ]; then
    printf '%s\n' "$out"
    echo "static_clang_tidy: $n finding(s)"
    exit 1
fi
echo "static_clang_tidy: $# files, 0 findings"
