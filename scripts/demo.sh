#!/bin/sh
# SPDX-License-Identifier: MIT
# demo.sh: the whole chain on this machine, from a fresh Debian (installs what is missing):
#
#   sl-sim (a bundled scene) -> capture + truth
#   sl-replay serve (a radar emulator on 127.0.0.1, real time, free port)
#   shadowleand --radar 127.0.0.1:PORT --can-log out/demo/can.log (the daemon: TCP in, CAN out)
#   python3-canmatrix decodes the candump log with the board's generated DBC -> warning table,
#   decoded leans next to the simulator's truth, and a picture (sl-view) when it is built.
#
# Scene: scenes/demo_three_poles.ini when present, else tests/system/daemon/scenes/static_four_poles.ini
# (or the scene given as the first argument). A moving scene's speed (speed_mps) is passed as
# --motion (there is no vehicle bus on loopback). Outputs land in out/demo/. About 15 s plus
# the build (host-release preset, only the targets needed).
set -eu
cd "$(dirname "$0")/.."
ROOT=$(pwd)
sh scripts/deps.sh build demo
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j 2 --target shadowleand sl-sim sl-replay
BIN=build/host-release/host_tools
VIEW=""
if [ -f host_tools/view/CMakeLists.txt ] &&
    cmake --build --preset host-release -j 2 --target sl-view >/dev/null 2>&1; then
    VIEW=$BIN/view/sl-view
fi
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
OUT=out/demo
rm -rf "$OUT"
mkdir -p "$OUT"

SCENE=${1:-}
if [ -z "$SCENE" ]; then
    SCENE=scenes/demo_three_poles.ini
    [ -f "$SCENE" ] || SCENE=tests/system/daemon/scenes/static_four_poles.ini
fi
BOARD=$(sed -n 's/^[[:space:]]*board[[:space:]]*=[[:space:]]*\([A-Za-z0-9_-]*\).*/\1/p' "$SCENE" | head -1)
SPEED=$(sed -n 's/^[[:space:]]*speed_mps[[:space:]]*=[[:space:]]*\([-0-9.eE+]*\).*/\1/p' "$SCENE" | head -1)
MOTION=""
case "${SPEED:-0}" in
0|0.0|0.00|-0|"") ;;
*) MOTION="--motion $SPEED" ;; # no vehicle bus on loopback: tell the daemon the scene's speed
esac
DBC=boards/$BOARD/shadowlean.dbc
[ -f "$DBC" ] || { echo "demo: board '$BOARD' of $SCENE has no boards/$BOARD/shadowlean.dbc"; exit 1; }

REPLAY_PID=""
cleanup() {
    if [ -n "$REPLAY_PID" ]; then
        kill "$REPLAY_PID" 2>/dev/null || true
        wait "$REPLAY_PID" 2>/dev/null || true
    fi
}
trap cleanup EXIT INT TERM

echo
echo "== 1. Simulate $SCENE (board $BOARD) with sl-sim"
"$BIN/sim/sl-sim" "$SCENE" -o "$OUT/scene.colossus" --quiet
ROTS=$(awk -F, 'NR > 1 { if ($1 > m) m = $1 } END { print m + 1 }' "$OUT/scene.gt.csv")
echo "   $OUT/scene.colossus ($(wc -c < "$OUT/scene.colossus") bytes, $ROTS rotations) + truth $OUT/scene.gt.csv"

echo
echo "== 2. Serve it as a radar on 127.0.0.1 (sl-replay serve, real time, any free port)"
: > "$OUT/replay.out" # exists before the server writes its port line into it
"$BIN/replay/sl-replay" serve "$OUT/scene.colossus" --port 0 > "$OUT/replay.out" 2> "$OUT/replay.err" &
REPLAY_PID=$!
PORT=""
i=0
while [ -z "$PORT" ]; do
    PORT=$(sed -n 's/^sl-replay: listening on 127\.0\.0\.1:\([0-9][0-9]*\)$/\1/p' "$OUT/replay.out")
    [ -n "$PORT" ] && break
    i=$((i + 1))
    if [ $i -gt 100 ] || ! kill -0 "$REPLAY_PID" 2>/dev/null; then
        echo "demo: sl-replay did not start:"; cat "$OUT/replay.err"; exit 1
    fi
    sleep 0.1
done
echo "   listening on 127.0.0.1:$PORT"

echo
echo "== 3. shadowleand --board $BOARD --radar 127.0.0.1:$PORT --can-log $OUT/can.log${MOTION:+ $MOTION}"
echo "   (stops 1.5 s after the last FFT message: --exit-idle 1.5)"
# shellcheck disable=SC2086
build/host-release/apps/shadowleand/shadowleand --board "$BOARD" --radar "127.0.0.1:$PORT" --can-log "$OUT/can.log" $MOTION \
    --targets-out "$OUT/targets.jsonl" --exit-idle 1.5 --duration 300 --stats-every 2 2>&1 |
    sed 's/^/   /'
kill "$REPLAY_PID" 2>/dev/null || true
wait "$REPLAY_PID" 2>/dev/null || true
REPLAY_PID=""
echo "   $(wc -l < "$OUT/can.log") CAN frames in $OUT/can.log (candump -L format), e.g.:"
head -3 "$OUT/can.log" | sed 's/^/     /'

echo
echo "== 4. The CAN log decoded with $DBC (python3-canmatrix)"
echo "   Every Status frame (collapsed), with the rotation's LeanWarning:"
"$PY" scripts/sl_can_decode.py "$DBC" "$OUT/can.log" --summary | sed 's/^/   /'
echo
echo "   The PoleLean frames of the last rotation (warning = the LeanWarning's target):"
"$PY" scripts/sl_can_decode.py "$DBC" "$OUT/can.log" --table --last 1 | sed 's/^/   /'

echo
echo "== 5. Decoded leans against the simulator's truth (per pole: the last rotation it was reported)"
echo "   Expected: within 1.0 deg. A parked vehicle and a noise-free scene quantise every rotation"
echo "   the same way, so the tracker cannot average the 4.38 cm range bins out; the range profile"
echo "   reads each bound within its bin from the edge bins' power (sl_profile.h, step 6). What is"
echo "   left is mostly the poles' radius: r1 is their front surface."
"$PY" tests/system/daemon/lean_vs_truth.py "$DBC" "$OUT/can.log" "$OUT/scene.gt.csv" --tol 1.0 |
    sed 's/^/   /' || true

echo
if [ -n "$VIEW" ]; then
    echo "== 6. Picture of the last rotation (sl-view): $OUT/view.png"
    "$VIEW" "$OUT/scene.colossus" --board "$BOARD" --out "$OUT/view.png" --rotation $((ROTS - 1)) \
        --truth "$OUT/scene.gt.csv" --title "shadowlean demo: $(basename "$SCENE")" > "$OUT/view.log" 2>&1 ||
        echo "   (sl-view failed: see $OUT/view.log)"
else
    echo "== 6. (no picture: sl-view is not built)"
fi
echo
echo "demo: outputs in $ROOT/$OUT (can.log, targets.jsonl, scene.colossus, scene.gt.csv${VIEW:+, view.png})"
