/// @file candump_text.h
/// @brief can-utils text frames ("123#DEADBEEF", "1ABCDE0F#0102", "123#R", error frames)
///        and candump -L log lines "(1700000000.123456) can0 123#DEADBEEF", both ways.
///
/// Syntax (can-utils lib.h / lib.c, 2020.11): 3 hex digits = 11-bit id, 8 hex digits =
/// 29-bit id (an 8-digit id with 0x20000000 set is an error frame), `R` after `#` = remote
/// request with an optional DLC digit, data as hex byte pairs with optional `.` separators.
/// CAN FD (`##`) is not supported (classic adapters only). Output is upper-case hex,
/// no separators, exactly as candump prints.
#ifndef SHADOWLEAN_CANDUMP_TEXT_H
#define SHADOWLEAN_CANDUMP_TEXT_H

#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Parse one frame text ("123#DEADBEEF"). Error frames get SL_CAN_FLAG_ERR and their class
/// bits in `id`. @return SL_OK or SL_ERR_MALFORMED (with `*why` a static reason).
sl_err_t sl_candump_parse_frame(const char *s, sl_can_frame_t *out, const char **why);

/// Parse one candump log line: "(sec.usec) iface frame", or a bare frame. Leading/trailing
/// blanks are ignored. @return SL_OK, SL_ERR_NEED_MORE (blank line: skip it) or
/// SL_ERR_MALFORMED.
sl_err_t sl_candump_parse_line(const char *line, sl_can_frame_t *out, const char **why);

/// Format a frame as candump text into `buf` (at least 32 bytes). @return `buf`.
char *sl_candump_format_frame(const sl_can_frame_t *f, char *buf, size_t cap);

/// Format a candump -L line "(%010lu.%06lu) iface frame" (no newline). @return `buf`.
char *sl_candump_format_line(const sl_can_frame_t *f, uint64_t t_us, const char *iface, char *buf,
                             size_t cap);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_CANDUMP_TEXT_H
