#!/bin/sh
# SPDX-License-Identifier: MIT
# check_size_budget.sh SIZE CPU BUDGET_FILE FILE...
# Compares the footprint of every object of a core archive (and of a linked image) with
# firmware/size_budget.txt: per object text, rodata, data, bss in bytes for the firmware
# configuration at -Os. An object without its own row takes the CPU's "*" row (new modules
# are covered without editing the file); "TOTAL" bounds the sum over the archive's core
# objects (board tables have their own row, one per linked board). Prints
# the table, exits 1 naming every value over its budget. Run after every Cortex-M build of
# sl_core / the example firmware (POST_BUILD) and by ctest (check_size_budget_*).
set -eu
SIZE=$1; CPU=$2; BUDGET=$3; shift 3
here=$(dirname "$0")
rows=$(for f in "$@"; do $SIZE -A "$f" | awk -f "$here/size_table.awk"; done | sort)
printf '%s\n' "$rows" | awk -v cpu="$CPU" -v bf="$BUDGET" '
    BEGIN {
        while ((getline line < bf) > 0) {
            sub(/#.*/, "", line); n = split(line, f, /[ \t]+/)
            if (n < 6 || f[1] != cpu) continue
            nb++; pat[nb] = f[2]; bt[nb] = f[3]; br[nb] = f[4]; bd[nb] = f[5]; bb[nb] = f[6]
        }
        if (nb == 0) { print "check_size_budget: no rows for " cpu " in " bf; exit 2 }
        printf "%-26s %14s %14s %10s %10s\n", "object (" cpu ")", "text/budget", "rodata/budget", "data", "bss"
    }
    function find(o,   i, re) {
        for (i = 1; i <= nb; i++) {
            if (pat[i] == "*" || pat[i] == "TOTAL") continue
            re = pat[i]; gsub(/\./, "\\.", re); gsub(/\*/, ".*", re)
            if (o ~ ("^" re "$")) return i
        }
        for (i = 1; i <= nb; i++) if (pat[i] == "*") return i
        return 0
    }
    function chk(o, what, v, b) { if (v > b) { printf "OVER BUDGET: %s %s %d > %d\n", o, what, v, b; bad = 1 } }
    NF == 5 {
        i = find($1)
        if (i == 0) { print "check_size_budget: no budget row for " $1; bad = 1; next }
        printf "%-26s %6d/%-7d %6d/%-7d %10d %10d\n", $1, $2, bt[i], $3, br[i], $4, $5
        chk($1, "text", $2, bt[i]); chk($1, "rodata", $3, br[i]); chk($1, "data", $4, bd[i]); chk($1, "bss", $5, bb[i])
        if ($1 != "image" && $1 !~ /^sl_board_/) { st += $2; sr += $3; sd += $4; sb += $5; na++ }
    }
    END {
        if (nb == 0) exit 2
        for (i = 1; i <= nb; i++) if (pat[i] == "TOTAL" && na > 0) {
            printf "%-26s %6d/%-7d %6d/%-7d %10d %10d\n", "TOTAL (core, no boards)", st, bt[i], sr, br[i], sd, sb
            chk("TOTAL", "text", st, bt[i]); chk("TOTAL", "rodata", sr, br[i]); chk("TOTAL", "data", sd, bd[i]); chk("TOTAL", "bss", sb, bb[i])
        }
        if (bad) { print "check_size_budget: " cpu " over budget (firmware/size_budget.txt)"; exit 1 }
        print "check_size_budget: " cpu " within budget"
    }'
