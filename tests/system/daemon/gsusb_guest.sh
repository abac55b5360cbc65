# SPDX-License-Identifier: MIT
# gsusb_guest.sh: runs INSIDE the gs_usb test VM (tests/support/vm/build_vm.sh image: chroot on
# the host's read-only root, $OUT writable, $KMOD the extracted kernel modules). Presents the
# fake candleLight of tests/system/gsusb (dummy_hcd + configfs + FunctionFS, echo + reply mode) and
# runs shadowleand --gs-usb 1d50:606f on a capture (24 rotations, 6 s) in real time, next to
# --can-log.
# Settings from $OUT/vm.env: SL_DAEMON, SL_GSDIR, SL_CAPTURE.
. "$OUT/vm.env"
t() { read -r up _ < /proc/uptime; echo "[guest t=${up}s] $*"; }
wait_for() { n=$1; shift; while [ "$n" -gt 0 ]; do "$@" && return 0; sleep 0.1; n=$((n - 1)); done; return 1; }
for m in drivers/usb/common/usb-common drivers/usb/core/usbcore drivers/usb/gadget/udc/udc-core \
         drivers/usb/gadget/udc/dummy_hcd fs/configfs/configfs drivers/usb/gadget/libcomposite \
         drivers/usb/gadget/function/usb_f_fs net/can/can net/can/can-raw \
         drivers/net/can/dev/can-dev drivers/net/can/usb/gs_usb; do
    insmod "$KMOD/$m.ko" || echo "insmod $m FAILED"
done
mount -t configfs none /sys/kernel/config
G=/sys/kernel/config/usb_gadget/gs
mkdir $G && cd $G || exit 1
echo 0x1d50 > idVendor; echo 0x606f > idProduct; echo 0x0200 > bcdUSB
mkdir strings/0x409
echo FAKE0001 > strings/0x409/serialnumber
echo "shadowlean (fake)" > strings/0x409/manufacturer
echo "candleLight USB to CAN adapter (FunctionFS emulation)" > strings/0x409/product
mkdir -p configs/c.1/strings/0x409 && echo gs_usb > configs/c.1/strings/0x409/configuration
mkdir functions/ffs.gs && ln -s functions/ffs.gs configs/c.1/
mkdir -p /run/ffs-gs && mount -t functionfs gs /run/ffs-gs
cd "$OUT" || exit 1
printf 'scenario=daemon\nmode=normal\n' > "$OUT/ctl"
python3 -S -u "$SL_GSDIR/fake_candlelight.py" /run/ffs-gs "$OUT" "$OUT/ctl" $G/UDC dummy_udc.0 \
    > gadget.log 2>&1 &
wait_for 100 test -e /run/ffs-gs/ep2 || t "gadget did not start"
echo dummy_udc.0 > $G/UDC
wait_for 100 test -e /sys/class/net/can0 || t "can0 did not appear"
t "fake candleLight bound (kernel gs_usb: can0); starting shadowleand --gs-usb"
# --gs-usb-max-age-ms 0: a TCG guest on a loaded host can be descheduled for longer than
# the 200 ms age limit; this test checks the transport and its accounting (every frame
# logged is confirmed by the device), not the age limit (tests/system/gsusb: stall scenarios).
"$SL_DAEMON" --board paper-sim --input "$SL_CAPTURE" --realtime --gs-usb 1d50:606f --gs-usb-max-age-ms 0 \
    --can-log "$OUT/daemon.log" --targets-out "$OUT/targets.jsonl" > daemon.out 2>&1
echo $? > rc_daemon
t "shadowleand exit $(cat rc_daemon)"
wait_for 50 test -e /sys/class/net/can0 && echo 1 > can0_back || echo 0 > can0_back
t "done"
