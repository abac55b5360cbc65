#!/bin/sh
# cross_core.sh SRC_DIR BUILD_DIR TOOLCHAIN BOARD: configure + build the core alone for a
# bare-metal target (as the cross presets do) so ctest can check its symbols.
set -eu
cmake -S "$1" -B "$2" -G "Unix Makefiles" --toolchain "$3" -DSL_CORE_ONLY=ON -DSL_BOARDS="$4" \
      -DCMAKE_BUILD_TYPE=MinSizeRel >/dev/null
cmake --build "$2" --target sl_core -j2
