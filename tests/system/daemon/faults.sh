#!/bin/sh
# SPDX-License-Identifier: MIT
# faults.sh SL_SIM SL_REPLAY SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# Issue 14: every fault a radar or its network can inject (sl-replay serve fault options) is
# visible to a CAN consumer, decoded with the board's DBC only (health_summary.py): the
# LinkState of every Status frame, the OR of the Health frames' Fault bits, Reconnects,
# Rotations; and nothing that was valid is lost (the daemon's own azimuth count). Each run
# is bounded (--duration / --exit-idle); the data watchdog and silence timeouts are set
# well apart from each other and from the run length, so ordering does not depend on load.
set -u
SL_SIM=$1; SL_REPLAY=$2; DAEMON=$3; PY=$4; SRC=$5; OUT=$6
. "$SRC/lib.sh"
rm -rf "$OUT"; mkdir -p "$OUT"
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
REPLAY_PID=""
trap 'stop_pid "$REPLAY_PID"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" -o "$OUT/s.colossus" --rotations 8 --quiet || exit 1
FFT=3200 # 8 rotations x 400 azimuths

# run NAME "REPLAY ARGS" DAEMON ARGS...: serve, run the daemon, summarise its CAN log.
run() {
    name=$1; rargs=$2; shift 2
    # shellcheck disable=SC2086
    start_replay "$OUT/$name.replay" "$OUT/s.colossus" $rargs || exit 1
    "$DAEMON" --board paper-sim --radar "127.0.0.1:$REPLAY_PORT" --can-log "$OUT/$name.log" \
        --status-period-ms 200 "$@" 2> "$OUT/$name.err" &
    dpid=$!
    if [ -n "${PAUSE:-}" ]; then # a daemon that lags behind the radar: stopped for a while
        sleep 0.2; kill -STOP $dpid; sleep "$PAUSE"; kill -CONT $dpid
    fi
    wait $dpid
    rc=$?
    stop_pid "$REPLAY_PID"; REPLAY_PID=""
    sum=$("$PY" "$SRC/health_summary.py" "$DBC" "$OUT/$name.log") || fail "$name: decode"
    echo "$name: exit $rc: $sum"
    [ $rc -eq 0 ] || { cat "$OUT/$name.err"; fail "$name: daemon exit status $rc"; }
    case "$sum" in *"unpaired=0 badcrc=0"*) ;; *) fail "$name: a Status without its Health, or a bad CRC";; esac
}
val() { echo "$sum" | tr ' ' '\n' | sed -n "s/^$1=//p"; }
has_fault() { case ",$(val faults)," in *",$1,"*) ;; *) fail "$name: Health Fault lacks $1 ($sum)";; esac; }
no_fault() { case ",$(val faults)," in *",$1,"*) fail "$name: Health Fault has $1 ($sum)";; esac; }
never_streaming() { case ",$(val links)," in *",3,"*) fail "$name: a Status said STREAMING ($sum)";; esac; }
azimuths() { sed -n 's/.*exit: [0-9]* rotations, \([0-9]*\) azimuths.*/\1/p' "$OUT/$name.err"; }

# 1. keep-alives only: the data watchdog sends Start FFT again, then reconnects; never
#    STREAMING, NO_USABLE_ROWS, Reconnects counted.
run keepalive "--keepalive-only --keepalive-ms 100" --data-timeout-ms 600 \
    --silence-timeout-ms 10000 --duration 4
never_streaming; has_fault NO_USABLE_ROWS
[ "$(val reconnects)" -ge 1 ] || fail "keepalive: no reconnect on CAN ($sum)"
grep -q "radar disconnected (NO_DATA" "$OUT/keepalive.err" || fail "keepalive: no data watchdog drop"
grep -Eq "client 1 .* starts [2-9]" "$OUT/keepalive.replay.err" || fail "keepalive: Start FFT not sent again"

# 2. slowloris: bytes keep coming (no silence timeout) but never a whole FFT message in time.
run trickle "--trickle-bps 200 --keepalive-ms 100" --data-timeout-ms 600 \
    --silence-timeout-ms 10000 --duration 4
never_streaming; has_fault NO_USABLE_ROWS
grep -q "radar disconnected (NO_DATA" "$OUT/trickle.err" || fail "trickle: no data watchdog drop"
grep -q "radar disconnected (SILENCE" "$OUT/trickle.err" && fail "trickle: bytes were flowing, not silent"

# 3./4. the connection ends in the middle of a message (FIN, then RST): reconnect, counted on
#    CAN, every FFT message still processed once (the replay resends the cut one whole).
run cut "--cut-after 1000" --exit-idle 1.5 --duration 20
[ "$(val reconnects)" -ge 1 ] || fail "cut: no reconnect on CAN ($sum)"
[ "$(azimuths)" -eq $FFT ] || fail "cut: $(azimuths) azimuths processed, want $FFT"
run rst "--rst-after 1000" --exit-idle 1.5 --duration 20
[ "$(val reconnects)" -ge 1 ] || fail "rst: no reconnect on CAN ($sum)"
[ "$(azimuths)" -eq $FFT ] || fail "rst: $(azimuths) azimuths processed, want $FFT"
grep -q "radar disconnected (ERROR" "$OUT/rst.err" || fail "rst: the reset was not seen as an error"
# ... also when the daemon lags behind: what the radar sent before its reset is still read
#    (a RST discards the sender's unsent bytes, so the replay resets once all are acknowledged;
#    CI once lost 6 messages here under ASan).
PAUSE=1 run rstlag "--rst-after 1000" --exit-idle 5 --duration 30
[ "$(azimuths)" -eq $FFT ] || fail "rstlag: $(azimuths) azimuths processed, want $FFT"

# 5./6. a radar with another azimuth count or encoder size: refused loudly, never blind in
#    silence: CONFIG_MISMATCH, never STREAMING, no rotation, an error in the log.
run az7 "--config-azimuths 7" --duration 3
never_streaming; has_fault CONFIG_MISMATCH; has_fault NO_USABLE_ROWS
[ "$(val rotations)" -eq 0 ] || fail "az7: rotations counted while every row is refused"
grep -q "error: radar geometry (7 azimuths" "$OUT/az7.err" || fail "az7: no error logged"
run enc "--config-encoder 5601" --duration 3
never_streaming; has_fault CONFIG_MISMATCH

# 7. another bin size (CIR-class 0.0596 m): flagged, data still processed.
run bin "--config-bin-size-m 0.0596" --exit-idle 1.5 --duration 20
has_fault RANGE_RESOLUTION_MISMATCH
grep -q "error: radar bin size 59600 um" "$OUT/bin.err" || fail "bin: no error logged"
run binok "--config-bin-size-m 0.0440" --exit-idle 1.5 --duration 20
no_fault RANGE_RESOLUTION_MISMATCH # 0.5 %: within 1 %

# 8. shuffled azimuths (each rotation's messages in random order): one rotation per pass,
#    every row kept, AZIMUTH_DISORDER, the CAN rate stays at the rotation rate.
run shuffle "--shuffle 400" --exit-idle 1.5 --duration 20
has_fault AZIMUTH_DISORDER
[ "$(azimuths)" -eq $FFT ] || fail "shuffle: $(azimuths) azimuths processed, want $FFT"
r=$(val rotations); [ "$r" -ge 8 ] && [ "$r" -le 10 ] || fail "shuffle: $r rotations for 8 passes"
[ "$(val max_frames_per_s)" -le 60 ] || fail "shuffle: $(val max_frames_per_s) CAN frames in 1 s"
echo "faults: OK"
