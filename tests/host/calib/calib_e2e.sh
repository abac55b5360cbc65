#!/bin/sh
# SPDX-License-Identifier: MIT
# calib_e2e.sh SL_SIM SL_CALIB SL_TABLES SHADOWLEAND PYTHON SRC_DIR OUT_DIR SL_EVAL SL_VIEW
# Calibration as data, end to end, with one daemon binary and no rebuild:
#  1. sl-sim: the vehicle of tests/host/calib/data/paper-sim-lower-body.ini (its body 9 cm lower
#     than boards/paper-sim says: true theta 30.01 deg, nominal 26) on empty ground;
#  2. sl-calib shadow --out-ini: the vehicle's calibration INI (theta per azimuth);
#  3. sl-tables paper-sim --calibration INI --blob BIN: the same calibration as the core's blob;
#  4. sl-sim: five leaning poles around that vehicle; shadowleand --board paper-sim
#     --calibration (the INI, then the blob): every decoded lean within 1.0 deg of the truth,
#     the same frames from INI and blob; the nominal board alone: NOT within 1.0 deg;
#  5. the nominal board's own blob gives the nominal frames byte for byte, and a blob with
#     one flipped bit, a truncated one, or one for another board: exit 1, a clear error;
#  6. sl-eval and sl-view take the same --calibration (sl-eval: every pole within 1.0 deg).
set -u
SL_SIM=$1; SL_CALIB=$2; SL_TABLES=$3; DAEMON=$4; PY=$5; SRC=$6; OUT=$7; SL_EVAL=$8; SL_VIEW=$9
D="$SRC/data"
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
LVT="$SRC/../../system/daemon/lean_vs_truth.py"
rm -rf "$OUT"; mkdir -p "$OUT"
fail() { echo "FAIL: $*"; exit 1; }

"$SL_SIM" "$D/lower_body_empty.ini" -o "$OUT/empty.colossus" --quiet || fail "sl-sim empty"
"$SL_CALIB" shadow "$OUT/empty.colossus" --board paper-sim --out-ini "$OUT/vehicle.ini" > "$OUT/calib.txt" ||
    fail "sl-calib shadow"
grep -q "theta (median over usable): 30\.[0-3]" "$OUT/calib.txt" || { cat "$OUT/calib.txt"; fail "measured theta not ~30 deg"; }
"$SL_TABLES" paper-sim --calibration "$OUT/vehicle.ini" --blob "$OUT/vehicle.bin" || fail "sl-tables --blob"
"$SL_TABLES" paper-sim --blob "$OUT/nominal.bin" || fail "sl-tables --blob (nominal)"

"$SL_SIM" "$D/lower_body_poles.ini" -o "$OUT/poles.colossus" --gt "$OUT/poles.gt.csv" --quiet || fail "sl-sim poles"
run() { # name [daemon options]
    n=$1; shift
    "$DAEMON" --board paper-sim "$@" --input "$OUT/poles.colossus" --can-log "$OUT/$n.log" -q ||
        fail "$n: shadowleand exit status $?"
}
run ini --calibration "$OUT/vehicle.ini"
"$PY" "$LVT" "$DBC" "$OUT/ini.log" "$OUT/poles.gt.csv" --tol 1.0 || fail "calibrated (INI): a lean beyond 1.0 deg"
run blob --calibration "$OUT/vehicle.bin"
cmp "$OUT/ini.log" "$OUT/blob.log" || fail "the blob's frames differ from the INI's"
run nominal
if "$PY" "$LVT" "$DBC" "$OUT/nominal.log" "$OUT/poles.gt.csv" --tol 1.0; then
    fail "the nominal board alone is within 1.0 deg: the test vehicle does not differ from its board"
fi
echo "nominal board alone: leans off by more than 1.0 deg (expected)"
run nominal_blob --calibration "$OUT/nominal.bin"
cmp "$OUT/nominal.log" "$OUT/nominal_blob.log" || fail "the nominal blob changes the frames"
# The same calibration in the daemon's config file.
printf '[daemon]\ncalibration = %s\n' "$OUT/vehicle.bin" > "$OUT/daemon.ini"
run config --config "$OUT/daemon.ini"
cmp "$OUT/ini.log" "$OUT/config.log" || fail "[daemon] calibration differs from --calibration"

# Bad files: exit status 1 and the reason named; never a silent fallback.
reject() { # file expected-error
    if "$DAEMON" --board paper-sim --calibration "$1" --input "$OUT/poles.colossus" --can-log "$OUT/bad.log" \
        2> "$OUT/bad.txt"; then fail "$1 accepted"; fi
    st=0; "$DAEMON" --board paper-sim --calibration "$1" --input "$OUT/poles.colossus" --can-log "$OUT/bad.log" \
        2> /dev/null || st=$?
    [ "$st" -eq 1 ] || fail "$1: exit status $st, expected 1"
    grep -q "$2" "$OUT/bad.txt" || { cat "$OUT/bad.txt"; fail "$1: no '$2' in the error"; }
    echo "rejected $(basename "$1"): $2"
}
cp "$OUT/vehicle.bin" "$OUT/flip.bin"
printf '\001' | dd of="$OUT/flip.bin" bs=1 seek=9000 conv=notrunc 2> /dev/null
reject "$OUT/flip.bin" SL_ERR_CAL_CRC
head -c 19000 "$OUT/vehicle.bin" > "$OUT/short.bin"
reject "$OUT/short.bin" SL_ERR_CAL_SIZE
"$SL_TABLES" robotcar-leaf --blob "$OUT/leaf.bin" > /dev/null || fail "sl-tables robotcar-leaf --blob"
reject "$OUT/leaf.bin" SL_ERR_CAL_BOARD
sed 's/^board = paper-sim/board = paper-bench/' "$OUT/vehicle.ini" > "$OUT/other.ini"
reject "$OUT/other.ini" "board = 'paper-bench' but the board is 'paper-sim'"
reject "$OUT/missing.ini" "No such file"
# sl-tables bakes the calibration into C tables when asked (--out DIR; never boards/).
"$SL_TABLES" paper-sim --calibration "$OUT/vehicle.ini" --out "$OUT/baked" --no-png > /dev/null ||
    fail "sl-tables --calibration --out"
grep -q "Calibrated with vehicle.ini" "$OUT/baked/sl_board_paper_sim.c" || fail "baked tables: no calibration banner"
grep -q "^    30[0-9][0-9], 30[0-9][0-9]," "$OUT/baked/sl_board_paper_sim.c" || fail "baked tables: theta not ~30 deg"
if "$SL_TABLES" paper-sim --calibration "$OUT/vehicle.ini" --no-png > /dev/null 2>&1; then
    fail "sl-tables --calibration without --out would overwrite the committed tables"
fi
# The host tools on the same calibration.
ev() { "$SL_EVAL" run "$OUT/poles.colossus" "$OUT/poles.gt.csv" --board paper-sim --extract pipeline \
    --beam-deg 2 "$@" 2>/dev/null | grep '^pole' | sed 's/.* max \([0-9.]*\) deg/\1/'; }
ev --calibration "$OUT/vehicle.bin" > "$OUT/eval_cal.txt"
ev > "$OUT/eval_nom.txt"
[ "$(wc -l < "$OUT/eval_cal.txt")" -eq 5 ] || fail "sl-eval: not 5 poles"
awk '$1 > 1.0 { bad = 1 } END { exit bad }' "$OUT/eval_cal.txt" || fail "sl-eval --calibration: a pole beyond 1.0 deg"
awk '$1 > 1.0 { bad = 1 } END { exit !bad }' "$OUT/eval_nom.txt" || fail "sl-eval without calibration within 1.0 deg"
echo "sl-eval max errors: calibrated $(tr '\n' ' ' < "$OUT/eval_cal.txt")/ nominal $(tr '\n' ' ' < "$OUT/eval_nom.txt")"
"$SL_VIEW" "$OUT/poles.colossus" --board paper-sim --calibration "$OUT/vehicle.ini" --out "$OUT/view.png" > /dev/null ||
    fail "sl-view --calibration"
test -s "$OUT/view.png" || fail "sl-view wrote no picture"
if "$SL_VIEW" "$OUT/poles.colossus" --board paper-sim --calibration "$OUT/flip.bin" --out "$OUT/bad.png" 2> /dev/null; then
    fail "sl-view accepted a corrupt blob"
fi
echo "calibration end to end: OK"
