#!/bin/sh
# SPDX-License-Identifier: MIT
# qemu_run.sh SOURCE_DIR CACHE_DIR OUT_DIR GUEST_SCRIPT
#
# The one QEMU harness of the VM tests (the user-mode Linux one is uml_run.sh beside it):
# prepares the throw-away test VM once (build_vm.sh: a stock Debian kernel and a busybox
# initramfs, cached in CACHE_DIR), then boots it (TCG: a /dev/kvm may not boot a
# stock kernel) with the host's / read-only and OUT_DIR read-write over virtio-9p; the
# initramfs chroots into the host's root and runs GUEST_SCRIPT, whose variables the caller
# wrote into OUT_DIR/vm.env and whose results it leaves in OUT_DIR (OUT_DIR/console.log:
# the console; the guest's "[guest ...]" / "[init ...]" lines are printed here).
# Exit: 0 = the VM ran and halted (the caller judges the results), 1 = it did not finish
# within $SL_VM_TIMEOUT seconds (default 150; qemu is killed), 77 = skip (ctest
# SKIP_RETURN_CODE: qemu-system-x86_64 is not installed).
set -eu
SRC=${1:?usage: qemu_run.sh SOURCE_DIR CACHE_DIR OUT_DIR GUEST_SCRIPT}
CACHE=${2:?}; OUT=${3:?}; GUEST=${4:?}
if ! command -v qemu-system-x86_64 >/dev/null 2>&1; then
    echo "SKIP: qemu-system-x86_64 is not installed (sh scripts/deps.sh test installs it)"
    exit 77
fi
TIMEOUT=${SL_VM_TIMEOUT:-150}
sh "$SRC/tests/support/vm/build_vm.sh" "$CACHE" "$SRC"
KERNEL=$(cat "$CACHE/kernel_path")
KMOD=$(cat "$CACHE/kmod_path")
OUT=$(cd "$OUT" && pwd)
set +e
timeout -k 5 "$TIMEOUT" qemu-system-x86_64 -accel tcg,thread=multi -cpu max -m 1024 -smp 2 \
    -nographic -no-reboot -nic none \
    -kernel "$KERNEL" -initrd "$CACHE/initrd.gz" \
    -append "console=ttyS0 quiet panic=-1 sl_out=$OUT sl_guest=$GUEST sl_kmod=$KMOD" \
    -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
    -virtfs local,path="$OUT",mount_tag=out,security_model=none \
    < /dev/null > "$OUT/console.log" 2>&1
QRC=$?
set -e
echo "qemu_run: VM finished (qemu exit $QRC)"
grep -E "^\[(guest|init)" "$OUT/console.log" || true
if [ $QRC -eq 124 ] || [ $QRC -eq 137 ]; then
    echo "FAIL: the VM did not finish within $TIMEOUT s (console: $OUT/console.log)"
    tail -30 "$OUT/console.log"
    exit 1
fi
exit 0
