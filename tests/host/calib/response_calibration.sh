#!/bin/sh
# SPDX-License-Identifier: MIT
# response_calibration.sh SL_CALIB SL_REPLAY SHADOWLEAND SL_TABLES PYTHON3 OXFORD_DIR SRC OUT: the range
# response measured on the Oxford scans by `sl-calib response --out-ini`, merged into a
# vehicle calibration file next to a shadow block, reaches the pipeline: the daemon started
# with that file reports the response "from the calibration" (exit log) and every Health
# frame carries ResponseSource = CALIBRATED (decoded with the board's DBC); started without
# it, PRIOR. The file converts to a blob with the response section (sl-tables --blob: 84
# bytes more than a blob without one), which the daemon uses the same way.
set -u
CALIB=$1; REPLAY=$2; DAEMON=$3; TABLES=$4; PY=$5; OXF=$6; SRC=$7; OUT=$8
DBC="$SRC/../../../boards/robotcar-leaf/shadowlean.dbc"
rm -rf "$OUT"; mkdir -p "$OUT"
fail() { echo "FAIL: $*"; exit 1; }
printf '; --- sl-calib shadow ---\n[calib]\nversion = 1\nboard = robotcar-leaf\nazimuths = 400\n' \
    > "$OUT/vehicle.ini"
"$CALIB" response "$OXF" --board robotcar-leaf --out-ini "$OUT/vehicle.ini" -q || fail "sl-calib response"
grep -q '^\[calib\]' "$OUT/vehicle.ini" || fail "the shadow block was not kept"
grep -q '^drops_q8 =' "$OUT/vehicle.ini" || fail "no [response] drops_q8 written"
"$REPLAY" from-oxford "$OXF" --out "$OUT/oxford.colossus" > /dev/null || fail "sl-replay from-oxford"
"$TABLES" robotcar-leaf --calibration "$OUT/vehicle.ini" --blob "$OUT/vehicle.bin" || fail "sl-tables --blob"
size=$(wc -c < "$OUT/vehicle.bin")
[ "$size" -eq $((208 + 48 * 400 + 84)) ] || fail "blob of $size bytes, want a response section"
for mode in calibrated blob prior; do
    set --
    [ "$mode" = calibrated ] && set -- --calibration "$OUT/vehicle.ini"
    [ "$mode" = blob ] && set -- --calibration "$OUT/vehicle.bin"
    "$DAEMON" --board robotcar-leaf --input "$OUT/oxford.colossus" --can-log "$OUT/$mode.log" "$@" \
        2> "$OUT/$mode.txt" || fail "shadowleand ($mode) exit status $?"
    grep "sensor model" "$OUT/$mode.txt"
    want=$( [ "$mode" = prior ] && echo "the board's prior" || echo "from the calibration")
    grep -q "range response $want" "$OUT/$mode.txt" || fail "$mode: the exit log does not say '$want'"
    "$PY" - "$DBC" "$OUT/$mode.log" "$( [ "$mode" = prior ] && echo PRIOR || echo CALIBRATED)" "$SRC" <<'PYEOF' || fail "$mode: Health.ResponseSource"
import os, sys
sys.path.insert(0, os.path.join(sys.argv[4], "..", "..", "..", "scripts"))
import sl_can_decode as scd
want = {"PRIOR": 0, "LEARNED": 1, "CALIBRATED": 2}[sys.argv[3]]  # the DBC's value table
got = [d.raw["ResponseSource"] for _, d in scd.decode_log(sys.argv[1], sys.argv[2])
       if d is not None and d.name == "Health" and d.crc_ok]
print("Health frames %d, ResponseSource raw %s (want %d)" % (len(got), sorted(set(got)), want))
sys.exit(0 if got and all(g == want for g in got) else 1)
PYEOF
done
echo "response calibration end to end: OK"
