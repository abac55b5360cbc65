# SPDX-License-Identifier: MIT
# guest.sh: runs INSIDE the test VM (chroot on the host's read-only root, $OUT writable).
# Presents a fake candleLight through dummy_hcd + configfs + FunctionFS and runs every
# scenario of the gs_usb integration test in one boot. It only runs things and records
# exit codes and logs in $OUT; check_results.py judges them on the host afterwards.
# Settings come from $OUT/vm.env (written by run_vm_test.sh): SL_SEND, SL_DIR.
. "$OUT/vm.env"
. "$SL_DIR/fake_device.sh"
rc_of() { echo "$2" > "$OUT/rc_$1"; }
fake_candlelight_up "$SL_DIR" kernel normal
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
