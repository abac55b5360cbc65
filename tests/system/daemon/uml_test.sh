#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_test.sh UML_RUN SHADOWLEAND SL_SIM PYTHON SRC_DIR OUT_DIR [BOARD]
# Real SocketCAN inside user-mode Linux (tests/support/vm/uml_run.sh): shadowleand --board BOARD
# (default paper-sim) --input CAPTURE --can vcan0 --can-log OUT while `candump -L vcan0`
# records (uml_guest.sh); on the host: the recording equals the --can-log output field by
# field (id, 11/29-bit, DLC, data), the real-time run took VehicleMotion from vcan0, and the
# fast run's frames match its targets (DBC decode). A board whose ids are all 29-bit
# (paper-sim-29bit) must come out as extended frames: candump wrote every frame of the fast
# run with an 8-digit id, canmatrix (its own DBC loader and decoder) decodes each to the
# board's message, and `python3 -m shadowlean decode --check` accepts them all (E2E Profile
# 11, Health in 11C).
# Exit 77 (ctest skip) when linux.uml is not installed.
set -u
uml_run=$1; daemon=$2; sim=$3; py=$4; src=$(cd "$5" && pwd); out=$6; board=${7:-paper-sim}
rm -rf "$out"; mkdir -p "$out"; out=$(cd "$out" && pwd)
root=$(cd "$src/../../.." && pwd)
dbc="$root/boards/$board/shadowlean.dbc"
"$sim" "$src/scenes/static_four_poles.ini" -o "$out/scene.colossus" --quiet || exit 1
"$sim" "$src/scenes/static_four_poles.ini" --rotations 40 -o "$out/short.colossus" --quiet || exit 1
"$py" "$src/motion_frames.py" "$dbc" 0.10 0 > "$out/motion.txt" || exit 1
SL_UML_TIMEOUT=${SL_UML_TIMEOUT:-150} sh "$uml_run" "$out/vm" sh "$src/uml_guest.sh" "$daemon" \
    "$out/scene.colossus" "$out/short.colossus" "$out/motion.txt" "$out" "$board"
rc=$?
[ $rc -eq 0 ] || exit $rc
"$py" "$src/uml_compare.py" "$out" "$dbc" || exit 1
"$py" "$src/check_can_vs_targets.py" "$dbc" "$out/daemon_fast.log" "$out/targets_fast.jsonl" \
    --rotations 24 --min-poles 4 || exit 1
case "$board" in *29bit*) ;; *) exit 0 ;; esac
# candump's own recording of run 1 (between the SYNC and MID markers).
awk '/ 7FF#53594E43/ { on = 1; next } / 7FF#4D4944/ { on = 0 } on' "$out/candump.log" > "$out/fast_bus.log"
n=$(grep -c . "$out/fast_bus.log")
n_eff=$(grep -cE ' [0-9A-F]{8}#' "$out/fast_bus.log")
echo "29-bit: candump recorded $n frames of run 1, $n_eff with an 8-digit (29-bit) id"
[ "$n" -gt 0 ] && [ "$n" -eq "$n_eff" ] || { echo "FAIL: not every frame is an extended frame"; exit 1; }
"$py" - "$dbc" "$out/fast_bus.log" <<'PY' || exit 1
import contextlib, io, re, sys
with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
    import canmatrix, canmatrix.formats
    db = canmatrix.formats.loadp_flat(sys.argv[1])
names = {}
for line in open(sys.argv[2]):
    cid, data = re.match(r"\(\S+\) \S+ ([0-9A-F]{8})#([0-9A-F]*)", line).groups()
    fr = db.frame_by_id(canmatrix.ArbitrationId(int(cid, 16), extended=True))
    if fr is None or not fr.arbitration_id.extended:
        sys.exit(f"FAIL: canmatrix has no extended frame {cid}")
    fr.decode(bytes.fromhex(data))
    names[fr.name] = names.get(fr.name, 0) + 1
print("29-bit: canmatrix decodes every frame:", ", ".join(f"{k} {v}" for k, v in sorted(names.items())))
PY
PYTHONPATH="$root/python" "$py" -m shadowlean decode "$out/fast_bus.log" --dbc "$dbc" --check > "$out/fast_bus.decoded" ||
    { echo "FAIL: python3 -m shadowlean decode --check"; tail -12 "$out/fast_bus.decoded"; exit 1; }
echo "29-bit: python3 -m shadowlean decodes and accepts all $(grep -c 'crc=ok' "$out/fast_bus.decoded") frames (E2E Profile 11)"
