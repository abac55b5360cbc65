// SPDX-License-Identifier: MIT
/// @file candump.h
/// @brief The candump text format in one place (Linux port): can-utils frames
///        ("123#DEADBEEF", "1ABCDE0F#0102", "123#R", error frames) and candump -L log lines
///        "(1700000000.123456) can0 123#DEADBEEF", both ways, plus a CAN sink that appends
///        such lines to a file (the daemon's --can-log; sl-gsusb-send's logs).
///
/// Syntax (can-utils lib.h / lib.c, 2020.11): 3 hex digits = 11-bit id, 8 hex digits =
/// 29-bit id (an 8-digit id with 0x20000000 set is an error frame), `R` after `#` = remote
/// request with an optional DLC digit, data as hex byte pairs with optional `.` separators.
/// CAN FD (`##`) is not supported (classic adapters only). Output is upper-case hex,
/// no separators, exactly as candump prints.
#ifndef SHADOWLEAN_PORT_CANDUMP_H
#define SHADOWLEAN_PORT_CANDUMP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "can_sink.h"

#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Parse one frame text ("123#DEADBEEF"). Error frames get SL_CAN_FLAG_ERR and their class
/// bits in `id`. @return SL_OK or SL_ERR_MALFORMED (with `*why` a static reason).
sl_err_t slp_candump_parse_frame(const char *s, sl_can_frame_t *out, const char **why);

/// Parse one candump log line: "(sec.usec) iface frame", or a bare frame. Leading/trailing
/// blanks are ignored. @return SL_OK, SL_ERR_NEED_MORE (blank line: skip it) or
/// SL_ERR_MALFORMED.
sl_err_t slp_candump_parse_line(const char *line, sl_can_frame_t *out, const char **why);

/// Format a frame as candump text into `buf` (at least 32 bytes). @return `buf`.
char *slp_candump_format_frame(const sl_can_frame_t *f, char *buf, size_t cap);

/// Format a candump -L line "(%010lu.%06lu) iface frame" (no newline). @return `buf`.
char *slp_candump_format_line(const sl_can_frame_t *f, uint64_t t_us, const char *iface, char *buf,
                             size_t cap);

/// One candump -L line, parsed strictly (slp_candump_parse_record).
typedef struct slp_candump_record {
    uint64_t t_us;          ///< sec x 1e6 + usec (fraction digits beyond 6 dropped)
    char iface[16];         ///< interface name (IFNAMSIZ)
    sl_can_frame_t frame;
} slp_candump_record_t;

/// Parse one log line strictly: "(<seconds>.<1..9 digits>) <iface> <frame>", optionally
/// followed by python-can's " R"/" T" marker; a trailing '\n'/'\r' is allowed.
/// @return SL_OK, or SL_ERR_MALFORMED with `*why` a static reason (`why` may be NULL).
sl_err_t slp_candump_parse_record(const char *line, slp_candump_record_t *out, const char **why);

/// True when `f` can be written: the id fits its kind (11 or 29 bits), dlc <= 8.
bool slp_candump_frame_ok(const sl_can_frame_t *f);

// ---------------------------------------------------------------------------------------
// Log file sink
//
// Appends `(%010llu.%06llu) IFACE FRAME\n` lines (slp_candump_format_frame). The timestamp
// written is `stamp_us` (UNIX microseconds), which the owner sets before each send (the
// daemon writes the wall clock or the radar data time, `--log-time`); the sink vtable's
// `t_us` (monotonic) is not used for the text. Output is buffered by stdio and flushed by
// `poll` (once per main-loop turn) and at close.
//
// Contract (can_sink.h): `send` never blocks on anything but the file system; SL_ERR_PORT
// when the write failed (counted in `dropped` and `errors`, errno in `last_errno`; EPIPE
// sets `broken_pipe`: the reader of stdout went away); SL_ERR_ARG (dropped) for a frame
// slp_candump_frame_ok() rejects. Not thread-safe.

/// One log sink. Caller-owned; fields read-only except `stamp_us`.
typedef struct slp_candump {
    FILE *fp;                 ///< NULL when closed
    bool own;                 ///< fp is ours to fclose (false for stdout)
    bool broken_pipe;         ///< a write failed with EPIPE
    char iface[16];
    uint64_t stamp_us;        ///< timestamp of the next line (set by the owner)
    int last_errno;
    uint32_t unflushed;       ///< lines written since the last successful flush
    slp_can_sink_stats_t stats;///< sent = lines, dropped (incl. lines a failed flush lost),
                              ///< errors = I/O errors
} slp_candump_t;

/// Open (truncate) `path`, "-" = stdout. @return SL_OK, SL_ERR_ARG (bad iface), SL_ERR_PORT
/// (cannot create: `last_errno`).
sl_err_t slp_candump_open(slp_candump_t *c, const char *path, const char *iface);

/// Write one line with `c->stamp_us` (see above for the contract).
sl_err_t slp_candump_send(slp_candump_t *c, const sl_can_frame_t *f);

/// Flush buffered lines. Errors are counted.
void slp_candump_flush(slp_candump_t *c);

/// Flush and close (stdout is flushed, not closed). Idempotent.
void slp_candump_close(slp_candump_t *c);

/// This object as a sink (ctx = c, borrowed). poll() flushes.
slp_can_sink_t slp_candump_sink(slp_candump_t *c);

#ifdef __cplusplus
}
#endif


#endif // SHADOWLEAN_CANDUMP_TEXT_H
