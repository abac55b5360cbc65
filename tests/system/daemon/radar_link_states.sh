#!/bin/sh
# SPDX-License-Identifier: MIT
# radar_link_states.sh SL_SIM SL_REPLAY SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# The Status frames without data and the clean shutdown, on loopback:
# 1. no radar (a closed port): Status frames keep coming (--status-period-ms 200) with
#    LinkState DISCONNECTED/CONNECTING and Rotations 0; SIGTERM -> exit 0, log complete.
# 2. a radar that stalls (sl-replay --stall-after 2000: socket open, no data, no
#    keep-alive): LinkState SILENT (--silent-ms 300) in the idle Status frames; after the
#    client's silence timeout (1.5 s) it reconnects and the replay continues: 8 rotations
#    in all. Every frame decodes and the rotation groups match the targets
#    (check_can_vs_targets.py --idle-ok).
# 3. SIGINT during a --realtime capture replay: exit 0, last rotation flushed.
set -u
SL_SIM=$1; SL_REPLAY=$2; DAEMON=$3; PY=$4; SRC=$5; OUT=$6
. "$SRC/lib.sh"
rm -rf "$OUT"; mkdir -p "$OUT"
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
REPLAY_PID=""; DPID=""
trap 'stop_pid "$REPLAY_PID"; stop_pid "$DPID"' EXIT
count() { # PATTERN FILE: matching lines (0 when none or no file)
    _n=$(grep -c -- "$1" "$2" 2>/dev/null); echo "${_n:-0}"
}
states() { # LOG: "LinkState values of the Status frames" and "last Rotations"
    "$PY" - "$DBC" "$1" "$SRC" <<'PY'
import sys
sys.path.insert(0, sys.argv[3] + "/../../../scripts")
import sl_can_decode as scd
st = [d for _, d in scd.decode_log(sys.argv[1], sys.argv[2]) if d is not None and d.name == "Status"]
print(" ".join(str(d.raw["LinkState"]) for d in st), "|", st[-1].raw["Rotations"] if st else -1)
PY
}
# 1. nobody listening
PORT=$(free_port)
"$DAEMON" --board paper-sim --radar "127.0.0.1:$PORT" --can-log "$OUT/none.log" \
    --status-period-ms 200 --connect-timeout-ms 500 --duration 30 2> "$OUT/none.err" &
DPID=$!
i=0
while [ "$(count '#' "$OUT/none.log")" -lt 3 ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
kill -TERM $DPID; wait $DPID; rc=$?; DPID=""
cat "$OUT/none.err"
[ $rc -eq 0 ] || { echo "FAIL: exit status $rc after SIGTERM"; exit 1; }
s=$(states "$OUT/none.log"); echo "no radar: LinkState per Status frame: $s"
case "$s" in
*"| 0") ;;
*) echo "FAIL: Rotations should be 0"; exit 1 ;;
esac
n=$(echo "$s" | tr ' ' '\n' | grep -c '^[01]$')
[ "$n" -ge 3 ] || { echo "FAIL: want >= 3 Status frames DISCONNECTED/CONNECTING"; exit 1; }
if echo "${s% |*}" | tr ' ' '\n' | grep -q '^[234]$'; then echo "FAIL: impossible link state"; exit 1; fi
grep -q "stopping (SIGTERM)" "$OUT/none.err" || { echo "FAIL: no clean stop logged"; exit 1; }

# 2. a radar that stalls after 2000 FFT messages (5 rotations), then comes back
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" --rotations 8 -o "$OUT/s.colossus" --quiet || exit 1
start_replay "$OUT/replay.out" "$OUT/s.colossus" --rate realtime --stall-after 2000 || exit 1
# Ends by itself 3 s after the last FFT message (the replay then only sends keep-alives).
"$DAEMON" --board paper-sim --radar "127.0.0.1:$REPLAY_PORT" --can-log "$OUT/stall.log" \
    --targets-out "$OUT/stall.jsonl" --silent-ms 300 --status-period-ms 200 \
    --silence-timeout-ms 1500 --data-timeout-ms 10000 --exit-idle 3 --duration 30 2> "$OUT/stall.err"
rc=$?
stop_pid "$REPLAY_PID"; REPLAY_PID=""
cat "$OUT/stall.err"
[ $rc -eq 0 ] || { echo "FAIL: exit status $rc"; exit 1; }
s=$(states "$OUT/stall.log"); echo "stalling radar: LinkState per Status frame: $s"
echo "${s% |*}" | tr ' ' '\n' | grep -q '^4$' || { echo "FAIL: no SILENT Status frame"; exit 1; }
grep -q "radar disconnected (SILENCE" "$OUT/stall.err" || { echo "FAIL: no silence timeout"; exit 1; }
grep -q "1 reconnects" "$OUT/stall.err" || { echo "FAIL: no reconnection"; exit 1; }
grep -q "Stop FFT sent to the radar" "$OUT/stall.err" || { echo "FAIL: no Stop FFT at exit"; exit 1; }
# ... and the radar emulator received it on the second connection (its own count; the data
# watchdog is set beyond --exit-idle here, data_watchdog.sh tests it).
grep -q "client 2 .* starts 1, stops 1," "$OUT/replay.out.err" || {
    cat "$OUT/replay.out.err"; echo "FAIL: sl-replay did not see Start + Stop FFT"; exit 1; }
rot=${s#*| }
[ "$rot" -eq 8 ] || { echo "FAIL: $rot rotations, want 8 (5 before the stall, 3 after the reconnection)"; exit 1; }
"$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$OUT/stall.log" "$OUT/stall.jsonl" --idle-ok --link 0,1,2,3,4 \
    --rotations 8 || exit 1

# 3. SIGINT in the middle of a real-time capture replay: exit 0, the partial rotation is
#    flushed (the log ends with its Status and Health frames), the targets file is complete JSON.
"$DAEMON" --board paper-sim --input "$OUT/s.colossus" --realtime --can-log "$OUT/int.log" \
    --targets-out "$OUT/int.jsonl" 2> "$OUT/int.err" &
DPID=$!
i=0
while [ "$(count ' 5C2#' "$OUT/int.log")" -lt 2 ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
kill -INT $DPID; wait $DPID; rc=$?; DPID=""
cat "$OUT/int.err"
[ $rc -eq 0 ] || { echo "FAIL: exit status $rc after SIGINT"; exit 1; }
grep -q "stopping (SIGINT)" "$OUT/int.err" || { echo "FAIL: no clean stop logged"; exit 1; }
tail -2 "$OUT/int.log" | head -1 | grep -q ' 5C2#' && tail -1 "$OUT/int.log" | grep -q ' 5C3#' ||
    { echo "FAIL: the log does not end with a Status frame and its Health frame"; exit 1; }
"$PY" "$SRC/check_can_vs_targets.py" "$DBC" "$OUT/int.log" "$OUT/int.jsonl" || exit 1
