#!/bin/sh
# SPDX-License-Identifier: MIT
# exit_statuses.sh SL_SIM SHADOWLEAND PYTHON SRC_DIR OUT_DIR
# Capture mode exit statuses (docs/DAEMON.md, "Exit statuses"), each with what CAN says:
#   0 ok; 1 unreadable input; 2 bad options; 3 no usable rotation or a configuration fault
#   (Health CONFIG_MISMATCH / RANGE_RESOLUTION_MISMATCH); 4 an output could not be written
#   (--can-log /dev/full).
# The streams are made here: a simulated capture, then byte-patched copies of it.
set -u
SL_SIM=$1; DAEMON=$2; PY=$3; SRC=$4; OUT=$5
rm -rf "$OUT"; mkdir -p "$OUT"
DBC="$SRC/../../../boards/paper-sim/shadowlean.dbc"
fail() { echo "FAIL: $*"; exit 1; }
"$SL_SIM" "$SRC/scenes/static_four_poles.ini" -o "$OUT/ok.colossus" --rotations 4 --quiet || exit 1
# patch FILE OUT FIELD VALUE: rewrite the Configuration (the first message) in a copy.
patch() {
    "$PY" - "$1" "$2" "$3" "$4" <<'PY'
import struct, sys
src, dst, field, value = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
b = bytearray(open(src, "rb").read())
assert b[17] == 10, "the capture does not start with a Configuration"
off = {"azimuths": 0, "bin_100um": 2, "encoder": 6}[field]
struct.pack_into(">H", b, 22 + off, value)
if field == "bin_100um":  # the protobuf's rangeresolutionmetres (field 10, fixed32) too
    plen = struct.unpack_from(">I", b, 18)[0]
    pb = b[22 + 20:22 + plen]
    i = pb.find(bytes([(10 << 3) | 5]))
    if i >= 0:
        struct.pack_into("<f", b, 22 + 20 + i + 1, value / 10000.0)
open(dst, "wb").write(b)
PY
}
expect() { # WANT NAME ARGS...: run, check the exit status, summarise the CAN log if any
    want=$1; name=$2; shift 2
    "$DAEMON" --board paper-sim "$@" 2> "$OUT/$name.err"
    rc=$?
    sum=""
    if [ -s "$OUT/$name.log" ]; then
        sum=$("$PY" "$SRC/health_summary.py" "$DBC" "$OUT/$name.log") || fail "$name: decode"
    fi
    echo "$name: exit $rc (want $want) $sum"
    [ $rc -eq "$want" ] || { cat "$OUT/$name.err"; fail "$name: exit status $rc, want $want"; }
}
faults_have() { case "$sum" in *"faults="*"$1"*) ;; *) fail "$name: Health Fault lacks $1";; esac; }

expect 0 ok --input "$OUT/ok.colossus" --can-log "$OUT/ok.log"
case "$sum" in *"fault=0x0000"*"rotations=4"*) ;; *) fail "ok: want no fault, 4 rotations";; esac
expect 1 missing --input "$OUT/nope.colossus" --can-log "$OUT/missing.log"
mkdir -p "$OUT/adir"
expect 1 directory --input "$OUT/adir" --can-log "$OUT/directory.log"
expect 2 badopt --input "$OUT/ok.colossus" --frobnicate
# No usable rotation: junk only, or FFT messages that are all malformed.
head -c 200000 /dev/urandom > "$OUT/junk.colossus"
expect 1 junk --input "$OUT/junk.colossus" --can-log "$OUT/junk.log"
"$PY" - "$OUT/ok.colossus" "$OUT/malformed.colossus" <<'PY'
import struct, sys
b = bytearray(open(sys.argv[1], "rb").read())
i = 0
while i + 22 <= len(b):
    plen = struct.unpack_from(">I", b, i + 18)[0]
    if b[i + 17] in (30, 31):
        struct.pack_into(">H", b, i + 22, 5)  # data offset 5 < 14: malformed
    i += 22 + plen
open(sys.argv[2], "wb").write(b)
PY
expect 3 malformed --input "$OUT/malformed.colossus" --can-log "$OUT/malformed.log"
grep -q "no usable rotation" "$OUT/malformed.err" || fail "malformed: no error logged"
# Configuration faults: 7 azimuths (every row refused), encoder 5601, bin size 0.0596 m.
patch "$OUT/ok.colossus" "$OUT/az7.colossus" azimuths 7
expect 3 az7 --input "$OUT/az7.colossus" --can-log "$OUT/az7.log"
faults_have CONFIG_MISMATCH
case "$sum" in *"links=4 "*"rotations=0"*) ;; *) fail "az7: want SILENT and no rotation";; esac
grep -q "differs from board paper-sim: [0-9]* rows refused" "$OUT/az7.err" || fail "az7: no error logged"
patch "$OUT/ok.colossus" "$OUT/enc.colossus" encoder 5601
expect 3 enc --input "$OUT/enc.colossus" --can-log "$OUT/enc.log"
faults_have CONFIG_MISMATCH
patch "$OUT/ok.colossus" "$OUT/bin.colossus" bin_100um 596
expect 3 bin --input "$OUT/bin.colossus" --can-log "$OUT/bin.log"
faults_have RANGE_RESOLUTION_MISMATCH
grep -q "radar bin size 59600 um differs" "$OUT/bin.err" || fail "bin: no error logged"
# Output write failure: the CAN log on a full disk.
if [ -w /dev/full ]; then
    expect 4 full --input "$OUT/ok.colossus" --can-log /dev/full
    grep -q "error: --can-log /dev/full" "$OUT/full.err" || fail "full: not logged as an error"
else
    echo "(no /dev/full: output failure check skipped)"
fi
echo "exit_statuses: OK"
