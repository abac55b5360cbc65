#!/bin/sh
# SPDX-License-Identifier: MIT
# ground_terrain.sh SL_EVAL SCENES_DIR WORKDIR: the ground from the shadow's edge on the
# shipped ground scenes (sl-eval terrain --json), CTS350-X physics:
# - ground_attitude.ini (parked, pitch 2, roll -1.5 deg, two poles in the shadow): pitch and
#   roll within 0.3 deg on every scored rotation;
# - ground_kerb.ini (a 0.1 m pavement 4.5 m to the left): found as STEP, at most one false
#   onset;
# - ground_dropoff.ini (1 m/s towards a 0.2 m drop-off): the first DROP ahead while the
#   vehicle's front is still more than 1.5 m from the edge, the distance reported no further
#   than the edge by more than 0.25 m.
set -eu
eval=$1 scenes=$2 dir=$3
rm -rf "$dir"; mkdir -p "$dir"
"$eval" terrain "$scenes/ground_attitude.ini" "$scenes/ground_kerb.ini" "$scenes/ground_dropoff.ini" \
    --threads 1 --json > "$dir/terrain.jsonl"
cat "$dir/terrain.jsonl"
python3 - "$dir/terrain.jsonl" <<'PY'
import json, sys
rows = {r["scene"].rsplit("/", 1)[-1]: r for r in map(json.loads, open(sys.argv[1]))}
fail = []
a = rows["ground_attitude.ini"]
if not (a["scored"] > 0 and a["pitch_err_max_deg"] <= 0.3 and a["roll_err_max_deg"] <= 0.3):
    fail.append("attitude: pitch/roll beyond 0.3 deg")
k = rows["ground_kerb.ini"]
if not (k["terrain_pieces_found"] >= 1 and k["false_hazard_onsets"] <= 1):
    fail.append("kerb: not found as STEP, or more than one false onset")
d = rows["ground_dropoff.ini"]
if not (d["drop_warned"] and d["drop_true_m"] >= 1.5 and d["drop_reported_m"] <= d["drop_true_m"] + 0.25):
    fail.append("drop-off: not warned 1.5 m before the front, or reported too far")
for f in fail:
    print("ground_terrain:", f)
sys.exit(1 if fail else 0)
PY
