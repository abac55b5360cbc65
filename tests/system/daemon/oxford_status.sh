#!/bin/sh
# SPDX-License-Identifier: MIT
# oxford_status.sh SL_REPLAY SHADOWLEAND PYTHON SRC_DIR OUT_DIR OXFORD_DIR
# Must show: the 11 real Oxford RobotCar scans, converted by `sl-replay from-oxford`, through
# `shadowleand --board robotcar-leaf --input X --can-log -`: no errors, and its Status
# frames report the rotations it saw. 11 Status frames with Rotations 1..11: the first 10
# rotations end when the next scan's first azimuth arrives (the azimuth index wraps), the
# 11th is complete (400/400 azimuths) but nothing follows it, so it is reported when the
# daemon ends the stream at end of file (sl_pipeline_finish, scan end FLUSH). A reader that
# did not flush at EOF would report 10. All 400 x 11 azimuths valid: AzimuthsMissing 0.
set -u
SL_REPLAY=$1; DAEMON=$2; PY=$3; SRC=$4; OUT=$5; OX=$6
if [ ! -d "$OX" ]; then echo "SKIP: $OX missing"; exit 77; fi
rm -rf "$OUT"; mkdir -p "$OUT"
"$SL_REPLAY" from-oxford "$OX" --out "$OUT/oxford.colossus" || exit 1
"$DAEMON" --board robotcar-leaf --input "$OUT/oxford.colossus" --can-log - \
    --targets-out "$OUT/targets.jsonl" > "$OUT/can.log" 2> "$OUT/daemon.err"
rc=$?
cat "$OUT/daemon.err"
[ $rc -eq 0 ] || { echo "FAIL: exit status $rc"; exit 1; }
if grep -E "^shadowleand: (error|warning):" "$OUT/daemon.err"; then echo "FAIL: errors or warnings logged"; exit 1; fi
DBC="$SRC/../../../boards/robotcar-leaf/shadowlean.dbc"
"$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$OUT/can.log" "$OUT/targets.jsonl" --rotations 11 || exit 1
"$PY" - "$DBC" "$OUT/can.log" "$SRC" <<'PY' || exit 1
import sys
sys.path.insert(0, sys.argv[3] + "/../../../scripts")
import sl_can_decode as scd
st = [d for _, d in scd.decode_log(sys.argv[1], sys.argv[2]) if d is not None and d.name == "Status"]
rot = [d.raw["Rotations"] for d in st]
miss = [d.raw["AzimuthsMissing"] for d in st]
print(f"Status frames: {len(st)}, Rotations {rot}, AzimuthsMissing max {max(miss) if miss else '-'}")
ok = rot == list(range(1, 12)) and max(miss) == 0 and all(d.raw["LinkState"] == 3 for d in st)
print("oxford: OK" if ok else "FAIL: want 11 Status frames, Rotations 1..11, nothing missing, STREAMING")
sys.exit(0 if ok else 1)
PY
