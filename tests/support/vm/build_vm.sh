#!/bin/sh
# SPDX-License-Identifier: MIT
# build_vm.sh CACHE_DIR [SOURCE_DIR]: prepare (once, cached) the throw-away test VM for the
# gs_usb integration test: a stock Debian kernel (only vmlinuz + the ~25 modules the test
# needs are extracted from the linux-image .deb) and a busybox initramfs whose /init mounts
# the host's root read-only over virtio-9p, chroots into it and runs the guest script.
#
# Network: the only access is one `apt-get download` of the kernel package, pinned by
# asking apt which linux-image-<ver>-amd64 the linux-image-amd64 meta package depends on.
# The result is cached in CACHE_DIR (stamp file `kver`); later runs cost ~0 s unless the
# pinned version moves (a security update), which triggers one new download.
# Missing Debian packages are installed through scripts/deps.sh (group "test").
set -eu
CACHE=${1:?usage: build_vm.sh CACHE_DIR [SOURCE_DIR]}
SRC=${2:-$(cd "$(dirname "$0")/../../.." && pwd)}
mkdir -p "$CACHE"
CACHE=$(cd "$CACHE" && pwd)
cd "$CACHE"

need=""
for t in busybox cpio insmod cansend candump ip python3 dpkg-deb; do
    command -v "$t" >/dev/null 2>&1 || need="$need $t"
done
[ -x /bin/busybox ] || need="$need busybox-static"
if [ -n "$need" ]; then
    echo "build_vm: missing:$need -> scripts/deps.sh test"
    sh "$SRC/scripts/deps.sh" test
fi

# The kernel package apt would install today (Debian moves it with security updates).
PKG=$(apt-cache depends linux-image-amd64 2>/dev/null |
      sed -n 's/.*Depends: \(linux-image-[0-9][^ ]*-amd64\)$/\1/p' | head -1)
if [ -z "$PKG" ]; then
    if [ -s kver ] && [ -d kx ]; then
        echo "build_vm: apt cannot resolve linux-image-amd64; using cached kernel $(cat kver)"
        PKG=cached
    else
        echo "build_vm: apt-cache cannot resolve linux-image-amd64 (run apt-get update)" >&2
        exit 1
    fi
fi
if [ "$PKG" != cached ] && [ "$(cat pkg 2>/dev/null)" != "$PKG" ]; then
    echo "build_vm: fetching $PKG (one-time download, cached in $CACHE)"
    rm -rf kx dl initrd.gz kver pkg
    mkdir -p dl kx
    (cd dl && apt-get download "$PKG" >/dev/null)
    deb=$(ls dl/*.deb)
    # Only what the VM needs: the kernel image, its config and these modules.
    dpkg-deb --fsys-tarfile "$deb" | tar -x -C kx --wildcards \
        './boot/vmlinuz-*' './boot/config-*' \
        '*/kernel/drivers/virtio/virtio_ring.ko' '*/kernel/drivers/virtio/virtio.ko' \
        '*/kernel/drivers/virtio/virtio_pci_modern_dev.ko' \
        '*/kernel/drivers/virtio/virtio_pci_legacy_dev.ko' '*/kernel/drivers/virtio/virtio_pci.ko' \
        '*/kernel/fs/netfs/netfs.ko' '*/kernel/fs/fscache/fscache.ko' \
        '*/kernel/net/9p/9pnet.ko' '*/kernel/net/9p/9pnet_virtio.ko' '*/kernel/fs/9p/9p.ko' \
        '*/kernel/drivers/usb/common/usb-common.ko' '*/kernel/drivers/usb/core/usbcore.ko' \
        '*/kernel/drivers/usb/gadget/udc/udc-core.ko' '*/kernel/drivers/usb/gadget/udc/dummy_hcd.ko' \
        '*/kernel/fs/configfs/configfs.ko' '*/kernel/drivers/usb/gadget/libcomposite.ko' \
        '*/kernel/drivers/usb/gadget/function/usb_f_fs.ko' \
        '*/kernel/net/can/can.ko' '*/kernel/net/can/can-raw.ko' \
        '*/kernel/drivers/net/can/dev/can-dev.ko' '*/kernel/drivers/net/can/usb/gs_usb.ko'
    rm -rf dl
    mdir=$(find kx -type d -name kernel -path '*/modules/*' | head -1)
    [ -n "$mdir" ] || { echo "build_vm: no modules in $PKG" >&2; exit 1; }
    basename "$(dirname "$mdir")" > kver
    echo "$PKG" > pkg
fi
KVER=$(cat kver)
MDIR=$(find kx -type d -name kernel -path "*/modules/$KVER/*" | head -1)
if [ ! -s initrd.gz ]; then
    rm -rf ird && mkdir -p ird/bin ird/mods ird/proc ird/sys ird/dev ird/host
    for m in drivers/virtio/virtio_ring drivers/virtio/virtio drivers/virtio/virtio_pci_modern_dev \
             drivers/virtio/virtio_pci_legacy_dev drivers/virtio/virtio_pci fs/netfs/netfs \
             fs/fscache/fscache net/9p/9pnet net/9p/9pnet_virtio fs/9p/9p; do
        cp "$MDIR/$m.ko" ird/mods/
    done
    cp /bin/busybox ird/bin/
    cat > ird/init <<'INIT'
#!/bin/busybox sh
# Minimal init: 9p host root (ro) + writable out dir, chroot, run the guest script, power off.
/bin/busybox --install -s /bin; export PATH=/bin
mount -t proc proc /proc; mount -t sysfs sysfs /sys; mount -t devtmpfs devtmpfs /dev
for m in virtio_ring virtio virtio_pci_modern_dev virtio_pci_legacy_dev virtio_pci netfs fscache \
         9pnet 9pnet_virtio 9p; do insmod /mods/$m.ko; done
arg() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" /proc/cmdline; }
OUT=$(arg sl_out); SCRIPT=$(arg sl_guest)
mount -t 9p -o trans=virtio,version=9p2000.L,ro,msize=512000,cache=loose hostroot /host
mount -t 9p -o trans=virtio,version=9p2000.L,rw,msize=512000 out /host$OUT
mount -t proc proc /host/proc; mount -t sysfs sysfs /host/sys; mount -o bind /dev /host/dev
mount -t tmpfs tmpfs /host/run
mkdir -p /host/dev/pts; mount -t devpts devpts /host/dev/pts
echo "[init] host root mounted at t=$(cut -d' ' -f1 /proc/uptime)s"
chroot /host /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root OUT=$OUT \
  KMOD=$(arg sl_kmod) /bin/sh -c "cd $OUT && sh $SCRIPT" 2>&1
echo "[init] guest script exit=$? at t=$(cut -d' ' -f1 /proc/uptime)s"
sync; poweroff -f
INIT
    chmod +x ird/init
    (cd ird && find . | cpio -o -H newc 2>/dev/null | gzip -1) > initrd.gz.tmp
    mv initrd.gz.tmp initrd.gz
fi
# Paths the runner needs.
echo "$CACHE/kx/boot/vmlinuz-$KVER" > kernel_path
echo "$CACHE/$MDIR" > kmod_path
echo "build_vm: ready: kernel $KVER ($(cat pkg)), modules $(cat kmod_path)"
