# SPDX-License-Identifier: MIT
# guest.sh: runs INSIDE the test VM (chroot on the host's read-only root, $OUT writable).
# Presents a fake candleLight through dummy_hcd + configfs + FunctionFS and runs every
# scenario of the gs_usb integration test in one boot. It only runs things and records
# exit codes and logs in $OUT; check_results.py judges them on the host afterwards.
# Settings come from $OUT/vm.env (written by run_vm_test.sh): SL_SEND, SL_DIR.
. "$OUT/vm.env"
t() { read -r up _ < /proc/uptime; echo "[guest t=${up}s] $*"; }
rc_of() { echo "$2" > "$OUT/rc_$1"; }
scenario() { # name mode: switch the fake device's behaviour (atomically)
    printf 'scenario=%s\nmode=%s\n' "$1" "$2" > "$OUT/ctl.tmp" && mv "$OUT/ctl.tmp" "$OUT/ctl"
}
wait_for() { # TRIES command...: run command every 0.1 s until it succeeds
    n=$1; shift
    while [ "$n" -gt 0 ]; do "$@" && return 0; sleep 0.1; n=$((n - 1)); done
    return 1
}

for m in drivers/usb/common/usb-common drivers/usb/core/usbcore drivers/usb/gadget/udc/udc-core \
         drivers/usb/gadget/udc/dummy_hcd fs/configfs/configfs drivers/usb/gadget/libcomposite \
         drivers/usb/gadget/function/usb_f_fs net/can/can net/can/can-raw \
         drivers/net/can/dev/can-dev drivers/net/can/usb/gs_usb; do
    insmod "$KMOD/$m.ko" || echo "insmod $m FAILED"
done
t "modules loaded"
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
scenario kernel normal
python3 -S -u "$SL_DIR/fake_candlelight.py" /run/ffs-gs "$OUT" "$OUT/ctl" $G/UDC dummy_udc.0 \
    > gadget.log 2>&1 &
wait_for 100 test -e /run/ffs-gs/ep2 || t "gadget did not start"
echo dummy_udc.0 > $G/UDC
wait_for 100 test -e /sys/class/net/can0 || t "can0 did not appear"
t "gadget bound; net devices: $(ls /sys/class/net | tr '\n' ' ')"
BUSPORT=$(for d in /sys/bus/usb/devices/*-*; do
    case "$d" in *:*) continue ;; esac
    [ "$(cat "$d/idVendor" 2>/dev/null)" = 1d50 ] && basename "$d"; done | head -1)
echo "$BUSPORT" > busport
t "fake candleLight at bus-port $BUSPORT, driver: $(basename "$(readlink /sys/bus/usb/devices/$BUSPORT:1.0/driver)")"

# (a) The kernel's gs_usb driver: SocketCAN can0, frames sent with cansend.
t "== (a) kernel gs_usb + SocketCAN"
ip link set can0 type can bitrate 500000 && ip link set can0 up
ip -details link show can0 > kernel_iplink.txt 2>&1
candump -L can0 > candump_kernel.log 2>&1 & CPID=$!
# candump is listening once a marker frame (7E0#SYNC) shows up in its log; the end marker's
# reply (7E1#END) arrives after every earlier echo and reply. check_results.py drops markers.
n=0
until grep -q "7E0#53594E43" candump_kernel.log || [ $n -ge 40 ]; do
    cansend can0 7E0#53594E43; sleep 0.2; n=$((n + 1))
done
while read -r ts ifc frame; do
    [ -n "$frame" ] && cansend can0 "$frame"
done < "$SL_DIR/frames_kernel.log"
cansend can0 7E0#454E44
wait_for 100 grep -q "7E1#454E44" candump_kernel.log
kill $CPID
ip -s link show can0 > kernel_stats.txt 2>&1
ip link set can0 down
rc_of kernel 0

# (b) our libusb driver: sl-gsusb-send, the kernel driver detached meanwhile.
t "== (b1) libusb: frames from a candump log, VID:PID selector, one error frame"
scenario libusb_log normal+err
# The fake device (Python under TCG) can be slow: generous echo timeouts where every frame
# must be confirmed.
timeout 20 "$SL_SEND" 1d50:606f --bitrate 500000 --echo-timeout-ms 5000 --log "$SL_DIR/frames_libusb.log" \
    --expect-rx 12 --drain-ms 3000 --tx-log tx_libusb_log.log --rx-log rx_libusb_log.log --summary sum_libusb_log.txt \
    > out_libusb_log.txt 2>&1
rc_of libusb_log $?
wait_for 50 test -e /sys/class/net/can0 && echo 1 > can0_back_after_b1 || echo 0 > can0_back_after_b1
t "can0 back after release: $(cat can0_back_after_b1)"

t "== (b2) libusb: generated frames, bus-port selector"
scenario libusb_gen normal
timeout 20 "$SL_SEND" "$BUSPORT" --count 40 --echo-timeout-ms 5000 --expect-rx 40 --drain-ms 3000 --tx-log tx_libusb_gen.log \
    --rx-log rx_libusb_gen.log --summary sum_libusb_gen.txt --quiet > out_libusb_gen.txt 2>&1
rc_of libusb_gen $?

# (c) misbehaving device
t "== (c1) refused BITTIMING"
scenario refuse refuse:1
timeout 20 "$SL_SEND" 1d50:606f --count 3 --summary sum_refuse.txt > out_refuse.txt 2>&1
rc_of refuse $?

t "== (c2) stalled bulk endpoints"
scenario stall stall
timeout 20 "$SL_SEND" 1d50:606f --count 12 --echo-timeout-ms 5000 --tx-log tx_stall.log --summary sum_stall.txt \
    > out_stall.txt 2>&1
rc_of stall $?

t "== (c3) lost echoes"
scenario dropecho drop-echo:2
timeout 20 "$SL_SEND" 1d50:606f --count 15 --echo-timeout-ms 1500 --tx-log tx_dropecho.log \
    --summary sum_dropecho.txt > out_dropecho.txt 2>&1
rc_of dropecho $?

t "== (c4) device vanishes mid-stream and comes back"
wait_for 50 test -e /sys/class/net/can0
scenario vanish vanish:8:500
timeout 30 "$SL_SEND" 1d50:606f --count 80 --interval-ms 50 --reopen-ms 200 \
    --tx-log tx_vanish.log --summary sum_vanish.txt > out_vanish.txt 2>&1
rc_of vanish $?
t "all scenarios done"
dmesg > dmesg.txt 2>&1
sync
