// SPDX-License-Identifier: MIT
// sl_paths.h: where host tools find the project's files (boards, shared data).
#pragma once
#include <string>

namespace sl {

/// The source tree (boards/, tests/...): $SL_SOURCE_DIR if set, else the build's source dir.
std::string source_dir();

/// Directory of board `name`: <source>/boards/<name>, or `name` itself when it is a path
/// to a directory or a board.ini file.
std::string board_dir(const std::string &name);

} // namespace sl
