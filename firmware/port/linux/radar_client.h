// SPDX-License-Identifier: MIT
/// @file radar_client.h
/// @brief Linux TCP client for a Navtech Colossus radar (or `sl-replay serve`).
///
/// One non-blocking TCP connection, driven from the caller's loop; never blocks, never
/// spins. What it does (NAVTECH_PROTOCOL.md s.1 and s.7):
/// - connects with a timeout (`connect_timeout_ms`);
/// - waits for the Configuration message (id 10) that the radar sends on connect; sends a
///   Configuration Request (20) once if none came after `config_request_ms`; gives up on the
///   connection after `config_timeout_ms`;
/// - on the Configuration, sends Start FFT (21), or Start Non-Contour FFT (140) when
///   `non_contour` is set: FFT data then flows;
/// - feeds every received byte into the core decoder (`sl_proto`, byte-wise resync) and
///   hands each decoded message to `on_msg`;
/// - data watchdog: while streaming, when no usable FFT row (an FFT message that parses and
///   holds at least one bin) arrived for `data_timeout_ms` (keep-alives only, a byte
///   trickle, malformed FFT messages), sends Start FFT again once (`stats.data_restarts`);
///   if still nothing usable after another `data_timeout_ms`, drops the connection
///   (`SLP_RADAR_REASON_NO_DATA`, `stats.data_timeouts`) and reconnects with the backoff;
/// - treats a silent radar (no byte at all, keep-alives included, for `silence_timeout_ms`),
///   EOF, socket errors and connect failures alike: close, `sl_proto_finish()` (a partial
///   message is counted as truncated), event, then reconnect after a backoff that starts at
///   `backoff_initial_ms` and doubles up to `backoff_max_ms`; the backoff returns to its
///   initial value each time a usable FFT message arrives (a healthy session; a radar that
///   only sends its Configuration and keep-alives keeps backing off);
/// - on `slp_radar_client_stop()`, sends Stop FFT (22) when streaming and closes.
/// Everything is counted in `stats` (and the decoder's `proto.stats`).
///
/// ## Two ways to drive it
/// - Simple: `slp_radar_client_poll(c, timeout_ms)` blocks in poll() for at most
///   `timeout_ms` (or until the client's own next deadline) and does all the work; time
///   comes from `cfg.clock_us` (default CLOCK_MONOTONIC).
/// - Inside your own poll loop: put `slp_radar_client_fd()` with
///   `slp_radar_client_events()` in your pollfd set (skip it when the fd is -1), bound your
///   timeout by `slp_radar_client_timeout_ms()`, then call `slp_radar_client_handle(c,
///   revents, now_us)` every time round (revents 0 when the fd was not ready): it also runs
///   the timers. Time is whatever `now_us` you pass (monotonic microseconds).
///
/// ## Memory and cost
/// `slp_radar_client_t` is caller-allocated (about 70 KB with its receive buffer; static is
/// fine). The decoder's reassembly buffer is the caller's (`cfg.reasm_buf`, borrowed until
/// `slp_radar_client_deinit`). No allocation after init. Per handle call: at most
/// `SL_RADAR_RX_BUDGET` bytes are read (so one busy radar cannot starve the caller's other
/// fds), O(bytes) decoding. Not thread-safe; callbacks must not call back into the same
/// client except `slp_radar_client_stats()`-style reads.
#ifndef SHADOWLEAN_PORT_RADAR_CLIENT_H
#define SHADOWLEAN_PORT_RADAR_CLIENT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <sys/socket.h>

#include "shadowlean/sl_err.h"
#include "shadowlean/sl_proto.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Bytes read per recv() call (the receive buffer inside the client).
#define SL_RADAR_RX_CHUNK 65536U
/// Bytes read at most per slp_radar_client_handle() call.
#define SL_RADAR_RX_BUDGET (8U * SL_RADAR_RX_CHUNK)
/// Addresses kept from name resolution; connection attempts cycle through them.
#define SLP_RADAR_MAX_ADDRS 4U

/// Connection state.
typedef enum slp_radar_state {
    SLP_RADAR_IDLE = 0,        ///< not started, or stopped
    SLP_RADAR_BACKOFF = 1,     ///< waiting before the next connection attempt
    SLP_RADAR_CONNECTING = 2,  ///< non-blocking connect() in progress
    SLP_RADAR_WAIT_CONFIG = 3, ///< connected, waiting for the Configuration (10)
    SLP_RADAR_STREAMING = 4,   ///< Start FFT sent; FFT data expected
} slp_radar_state_t;

/// What happened (second argument of `on_event`).
typedef enum slp_radar_event {
    SLP_RADAR_EV_CONNECTED = 0,       ///< TCP connected
    SLP_RADAR_EV_CONFIG = 1,          ///< Configuration received (Start FFT queued if first)
    SLP_RADAR_EV_DISCONNECTED = 2,    ///< connection closed; `reason` says why
    SLP_RADAR_EV_CONNECT_FAILED = 3,  ///< connect() failed or timed out; `reason` says which
    SLP_RADAR_EV_STOPPED = 4,         ///< slp_radar_client_stop() closed the connection
} slp_radar_event_t;

/// Why a connection ended or failed.
typedef enum slp_radar_reason {
    SLP_RADAR_REASON_NONE = 0,
    SLP_RADAR_REASON_EOF = 1,             ///< the radar closed the connection
    SLP_RADAR_REASON_ERROR = 2,           ///< recv/send/connect error (`stats.last_errno`)
    SLP_RADAR_REASON_SILENCE = 3,         ///< nothing received for silence_timeout_ms
    SLP_RADAR_REASON_CONFIG_TIMEOUT = 4,  ///< no Configuration within config_timeout_ms
    SLP_RADAR_REASON_CONNECT_TIMEOUT = 5, ///< connect() not done within connect_timeout_ms
    SLP_RADAR_REASON_STOP = 6,            ///< the application stopped the client
    SLP_RADAR_REASON_NO_DATA = 7,         ///< bytes but no usable FFT row (data watchdog)
} slp_radar_reason_t;

/// Decoded message callback: same contract as `sl_proto_on_msg_fn` (the message and its
/// payload are valid until the callback returns). `now_us` is the time of the handle call.
typedef void (*slp_radar_on_msg_fn)(void *ctx, const sl_proto_msg_t *msg, uint64_t now_us);
/// Raw bytes exactly as received, before decoding (for recording). Valid during the call.
typedef void (*slp_radar_on_bytes_fn)(void *ctx, const uint8_t *data, size_t len, uint64_t now_us);
/// State event (connected, config, disconnected with reason, ...).
typedef void (*slp_radar_on_event_fn)(void *ctx, slp_radar_event_t ev, slp_radar_reason_t reason,
                                     uint64_t now_us);
/// Clock: monotonic microseconds.
typedef uint64_t (*slp_radar_clock_fn)(void *ctx);

/// Configuration. Start from slp_radar_client_cfg_defaults(), then set host/port/callbacks.
typedef struct slp_radar_client_cfg {
    const char *host;              ///< name or numeric address (resolved once, at init)
    uint16_t port;                 ///< TCP port (radar default 6317)
    uint32_t connect_timeout_ms;   ///< default 2000
    uint32_t silence_timeout_ms;   ///< default 3000; 0 = never (not recommended)
    uint32_t data_timeout_ms;      ///< data watchdog (above); default 3000; 0 = never
    uint32_t config_request_ms;    ///< send id 20 once after this long; 0 = never. Default 1000
    uint32_t config_timeout_ms;    ///< default 5000; 0 = never
    uint32_t backoff_initial_ms;   ///< default 100 (>= 1)
    uint32_t backoff_max_ms;       ///< default 5000 (>= backoff_initial_ms)
    bool non_contour;              ///< Start with 140 (non-contour) instead of 21
    uint8_t *reasm_buf;            ///< decoder reassembly buffer (caller-owned, borrowed)
    size_t reasm_size;             ///< its size: the largest payload accepted
    uint32_t max_payload_bytes;    ///< board limit; 0 = reasm_size
    slp_radar_on_msg_fn on_msg;     ///< optional
    slp_radar_on_bytes_fn on_bytes; ///< optional (raw tap)
    slp_radar_on_event_fn on_event; ///< optional
    slp_radar_clock_fn clock_us;    ///< optional; NULL = slp_now_us (CLOCK_MONOTONIC)
    void *ctx;                     ///< passed to every callback
} slp_radar_client_cfg_t;

/// Counters since init. Read-only to the application.
typedef struct slp_radar_client_stats {
    uint32_t connect_attempts;  ///< socket()+connect() started
    uint32_t connects;          ///< TCP connections established
    uint32_t connect_failures;  ///< connect refused/unreachable/other error
    uint32_t connect_timeouts;  ///< connect not done within connect_timeout_ms
    uint32_t reconnects;        ///< connections established after the first one
    uint32_t disconnects_eof;   ///< the radar closed (recv() == 0)
    uint32_t disconnects_error; ///< recv()/send() error on an established connection
    uint32_t silence_timeouts;  ///< connections dropped because the radar went silent
    uint32_t data_restarts;     ///< Start FFT re-sent by the data watchdog
    uint32_t data_timeouts;     ///< connections dropped by the data watchdog
    uint32_t usable_fft;        ///< FFT messages that parse and hold at least one bin
    uint32_t config_timeouts;   ///< connections dropped waiting for the Configuration
    uint32_t configs;           ///< Configuration messages received
    uint32_t config_requests;   ///< Configuration Requests (20) sent
    uint32_t starts_sent;       ///< Start FFT (21 or 140) sent
    uint32_t stops_sent;        ///< Stop FFT (22) sent
    uint32_t keep_alives;       ///< keep-alive messages received
    uint32_t fft_messages;      ///< FFT data messages (30 + 31) received
    uint32_t messages;          ///< all decoded messages
    uint32_t tx_would_block;    ///< send() returned EAGAIN (command kept and retried)
    uint32_t tx_overflow;       ///< a command did not fit the transmit buffer (dropped)
    uint32_t handle_calls;      ///< slp_radar_client_handle() calls (wake-ups)
    uint64_t bytes_rx;          ///< bytes received
    uint64_t bytes_tx;          ///< bytes sent
    int last_errno;             ///< errno of the last socket error (0 = none)
    uint32_t backoff_ms;        ///< backoff that the next failure will use
} slp_radar_client_stats_t;

/// Client instance. Caller-allocated; fields read-only to the application.
typedef struct slp_radar_client {
    slp_radar_client_cfg_t cfg;
    sl_proto_t proto;                  ///< core decoder (its stats are readable)
    slp_radar_client_stats_t stats;
    slp_radar_state_t state;
    int fd;                            ///< socket, -1 when none
    struct sockaddr_storage addrs[SLP_RADAR_MAX_ADDRS];
    socklen_t addr_lens[SLP_RADAR_MAX_ADDRS];
    unsigned n_addrs;
    unsigned next_addr;
    uint64_t deadline_us;              ///< backoff end / connect timeout (state-dependent)
    uint64_t last_rx_us;               ///< time of the last received byte
    uint64_t last_data_us;             ///< time of the last usable FFT message (or of the
                                       ///< Start FFT the watchdog measures from)
    bool data_restarted;               ///< the watchdog re-sent Start FFT on this connection
    uint64_t connected_us;             ///< time the connection was established
    bool config_requested;             ///< id 20 already sent on this connection
    bool have_config;                  ///< a Configuration arrived on this connection
    uint64_t now_us;                   ///< time of the current handle call
    size_t tx_len;                     ///< bytes pending in tx
    uint8_t tx[8U * SL_PROTO_HEADER_BYTES];
    uint8_t rx[SL_RADAR_RX_CHUNK];
} slp_radar_client_t;

/// Fill `cfg` with the defaults listed above (host NULL, port 6317, no callbacks).
void slp_radar_client_cfg_defaults(slp_radar_client_cfg_t *cfg);

/// Initialise: copies cfg, resolves cfg->host (getaddrinfo: may block once for a name,
/// never for a numeric address), inits the decoder. State IDLE; nothing connects yet.
/// @return SL_OK; SL_ERR_ARG (NULL, no host, port 0, bad timeouts/backoff, NULL reasm_buf
/// with reasm_size > 0); SL_ERR_PORT (name resolution failed).
sl_err_t slp_radar_client_init(slp_radar_client_t *c, const slp_radar_client_cfg_t *cfg);

/// Start connecting (the first attempt happens at the next handle/poll call).
/// @return SL_OK, SL_ERR_ARG, SL_ERR_STATE (already started).
sl_err_t slp_radar_client_start(slp_radar_client_t *c);

/// The socket to poll, or -1 (no connection: only timers are pending).
int slp_radar_client_fd(const slp_radar_client_t *c);

/// poll() events wanted on the fd: POLLIN, plus POLLOUT while connecting or while a
/// command is waiting to be sent. 0 when fd is -1.
short slp_radar_client_events(const slp_radar_client_t *c);

/// Milliseconds until the client's next deadline (rounded up), 0 if due, -1 if none.
int slp_radar_client_timeout_ms(const slp_radar_client_t *c, uint64_t now_us);

/// Do the work: I/O according to `revents` (0 = fd not ready), then the timers (connect
/// timeout, silence, config request/timeout, backoff -> connect). Never blocks.
/// @return SL_OK or SL_ERR_ARG. Connection problems are not errors: they are counted and
/// reported through on_event.
sl_err_t slp_radar_client_handle(slp_radar_client_t *c, short revents, uint64_t now_us);

/// Convenience loop step: poll() on the client's fd for at most `timeout_ms` (shortened to
/// the next deadline; -1 = until something happens), then slp_radar_client_handle() with the
/// configured clock. EINTR returns SL_OK early (check your stop flag).
/// @return SL_OK, SL_ERR_ARG, SL_ERR_STATE (idle), SL_ERR_PORT (poll() failed).
sl_err_t slp_radar_client_poll(slp_radar_client_t *c, int timeout_ms);

/// Stop: when streaming, send Stop FFT (22), waiting at most `linger_ms` for the socket to
/// take it; then close. State IDLE (slp_radar_client_start() may be called again).
/// @return SL_OK, SL_ERR_ARG.
sl_err_t slp_radar_client_stop(slp_radar_client_t *c, uint32_t linger_ms);

/// Stop (without linger) and release nothing else: the client owns no heap memory.
void slp_radar_client_deinit(slp_radar_client_t *c);

/// Short constant names for logs: "IDLE", "EOF", ...
const char *slp_radar_state_str(slp_radar_state_t s);
const char *slp_radar_reason_str(slp_radar_reason_t r);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_RADAR_CLIENT_H
