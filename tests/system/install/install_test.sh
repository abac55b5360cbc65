#!/bin/sh
# SPDX-License-Identifier: MIT
# install_test.sh BUILD_DIR SOURCE_DIR WORK_DIR: what a user of the SDK and the packages gets.
#  1. cmake --install into a scratch prefix: headers, libsl_core.a, CMake package,
#     pkg-config file, daemon, tools, DBCs, example config, systemd unit (naming the
#     installed daemon), man pages when help2man is installed;
#  2. a tiny consumer (tests/system/install/consumer) built with find_package(shadowlean) and,
#     separately, with pkg-config; both link the core and a board and run the estimator;
#     the Python package (lib/python3/dist-packages/shadowlean) imported from the prefix,
#     its version the project's, decoding and verifying a daemon log with an installed DBC;
#  3. cpack -G DEB: four packages, contents listed, unpacked into a scratch root, their
#     dependencies named; lintian (when installed) reports no error.
set -eu
BUILD=$(cd "$1" && pwd); SRC=$(cd "$2" && pwd); WORK=$3
rm -rf "$WORK"; mkdir -p "$WORK"; WORK=$(cd "$WORK" && pwd)
fail() { echo "FAIL: $*"; exit 1; }
P="$WORK/prefix"

cmake --install "$BUILD" --prefix "$P" > "$WORK/install.log" || fail "cmake --install"
for f in include/shadowlean/sl_pipeline.h include/shadowlean/sl_port.h include/shadowlean/sl_version.h \
         include/shadowlean/boards/sl_board_paper_sim.h lib/libsl_core.a \
         lib/cmake/shadowlean/shadowleanConfig.cmake lib/cmake/shadowlean/shadowleanConfigVersion.cmake \
         lib/pkgconfig/shadowlean-core.pc sbin/shadowleand bin/sl-tables bin/sl-replay bin/sl-inspect \
         share/shadowlean/dbc/paper-sim.dbc share/shadowlean/shadowleand.conf \
         share/shadowlean/wireshark/colossus.lua share/shadowlean/wireshark/shadowlean_can.lua lib/systemd/system/shadowleand.service \
         share/shadowlean/schema/targets.schema.json share/shadowlean/schema/inspect.schema.json \
         share/doc/shadowleand/copyright share/doc/shadowlean-dev/copyright; do
    [ -e "$P/$f" ] || fail "not installed: $f"
done
grep -q "^ExecStart=$P/sbin/shadowleand " "$P/lib/systemd/system/shadowleand.service" ||
    fail "the installed unit does not start the installed daemon: $(grep ExecStart "$P/lib/systemd/system/shadowleand.service")"
"$P/sbin/shadowleand" --version | grep -q "^shadowleand [0-9]" || fail "installed daemon --version"
if command -v help2man >/dev/null 2>&1; then
    [ -e "$P/share/man/man8/shadowleand.8" ] || [ -e "$P/share/man/man8/shadowleand.8.gz" ] ||
        fail "no man page for shadowleand"
    MANPATH="$P/share/man" man -w shadowleand > /dev/null 2>&1 || fail "man shadowleand: not found under the prefix"
    MANPATH="$P/share/man" MANWIDTH=80 man shadowleand 2>/dev/null | grep -q "shadowleand" ||
        fail "man shadowleand does not render"
fi
PY3=/usr/bin/python3
[ -x "$PY3" ] || PY3=python3
# The Python package from the prefix alone (not the source tree), as a user runs it.
check_python() { # ROOT_PYTHON_DIR DBC LABEL
    (cd "$WORK" && PYTHONPATH="$1" PYTHONDONTWRITEBYTECODE=1 "$PY3" -c \
        'import shadowlean, sys; print(shadowlean.__file__); print(shadowlean.__version__)') \
        > "$WORK/py-$3.txt" 2>&1 || { cat "$WORK/py-$3.txt"; fail "$3: import shadowlean"; }
    case "$(head -1 "$WORK/py-$3.txt")" in "$1"/shadowlean/*) ;; *) fail "$3: shadowlean imported from $(head -1 "$WORK/py-$3.txt")";; esac
    want=$(sed -n 's/^project(shadowlean VERSION \([0-9.]*\).*/\1/p' "$SRC/CMakeLists.txt")
    [ "$(sed -n 2p "$WORK/py-$3.txt")" = "$want" ] || fail "$3: shadowlean.__version__ $(sed -n 2p "$WORK/py-$3.txt") != $want"
    (cd "$WORK" && PYTHONPATH="$1" PYTHONDONTWRITEBYTECODE=1 "$PY3" -m shadowlean decode \
        "$SRC/tests/system/daemon/golden/demo_three_poles.candump" --dbc "$2" --check) > "$WORK/py-$3.log" 2>&1 ||
        { tail -5 "$WORK/py-$3.log"; fail "$3: python3 -m shadowlean decode --check"; }
    echo "python ($3): shadowlean $want, $(grep -c 'crc=ok' "$WORK/py-$3.log") frames verified"
}
check_python "$P/lib/python3/dist-packages" "$P/share/shadowlean/dbc/paper-sim.dbc" prefix

echo "install: $(find "$P" -type f | wc -l) files under the prefix"

# 2. consumers
cmake -S "$SRC/tests/system/install/consumer" -B "$WORK/consumer-cmake" -DCMAKE_PREFIX_PATH="$P" \
    > "$WORK/consumer-cmake.log" 2>&1 || { cat "$WORK/consumer-cmake.log"; fail "find_package(shadowlean)"; }
cmake --build "$WORK/consumer-cmake" > "$WORK/consumer-build.log" 2>&1 ||
    { cat "$WORK/consumer-build.log"; fail "consumer build (CMake package)"; }
out1=$("$WORK/consumer-cmake/consumer") || fail "consumer (CMake package) exit $?"
echo "find_package: $out1"
CC=${CC:-cc}
# shellcheck disable=SC2046
$CC -std=c11 -Wall -Werror "$SRC/tests/system/install/consumer/main.c" \
    $(PKG_CONFIG_PATH="$P/lib/pkgconfig" pkg-config --cflags --libs shadowlean-core) \
    -o "$WORK/consumer-pc" || fail "consumer build (pkg-config)"
out2=$("$WORK/consumer-pc") || fail "consumer (pkg-config) exit $?"
echo "pkg-config:   $out2"
[ "$out1" = "$out2" ] || fail "the two consumers disagree"
echo "$out1" | grep -q "alpha [0-9-]* cdeg (flag 0)" || fail "unexpected consumer output"

# 3. Debian packages
(cd "$BUILD" && cpack -G DEB -B "$WORK/deb" > "$WORK/cpack.log" 2>&1) || { tail -20 "$WORK/cpack.log"; fail "cpack"; }
for p in shadowlean-dev shadowleand shadowlean-tools python3-shadowlean; do
    deb=$(ls "$WORK"/deb/${p}_*.deb 2>/dev/null | head -1)
    [ -n "$deb" ] || fail "no package $p"
    echo "== $(basename "$deb"): $(dpkg-deb -f "$deb" Depends)"
    dpkg-deb -c "$deb" | awk '{print "   " $6}' | grep -v '/$'
    dpkg-deb -x "$deb" "$WORK/root"
done
for f in usr/sbin/shadowleand usr/lib/systemd/system/shadowleand.service usr/lib/libsl_core.a \
         usr/include/shadowlean/sl_pipeline.h usr/share/shadowlean/dbc/paper-sim.dbc usr/bin/sl-inspect \
         usr/lib/python3/dist-packages/shadowlean/__init__.py; do
    [ -e "$WORK/root/$f" ] || fail "package root lacks $f"
done
grep -q "^ExecStart=/usr/sbin/shadowleand " "$WORK/root/usr/lib/systemd/system/shadowleand.service" ||
    fail "packaged unit does not start /usr/sbin/shadowleand"
"$WORK/root/usr/sbin/shadowleand" --version > /dev/null || fail "packaged daemon does not run"
check_python "$WORK/root/usr/lib/python3/dist-packages" "$WORK/root/usr/share/shadowlean/dbc/paper-sim.dbc" deb
if command -v lintian >/dev/null 2>&1; then
    lintian --tag-display-limit 0 "$WORK"/deb/*.deb > "$WORK/lintian.log" 2>&1 || true
    sed 's/^/   lintian: /' "$WORK/lintian.log"
    if grep -q "^E: " "$WORK/lintian.log"; then fail "lintian errors"; fi
fi
echo "install_test: ok"
