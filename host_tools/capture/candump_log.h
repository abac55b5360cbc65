// SPDX-License-Identifier: MIT
// candump_log.h: writer and reader of the can-utils log format (`candump -L`, `candump -l`,
// canplayer, log2long, python-can CanutilsLogReader):
//
//     (0000012345.678901) vcan0 123#DEADBEEF
//     (%010lu.%06lu) <iface> <frame>
//
// <frame> (can-utils lib.c sprint_canframe / parse_canframe, classic CAN only):
//   123#DEADBEEF    11-bit id: exactly 3 hex digits; data: 0..8 bytes, 2 hex digits each
//   1ABCDE0F#0102   29-bit id: exactly 8 hex digits
//   20000040#...    8 digits with 0x20000000 set: an error frame (id = error class bits)
//   123#R / 123#R7  remote request, optional DLC digit (written only when DLC > 0)
// The writer emits uppercase hex, no separators (candump's own style). The reader also
// accepts lowercase hex, '.' between data bytes, seconds of any width, 1..9 fraction
// digits, and a trailing " R"/" T" direction token (python-can's writer adds it). CAN FD
// lines ("123##1...") are rejected with a clear message: the module is classic CAN only.
//
// Timestamps are microseconds: t_us = sec x 1e6 + usec. Parsing and formatting are the
// port's C module (firmware/port/linux/candump.h); interface names are limited to 15
// characters (IFNAMSIZ).
#pragma once

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "can_sink.h"
#include "shadowlean/sl_can.h"

namespace sl {

/// One log line.
struct CandumpRecord {
    uint64_t t_us = 0;
    std::string iface;
    sl_can_frame_t frame{};
};

struct CandumpError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// The frame part: "123#DEADBEEF". Throws CandumpError for an id that does not fit its
/// kind or a DLC > 8.
std::string format_candump_frame(const sl_can_frame_t &f);

/// A whole line without the newline: "(0000000001.000002) vcan0 123#DEADBEEF".
std::string format_candump_line(const CandumpRecord &r);

/// Parse one line (a trailing '\n' / '\r' is allowed). Returns false and sets *err (when
/// not NULL) to a short reason on failure; *out is then unspecified.
bool parse_candump_line(const std::string &line, CandumpRecord *out, std::string *err);

/// Read a whole log file; blank lines are skipped. Throws CandumpError("<path>:<line>:
/// <reason>") on the first bad line or when the file cannot be read.
std::vector<CandumpRecord> read_candump_log(const std::string &path);

/// Appends frames to a log file as candump -L would print them. Also usable as a CAN sink
/// (`sink()`). (The daemon's sink is the port's C one, slp_candump_t.) Not thread-safe.
class CandumpWriter {
public:
    CandumpWriter() = default;
    ~CandumpWriter();
    CandumpWriter(const CandumpWriter &) = delete;
    CandumpWriter &operator=(const CandumpWriter &) = delete;

    /// Open (truncate) `path` ("-" = stdout); every line names interface `iface`. Throws
    /// CandumpError when the file cannot be created.
    void open(const std::string &path, const std::string &iface);
    bool is_open() const { return fp_ != nullptr; }
    /// Write one line. SL_OK, SL_ERR_PORT (not open or I/O error: dropped and counted),
    /// or SL_ERR_ARG (frame not representable: dropped and counted).
    sl_err_t write(const sl_can_frame_t &f, uint64_t t_us);
    /// Push buffered lines to the OS (the sink's poll does this too).
    void flush();
    /// Flush and close; safe to call twice.
    void close();
    /// Counters: sent = lines written, dropped, errors = I/O errors.
    const slp_can_sink_stats_t &stats() const { return stats_; }
    /// This writer as a sink (ctx = this; must outlive the sink). poll() flushes.
    slp_can_sink_t sink();

private:
    FILE *fp_ = nullptr;
    bool own_ = false;
    std::string iface_;
    slp_can_sink_stats_t stats_{};
};

} // namespace sl
