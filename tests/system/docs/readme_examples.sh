#!/bin/sh
# SPDX-License-Identifier: MIT
# readme_examples.sh SRC_DIR BUILD_DIR CC PYTHON: the README's examples, extracted from README.md
# as littlefs extracts its README's example, built or run in a scratch folder:
#   <!-- test: readme-sh -->            the next ```sh block runs with the build's tools first on
#                                       PATH and the Python package on PYTHONPATH; exit status 0
#   <!-- test: readme-c -->             the next ```c block compiles against the core and the
#                                       paper-sim board and runs on the demo scene's capture
#   <!-- test: readme-demo-output -->   the next ```text block is the demo's output: the same
#                                       scene through the daemon (capture input) decoded gives
#                                       the same rows (the link column aside: the demo's radar
#                                       emulator has stopped, a capture keeps STREAMING)
set -u
SRC=$1; B=$2; CC=$3; PY=$4
W=$B/readme-examples
rm -rf "$W"; mkdir -p "$W"
fail=0
block() { # MARKER N: the Nth block after the marker line
    awk -v m="<!-- test: $1 -->" -v want="$2" '
        $0 == m { armed = 1; next }
        armed && /^```/ && !inb { inb = 1; k++; next }
        inb && /^```/ { inb = 0; armed = 0; next }
        inb && k == want { print }' "$SRC/README.md"
}
count() { grep -c "^<!-- test: $1 -->\$" "$SRC/README.md"; }

for d in boards scenes tests python; do ln -s "$SRC/$d" "$W/$d"; done
TOOLS=$B/apps/shadowleand
for t in sim eval replay inspect view calib tables alpha dbc; do TOOLS=$TOOLS:$B/host_tools/$t; done
PYDIR=$(dirname "$PY")

n=$(count readme-sh)
[ "$n" -ge 1 ] || { echo "FAIL: no readme-sh block"; fail=1; }
i=1
while [ "$i" -le "$n" ]; do
    block readme-sh "$i" > "$W/sh$i.sh"
    if (cd "$W" && PATH="$TOOLS:$PYDIR:$PATH" PYTHONPATH="$SRC/python" sh -e "sh$i.sh" > "sh$i.out" 2>&1); then
        echo "readme-sh block $i: ok ($(wc -l < "$W/sh$i.sh") lines)"
    else
        echo "FAIL: readme-sh block $i:"; cat "$W/sh$i.sh"; tail -20 "$W/sh$i.out"; fail=1
    fi
    i=$((i + 1))
done

[ "$(count readme-c)" -eq 1 ] || { echo "FAIL: expected one readme-c block"; fail=1; }
block readme-c 1 > "$W/example.c"
if $CC -std=c11 -Wall -Wextra -Werror -I"$SRC/include" -I"$B/include" -I"$SRC/boards/paper-sim" \
    "$W/example.c" "$B/firmware/core/libsl_core.a" -o "$W/example" 2> "$W/cc.err"; then
    "$B/host_tools/sim/sl-sim" "$SRC/scenes/demo_three_poles.ini" -o "$W/demo.colossus" --quiet &&
        "$W/example" < "$W/demo.colossus" > "$W/example.out" &&
        echo "readme-c: built and ran: $(cat "$W/example.out")" ||
        { echo "FAIL: readme-c example did not run"; cat "$W/example.out"; fail=1; }
else
    echo "FAIL: readme-c example does not compile:"; cat "$W/cc.err"; fail=1
fi

block readme-demo-output 1 > "$W/readme_demo.txt"
"$B/host_tools/sim/sl-sim" "$SRC/scenes/demo_three_poles.ini" -o "$W/scene.colossus" --quiet &&
    "$B/apps/shadowleand/shadowleand" --board paper-sim --input "$W/scene.colossus" --can-log "$W/can.log" -q || fail=1
DBC=$SRC/boards/paper-sim/shadowlean.dbc
{
    "$PY" "$SRC/scripts/sl_can_decode.py" "$DBC" "$W/can.log" --table --last 1
    echo "== 5. Decoded leans against the simulator's truth"
    "$PY" "$SRC/tests/system/daemon/lean_vs_truth.py" "$DBC" "$W/can.log" "$W/scene.gt.csv" --tol 1.0 | grep -v '^lean_vs_truth:'
} > "$W/demo_now.txt"
norm() { sed -e 's/SILENT\|STREAMING/LINK/' -e 's/[[:space:]]\+/ /g' -e 's/^ //' -e 's/ $//' "$1"; }
if norm "$W/readme_demo.txt" > "$W/a" && norm "$W/demo_now.txt" > "$W/b" && [ -s "$W/a" ] && cmp -s "$W/a" "$W/b"; then
    echo "readme-demo-output: the README's demo output is the current one"
else
    echo "FAIL: the README's demo output differs from the current run (README first):"
    diff "$W/a" "$W/b"; fail=1
fi
[ $fail -eq 0 ] && echo "readme_examples: OK"
exit $fail
