#!/bin/sh
# SPDX-License-Identifier: MIT
# tools_conventions.sh VERSION WORKDIR EXE[@SUBCOMMAND]...
# The command-line conventions of docs/TOOLS.md, "Conventions", for every
# executable given (tests/host/CMakeLists.txt lists every EXECUTABLE target):
#   --help and -h     usage on stdout (a line starting "usage"), nothing on stderr, exit 0
#   --version         exactly "<program> VERSION" on stdout, nothing on stderr, exit 0
#   --no-such-option  nothing on stdout; stderr names it ("<program>: unknown option
#                     '--no-such-option'") and holds the usage; exit 2
# EXE@SUB runs the same checks as `EXE SUB ...` (subcommand tools).
# Each run has stdin from /dev/null and a time limit, so a tool that would start working
# (read stdin, open a device) instead of answering fails the test instead of hanging it.
set -u
version=$1
work=$2
shift 2
rm -rf "$work"
mkdir -p "$work"
fails=0
checked=0

fail() {
    echo "FAIL: $*"
    fails=$((fails + 1))
}

# run NAME EXE [SUB] ARG: stdout/stderr to $work/NAME.out/.err, status in $rc.
run() {
    name=$1
    exe=$2
    sub=$3
    arg=$4
    if [ -n "$sub" ]; then
        timeout 20 "$exe" "$sub" "$arg" </dev/null >"$work/$name.out" 2>"$work/$name.err"
    else
        timeout 20 "$exe" "$arg" </dev/null >"$work/$name.out" 2>"$work/$name.err"
    fi
    rc=$?
}

for spec in "$@"; do
    case "$spec" in
    *@*) exe=${spec%@*}; sub=${spec##*@} ;;
    *) exe=$spec; sub= ;;
    esac
    prog=$(basename "$exe")
    label=$prog${sub:+ $sub}
    tag=$prog${sub:+-$sub}
    if [ ! -x "$exe" ]; then
        fail "$label: $exe is not built"
        continue
    fi
    checked=$((checked + 1))

    for h in --help -h; do
        run "$tag$h" "$exe" "$sub" "$h"
        out=$work/$tag$h.out
        err=$work/$tag$h.err
        [ "$rc" -eq 0 ] || fail "$label $h: exit $rc, expected 0"
        grep -qi '^usage' "$out" || fail "$label $h: no usage on stdout"
        [ ! -s "$err" ] || fail "$label $h: stderr not empty: $(head -c 200 "$err")"
    done

    run "$tag--version" "$exe" "$sub" --version
    [ "$rc" -eq 0 ] || fail "$label --version: exit $rc, expected 0"
    got=$(cat "$work/$tag--version.out")
    [ "$got" = "$prog $version" ] || fail "$label --version: printed '$got', expected '$prog $version'"
    [ ! -s "$work/$tag--version.err" ] || fail "$label --version: stderr not empty"

    run "$tag--bad" "$exe" "$sub" --no-such-option
    out=$work/$tag--bad.out
    err=$work/$tag--bad.err
    [ "$rc" -eq 2 ] || fail "$label --no-such-option: exit $rc, expected 2"
    [ ! -s "$out" ] || fail "$label --no-such-option: stdout not empty: $(head -c 200 "$out")"
    grep -qF "$prog: unknown option '--no-such-option'" "$err" ||
        fail "$label --no-such-option: stderr does not say \"$prog: unknown option '--no-such-option'\": $(head -c 200 "$err")"
    grep -qi '^usage' "$err" || fail "$label --no-such-option: no usage on stderr"
done

echo "tools_conventions: $checked executables/subcommands checked, $fails failure(s)"
[ "$checked" -gt 0 ] || { echo "FAIL: no executable given"; exit 1; }
[ "$fails" -eq 0 ]
