#!/bin/sh
# SPDX-License-Identifier: MIT
# cross_core.sh SRC_DIR BUILD_DIR TOOLCHAIN BOARD [CMAKE_ARG...]: configure + build the core
# alone for a bare-metal target in the firmware configuration (as the cross presets do) so
# ctest can check its symbols, instructions, stack and size. Extra arguments are passed to
# the configure step (e.g. -DSL_FW_CAPTURE=... for the example firmware).
set -eu
src=$1; bld=$2; tc=$3; board=$4; shift 4
cmake -S "$src" -B "$bld" -G "Unix Makefiles" --toolchain "$tc" -DSL_CORE_ONLY=ON -DSL_BOARDS="$board" \
      -DSL_FIRMWARE_CONFIG=ON -DCMAKE_BUILD_TYPE=MinSizeRel "$@" >/dev/null
cmake --build "$bld" --target sl_core -j2
