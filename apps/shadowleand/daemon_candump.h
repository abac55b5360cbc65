/// @file daemon_candump.h
/// @brief CAN sink that appends frames to a can-utils log (`candump -L` format), in C for
///        the daemon (host_tools/common/candump_log.h is the C++ reader/writer of the same
///        format; the two are checked against each other and against can-utils by tests).
///
/// Line: `(%010llu.%06llu) IFACE FRAME\n`, FRAME = `123#DEADBEEF` (11-bit id, 3 hex digits),
/// `1ABCDE0F#0102` (29-bit, 8 digits), `123#R` (remote), error frames as 8 digits with
/// 0x20000000 set; upper-case hex, no separators (candump's own style).
///
/// The timestamp written is `stamp_us` (UNIX microseconds), which the owner sets before
/// each send (the daemon writes the wall clock or the radar data time, `--log-time`); the
/// sink vtable's `t_us` (monotonic) is not used for the text. Output is buffered by stdio
/// and flushed by `poll` (once per main-loop turn) and at close.
///
/// Contract (can_sink.h): `send` never blocks on anything but the file system; SL_ERR_PORT
/// when the write failed (counted in `dropped` and `errors`, errno in `last_errno`; EPIPE
/// sets `broken_pipe`: the reader of stdout went away). Not thread-safe.
#ifndef SHADOWLEAN_DAEMON_CANDUMP_H
#define SHADOWLEAN_DAEMON_CANDUMP_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "can_sink.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// One log sink. Caller-owned; fields read-only except `stamp_us`.
typedef struct sld_candump {
    FILE *fp;                 ///< NULL when closed
    bool own;                 ///< fp is ours to fclose (false for stdout)
    bool broken_pipe;         ///< a write failed with EPIPE
    char iface[16];
    uint64_t stamp_us;        ///< timestamp of the next line (set by the owner)
    int last_errno;
    uint32_t unflushed;       ///< lines written since the last successful flush
    sl_can_sink_stats_t stats;///< sent = lines, dropped (incl. lines a failed flush lost),
                              ///< errors = I/O errors
} sld_candump_t;

/// Open (truncate) `path`, "-" = stdout. @return SL_OK, SL_ERR_ARG (bad iface), SL_ERR_PORT
/// (cannot create: `last_errno`).
sl_err_t sld_candump_open(sld_candump_t *c, const char *path, const char *iface);

/// Format one frame as candump text ("123#DEADBEEF") into buf (>= 32 bytes).
/// @return SL_OK or SL_ERR_ARG (id does not fit its kind, dlc > 8).
sl_err_t sld_candump_format_frame(const sl_can_frame_t *f, char *buf, size_t cap);

/// Write one line with `c->stamp_us` (see the file comment for the contract).
sl_err_t sld_candump_send(sld_candump_t *c, const sl_can_frame_t *f);

/// Flush buffered lines. Errors are counted.
void sld_candump_flush(sld_candump_t *c);

/// Flush and close (stdout is flushed, not closed). Idempotent.
void sld_candump_close(sld_candump_t *c);

/// This object as a sink (ctx = c, borrowed). poll() flushes.
sl_can_sink_t sld_candump_sink(sld_candump_t *c);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_DAEMON_CANDUMP_H
