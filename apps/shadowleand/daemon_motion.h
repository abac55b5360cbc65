// SPDX-License-Identifier: MIT
/// @file daemon_motion.h
/// @brief VehicleMotion input of the daemon: a SocketCAN raw socket that receives only
///        the board's VehicleMotion id (kernel filter), non-blocking.
///
/// The frames are handed to the caller (the daemon passes them to
/// `sl_pipeline_on_can_rx()`, which does the E2E check). The socket is separate from the
/// SocketCAN output sink (which receives nothing): frames the daemon itself sends on the
/// same interface never match the filter. When the interface is missing at open, or
/// disappears later (ENODEV/ENETDOWN), the reader closes and retries every
/// `SLD_MOTION_REOPEN_US`. Not thread-safe. Cost per read call: at most
/// `SLD_MOTION_RX_BURST` recv() calls.
#ifndef SHADOWLEAN_DAEMON_MOTION_H
#define SHADOWLEAN_DAEMON_MOTION_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SLD_MOTION_RX_BURST 64U
#define SLD_MOTION_REOPEN_US 1000000U

/// Reader state. Caller-owned; fields read-only.
typedef struct sld_motion {
    int fd;                ///< -1 when closed
    char ifname[16];
    uint32_t id_dbc;       ///< VehicleMotion id, board/DBC style (bit 31 = 29-bit)
    uint64_t next_open_us; ///< retry time while closed
    int last_errno;
    struct {
        uint32_t frames;   ///< frames received (matching the filter)
        uint32_t opens;    ///< successful opens
        uint32_t failures; ///< failed opens / read errors
    } stats;
} sld_motion_t;

/// Open on `ifname` for `id_dbc`. @return SL_OK, SL_ERR_ARG, SL_ERR_PORT (retried later by
/// sld_motion_read; `last_errno` says why).
sl_err_t sld_motion_open(sld_motion_t *m, const char *ifname, uint32_t id_dbc, uint64_t now_us);

/// The fd to poll for POLLIN (-1 when closed).
int sld_motion_fd(const sld_motion_t *m);

/// Read every pending frame (at most SLD_MOTION_RX_BURST), calling `on_frame` for each;
/// reopen when closed and due. Never blocks. @return frames delivered.
unsigned sld_motion_read(sld_motion_t *m, uint64_t now_us,
                         void (*on_frame)(void *ctx, const sl_can_frame_t *f), void *ctx);

/// Close. Idempotent.
void sld_motion_close(sld_motion_t *m);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_DAEMON_MOTION_H
