#!/bin/sh
# SPDX-License-Identifier: MIT
# json_outputs.sh SHADOWLEAND SL_SIM SL_REPLAY SL_INSPECT SL_EVAL PYTHON SRC OUT OXFORD_DIR: every machine-readable output validated
# against its schema in docs/schema (validate_json.py), on real outputs:
#   shadowleand --targets-out: the demo scene (targets and tracks) and the Oxford scans;
#   sl-inspect --json --rotations: a raw capture and the same as pcapng (pcap report);
#   sl-eval table1 / realistic --json (reduced runs, --extract both: the pipeline sections);
#   sl-eval driveby --json (two passes of the quick sweep).
set -u
DAEMON=$1; SIM=$2; REPLAY=$3; INSPECT=$4; EVAL=$5; PY=$6; SRC=$7; OUT=$8; OX=$9
S="$SRC/docs/schema"
V="$PY $SRC/tests/system/json/validate_json.py"
rm -rf "$OUT"; mkdir -p "$OUT"
fail=0
run() { "$@" || { echo "FAIL: exit status $?: $*"; fail=1; }; }

run "$SIM" "$SRC/scenes/demo_three_poles.ini" -o "$OUT/demo.colossus" --threads 1 --quiet
run "$DAEMON" --board paper-sim --input "$OUT/demo.colossus" --can-log "$OUT/demo.can" \
    --targets-out "$OUT/demo.jsonl" -q
run $V "$S/targets.schema.json" "$OUT/demo.jsonl" --lines --expect-schema shadowlean-targets/1 \
    --require type=rotation.targets --require type=rotation.tracks
run "$INSPECT" --json --rotations "$OUT/demo.colossus" > "$OUT/demo.inspect.json"
run $V "$S/inspect.schema.json" "$OUT/demo.inspect.json" --expect-schema shadowlean-inspect/1 \
    --require rotations.list --require configuration
run "$REPLAY" to-pcapng "$OUT/demo.colossus" --out "$OUT/demo.pcapng" > /dev/null
run "$INSPECT" --json "$OUT/demo.pcapng" > "$OUT/pcapng.inspect.json"
run $V "$S/inspect.schema.json" "$OUT/pcapng.inspect.json" --expect-schema shadowlean-inspect/1 \
    --require pcap.flows

if [ -d "$OX" ]; then
    run "$REPLAY" from-oxford "$OX" --out "$OUT/oxford.colossus" > /dev/null
    run "$DAEMON" --board robotcar-leaf --input "$OUT/oxford.colossus" --can-log "$OUT/ox.can" \
        --targets-out "$OUT/oxford.jsonl" -q
    run $V "$S/targets.schema.json" "$OUT/oxford.jsonl" --lines --expect-schema shadowlean-targets/1
    run "$INSPECT" --json "$OUT/oxford.colossus" > "$OUT/oxford.inspect.json"
    run $V "$S/inspect.schema.json" "$OUT/oxford.inspect.json" --expect-schema shadowlean-inspect/1
else
    echo "FAIL: $OX missing (the Oxford scans are part of the test data)"; fail=1
fi

run "$EVAL" table1 --rotations 4 --extract both --threads 1 --quiet --json > "$OUT/table1.json"
run $V "$S/eval.schema.json" "$OUT/table1.json" --expect-schema shadowlean-eval-table1/1 \
    --require rows --require pipeline.captures
run "$EVAL" realistic --positions 2 --reps 1 --frames 4 --calib 2 --extract both --threads 1 \
    --quiet --json-out "$OUT/realistic.json" > /dev/null
run $V "$S/eval.schema.json" "$OUT/realistic.json" --expect-schema shadowlean-eval-realistic/1 \
    --require rows --require pipeline.rows
run "$EVAL" realistic --hard --positions 1 --reps 1 --frames 4 --calib 2 --range-bins 160 --extract both \
    --threads 1 --quiet --json-out "$OUT/realistic_hard.json" > /dev/null
run $V "$S/eval.schema.json" "$OUT/realistic_hard.json" --expect-schema shadowlean-eval-realistic/1 \
    --require rows --require pipeline.rows --require hard
run "$EVAL" driveby --quick --speeds 1 --psi 15 --offset 3 --phi 90 --quiet --json > "$OUT/driveby.json"
run $V "$S/eval.schema.json" "$OUT/driveby.json" --expect-schema shadowlean-eval-driveby/1 \
    --require passes --require summary
[ $fail -eq 0 ] && echo "json_outputs: ok"
exit $fail
