# SPDX-License-Identifier: MIT
# lib.sh: helpers for the daemon tests (sourced). POSIX sh.
# start_replay LOGFILE CAPTURE [ARGS...]: `sl-replay serve` on 127.0.0.1, any free port;
# sets REPLAY_PID and REPLAY_PORT (parsed from its "listening on" line).
start_replay() {
    _log=$1; _cap=$2; shift 2
    "$SL_REPLAY" serve "$_cap" --port 0 "$@" > "$_log" 2> "$_log.err" &
    REPLAY_PID=$!
    _i=0
    REPLAY_PORT=""
    while [ -z "$REPLAY_PORT" ]; do
        REPLAY_PORT=$(sed -n 's/^sl-replay: listening on 127\.0\.0\.1:\([0-9][0-9]*\)$/\1/p' "$_log" 2>/dev/null)
        [ -n "$REPLAY_PORT" ] && break
        _i=$((_i + 1))
        if [ $_i -gt 300 ] || ! kill -0 "$REPLAY_PID" 2>/dev/null; then
            echo "sl-replay did not start:"; cat "$_log" "$_log.err"; return 1
        fi
        sleep 0.1
    done
}
stop_pid() { # PID: TERM, then KILL after 5 s; never a broad kill
    [ -n "${1:-}" ] || return 0
    kill "$1" 2>/dev/null || return 0
    _i=0
    while kill -0 "$1" 2>/dev/null && [ $_i -lt 50 ]; do sleep 0.1; _i=$((_i + 1)); done
    kill -9 "$1" 2>/dev/null
    wait "$1" 2>/dev/null
    return 0
}
free_port() { # prints a TCP port that was free a moment ago (bound then closed)
    "$PY" -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1]); s.close()'
}
