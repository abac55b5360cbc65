// SPDX-License-Identifier: MIT
// calib_board.h: the core board a host tool runs on: a linked board by name, or its
// calibrated view from a vehicle's calibration file (INI or blob: calib_file.h), validated
// by the core exactly as the daemon and a firmware do (sl_calblob_open).
#pragma once

#include <string>

#include "shadowlean/sl_board.h"

namespace sl {

/// The linked board `name` (sl_board_find); with `calibration` non-empty, its calibrated
/// view, made once per (board, file) and kept until the program ends. Thread-safe.
/// Throws std::runtime_error naming the file and the failed check.
const sl_board_t *core_board(const std::string &name, const std::string &calibration);

} // namespace sl
