// SPDX-License-Identifier: MIT
/// @file can_sink.h
/// @brief A CAN frame sink: a const vtable + context, so the daemon can send every frame
///        to several outputs (SocketCAN, a candump log file, gs_usb over libusb), and the
///        exit drain of all of them (can_sink.c).
///
/// Contract of every sink:
/// - `send` never blocks. It returns SL_OK when the frame was written or queued for a
///   later write, SL_ERR_BUSY when it was dropped because the sink is congested (queue
///   full, bus-off), SL_ERR_PORT when it was dropped because the medium failed (interface
///   down or gone, I/O error). Every drop is counted in the sink's stats; the caller never
///   needs to retry (and must not, or frames would be duplicated).
/// - `poll` (may be NULL) does deferred work: retries queued frames, reads error reports,
///   flushes files. Call it at least once per main-loop turn. Never blocks.
/// - `get_stats` fills the common counters below (a sink may keep more detail).
/// Time `t_us` is the caller's monotonic clock in microseconds (the core's convention).
///
/// Thread safety: none; a sink belongs to one thread.
#ifndef SHADOWLEAN_PORT_CAN_SINK_H
#define SHADOWLEAN_PORT_CAN_SINK_H

#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Counters every sink reports. All totals since open; wrap at 2^32 (not saturating).
typedef struct slp_can_sink_stats {
    uint32_t sent;    ///< frames written to the medium
    uint32_t dropped; ///< frames lost, all reasons
    uint32_t queued;  ///< frames waiting in the sink right now
    uint32_t errors;  ///< error reports from the medium (bus errors, I/O errors)
} slp_can_sink_stats_t;

/// One sink: a vtable and its context. Plain value; the context is borrowed.
typedef struct slp_can_sink {
    const char *name; ///< short constant name for logs ("socketcan", "candump")
    void *ctx;
    /// Send one frame (see the contract above).
    sl_err_t (*send)(void *ctx, const sl_can_frame_t *f, uint64_t t_us);
    /// Deferred work; may be NULL.
    void (*poll)(void *ctx, uint64_t t_us);
    /// Common counters.
    void (*get_stats)(void *ctx, slp_can_sink_stats_t *out);
} slp_can_sink_t;

/// Send `f` to each of `n` sinks. @return SL_OK when every sink took it, else the first
/// error (every sink is still tried). O(n).
static inline sl_err_t slp_can_sinks_send(const slp_can_sink_t *sinks, size_t n,
                                         const sl_can_frame_t *f, uint64_t t_us)
{
    sl_err_t first = SL_OK;
    for (size_t i = 0; i < n; i++) {
        const sl_err_t e = sinks[i].send(sinks[i].ctx, f, t_us);
        if (e != SL_OK && first == SL_OK) {
            first = e;
        }
    }
    return first;
}

/// Poll each sink that has a poll function. O(n).
static inline void slp_can_sinks_poll(const slp_can_sink_t *sinks, size_t n, uint64_t t_us)
{
    for (size_t i = 0; i < n; i++) {
        if (sinks[i].poll != NULL) {
            sinks[i].poll(sinks[i].ctx, t_us);
        }
    }
}

/// Sum of the sinks' dropped counters (for Status.CanDropped). O(n).
static inline uint32_t slp_can_sinks_dropped(const slp_can_sink_t *sinks, size_t n)
{
    uint32_t sum = 0;
    for (size_t i = 0; i < n; i++) {
        slp_can_sink_stats_t st = {0, 0, 0, 0};
        sinks[i].get_stats(sinks[i].ctx, &st);
        sum += st.dropped;
    }
    return sum;
}

/// What slp_can_sinks_drain() did.
typedef struct slp_can_drain_result {
    uint32_t left;     ///< frames still queued when it gave up (0: every sink drained)
    uint32_t moved;    ///< frames that left the queues meanwhile (confirmed or dropped)
    uint32_t polls;    ///< poll rounds
    uint64_t stall_us; ///< time since the last progress when it ended
} slp_can_drain_result_t;

/// Drain at exit: poll the sinks until none holds a frame, or until none has made progress
/// (a frame sent or dropped, i.e. `sent + dropped` of some sink moved) for `stall_us`.
/// Progress-based, not bounded by total elapsed time: a slow adapter that keeps confirming
/// frames is drained completely however long that takes (at most the sinks' queued frames
/// times `stall_us` in total); an adapter that stops answering costs `stall_us`.
/// `now_us(ctx)` reads the caller's monotonic clock; `wait(ctx)` sleeps briefly between
/// rounds (both injected, so tests run on a fake clock). Frames left are NOT counted by the
/// sinks: the caller reports `left` (the daemon logs and counts them).
slp_can_drain_result_t slp_can_sinks_drain(const slp_can_sink_t *sinks, size_t n, uint64_t stall_us,
                                           uint64_t (*now_us)(void *ctx), void (*wait)(void *ctx),
                                           void *ctx);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_CAN_SINK_H
