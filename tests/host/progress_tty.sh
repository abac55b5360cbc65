#!/bin/sh
# SPDX-License-Identifier: MIT
# progress_tty.sh SL_SIM SL_EVAL SL_VIEW SL_CALIB SRC OUT: progress of long runs goes to
# stderr only when it is a terminal (host_tools/cli/sl_progress.h), and -q silences it.
# Each tool runs three times on a short job:
#   1. under script(1), which gives it a pseudo-terminal: its progress line must appear;
#   2. with stderr to a file (not a terminal): no progress line, no carriage return;
#   3. under script(1) with -q: no progress line.
# The exit status and the stdout of runs 1 and 2 must be the same.
set -u
SIM=$1; EVAL=$2; VIEW=$3; CALIB=$4; SRC=$5; OUT=$6
rm -rf "$OUT"; mkdir -p "$OUT"
fail=0
command -v script > /dev/null || { echo "FAIL: script(1) (bsdutils) missing"; exit 1; }

# Inputs: 6 rotations of the demo scene and its truth.
"$SIM" "$SRC/scenes/demo_three_poles.ini" -o "$OUT/demo.colossus" --rotations 6 --threads 1 -q ||
    { echo "FAIL: sl-sim"; exit 1; }
[ -s "$OUT/demo.gt.csv" ] || { echo "FAIL: no truth from sl-sim"; exit 1; }

check() { # name progress-regex command... (the command's -q form is "$@ -q")
    name=$1; pattern=$2; shift 2
    cmd=$*
    script -qec "$cmd > $OUT/$name.tty.out" /dev/null > "$OUT/$name.tty" 2>&1; rc_tty=$?
    "$@" > "$OUT/$name.pipe.out" 2> "$OUT/$name.pipe.err"; rc_pipe=$?
    script -qec "$cmd -q > $OUT/$name.quiet.out" /dev/null > "$OUT/$name.quiet" 2>&1; rc_q=$?
    if ! tr '\r' '\n' < "$OUT/$name.tty" | grep -Eq "$pattern"; then
        echo "FAIL: $name: no progress on a terminal (/$pattern/):"; head -c 600 "$OUT/$name.tty"; echo; fail=1
    fi
    if grep -Eq "$pattern" "$OUT/$name.pipe.err" || tr '\r' '@' < "$OUT/$name.pipe.err" | grep -q '@'; then
        echo "FAIL: $name: progress written to a file:"; head -c 600 "$OUT/$name.pipe.err"; echo; fail=1
    fi
    if tr '\r' '\n' < "$OUT/$name.quiet" | grep -Eq "$pattern"; then
        echo "FAIL: $name: progress with -q"; fail=1
    fi
    if [ $rc_tty -ne 0 ] || [ $rc_pipe -ne 0 ] || [ $rc_q -ne 0 ]; then
        echo "FAIL: $name: exit statuses $rc_tty (terminal) $rc_pipe (file) $rc_q (-q)"; fail=1
    fi
    # stdout is the same whether stderr is a terminal or not (sl-eval prints its run time:
    # compared without digits)
    a=$(tr -d '0-9' < "$OUT/$name.tty.out"); b=$(tr -d '0-9' < "$OUT/$name.pipe.out")
    [ "$a" = "$b" ] || { echo "FAIL: $name: stdout differs with a terminal on stderr"; fail=1; }
    n=$(tr '\r' '\n' < "$OUT/$name.tty" | grep -Ec "$pattern")
    echo "$name: $n progress line(s) on a terminal, none to a file, none with -q"
}

check sl-sim 'sl-sim: rotation [0-9]+/6 ' \
    "$SIM" "$SRC/scenes/demo_three_poles.ini" -o "$OUT/again.colossus" --rotations 6 --threads 1
check sl-eval 'sl-eval table1: capture [0-9]+/[0-9]+' \
    "$EVAL" table1 --rotations 2 --threads 1
check sl-view 'sl-view: picture [0-9]+/6 ' \
    "$VIEW" "$OUT/demo.colossus" --board paper-sim --all --out "$OUT/view.png"
check sl-calib-elongation 'sl-calib: capture [0-9]+/2 ' \
    "$CALIB" elongation "$OUT/demo.colossus" "$OUT/demo.colossus" --truth "$OUT/demo.gt.csv" \
    --truth "$OUT/demo.gt.csv" --board paper-sim
[ $fail -eq 0 ] && echo "progress_tty: ok"
exit $fail
