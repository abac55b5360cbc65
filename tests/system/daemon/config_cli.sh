#!/bin/sh
# SPDX-License-Identifier: MIT
# config_cli.sh SHADOWLEAND SRC_DIR OUT_DIR
# Settings: the example config file parses; the command line overrides it key by key;
# --print-config output reads back to the same settings; bad files and options are
# rejected with exit status 2 and a message naming the file and line; --user drops root.
set -u
D=$1; SRC=$2; OUT=$3
rm -rf "$OUT"; mkdir -p "$OUT"
CONF="$SRC/../../../packaging/shadowleand.conf"
fail() { echo "FAIL: $*"; exit 1; }
has() { grep -qx -- "$2" "$1" || { echo "--- $1:"; cat "$1"; fail "missing line '$2'"; }; }
hasnt() { ! grep -q -- "$2" "$1" || { cat "$1"; fail "unexpected '$2'"; }; }

# 1. the example config
"$D" --config "$CONF" --print-config > "$OUT/example.ini" || fail "example config rejected"
has "$OUT/example.ini" "board = robotcar-leaf"
has "$OUT/example.ini" "radar = 192.168.0.1:6317"
has "$OUT/example.ini" "interface = can0"
has "$OUT/example.ini" "stats_every = 60.000"

# 2. command line over config file
"$D" --config "$CONF" --board paper-sim --input /some/capture.pcap --can vcan1 -v --stats-every 0.5 \
    --gs-usb 1-1.4 --bitrate 250000 --targets-out t.jsonl --tail-slope 3.27 --front-bins 4 --r2-offset 12.66 --print-config > "$OUT/over.ini" \
    || fail "override rejected"
has "$OUT/over.ini" "board = paper-sim"
has "$OUT/over.ini" "capture = /some/capture.pcap"
hasnt "$OUT/over.ini" "radar ="
has "$OUT/over.ini" "interface = vcan1"
has "$OUT/over.ini" "motion_interface = can0"      # from the file, not overridden
has "$OUT/over.ini" "verbosity = debug"
has "$OUT/over.ini" "stats_every = 0.500"
has "$OUT/over.ini" "gs_usb = 1-1.4"
has "$OUT/over.ini" "bitrate = 250000"
has "$OUT/over.ini" "targets = t.jsonl"
has "$OUT/over.ini" "tail_slope = 3.2695"            # 837 / 256: what the core keeps
has "$OUT/over.ini" "front_bins = 4"
has "$OUT/over.ini" "r2_offset_mm = 12.660"

# 3. --print-config reads back to the same settings
grep -v '^;' "$OUT/over.ini" > "$OUT/rt1.ini"
"$D" --config "$OUT/rt1.ini" --print-config | grep -v '^;' > "$OUT/rt2.ini" || fail "printed config rejected"
cmp "$OUT/rt1.ini" "$OUT/rt2.ini" || { diff "$OUT/rt1.ini" "$OUT/rt2.ini"; fail "print/read round trip differs"; }

# 4. rejections (exit status 2, a message that says where)
rejects() { # WHAT EXPECTED-TEXT ARGS...
    what=$1; text=$2; shift 2
    "$D" "$@" > "$OUT/rej.out" 2>&1
    rc=$?
    [ $rc -eq 2 ] || { cat "$OUT/rej.out"; fail "$what: exit status $rc, want 2"; }
    grep -q -- "$text" "$OUT/rej.out" || { cat "$OUT/rej.out"; fail "$what: no '$text' in the message"; }
    echo "rejected $what: $(head -1 "$OUT/rej.out")"
}
printf '[daemon]\nboard = paper-sim\n[input]\ncapture = x\n[can]\ninterfac = can0\n' > "$OUT/typo.ini"
rejects "an unknown key" "typo.ini:6: unknown setting \[can\] interfac" --config "$OUT/typo.ini"
printf '[daemon]\nboard = paper-sim\nstats_every = soon\n' > "$OUT/badval.ini"
rejects "a bad value" "badval.ini:3: daemon.stats_every" --config "$OUT/badval.ini" --input x
printf '[input]\nradar = 1.2.3.4\ncapture = x\n' > "$OUT/both.ini"
rejects "radar and capture in one file" "both \[input\] radar and capture" --config "$OUT/both.ini" --board paper-sim
rejects "a missing file" "cannot open" --config "$OUT/nope.ini"
mkdir -p "$OUT/confdir"
rejects "a directory as --config" "not a regular file (a directory)" --config "$OUT/confdir" --board paper-sim --input x
printf '[daemon]\nboard = paper-sim\n[input]\ncapture = x\nsilent_ms = 100\nsilent_ms = 200\n' > "$OUT/dup.ini"
rejects "a duplicate key" "dup.ini:6: input.silent_ms: duplicate key" --config "$OUT/dup.ini"
printf '[daemon]\nboard = paper-sim\n[input]\ncapture = x\n[daemon]\nboard = robotcar-leaf\n' > "$OUT/dup2.ini"
rejects "a key repeated in a second section" "dup2.ini:6: daemon.board: duplicate key" --config "$OUT/dup2.ini"
rejects "an unknown board" "unknown board 'moon-rover'" --board moon-rover --input x
rejects "no input" "no input" --board paper-sim
rejects "--realtime with a radar" "--realtime applies to --input only" --board paper-sim --radar 1.2.3.4 --realtime
rejects "a bad port" "expected HOST:PORT" --board paper-sim --radar 1.2.3.4:99999
rejects "an unknown option" "unknown option" --board paper-sim --input x --frobnicate
rejects "two motion inputs" "exclusive" --board paper-sim --input x --motion 1.0 --motion-can vcan0
rejects "a bad motion" "SPEED_M_S" --board paper-sim --input x --motion fast
rejects "an implausible tail slope" "0.5 .. 24 values per bin" --board paper-sim --input x --tail-slope 30
rejects "a tail slope that is not a number" "daemon.tail_slope" --board paper-sim --input x --tail-slope steep
rejects "a front part of one bin" "2 .. 7 bins" --board paper-sim --input x --front-bins 1
rejects "a front part too long" "daemon.front_bins" --board paper-sim --input x --front-bins 8
rejects "a walk-end offset beyond 100 mm" "-100 .. +100 mm" --board paper-sim --input x --r2-offset 150
rejects "a walk-end offset that is not a number" "daemon.r2_offset_mm" --board paper-sim --input x --r2-offset far
"$D" --board paper-sim --input x --can can0 --motion 2.5,-3 --print-config > "$OUT/motion.ini" || fail "--motion"
has "$OUT/motion.ini" "motion = 2.500,-3.00"
hasnt "$OUT/motion.ini" "motion_interface"
rejects "two stdout outputs" "cannot both be stdout" --board paper-sim --input x --can-log - --targets-out -
"$D" --list-boards > "$OUT/boards.txt" && has "$OUT/boards.txt" "robotcar-leaf" && has "$OUT/boards.txt" "paper-sim"
"$D" --help | grep -q -- "--gs-usb" || fail "--help"

# 5. --user: drop root after opening everything (root only)
if [ "$(id -u)" -eq 0 ] && id nobody > /dev/null 2>&1; then
    printf '' > "$OUT/empty.colossus"
    "$D" --board paper-sim --input "$OUT/empty.colossus" --can-log "$OUT/user.log" --user nobody \
        2> "$OUT/user.err"
    rc=$?  # an empty capture: no usable rotation (exit 3), after the privilege drop
    [ $rc -eq 3 ] || { cat "$OUT/user.err"; fail "--user nobody: exit $rc, want 3"; }
    grep -q "running as nobody (uid $(id -u nobody)" "$OUT/user.err" || { cat "$OUT/user.err"; fail "no privilege drop logged"; }
    "$D" --board paper-sim --input "$OUT/empty.colossus" --user no-such-user-xyz 2> "$OUT/user2.err"
    [ $? -eq 1 ] || fail "--user with an unknown user must fail"
    echo "--user nobody: $(grep 'running as' "$OUT/user.err")"
else
    echo "(--user check skipped: not root)"
fi
echo "config_cli: OK"
