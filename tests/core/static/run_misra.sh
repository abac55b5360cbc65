#!/bin/sh
# SPDX-License-Identifier: MIT
# run_misra.sh CPPCHECK RECORD INCLUDE_DIR SRC...
# MISRA C:2012 with cppcheck's misra addon on the core (firmware configuration). Every rule
# the addon reports must have a row in the deviation record RECORD (docs/MISRA.md:
# "| rule | category | findings | reason |"); a reported rule without a row, or any
# Mandatory rule, fails (exit 1) and is named. Prints the findings per rule next to the
# record's count. New findings of an already recorded rule pass (the record names the
# rule and the reason, not a line list), so new code is held to the same record.
set -eu
CPPCHECK=$1; RECORD=$2; INC=$3; shift 3
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
# A private build dir: the addon's dump files go there, not beside the sources, so
# concurrent runs (the self test, other trees) cannot clobber each other's dumps.
mkdir -p "$tmp/build"
"$CPPCHECK" --quiet --addon=misra --std=c11 -I "$INC" --cppcheck-build-dir="$tmp/build" \
    -DSL_CFG_MASK_BINS=160 -DSL_CFG_MASK_FRAMES_MAX=16 \
    --template='{file}:{line}: {id}' "$@" > "$tmp/out" 2>&1 || true
grep -o 'misra-c2012-[0-9]*\.[0-9]*' "$tmp/out" | sed 's/misra-c2012-//' | sort | uniq -c > "$tmp/counts" || true
sed -n 's/^| *\([0-9][0-9]*\.[0-9][0-9]*\) *| *\(Mandatory\|Required\|Advisory\) *| *\([0-9]*\) *|.*/\1 \2 \3/p' "$RECORD" > "$tmp/record"
[ -s "$tmp/record" ] || { echo "run_misra: no rule rows in $RECORD"; exit 2; }
awk -v rec="$tmp/record" '
    BEGIN { while ((getline l < rec) > 0) { split(l, f, " "); cat[f[1]] = f[2]; had[f[1]] = f[3] } 
            printf "%-6s %-10s %8s %8s\n", "rule", "category", "found", "record" }
    { n = $1; r = $2; total += n
      if (!(r in cat)) { printf "%-6s %-10s %8d %8s  NOT IN THE DEVIATION RECORD\n", r, "?", n, "-"; bad = 1; next }
      printf "%-6s %-10s %8d %8s%s\n", r, cat[r], n, had[r], (cat[r] == "Mandatory") ? "  MANDATORY: may not be deviated" : ""
      if (cat[r] == "Mandatory") bad = 1 }
    END { printf "total %d findings\n", total
          if (bad) { print "run_misra: findings outside the deviation record"; exit 1 }
          print "run_misra: every reported rule has a deviation record" }' "$tmp/counts"
