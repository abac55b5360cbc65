#!/bin/sh
# SPDX-License-Identifier: MIT
# lint_selftest.sh PYTHON LINT: docs_lint must fail on a tree that breaks each of its rules,
# and name every rule (a check that cannot fail proves nothing).
set -u
PY=$1; LINT=$2
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
mkdir -p "$T/docs"
printf '# x\n\n[map](docs/A.md) [gone](docs/NOPE.md)\n' > "$T/README.md"
printf '# A\n\nMeasured in sess%s 17 of rou%s 2.\n' ion nd > "$T/docs/A.md"
printf '# B\n\nData in ..%sshared/data; tried %sleft out.\n' / "and " > "$T/docs/B.md"
out=$("$PY" "$LINT" "$T"); rc=$?
echo "$out"
[ $rc -eq 1 ] || { echo "FAIL: expected exit 1, got $rc"; exit 1; }
for rule in chronology shared-path left-out dead-link doc-map; do
    echo "$out" | grep -q ": $rule: " || { echo "FAIL: rule $rule not reported"; exit 1; }
done
echo "selftest OK: every rule fails on purpose"
