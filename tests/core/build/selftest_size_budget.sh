#!/bin/sh
# SPDX-License-Identifier: MIT
# selftest_size_budget.sh CHECK SIZE CPU BUDGET_FILE ARCHIVE
# Proves the size check can fail: the real archive must pass the real budget, and fail
# (exit 1, naming mask.c) against a copy whose mask.c text budget is cut to 1 byte.
set -eu
CHECK=$1; SIZE=$2; CPU=$3; BUDGET=$4; LIB=$5
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
sh "$CHECK" "$SIZE" "$CPU" "$BUDGET" "$LIB" >/dev/null || { echo "baseline fails the budget"; exit 1; }
sed "s/^\($CPU  *mask\.c  *\)[0-9][0-9]*/\11/" "$BUDGET" > "$tmp/budget.txt"
cmp -s "$BUDGET" "$tmp/budget.txt" && { echo "SELFTEST FAILED: no mask.c row for $CPU to cut"; exit 1; }
set +e
out=$(sh "$CHECK" "$SIZE" "$CPU" "$tmp/budget.txt" "$LIB" 2>&1)
rc=$?
set -e
echo "$out" | grep -E "OVER|check_size_budget" || true
[ $rc -eq 1 ] || { echo "SELFTEST FAILED: exit $rc, expected 1"; exit 1; }
echo "$out" | grep -q "OVER BUDGET: mask.c text" || { echo "SELFTEST FAILED: mask.c not named"; exit 1; }
echo "selftest OK: an object over its budget fails the check"
