#!/bin/sh
# SPDX-License-Identifier: MIT
# run_cppcheck.sh CPPCHECK SUPPRESSIONS INCLUDE_DIR SRC...: warning, style, performance and
# portability checks on the core, firmware configuration, as GCC compiles it (__GNUC__:
# SL_ASSERT traps with __builtin_trap, which cppcheck knows does not return); exit 1 on any
# unsuppressed finding.
set -eu
CPPCHECK=$1; SUPP=$2; INC=$3; shift 3
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
out=$("$CPPCHECK" --quiet --cppcheck-build-dir="$tmp" --enable=warning,style,performance,portability --std=c11 \
    --inline-suppr --suppressions-list="$SUPP" -I "$INC" \
    -DSL_CFG_MASK_BINS=160 -DSL_CFG_MASK_FRAMES_MAX=16 -D__GNUC__=12 \
    --template='{file}:{line}: {severity} {id}: {message}' "$@" 2>&1 || true)
n=$(printf '%s\n' "$out" | grep -c ': [a-z]* [A-Za-z0-9_]*: ' || true)
if [ "$n" -ne 0 ]; then
    printf '%s\n' "$out"
    echo "static_cppcheck: $n finding(s)"
    exit 1
fi
echo "static_cppcheck: $# files, 0 unsuppressed findings"
