#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_sink_guest.sh EXE OUTDIR: runs INSIDE user-mode Linux (via uml_run.sh, vcan0 up).
# Records the bus with `candump -L any` (survives the interface being deleted and
# re-created in phase G) while vcan_sink_check drives the SocketCAN sink. Marker frames
# (7FF#53594E43 "SYNC" before, 7FF#454E4400 "END" after) make sure candump records from
# the first frame to the last without timing assumptions; the host comparison skips them.
set -u
exe=$1; out=$2
M=/usr/lib/uml/modules/$(uname -r)/kernel
insmod "$M/net/sched/sch_plug.ko" || { echo "cannot load sch_plug"; exit 1; }
. "$(dirname "$0")/../../support/vm/candump_guest.sh"
candump_start "$out/candump.log" any
candump_mark 53594E43 || exit 1
"$exe" --out "$out" --iface vcan0 --n "${SL_SINK_N:-500}"
rc=$?
candump_mark 454E4400 || rc=1
candump_stop
exit $rc
