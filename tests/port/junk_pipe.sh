#!/bin/sh
# SPDX-License-Identifier: MIT
# junk_pipe.sh SHADOWLEAND MIB OUT_DIR [EMULATOR...]
# MIB MiB of junk (half zeros, half text: no Colossus message) through a pipe into
# `shadowleand --input -`: memory stays constant (peak RSS <= 64 MiB, /usr/bin/time -v),
# every byte is counted (read = skipped = MIB MiB in the daemon's input report) and the exit
# status says the input held no message (1).
set -u
D=$1; MIB=$2; OUT=$3; shift 3
rm -rf "$OUT"; mkdir -p "$OUT"
N=$((MIB * 1048576)); HALF=$((N / 2))
[ -x /usr/bin/time ] || { echo "SKIP: /usr/bin/time missing (Debian package time)"; exit 77; }
{ head -c "$HALF" /dev/zero; yes "shadowlean junk line, no signature here" | head -c $((N - HALF)); } |
    /usr/bin/time -v -o "$OUT/time.txt" "$@" "$D" --board robotcar-leaf --input - --can-log "$OUT/can.log" \
    2> "$OUT/daemon.err"
rc=$?
cat "$OUT/daemon.err"
[ "$rc" -eq 1 ] || { echo "FAIL: exit status $rc, expected 1 (no Colossus message)"; exit 1; }
grep -q "input - (raw): $N bytes read, $N stream bytes, 0 messages, 0 FFT, 0 discontinuities, $N bytes skipped" \
    "$OUT/daemon.err" || { echo "FAIL: not every one of the $N bytes counted as read and skipped"; exit 1; }
grep -q "no Colossus message in $N bytes ($N skipped)" "$OUT/daemon.err" || { echo "FAIL: no error naming the junk"; exit 1; }
rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$OUT/time.txt")
echo "junk: $N bytes through a pipe, exit 1, peak RSS $rss KiB"
[ "$rss" -le 65536 ] || { echo "FAIL: peak RSS $rss KiB > 64 MiB"; exit 1; }
