// SPDX-License-Identifier: MIT
/// @file gsusb_sink.h
/// @brief CAN sink (can_sink.h) for a gs_usb / candleLight USB adapter driven through libusb:
///        the daemon's `--gs-usb` output. Wraps the libusb transport (gsusb_usb.h) and
///        the driver (gsusb_proto.h), adds a small ordered queue, unplug handling and
///        periodic reopening.
///
/// ## Use from the daemon
/// ```c
/// static slp_gsusb_sink_t gs;                       // ~10 KB: static or heap
/// slp_gsusb_sink_cfg_t cfg = slp_gsusb_sink_default_cfg();
/// cfg.selector = "1d50:606f";                      // or "1-1.4" (bus-port), or NULL: first known adapter
/// cfg.can.bitrate = board_bitrate;                 // bit/s
/// sl_err_t rc = slp_gsusb_sink_open(&gs, &cfg, now_us);
/// if (rc != SL_OK) log("gs_usb: %s", slp_gsusb_sink_last_error(&gs));  // still usable unless SL_ERR_ARG
/// slp_can_sink_t sink = slp_gsusb_sink_as_sink(&gs); // add to the daemon's sink array
/// ... every frame:     slp_can_sinks_send(sinks, n, &frame, now_us);
/// ... every loop turn: slp_can_sinks_poll(sinks, n, now_us);   // echoes, RX, timeouts, reopen
/// ... at exit:         slp_gsusb_sink_close(&gs);               // MODE RESET, release, kernel driver back
/// ```
///
/// ## Behaviour (the can_sink.h contract)
/// - `send` never waits for the bus. SL_OK: the frame went to the adapter (its echo will
///   confirm it, counted in `confirmed`) or was queued behind earlier frames because the
///   echo window (10 frames in flight) is full; queued frames are sent from `send`/`poll` as
///   echoes free the window, in order, unless older than `max_age_us` (dropped, `stale`).
///   SL_ERR_BUSY: dropped, queue full. SL_ERR_PORT: dropped, adapter missing / vanished /
///   USB error. SL_ERR_ARG: dropped, the frame is invalid (dlc > 8, id too wide, ERR flag).
/// - `poll` never blocks when the adapter is up (USB events are handled with a zero
///   timeout). While the adapter is down it tries to reopen it every `reopen_interval_us`:
///   one bus scan plus, when found, the start-up sequence (5-6 control requests, a few ms on
///   a healthy adapter, bounded by `can.control_timeout_ms` each).
/// - Unplug (LIBUSB_ERROR_NO_DEVICE, or repeated transfer errors): the sink goes down, the
///   frames in flight and queued are counted as dropped, later sends are dropped
///   (`dropped_down`) until a reopen succeeds (`reopens`).
/// - Frames received from the bus (and error frames) are passed to `cfg.on_rx` if set;
///   every transmitted frame's fate goes to `cfg.on_tx_done` if set.
/// - `sent` in slp_can_sink_stats_t counts frames the adapter CONFIRMED (echo: on the bus);
///   `queued` = frames queued + in flight; `dropped` = every loss including frames never
///   confirmed; `errors` = error frames + USB errors.
///
/// Not thread-safe. Time `t_us`: the caller's CLOCK_MONOTONIC microseconds.
#ifndef SHADOWLEAN_PORT_GSUSB_SINK_H
#define SHADOWLEAN_PORT_GSUSB_SINK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "can_sink.h"
#include "gsusb_usb.h"
#include "gsusb_proto.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SLP_GSUSB_SINK_QUEUE_MAX 64U ///< largest queue (frames waiting for a free echo id)

/// Configuration. Start from slp_gsusb_sink_default_cfg().
typedef struct slp_gsusb_sink_cfg {
    const char *selector;        ///< "VID:PID", "BUS-PORT[.PORT]" or NULL (copied at open)
    slp_gsusb_cfg_t can;          ///< bit rate, window, timeouts (its on_rx/on_tx_done/ctx are
                                 ///< replaced by the sink's: use the fields below)
    uint16_t queue_cap;          ///< 0..SLP_GSUSB_SINK_QUEUE_MAX (default 32)
    uint64_t max_age_us;         ///< queued longer than this: dropped (default 200 ms; 0 = none)
    uint64_t reopen_interval_us; ///< reopen attempts while down (default 1 s)
    slp_gsusb_on_rx_fn on_rx;     ///< optional: frames and error frames from the bus
    slp_gsusb_on_tx_done_fn on_tx_done; ///< optional: confirmed / unconfirmed / dropped frames
    void *user;                  ///< ctx of the two callbacks
} slp_gsusb_sink_cfg_t;

/// Counters since open. Read-only.
typedef struct slp_gsusb_sink_stats {
    uint32_t offered;           ///< frames given to send()
    uint32_t submitted;         ///< frames handed to the adapter
    uint32_t confirmed;         ///< ... echoed by the adapter (on the bus)
    uint32_t unconfirmed;       ///< ... no echo within can.echo_timeout_ms
    uint32_t dropped_in_flight; ///< ... lost in flight (unplug, stop)
    uint32_t dropped_down;      ///< refused: adapter down/missing
    uint32_t dropped_full;      ///< refused: queue full
    uint32_t dropped_stale;     ///< queued longer than max_age_us
    uint32_t dropped_error;     ///< USB transfer failed
    uint32_t dropped_invalid;   ///< invalid frame
    uint32_t down_events;       ///< up -> down transitions (unplug)
    uint32_t reopen_attempts;   ///< opens tried while down
    uint32_t reopens;           ///< successful opens after the first one
    uint32_t open_failures;     ///< opens (first or reopen) that failed
    uint32_t rx_frames;         ///< frames received from the bus
    uint32_t rx_error_frames;   ///< error frames received
} slp_gsusb_sink_stats_t;

/// The sink. Caller-allocated; fields read-only to the application.
typedef struct slp_gsusb_sink {
    slp_gsusb_sink_cfg_t cfg;
    char selector[48];
    slp_gsusb_usb_sel_t sel;
    slp_gsusb_usb_t usb;
    slp_gsusb_t drv;
    bool opened;                ///< slp_gsusb_sink_open() succeeded at least as an object
    bool up;                    ///< adapter open and channel started
    bool ever_up;
    uint64_t next_reopen_us;
    sl_can_frame_t q[SLP_GSUSB_SINK_QUEUE_MAX];
    uint64_t q_t_us[SLP_GSUSB_SINK_QUEUE_MAX];
    uint16_t q_head, q_len;
    uint32_t tag;               ///< sequence number given to each submitted frame
    slp_gsusb_sink_stats_t stats;
    char last_error[256];       ///< why the last open/reopen failed, or why it went down
} slp_gsusb_sink_t;

/// Defaults: selector NULL, slp_gsusb_cfg_defaults() (500 kbit/s, window 10, echo timeout
/// 1 s, control timeout 1 s), queue 32, max age 200 ms, reopen every 1 s.
slp_gsusb_sink_cfg_t slp_gsusb_sink_default_cfg(void);

/// Initialise and try to open the adapter and start the channel.
/// @return SL_OK (up); SL_ERR_ARG (bad selector or config: the sink is NOT usable);
///         otherwise the sink is usable but down (sends are dropped and counted, poll()
///         retries every reopen_interval_us): SL_ERR_PORT (no adapter, USB failure, a
///         request refused), SL_ERR_RANGE (bit rate impossible on this adapter),
///         SL_ERR_MALFORMED (nonsense answers). slp_gsusb_sink_last_error() says why.
sl_err_t slp_gsusb_sink_open(slp_gsusb_sink_t *s, const slp_gsusb_sink_cfg_t *cfg, uint64_t t_us);

/// Send one frame (see the file comment). Never blocks on the bus.
sl_err_t slp_gsusb_sink_send(slp_gsusb_sink_t *s, const sl_can_frame_t *f, uint64_t t_us);

/// Deferred work: echoes, RX frames, echo timeouts, the queue; reopen when down and due.
void slp_gsusb_sink_poll(slp_gsusb_sink_t *s, uint64_t t_us);

/// Like poll, but wait up to `timeout_ms` for USB activity first (for tools with nothing
/// else to do; the daemon uses poll). Time is read from CLOCK_MONOTONIC after the wait.
void slp_gsusb_sink_wait(slp_gsusb_sink_t *s, uint32_t timeout_ms);

/// Close (if open) and open again now, whatever the reopen timer says. Same returns as
/// slp_gsusb_sink_open() (SL_ERR_STATE before a successful slp_gsusb_sink_open()).
sl_err_t slp_gsusb_sink_reopen(slp_gsusb_sink_t *s, uint64_t t_us);

/// True while the adapter is open and the channel started.
bool slp_gsusb_sink_is_up(const slp_gsusb_sink_t *s);

/// Frames queued + in flight.
uint32_t slp_gsusb_sink_pending(const slp_gsusb_sink_t *s);

/// Text of the last problem ("" when none). Valid until the next call on `s`.
const char *slp_gsusb_sink_last_error(const slp_gsusb_sink_t *s);

/// Stop the channel (MODE RESET), drop what is queued or in flight (counted), release the
/// interface, re-attach the kernel driver, free libusb. Idempotent.
void slp_gsusb_sink_close(slp_gsusb_sink_t *s);

/// This sink as a generic slp_can_sink_t (ctx = s; borrowed, must outlive the sink value).
slp_can_sink_t slp_gsusb_sink_as_sink(slp_gsusb_sink_t *s);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_GSUSB_SINK_H
