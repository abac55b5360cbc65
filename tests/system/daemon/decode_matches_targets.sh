#!/bin/sh
# SPDX-License-Identifier: MIT
# decode_matches_targets.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# Item 4: shadowleand --input (simulated capture) --can-log --targets-out; every frame
# decodes with boards/paper-sim/shadowlean.dbc (python3-canmatrix) and matches the
# pipeline's targets and tracks (check_can_vs_targets.py). Then the checker must REJECT
# three corrupted copies (a flipped data bit, a changed lean in the JSON, a dropped frame),
# so a checker that accepts anything cannot pass. Also: the same capture as a pcap (TCP
# segments retransmitted and reordered, make_pcap.py) gives byte-identical outputs.
set -u
SL_SIM=$1; DAEMON=$2; PY=$3; SRC=$4; OUT=$5
rm -rf "$OUT"; mkdir -p "$OUT"
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" -o "$OUT/scene.colossus" --quiet || exit 1
"$DAEMON" --board paper-sim --input "$OUT/scene.colossus" --can-log "$OUT/can.log" \
    --targets-out "$OUT/targets.jsonl" || { echo "FAIL: shadowleand exit status $?"; exit 1; }
"$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$OUT/can.log" "$OUT/targets.jsonl" \
    --rotations 24 --min-poles 4 --no-fault || exit 1

# The checker rejects corrupted inputs.
must_fail() { # what log jsonl
    if "$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$2" "$3" --rotations 24 > "$OUT/neg.out" 2>&1; then
        echo "FAIL: the checker accepted $1"; cat "$OUT/neg.out"; exit 1
    fi
    echo "checker rejects $1: $(grep -m1 FAIL "$OUT/neg.out")"
}
# 1. one data bit flipped in the 30th frame (breaks the CRC)
awk 'NR == 30 { n = split($3, a, "#"); d = a[2]; c = substr(d, 5, 1);
     c = (c == "0") ? "1" : "0"; $3 = a[1] "#" substr(d, 1, 4) c substr(d, 6) } { print }' \
    "$OUT/can.log" > "$OUT/bad_bit.log"
must_fail "a flipped data bit" "$OUT/bad_bit.log" "$OUT/targets.jsonl"
# 2. a filtered lean changed by 0.3 deg in the JSON of the last rotation
"$PY" - "$OUT/targets.jsonl" "$OUT/bad_lean.jsonl" <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
t = next(t for t in lines[-1]["tracks"] if t["valid_hits"] > 0)
t["alpha_cdeg"] += 30
open(sys.argv[2], "w").write("".join(json.dumps(l) + "\n" for l in lines))
PY
must_fail "a changed lean" "$OUT/can.log" "$OUT/bad_lean.jsonl"
# 3. the first PoleLean frame dropped
awk '!done && $3 ~ /^5C0#/ { done = 1; next } { print }' "$OUT/can.log" > "$OUT/bad_drop.log"
must_fail "a missing PoleLean frame" "$OUT/bad_drop.log" "$OUT/targets.jsonl"

# pcap input: same frames, same targets.
"$PY" "$SRC/make_pcap.py" "$OUT/scene.colossus" "$OUT/scene.pcap" || exit 1
"$DAEMON" --board paper-sim --input "$OUT/scene.pcap" --can-log "$OUT/can_pcap.log" \
    --targets-out "$OUT/targets_pcap.jsonl" || { echo "FAIL: shadowleand (pcap) exit status $?"; exit 1; }
cmp "$OUT/can.log" "$OUT/can_pcap.log" || { echo "FAIL: the pcap gives other CAN frames"; exit 1; }
cmp "$OUT/targets.jsonl" "$OUT/targets_pcap.jsonl" || { echo "FAIL: the pcap gives other targets"; exit 1; }
echo "pcap input: identical CAN log and targets"
