#!/bin/sh
# SPDX-License-Identifier: MIT
# can_drops_counted_once.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# Status.CanDropped counts every lost frame exactly once: shadowleand with a SocketCAN sink
# on a missing interface (every frame refused at send: the pipeline counts it from can_tx's
# return value) and a candump log (every frame written). The daemon also adds the sinks'
# later drops (sl_pipeline_add_can_dropped, the summed sink counters); a drop refused at
# send must not be added a second time, so the k-th frame of the log (0-based) being a
# Status frame must carry CanDropped = k (all earlier frames were dropped by the socket).
set -u
SL_SIM=$1; DAEMON=$2; PY=$3; SRC=$4; OUT=$5
rm -rf "$OUT"; mkdir -p "$OUT"
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" -o "$OUT/scene.colossus" --quiet || exit 1
"$DAEMON" --board paper-sim --input "$OUT/scene.colossus" --can-log "$OUT/can.log" \
    --can slnosuchcan0 2> "$OUT/daemon.err" || { echo "FAIL: shadowleand exit status $?"; cat "$OUT/daemon.err"; exit 1; }
"$PY" - "$OUT/can.log" <<'PYEOF'
import sys
frames = [l.split()[2] for l in open(sys.argv[1]) if l.strip()]
status = [(k, f) for k, f in enumerate(frames) if f.split("#")[0] == "5C2"]  # paper-sim id_status
bad = [(k, int(f.split("#")[1][14:16], 16)) for k, f in status if int(f.split("#")[1][14:16], 16) != min(k, 255)]
print(f"can_drops_counted_once: {len(frames)} frames, {len(status)} Status, CanDropped of the last {int(status[-1][1].split('#')[1][14:16], 16) if status else None}")
if len(status) < 10 or bad:
    print("FAIL: Status frames (index, CanDropped) not counting each drop once:", bad[:5])
    sys.exit(1)
PYEOF
