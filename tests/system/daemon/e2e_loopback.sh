#!/bin/sh
# SPDX-License-Identifier: MIT
# e2e_loopback.sh SL_SIM SL_REPLAY SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# End to end on loopback: sl-sim (tests/system/daemon/scenes/static_four_poles.ini) -> sl-replay
# serve on 127.0.0.1 (free port, parsed) -> shadowleand --radar -> candump log + targets
# -> (1) every frame decodes with the DBC and matches the pipeline's targets
# (check_can_vs_targets.py) and (2) the decoded leans are within 0.5 deg of the
# simulator's truth (lean_vs_truth.py). Bounded: the daemon stops 1.5 s after the last FFT
# message (--exit-idle), --duration 60 and ctest's TIMEOUT are the backstops.
set -u
SL_SIM=$1; SL_REPLAY=$2; DAEMON=$3; PY=$4; SRC=$5; OUT=$6
. "$SRC/lib.sh"
rm -rf "$OUT"; mkdir -p "$OUT"
REPLAY_PID=""
trap 'stop_pid "$REPLAY_PID"' EXIT
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" -o "$OUT/scene.colossus" --quiet || exit 1
# real-time pacing: the CAN output ceiling (sl_can.h) is on the daemon's clock
start_replay "$OUT/replay.out" "$OUT/scene.colossus" --rate realtime || exit 1
echo "sl-replay serving on 127.0.0.1:$REPLAY_PORT"
"$DAEMON" --board paper-sim --radar "127.0.0.1:$REPLAY_PORT" --can-log "$OUT/can.log" \
    --targets-out "$OUT/targets.jsonl" --exit-idle 1.5 --duration 60 --stats-every 1 || {
    echo "FAIL: shadowleand exit status $?"; exit 1; }
stop_pid "$REPLAY_PID"; REPLAY_PID=""
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
# LinkState of the rotation Status frames: STREAMING, or SILENT for the last one (flushed
# when the daemon stops, after --exit-idle of silence).
"$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$OUT/can.log" "$OUT/targets.jsonl" \
    --idle-ok --link 3,4 --rotations 24 --min-poles 4 || exit 1
"$PY" "$SRC/lean_vs_truth.py" "$DBC" "$OUT/can.log" "$OUT/scene.gt.csv" --tol 0.5 || exit 1
