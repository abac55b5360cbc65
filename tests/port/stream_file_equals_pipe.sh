#!/bin/sh
# SPDX-License-Identifier: MIT
# stream_file_equals_pipe.sh MAKE_STREAM SHADOWLEAND OUT_DIR [EMULATOR...]
# A generated Colossus stream (24 rotations) through `shadowleand --input FILE` and through
# a pipe (`--input -`): the same CAN frames byte for byte, with Status frames for every
# rotation and exit status 0. Needs no host tool (runs in the aarch64 build under qemu).
# Board paper-sim: the stream has 0.0438 m bins (robotcar-leaf has 0.0432 m: a 1.4 %
# RANGE_RESOLUTION_MISMATCH, exit status 3).
set -u
MK=$1; D=$2; OUT=$3; shift 3
rm -rf "$OUT"; mkdir -p "$OUT"
"$@" "$MK" "$OUT/s.colossus" 24 || exit 1
"$@" "$D" --board paper-sim --input "$OUT/s.colossus" --can-log "$OUT/file.log" -q ||
    { echo "FAIL: file input exit status $?"; exit 1; }
cat "$OUT/s.colossus" | "$@" "$D" --board paper-sim --input - --can-log "$OUT/pipe.log" -q ||
    { echo "FAIL: pipe input exit status $?"; exit 1; }
n=$(grep -c " 5C1#" "$OUT/file.log")
[ "$n" -ge 20 ] || { echo "FAIL: $n Status frames (621) for 24 rotations"; cat "$OUT/file.log" | head; exit 1; }
cmp "$OUT/file.log" "$OUT/pipe.log" || { echo "FAIL: pipe input gives other frames"; exit 1; }
echo "file == pipe: $(wc -l < "$OUT/file.log") frames, $n Status"
