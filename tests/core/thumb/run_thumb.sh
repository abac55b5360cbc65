#!/bin/sh
# SPDX-License-Identifier: MIT
# run_thumb.sh CPU MACHINE ELF HOST_FRAMES CAPTURE BOARD MAX_INSTR_PER_AZIMUTH [PSRAM_BOARD_INDEX [CHUNK]]
# Runs the example firmware (capture linked into its flash) under qemu-system-arm with
# -icount shift=0 and semihosting, runs the same application on the host over the same
# capture, and requires: the image exits 0, every rotation and CAN frame line is identical
# (and the capture does produce targets, so the comparison is not vacuous), and the
# instruction count per azimuth is within the budget. Prints the image's figures, among
# them "thumb: <cpu> <N> instructions per azimuth". Deterministic: instruction counts,
# not time; the timeout only guards against a hung guest.
# With PSRAM_BOARD_INDEX the image carries no capture: QEMU loads CAPTURE (cut to the
# 16 MB PSRAM, at most 16 MB - 16 bytes) into the board's PSRAM, and the host is given the
# same cut bytes; CHUNK is the image's feed size (default 1460, a TCP segment; the host
# output does not depend on it).
set -eu
cpu=$1; machine=$2; elf=$3; host=$4; cap=$5; board=$6; budget=$7; psram=${8:-}; chunk=${9:-0}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
load=""
if [ -n "$psram" ]; then
    head -c $((16 * 1024 * 1024 - 16)) "$cap" > "$tmp/cap.bin"
    cap=$tmp/cap.bin
    n=$(wc -c < "$cap")
    load="-device loader,addr=0x21000000,data=0x50434c53,data-len=4
          -device loader,addr=0x21000004,data=$n,data-len=4
          -device loader,addr=0x21000008,data=$psram,data-len=4
          -device loader,addr=0x2100000c,data=$chunk,data-len=4
          -device loader,file=$cap,addr=0x21000010,force-raw=on"
fi
"$host" "$cap" "$board" > "$tmp/host.txt"
set +e
# shellcheck disable=SC2086
timeout 600 qemu-system-arm -machine "$machine" -nographic -monitor none -serial none \
    -semihosting-config enable=on,target=native -icount shift=0 $load -kernel "$elf" > "$tmp/fw.txt" 2>&1
rc=$?
set -e
grep -Ev '^(frame|rotation) ' "$tmp/fw.txt" || true
[ $rc -eq 0 ] || { echo "FAIL: $cpu image exited $rc under $machine"; exit 1; }
grep -q '^done$' "$tmp/fw.txt" || { echo "FAIL: $cpu image did not finish"; exit 1; }
grep -E '^(frame|rotation) ' "$tmp/host.txt" > "$tmp/h"
grep -E '^(frame|rotation) ' "$tmp/fw.txt" > "$tmp/f"
if [ -z "$psram" ]; then # the simulated capture has targets; the Oxford scans have none
    grep -Eq '^rotation .* targets [1-9]' "$tmp/h" || { echo "FAIL: the capture gives no target on the host"; exit 1; }
fi
[ "$(grep -c '^rotation ' "$tmp/h")" -gt 0 ] || { echo "FAIL: no rotation on the host"; exit 1; }
if ! cmp -s "$tmp/h" "$tmp/f"; then
    echo "FAIL: $cpu frames differ from the host's:"; diff "$tmp/h" "$tmp/f" | head -20; exit 1
fi
echo "same rotations and CAN frames as the host: $(grep -c '^frame ' "$tmp/h") frames, $(grep -c '^rotation ' "$tmp/h") rotations"
n=$(sed -n "s/^thumb: $cpu \([0-9]*\) instructions per azimuth$/\1/p" "$tmp/fw.txt")
[ -n "$n" ] || { echo "FAIL: no 'thumb: $cpu' line"; exit 1; }
if [ "$n" -gt "$budget" ]; then
    echo "FAIL: $cpu $n instructions per azimuth > budget $budget"; exit 1
fi
echo "thumb: $cpu $n instructions per azimuth (budget $budget; $(basename "$5"), $board, feed chunks of $(sed -n 's/^feed chunks of \([0-9]*\) bytes$/\1/p' "$tmp/fw.txt") B) OK"
