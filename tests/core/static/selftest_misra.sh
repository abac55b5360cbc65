#!/bin/sh
# SPDX-License-Identifier: MIT
# selftest_misra.sh RUN_MISRA CPPCHECK RECORD INCLUDE_DIR SRC...: the MISRA check must fail
# (exit 1, naming the rule) when the record lacks the row of a rule the code breaks (10.4).
set -eu
RUN=$1; CPPCHECK=$2; RECORD=$3; INC=$4; shift 4
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
grep -v '^| 10\.4 |' "$RECORD" > "$tmp/record.md"
set +e
out=$(sh "$RUN" "$CPPCHECK" "$tmp/record.md" "$INC" "$@" 2>&1)
rc=$?
set -e
echo "$out" | grep -E "NOT IN|run_misra" || true
[ $rc -eq 1 ] || { echo "SELFTEST FAILED: exit $rc, expected 1"; exit 1; }
echo "$out" | grep -q "^10\.4 .*NOT IN THE DEVIATION RECORD" || { echo "SELFTEST FAILED: 10.4 not named"; exit 1; }
echo "selftest OK: a rule without a deviation record fails"
