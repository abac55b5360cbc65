#!/bin/sh
# SPDX-License-Identifier: MIT
# selftest_inject.sh CHECKER NM AR CC CFLAGS ARCHIVE SRC SYMBOL_REGEX [--no-softfloat]
# (CHECKER is called as CHECKER NM ARCHIVE [MODE]; the VFP check takes objdump as NM.)
# Proves the symbol check can fail: copies the real core archive, adds one object compiled
# from SRC (which references a forbidden symbol), and requires the checker to exit 1 and
# name the symbol. Also requires the untouched copy to pass, so the failure is the
# injection's.
set -eu
CHECK=$1; NM=$2; AR=$3; CC=$4; CFLAGS=$5; LIB=$6; SRC=$7; PAT=$8; MODE=${9:-}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp "$LIB" "$tmp/clean.a"
sh "$CHECK" "$NM" "$tmp/clean.a" $MODE >/dev/null || { echo "baseline archive fails the check"; exit 1; }
# shellcheck disable=SC2086
$CC $CFLAGS -c "$SRC" -o "$tmp/injected.o"
cp "$LIB" "$tmp/dirty.a"
$AR rs "$tmp/dirty.a" "$tmp/injected.o"
set +e
out=$(sh "$CHECK" "$NM" "$tmp/dirty.a" $MODE 2>&1)
rc=$?
set -e
echo "$out"
[ $rc -eq 1 ] || { echo "SELFTEST FAILED: checker exit $rc, expected 1"; exit 1; }
echo "$out" | grep -Eq "FORBIDDEN.*$PAT" || { echo "SELFTEST FAILED: '$PAT' not named"; exit 1; }
echo "selftest OK: injected $(basename "$SRC") was caught"
