// SPDX-License-Identifier: MIT
/// @file fw_app.h
/// @brief The example firmware's application: runs the core pipeline over a capture held in
/// memory (flash on the target), the way a port feeds it from a TCP socket, and reports
/// every CAN frame and rotation as text lines. The same file is built for the host
/// (tests/core/thumb/host_frames.c) so the two outputs can be compared line for line.
///
/// Not part of the core: it may use what a bare-metal application has (no heap, no stdio;
/// numbers are formatted here). Ownership: one static sl_pipeline_t inside fw_app.c.
#ifndef SHADOWLEAN_FW_APP_H
#define SHADOWLEAN_FW_APP_H

#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// What the platform gives the application.
typedef struct fw_platform {
    /// Write a NUL-terminated text (a whole line including its '\n').
    void (*write)(const char *s);
    /// A free-running up-counter of clock ticks (NULL: no timing). Only differences
    /// modulo `tick_mask + 1` are used, taken around each sl_pipeline_feed() call, so the
    /// count covers the core and the port callbacks (which only copy frames to a buffer),
    /// never the printing.
    uint32_t (*ticks)(void);
    uint32_t tick_mask;
} fw_platform_t;

typedef struct fw_result {
    uint64_t ticks;          ///< ticks spent inside sl_pipeline_feed/finish
    uint32_t azimuths;       ///< azimuth rows the pipeline processed
    uint32_t rotations;
    uint32_t targets;        ///< targets over all rotations
    uint32_t frames;         ///< CAN frames sent
    uint32_t frames_lost;    ///< frames that did not fit the report buffer (must be 0)
} fw_result_t;

/// Feed `len` bytes at `cap` in chunks of `chunk` bytes (a TCP segment: 1460) to a pipeline
/// initialised for the board `board_name` (the registry's first board when NULL), print one
/// line per CAN frame ("frame <rotation> <id> <dlc> <data>") and per rotation
/// ("rotation <n> valid <v> missing <m> targets <k> level <l>"), then finish the stream.
/// @return SL_OK, SL_ERR_ARG (no such board, chunk 0), or the pipeline's init error.
sl_err_t fw_app_run(const fw_platform_t *pf, const char *board_name, const uint8_t *cap,
                    size_t len, size_t chunk, fw_result_t *res);

/// Decimal text of `v` into `buf` (>= 21 bytes); returns `buf`.
char *fw_u64(char *buf, uint64_t v);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_FW_APP_H
