#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_sink_test.sh UML_RUN EXE PYTHON SRC_DIR OUT_DIR
# The SocketCAN sink inside user-mode Linux (uml_sink_guest.sh), then the host-side
# comparison of candump's recording with the sink's logs. Exit 77 (skip) without linux.uml.
set -u
uml_run=$1; exe=$2; py=$3; src=$(cd "$4" && pwd); out=$5
rm -rf "$out"
mkdir -p "$out"
SL_SINK_N=${SL_SINK_N:-500} SL_UML_ENV="${SL_UML_ENV:-} SL_SINK_N" \
    sh "$uml_run" "$out" sh "$src/uml_sink_guest.sh" "$exe" "$out"
rc=$?
[ $rc -eq 0 ] || exit $rc
"$py" "$src/uml_sink_compare.py" "$out/candump.log" "$out/sent.log" "$out/produced_a.log"
