#!/bin/sh
# SPDX-License-Identifier: MIT
# junk_cost.sh BENCH_JUNK [MAX]: instructions per junk byte of the decoder's resync, counted
# by valgrind's callgrind over sl_bench_junk_run only (1 MiB per kind, 64 KiB and 1448-byte
# chunks). With MAX, exits 1 when zero fill, random bytes or a repeated signature prefix
# (lengths 1..15) costs more than MAX instructions per byte; fe and badsig are reported only.
set -eu
bench=$1
max=${2:-}
command -v valgrind >/dev/null || { echo "junk_cost.sh: valgrind not installed" >&2; exit 2; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/sl_junk.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
kinds="zero random prefix1 prefix2 prefix3 prefix4 prefix5 prefix6 prefix7 prefix8 prefix9"
kinds="$kinds prefix10 prefix11 prefix12 prefix13 prefix14 prefix15 fe badsig"
bad=0
printf '%-9s %6s %12s %10s %11s\n' kind chunk instructions bytes instr/byte
for chunk in 65536 1448; do
    for k in $kinds; do
        valgrind --tool=callgrind --toggle-collect=sl_bench_junk_run \
            --callgrind-out-file="$tmp/cg" "$bench" "$k" 1048576 "$chunk" >"$tmp/log" 2>"$tmp/err" || {
                cat "$tmp/err" "$tmp/log" >&2; echo "junk_cost.sh: $k failed" >&2; exit 1; }
        ir=$(awk '/^(summary|totals):/ {print $2; exit}' "$tmp/cg")
        by=$(awk '/^bytes:/ {print $2; exit}' "$tmp/log")
        per=$(awk -v a="$ir" -v b="$by" 'BEGIN {printf "%.2f", a / b}')
        note=
        case $k in fe|badsig) note="(reported)";; esac
        if [ -n "$max" ] && [ -z "$note" ] && awk -v p="$per" -v m="$max" 'BEGIN {exit !(p > m)}'; then
            note="ABOVE $max"
            bad=1
        fi
        printf '%-9s %6s %12s %10s %11s %s\n' "$k" "$chunk" "$ir" "$by" "$per" "$note"
    done
done
[ "$bad" = 0 ] || { echo "junk_cost.sh: resync above $max instructions per byte" >&2; exit 1; }
echo "junk_cost.sh: OK"
