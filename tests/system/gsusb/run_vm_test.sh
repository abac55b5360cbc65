#!/bin/sh
# SPDX-License-Identifier: MIT
# run_vm_test.sh SOURCE_DIR CACHE_DIR SENDER: the gs_usb integration test.
# One boot of the test VM (tests/support/vm/qemu_run.sh) whose guest presents a fake candleLight (dummy_hcd + configfs + FunctionFS) and
# runs every scenario (tests/system/gsusb/guest.sh); then check_results.py compares, on the host,
# what the fake device received with what the senders logged, and asserts the counters.
# Exit: 0 pass, 1 fail, 77 skip (only when qemu-system-x86_64 is not installed).
set -eu
SRC=${1:?usage: run_vm_test.sh SOURCE_DIR CACHE_DIR SENDER}
CACHE=${2:?}
SEND=${3:?}
HERE="$SRC/tests/system/gsusb"
T0=$(date +%s.%N)
el() { awk -v a="$T0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
[ -x "$SEND" ] || { echo "FAIL: sender $SEND not built"; exit 1; }
mkdir -p "$CACHE"
OUT="$(cd "$CACHE" && pwd)/out"
rm -rf "$OUT"
mkdir -p "$OUT"
printf 'SL_SEND=%s\nSL_DIR=%s\n' "$SEND" "$HERE" > "$OUT/vm.env"
rc=0
sh "$SRC/tests/support/vm/qemu_run.sh" "$SRC" "$CACHE" "$OUT" "$HERE/guest.sh" || rc=$?
[ $rc -eq 0 ] || exit $rc
echo "[host $(el)s] VM finished"
RC=0
python3 "$HERE/check_results.py" "$OUT" "$HERE" || RC=$?
echo "[host $(el)s] total wall time"
exit $RC
