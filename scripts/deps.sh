#!/bin/sh
# SPDX-License-Identifier: MIT
# deps.sh GROUP...: install the Debian packages a group needs, only when missing.
# Groups: build (host build + tools), test (cross + qemu-user + fuzz + CAN/VM tests), demo.
# Needs root (or sudo) only when something is missing.
# python3-canmatrix's optional formats: lxml (arxml, kcd), xlrd/xlsxwriter/xlwt (xls, xlsx),
# yaml are installed with it, so importing canmatrix.formats prints only "ldf is not
# supported": its LDF reader needs ldfparser, which Debian does not package. The Python
# package (python/shadowlean) and the scripts silence that line; the test
# python_shadowlean_package checks `python3 -m shadowlean` writes nothing to stderr.
set -eu
pkgs=""
for g in "$@"; do
    case "$g" in
    build) pkgs="$pkgs build-essential cmake pkg-config git python3 libcmocka-dev libinih-dev
             libopencv-dev libpcap-dev libusb-1.0-0-dev nlohmann-json3-dev" ;;
    test) pkgs="$pkgs valgrind clang libfuzzer-14-dev libclang-rt-14-dev
             gcc-arm-none-eabi libnewlib-arm-none-eabi gcc-aarch64-linux-gnu gcc-s390x-linux-gnu libc6-dev-arm64-cross libc6-dev-s390x-cross
             qemu-user libcmocka-dev:arm64 libcmocka-dev:s390x
             libpcap-dev:arm64 libusb-1.0-0-dev:arm64 libinih-dev:arm64 libc6:arm64 libc6:s390x
             python3-canmatrix python3-lxml python3-xlrd python3-xlsxwriter python3-xlwt python3-yaml
             python3-can python3-numpy python3-jsonschema can-utils user-mode-linux iproute2 kmod
             qemu-system-x86 busybox-static cpio usbutils
             qemu-system-arm cppcheck clang-tidy tshark help2man lintian" ;;
    demo) pkgs="$pkgs python3-canmatrix python3-lxml python3-xlrd python3-xlsxwriter python3-xlwt
             python3-yaml can-utils" ;;
    *) echo "deps.sh: unknown group '$g'" >&2; exit 2 ;;
    esac
done
missing=""
for p in $pkgs; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "deps.sh: installing:$missing"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO=sudo
case "$missing" in
*:arm64*|*:s390x*)
    $SUDO dpkg --add-architecture arm64
    $SUDO dpkg --add-architecture s390x ;;
esac
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
# shellcheck disable=SC2086
$SUDO apt-get install -y -q --no-install-recommends $missing
