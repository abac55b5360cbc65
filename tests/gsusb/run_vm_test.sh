#!/bin/sh
# SPDX-License-Identifier: MIT
# run_vm_test.sh SOURCE_DIR CACHE_DIR SENDER: the gs_usb integration test.
# One QEMU boot (TCG; this machine's /dev/kvm cannot boot a stock kernel) of a Debian
# kernel whose guest presents a fake candleLight (dummy_hcd + configfs + FunctionFS) and
# runs every scenario (tests/gsusb/guest.sh); then check_results.py compares, on the host,
# what the fake device received with what the senders logged, and asserts the counters.
# Exit: 0 pass, 1 fail, 77 skip (only when qemu-system-x86_64 is not installed).
set -eu
SRC=${1:?usage: run_vm_test.sh SOURCE_DIR CACHE_DIR SENDER}
CACHE=${2:?}
SEND=${3:?}
HERE="$SRC/tests/gsusb"
if ! command -v qemu-system-x86_64 >/dev/null 2>&1; then
    echo "SKIP: qemu-system-x86_64 is not installed (sh scripts/deps.sh test installs it)"
    exit 77
fi
T0=$(date +%s.%N)
el() { awk -v a="$T0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
[ -x "$SEND" ] || { echo "FAIL: sender $SEND not built"; exit 1; }

sh "$HERE/build_vm.sh" "$CACHE" "$SRC"
echo "[host $(el)s] VM image ready"
KERNEL=$(cat "$CACHE/kernel_path")
KMOD=$(cat "$CACHE/kmod_path")
OUT="$CACHE/out"
rm -rf "$OUT"
mkdir -p "$OUT"
printf 'SL_SEND=%s\nSL_DIR=%s\n' "$SEND" "$HERE" > "$OUT/vm.env"

# Hard limit for the whole boot: 150 s (a normal run takes well under a minute).
set +e
timeout -k 5 150 qemu-system-x86_64 -accel tcg,thread=multi -cpu max -m 1024 -smp 2 \
    -nographic -no-reboot -nic none \
    -kernel "$KERNEL" -initrd "$CACHE/initrd.gz" \
    -append "console=ttyS0 quiet panic=-1 sl_out=$OUT sl_guest=$HERE/guest.sh sl_kmod=$KMOD" \
    -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
    -virtfs local,path="$OUT",mount_tag=out,security_model=none \
    < /dev/null > "$OUT/console.log" 2>&1
QRC=$?
set -e
echo "[host $(el)s] VM finished (qemu exit $QRC)"
grep -E "^\[(guest|init)" "$OUT/console.log" || true
if [ $QRC -eq 124 ] || [ $QRC -eq 137 ]; then
    echo "FAIL: the VM did not finish within 150 s (console: $OUT/console.log)"
    tail -30 "$OUT/console.log"
    exit 1
fi
RC=0
python3 "$HERE/check_results.py" "$OUT" "$HERE" || RC=$?
echo "[host $(el)s] total wall time"
exit $RC
