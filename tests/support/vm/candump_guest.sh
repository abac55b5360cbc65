# SPDX-License-Identifier: MIT
# candump_guest.sh: sourced INSIDE the user-mode Linux guest (uml_run.sh) by the tests that
# record the bus (tests/system/can/uml_sink_guest.sh, tests/system/daemon/uml_guest.sh).
#   candump_start LOG IFACE  record IFACE ("any" too) with `candump -L` into LOG (stderr: LOG without .log + .err)
#   candump_mark HEX         send 7FF#HEX on vcan0 until the recording has it (a marker that
#                            orders the recording against what the test does); false after
#                            200 tries
#   candump_stop             SIGINT to candump, then wait: the log is complete
candump_start() {
    CANDUMP_LOG=$1
    candump -L -r 8000000 "$2" > "$CANDUMP_LOG" 2> "${CANDUMP_LOG%.log}.err" &
    CANDUMP_PID=$!
}
candump_mark() {
    _i=0
    while ! grep -q "7FF#$1" "$CANDUMP_LOG" 2>/dev/null; do
        _i=$((_i + 1))
        if [ $_i -gt 200 ]; then echo "candump did not record 7FF#$1"; return 1; fi
        cansend vcan0 "7FF#$1"
        sleep 0.05
    done
}
candump_stop() {
    kill -INT "$CANDUMP_PID"
    wait "$CANDUMP_PID"
}
