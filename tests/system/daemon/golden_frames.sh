#!/bin/sh
# SPDX-License-Identifier: MIT
# golden_frames.sh SL_SIM SL_REPLAY SHADOWLEAND SRC_DIR OUT_DIR OXFORD_DIR [--pipe|--regen]
# Behaviour pinned byte for byte: the CAN frames (candump -L log, data clock) the daemon
# writes for the demo scene (scenes/demo_three_poles.ini through sl-sim) and for the
# 11 real Oxford scans (sl-replay from-oxford), each read from a file (and with --pipe from
# a pipe on stdin, `--input -`, as fast as possible and --realtime), must equal tests/system/daemon/golden/<name>.candump. The golden logs were written by
# the daemon at "Layers step 1" (a pure move of main 1eb0496), before the capture reader
# moved into the port. The sha256 of each input
# capture is pinned too, so a changed simulator is told apart from a changed daemon.
# A deliberate behaviour change: rerun with --regen and commit the new golden files.
set -u
SL_SIM=$1; SL_REPLAY=$2; DAEMON=$3; SRC=$4; OUT=$5; OX=$6; REGEN=${7:-}
G="$SRC/golden"
rm -rf "$OUT"; mkdir -p "$OUT"
fail=0

check() { # name board capture
    name=$1; board=$2; cap=$3
    sum=$(sha256sum < "$cap" | cut -d' ' -f1)
    "$DAEMON" --board "$board" --input "$cap" --can-log "$OUT/$name.candump" -q ||
        { echo "FAIL: $name: shadowleand exit status $?"; fail=1; return; }
    if [ "$REGEN" = "--regen" ]; then
        cp "$OUT/$name.candump" "$G/$name.candump"
        echo "$sum" > "$G/$name.input.sha256"
        echo "regenerated $G/$name.candump ($(wc -l < "$G/$name.candump") frames)"
        return
    fi
    if [ "$sum" != "$(cat "$G/$name.input.sha256")" ]; then
        echo "FAIL: $name: the input capture changed (sha256 $sum): simulator or converter, not the daemon"
        fail=1; return
    fi
    n=$(wc -l < "$G/$name.candump")
    [ "$n" -gt 0 ] || { echo "FAIL: $name: empty golden log"; fail=1; return; }
    if cmp "$G/$name.candump" "$OUT/$name.candump"; then
        echo "$name: $n frames byte for byte (file input)"
    else
        echo "FAIL: $name: frames differ from $G/$name.candump"
        diff "$G/$name.candump" "$OUT/$name.candump" | head -10; fail=1
    fi
    [ "$REGEN" = "--pipe" ] || return
    # The same capture through a pipe: no byte lost to format sniffing.
    cat "$cap" | "$DAEMON" --board "$board" --input - --can-log "$OUT/$name.pipe.candump" -q ||
        { echo "FAIL: $name: shadowleand --input - exit status $?"; fail=1; return; }
    if cmp "$G/$name.candump" "$OUT/$name.pipe.candump"; then
        echo "$name: $n frames byte for byte (stdin pipe)"
    else
        echo "FAIL: $name: frames through a pipe differ"; diff "$G/$name.candump" "$OUT/$name.pipe.candump" | head -5; fail=1
    fi
    # ... and paced in real time (messages held until due): the same frames.
    cat "$cap" | "$DAEMON" --board "$board" --input - --realtime --can-log "$OUT/$name.rt.candump" -q ||
        { echo "FAIL: $name: shadowleand --input - --realtime exit status $?"; fail=1; return; }
    if cmp "$G/$name.candump" "$OUT/$name.rt.candump"; then
        echo "$name: $n frames byte for byte (stdin pipe, --realtime)"
    else
        echo "FAIL: $name: frames through a pipe differ"; diff "$G/$name.candump" "$OUT/$name.pipe.candump" | head -5; fail=1
    fi
}

"$SL_SIM" "$SRC/../../../scenes/demo_three_poles.ini" -o "$OUT/demo.colossus" --threads 1 --quiet || exit 1
check demo_three_poles paper-sim "$OUT/demo.colossus"
if [ -d "$OX" ]; then
    "$SL_REPLAY" from-oxford "$OX" --out "$OUT/oxford.colossus" > /dev/null || exit 1
    check oxford_robotcar robotcar-leaf "$OUT/oxford.colossus"
else
    echo "FAIL: $OX missing (the Oxford scans are part of the test data)"; fail=1
fi
exit $fail
