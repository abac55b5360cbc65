// SPDX-License-Identifier: MIT
/// @file sl_port.h
/// @brief The core's output seam: what a port (Linux daemon, MCU firmware, test double)
///        gives the pipeline to receive its results. House style s.6: a const vtable plus a
///        context, copied at sl_pipeline_init(); the core never calls the OS itself.
///
/// Contract:
/// - `can_tx(ctx, f)`: one CAN frame, borrowed for the call. Must not block: return
///   SL_ERR_BUSY when the bus or queue cannot take it (the pipeline counts the frame as
///   dropped and reports it in the next Status); SL_OK when queued or sent.
/// - `on_rotation(ctx, r)`: one completed rotation (targets and tracks); `r` and every
///   pointer in it are valid only until the callback returns.
/// Both callbacks are optional (NULL). They run inside the sl_pipeline_feed() /
/// sl_pipeline_on_msg() / sl_pipeline_finish() call that completed the rotation, in the
/// caller's context (task, not ISR, unless the caller feeds from an ISR), and must not call
/// back into the same pipeline. Cost: whatever the port does; the pipeline makes at most
/// SL_CFG_MAX_TARGETS + 2 can_tx calls and one on_rotation call per rotation.
#ifndef SHADOWLEAN_SL_PORT_H
#define SHADOWLEAN_SL_PORT_H

#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// One completed rotation (defined in sl_pipeline.h).
typedef struct sl_pipeline_rotation sl_pipeline_rotation_t;

/// Output port: a const vtable + context (copied at init). Both callbacks are optional.
typedef struct sl_port {
    /// Send one CAN frame (borrowed for the call). Must not block: return SL_ERR_BUSY when
    /// the bus/queue cannot take it (counted as a drop); SL_OK when queued/sent.
    sl_err_t (*can_tx)(void *ctx, const sl_can_frame_t *f);
    /// One completed rotation (borrowed for the call; every pointer in it is valid only
    /// until the callback returns).
    void (*on_rotation)(void *ctx, const sl_pipeline_rotation_t *r);
    void *ctx;
} sl_port_t;

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_PORT_H
