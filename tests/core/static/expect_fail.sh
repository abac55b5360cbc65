#!/bin/sh
# SPDX-License-Identifier: MIT
# expect_fail.sh PATTERN COMMAND...: the command must exit 1 and print PATTERN (a checker
# run on an injected defect), proving the checker can fail.
set -u
PAT=$1; shift
out=$("$@" 2>&1); rc=$?
printf '%s\n' "$out" | tail -5
[ $rc -eq 1 ] || { echo "SELFTEST FAILED: exit $rc, expected 1"; exit 1; }
printf '%s\n' "$out" | grep -q "$PAT" || { echo "SELFTEST FAILED: '$PAT' not reported"; exit 1; }
echo "selftest OK: the injected defect was reported ($PAT)"
