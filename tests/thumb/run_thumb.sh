#!/bin/sh
# run_thumb.sh CPU MACHINE ELF HOST_FRAMES CAPTURE BOARD MAX_INSTR_PER_AZIMUTH
# Runs the example firmware (capture linked into its flash) under qemu-system-arm with
# -icount shift=0 and semihosting, runs the same application on the host over the same
# capture, and requires: the image exits 0, every rotation and CAN frame line is identical
# (and the capture does produce targets, so the comparison is not vacuous), and the
# instruction count per azimuth is within the budget. Prints the image's figures, among
# them "thumb: <cpu> <N> instructions per azimuth". Deterministic: instruction counts,
# not time; the timeout only guards against a hung guest.
set -eu
cpu=$1; machine=$2; elf=$3; host=$4; cap=$5; board=$6; budget=$7
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
"$host" "$cap" "$board" > "$tmp/host.txt"
set +e
timeout 600 qemu-system-arm -machine "$machine" -nographic -monitor none -serial none \
    -semihosting-config enable=on,target=native -icount shift=0 -kernel "$elf" > "$tmp/fw.txt" 2>&1
rc=$?
set -e
grep -Ev '^(frame|rotation) ' "$tmp/fw.txt" || true
[ $rc -eq 0 ] || { echo "FAIL: $cpu image exited $rc under $machine"; exit 1; }
grep -q '^done$' "$tmp/fw.txt" || { echo "FAIL: $cpu image did not finish"; exit 1; }
grep -E '^(frame|rotation) ' "$tmp/host.txt" > "$tmp/h"
grep -E '^(frame|rotation) ' "$tmp/fw.txt" > "$tmp/f"
grep -Eq '^rotation .* targets [1-9]' "$tmp/h" || { echo "FAIL: the capture gives no target on the host"; exit 1; }
if ! cmp -s "$tmp/h" "$tmp/f"; then
    echo "FAIL: $cpu frames differ from the host's:"; diff "$tmp/h" "$tmp/f" | head -20; exit 1
fi
echo "same rotations and CAN frames as the host: $(grep -c '^frame ' "$tmp/h") frames, $(grep -c '^rotation ' "$tmp/h") rotations"
n=$(sed -n "s/^thumb: $cpu \([0-9]*\) instructions per azimuth$/\1/p" "$tmp/fw.txt")
[ -n "$n" ] || { echo "FAIL: no 'thumb: $cpu' line"; exit 1; }
if [ "$n" -gt "$budget" ]; then
    echo "FAIL: $cpu $n instructions per azimuth > budget $budget"; exit 1
fi
echo "thumb: $cpu $n instructions per azimuth (budget $budget) OK"
