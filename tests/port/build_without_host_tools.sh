#!/bin/sh
# SPDX-License-Identifier: MIT
# build_without_host_tools.sh SOURCE_DIR OUT_DIR
# -DSL_BUILD_HOST_TOOLS=OFF configures and builds core + port + daemon with no C++ and no
# OpenCV: CMake never enables C++ (no CMAKE_CXX_COMPILER in the cache), never looks for
# OpenCV, and shadowleand needs neither libstdc++ nor an OpenCV library.
set -u
SRC=$1; OUT=$2
rm -rf "$OUT"; mkdir -p "$OUT"
cmake -S "$SRC" -B "$OUT" -DSL_BUILD_HOST_TOOLS=OFF -DSL_BUILD_TESTS=OFF -DCMAKE_BUILD_TYPE=Release \
    > "$OUT/configure.log" 2>&1 || { cat "$OUT/configure.log"; echo "FAIL: configure"; exit 1; }
cmake --build "$OUT" --target shadowleand -j2 > "$OUT/build.log" 2>&1 ||
    { tail -30 "$OUT/build.log"; echo "FAIL: build"; exit 1; }
if grep -q "^CMAKE_CXX_COMPILER" "$OUT/CMakeCache.txt"; then echo "FAIL: C++ was enabled"; exit 1; fi
if grep -qi "^OpenCV_DIR" "$OUT/CMakeCache.txt"; then echo "FAIL: OpenCV was looked for"; exit 1; fi
D=$(find "$OUT" -name shadowleand -type f -perm -u+x | head -1)
[ -n "$D" ] || { echo "FAIL: no shadowleand built"; exit 1; }
needed=$(readelf -d "$D" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
echo "shadowleand needs: $needed"
case "$needed" in
*libstdc++*|*opencv*) echo "FAIL: the daemon links C++ or OpenCV"; exit 1 ;;
esac
echo "core + port + daemon built without host tools, C++ or OpenCV"
