# SPDX-License-Identifier: MIT
# fake_device.sh: sourced INSIDE the gs_usb test VM by both guests (guest.sh here,
# ../daemon/gsusb_guest.sh): the helpers they share and the fake candleLight they stand up.
#   t MSG...              a console line "[guest t=<uptime>s] MSG" (printed by qemu_run.sh)
#   wait_for TRIES CMD... run CMD every 0.1 s until it succeeds (false after TRIES)
#   scenario NAME MODE    switch the fake device's behaviour (atomically, $OUT/ctl)
#   fake_candlelight_up GSDIR SCENARIO MODE
#                         load the modules, present the fake candleLight (dummy_hcd +
#                         configfs + FunctionFS, GSDIR/fake_candlelight.py) in SCENARIO/MODE
#                         and wait for the kernel's gs_usb driver to bind it (can0). Sets G
#                         (the gadget's configfs folder); the working directory is $OUT.
t() { read -r up _ < /proc/uptime; echo "[guest t=${up}s] $*"; }
wait_for() {
    n=$1; shift
    while [ "$n" -gt 0 ]; do "$@" && return 0; sleep 0.1; n=$((n - 1)); done
    return 1
}
scenario() {
    printf 'scenario=%s\nmode=%s\n' "$1" "$2" > "$OUT/ctl.tmp" && mv "$OUT/ctl.tmp" "$OUT/ctl"
}
fake_candlelight_up() {
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
    scenario "$2" "$3"
    python3 -S -u "$1/fake_candlelight.py" /run/ffs-gs "$OUT" "$OUT/ctl" $G/UDC dummy_udc.0 \
        > gadget.log 2>&1 &
    wait_for 100 test -e /run/ffs-gs/ep2 || t "gadget did not start"
    echo dummy_udc.0 > $G/UDC
    wait_for 100 test -e /sys/class/net/can0 || t "can0 did not appear"
}
