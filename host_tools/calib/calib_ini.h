// SPDX-License-Identifier: MIT
// calib_ini.h: one calibration file per vehicle, written by several sl-calib commands.
//
// Each command owns one block of the file, which starts with the marker line
// "; --- sl-calib <command> ---" and holds its comments and INI section(s): `shadow` writes
// [calib] (theta per azimuth, provenance), `elongation` writes [detect] (elongation = ...).
// Writing a block replaces that command's previous block and keeps every other block as it
// was (so `sl-calib shadow --out-ini F` and `sl-calib elongation --out-ini F` merge into
// one file, in any order, any number of times). Text before the first marker (a file from
// an older sl-calib) is kept unless it contains this block's section header.
// The reader of the merged file is firmware/port/linux/calib_file.h.
#pragma once

#include <string>

namespace sl {

/// Provenance line values: the tool and version ("sl-calib 1.2.0") and the UTC date
/// ("2026-11-24T06:40:00Z").
std::string calib_tool_version();
std::string calib_utc_date();

/// Write `block` (its lines, without the marker) as command `cmd`'s block of `path`,
/// merged as described above. Returns false (and `why`) when the file cannot be written.
bool write_calib_block(const std::string &path, const std::string &cmd, const std::string &block,
                       const std::string &section_header, std::string *why);

} // namespace sl
