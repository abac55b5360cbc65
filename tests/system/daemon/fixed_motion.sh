#!/bin/sh
# SPDX-License-Identifier: MIT
# fixed_motion.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# --motion V: a constant vehicle motion instead of VehicleMotion frames (benches, replays
# without a vehicle bus). The static test scene driven at 1 m/s (the same file with
# speed_mps = 1): without a motion input the 16-frame consistency window sees nothing
# stable (no PoleLean frame); with --motion 1.0 every rotation reports motion_valid and
# speed 1000 mm/s in the targets file, the window shrinks to n_eff = 1 and the poles are
# reported. (Lean accuracy while driving is the pipeline's business and not asserted here.)
set -u
SL_SIM=$1; D=$2; PY=$3; SRC=$4; OUT=$5
rm -rf "$OUT"; mkdir -p "$OUT"
sed 's/^speed_mps = 0/speed_mps = 1.0/; s/^y_m = 0$/y_m = -1.0/' "$SRC/scenes/static_four_poles.ini" > "$OUT/moving.ini"
grep -q '^speed_mps = 1.0' "$OUT/moving.ini" || { echo "FAIL: scene edit"; exit 1; }
"$SL_SIM" "$OUT/moving.ini" -o "$OUT/moving.colossus" --quiet || exit 1
"$D" --board paper-sim --input "$OUT/moving.colossus" --can-log "$OUT/still.log" --targets-out "$OUT/still.jsonl" -q || exit 1
"$D" --board paper-sim --input "$OUT/moving.colossus" --motion 1.0 --can-log "$OUT/moving.log" \
    --targets-out "$OUT/moving.jsonl" -q || exit 1
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
"$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$OUT/moving.log" "$OUT/moving.jsonl" --rotations 24 --min-poles 3 --no-fault || exit 1
"$PY" - "$OUT" <<'PY'
import json, os, sys
out = sys.argv[1]
def rots(name):
    return [json.loads(l) for l in open(os.path.join(out, name))][1:]
still, moving = rots("still.jsonl"), rots("moving.jsonl")
n_still = sum(1 for l in open(os.path.join(out, "still.log")) if " 5C0#" in l)
n_moving = sum(1 for l in open(os.path.join(out, "moving.log")) if " 5C0#" in l)
errs = []
if n_still != 0 or any(r["motion_valid"] for r in still):
    errs.append(f"without motion: {n_still} PoleLean frames, motion_valid {[r['motion_valid'] for r in still][:3]}")
if not all(r["motion_valid"] and r["speed_mm_s"] == 1000 and r["frames_eff"] == 1 for r in moving):
    errs.append("with --motion 1.0: not every rotation used speed 1000 mm/s with n_eff 1")
if n_moving == 0:
    errs.append("with --motion 1.0: no PoleLean frame")
print(f"fixed motion: PoleLean frames without motion {n_still}, with --motion 1.0 {n_moving}; "
      f"n_eff {sorted(set(r['frames_eff'] for r in moving))}")
for e in errs:
    print("FAIL:", e)
sys.exit(1 if errs else 0)
PY
