// SPDX-License-Identifier: MIT
/// @file socketcan.h
/// @brief SocketCAN raw sink: non-blocking transmit with a small bounded retry queue,
///        error-frame monitoring (bus-off, error passive, restarts), interface down/gone.
///
/// Behaviour of `slp_socketcan_send()` (never blocks, never sleeps):
/// 1. `slp_socketcan_poll()` first: read pending error frames, retry queued frames,
///    reopen the socket if the interface had disappeared.
/// 2. Interface gone (ENODEV/ENXIO, or it did not exist at open): the frame is dropped
///    (`dropped_down`, SL_ERR_PORT); the socket is reopened every `reopen_interval_us`.
/// 3. Bus-off (an error frame with CAN_ERR_BUSOFF was seen and no CAN_ERR_RESTARTED /
///    CAN_ERR_CRTL_ACTIVE since): dropped (`dropped_bus_off`, SL_ERR_BUSY). A bus-off
///    controller cannot send, and by the time it recovers the frames would be stale. After
///    `bus_off_hold_us` without a restart report the sink tries again anyway
///    (`bus_off_timeouts`), so a missed restart report cannot silence it for ever.
/// 4. Frames already queued: the new frame is queued behind them to keep the order, or
///    dropped when the queue is full (`dropped_full`, SL_ERR_BUSY; tail drop).
/// 5. write(): success -> `sent`, `on_sent` callback. EAGAIN/EWOULDBLOCK (socket send
///    buffer full) or ENOBUFS (interface queue full: the qdisc dropped it) -> queued for a
///    retry (`retries`), or dropped when the queue is full. ENETDOWN (interface down) ->
///    dropped (`dropped_down`) together with everything queued; the next successful write
///    counts a `link_up` event. Any other errno -> `dropped_error`, SL_ERR_PORT.
/// Queued frames older than `max_age_us` are dropped (`dropped_stale`) instead of sent.
///
/// The socket receives no data frames (empty CAN_RAW_FILTER), only error frames
/// (CAN_RAW_ERR_FILTER = CAN_ERR_MASK); local loopback stays on, so other local sockets
/// (candump) see our frames. Needs CONFIG_CAN + CAN_RAW (UML and vcan work; the build host
/// kernel may have no CAN at all: open() then fails with `last_errno` EAFNOSUPPORT).
///
/// Cost: send/poll are O(queue + error frames read) system calls, bounded by
/// SLP_SOCKETCAN_QUEUE_MAX + SLP_SOCKETCAN_RX_BURST. RAM: ~sizeof(slp_socketcan_t)
/// (about 1.7 KiB: the queue array is always SLP_SOCKETCAN_QUEUE_MAX entries). Not thread-safe.
#ifndef SHADOWLEAN_PORT_SOCKETCAN_H
#define SHADOWLEAN_PORT_SOCKETCAN_H

#include <stdbool.h>
#include <stdint.h>

#include "can_sink.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Largest retry queue (frames). The configured capacity may be smaller.
#define SLP_SOCKETCAN_QUEUE_MAX 64U
/// Error frames read per poll at most (bounds the work per call).
#define SLP_SOCKETCAN_RX_BURST 32U

/// Configuration. Start from slp_socketcan_default_cfg().
typedef struct slp_socketcan_cfg {
    uint16_t queue_cap;          ///< retry queue capacity, 0..SLP_SOCKETCAN_QUEUE_MAX (default 16)
    int sndbuf_bytes;            ///< SO_SNDBUF, 0 = kernel default
    uint64_t max_age_us;         ///< queued frames older than this are dropped; 0 = no limit (default 200 ms)
    uint64_t bus_off_hold_us;    ///< drop everything this long after a bus-off report (default 1 s)
    uint64_t reopen_interval_us; ///< retry period when the interface is gone (default 1 s)
    /// Called for every frame actually written to the socket (directly or from the queue),
    /// with the `t_us` of the call that wrote it. May be NULL.
    void (*on_sent)(void *user, const sl_can_frame_t *f, uint64_t t_us);
    void *on_sent_user;
} slp_socketcan_cfg_t;

/// Counters (totals since open; fields read-only).
typedef struct slp_socketcan_stats {
    uint32_t sent;             ///< frames written to the socket
    uint32_t retries;          ///< writes that hit EAGAIN/ENOBUFS (frame kept for a retry)
    uint32_t eagain;           ///< ... of which EAGAIN/EWOULDBLOCK (socket buffer full)
    uint32_t enobufs;          ///< ... of which ENOBUFS (interface queue full)
    uint32_t dropped_full;     ///< retry queue full
    uint32_t dropped_stale;    ///< queued longer than max_age_us
    uint32_t dropped_down;     ///< interface down or gone
    uint32_t dropped_bus_off;  ///< controller bus-off
    uint32_t dropped_error;    ///< any other write error
    uint32_t link_down;        ///< transitions to "interface down" (ENETDOWN)
    uint32_t link_up;          ///< recoveries from down/gone (first write that worked)
    uint32_t reopens;          ///< socket reopened after the interface came back
    uint32_t error_frames;     ///< error frames received
    uint32_t bus_off;          ///< bus-off reports
    uint32_t bus_off_timeouts; ///< bus-off hold expired without a restart report
    uint32_t restarts;         ///< controller restarted / back to error active
    uint32_t error_passive;    ///< controller error-passive reports
    uint32_t error_warning;    ///< controller error-warning reports
    uint32_t ctrl_overflow;    ///< controller RX/TX buffer overflow reports
    uint32_t tx_timeouts;      ///< CAN_ERR_TX_TIMEOUT reports
    uint32_t bus_errors;       ///< protocol / ack / transceiver / lost arbitration reports
} slp_socketcan_stats_t;

/// One SocketCAN sink. Caller-owned; fields read-only to the application.
typedef struct slp_socketcan {
    int fd;                    ///< -1 when closed or gone
    char ifname[16];           ///< IFNAMSIZ
    slp_socketcan_cfg_t cfg;
    sl_can_frame_t q[SLP_SOCKETCAN_QUEUE_MAX];
    uint64_t q_t_us[SLP_SOCKETCAN_QUEUE_MAX]; ///< time each queued frame was handed in
    uint16_t q_head, q_len;
    bool link_down;            ///< last write said ENETDOWN
    bool gone;                 ///< no socket (interface missing); reopen pending
    bool bus_off;              ///< bus-off reported, no restart yet
    uint64_t bus_off_t_us;     ///< time of the last bus-off report
    uint64_t next_reopen_t_us;
    int last_errno;            ///< errno of the last failure (0 = none)
    slp_socketcan_stats_t stats;
} slp_socketcan_t;

/// Defaults: queue 16, kernel SO_SNDBUF, max age 200 ms, bus-off hold 1 s, reopen 1 s.
slp_socketcan_cfg_t slp_socketcan_default_cfg(void);

/// Open a raw CAN socket on `ifname` ("vcan0", "can0"), non-blocking, error frames on.
/// `cfg` may be NULL (defaults). @return SL_OK when bound; SL_ERR_ARG for a bad name or
/// config; SL_ERR_PORT when the socket or the interface is unavailable (last_errno says
/// why). After SL_ERR_PORT the object is still valid: send() drops and counts, and it
/// retries the open every reopen_interval_us. Always call slp_socketcan_close().
sl_err_t slp_socketcan_open(slp_socketcan_t *s, const char *ifname,
                               const slp_socketcan_cfg_t *cfg);

/// Close the socket; queued frames are discarded (not counted as drops). Idempotent.
void slp_socketcan_close(slp_socketcan_t *s);

/// Send one frame (see the file comment). Never blocks.
sl_err_t slp_socketcan_send(slp_socketcan_t *s, const sl_can_frame_t *f, uint64_t t_us);

/// Deferred work: error frames, queue retries, reopen. Never blocks.
void slp_socketcan_poll(slp_socketcan_t *s, uint64_t t_us);

/// Total frames dropped for any reason.
uint32_t slp_socketcan_dropped(const slp_socketcan_t *s);

/// This object as a generic sink (ctx = s; borrowed, must outlive the sink).
slp_can_sink_t slp_socketcan_sink(slp_socketcan_t *s);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_SOCKETCAN_H
