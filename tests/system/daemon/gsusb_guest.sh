# SPDX-License-Identifier: MIT
# gsusb_guest.sh: runs INSIDE the gs_usb test VM (tests/support/vm/build_vm.sh image: chroot on
# the host's read-only root, $OUT writable, $KMOD the extracted kernel modules). Presents the
# fake candleLight of tests/system/gsusb (dummy_hcd + configfs + FunctionFS, echo + reply mode) and
# runs shadowleand --gs-usb 1d50:606f on a capture (24 rotations, 6 s) in real time, next to
# --can-log.
# Settings from $OUT/vm.env: SL_DAEMON, SL_GSDIR, SL_CAPTURE, SL_BOARD.
. "$OUT/vm.env"
. "$SL_GSDIR/fake_device.sh"
fake_candlelight_up "$SL_GSDIR" daemon normal
t "fake candleLight bound (kernel gs_usb: can0); starting shadowleand --gs-usb"
# --gs-usb-max-age-ms 0: a TCG guest on a loaded host can be descheduled for longer than
# the 200 ms age limit; this test checks the transport and its accounting (every frame
# logged is confirmed by the device), not the age limit (tests/system/gsusb: stall scenarios).
"$SL_DAEMON" --board "$SL_BOARD" --input "$SL_CAPTURE" --realtime --gs-usb 1d50:606f --gs-usb-max-age-ms 0 \
    --can-log "$OUT/daemon.log" --targets-out "$OUT/targets.jsonl" > daemon.out 2>&1
echo $? > rc_daemon
t "shadowleand exit $(cat rc_daemon)"
wait_for 50 test -e /sys/class/net/can0 && echo 1 > can0_back || echo 0 > can0_back
t "done"
