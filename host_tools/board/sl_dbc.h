// SPDX-License-Identifier: MIT
// sl_dbc.h: the DBC file of a board's CAN interface, generated from the core's layout table
// (sl_can_layout() in include/shadowlean/sl_can.h) and the board's [can] section.
//
// The output is a pure function of the board spec and the layout (no time stamps), so a
// committed boards/<name>/shadowlean.dbc can be regenerated and diffed. It loads in
// Debian's python3-canmatrix 0.9.5 (tests/system/can/check_dbc_decode.py decodes frames the core
// encoded and compares every signal with the encoder's input).
//
// Contents: VERSION, NS_, BS_, BU_ (SHADOWLEAN, VEHICLE), BO_/SG_ for PoleLean,
// LeanWarning, Status (SHADOWLEAN -> VEHICLE) and VehicleMotion (VEHICLE -> SHADOWLEAN),
// CM_ comments (network: E2E profile with worked example; every message: its layout
// table and Data ID; every signal), BA_DEF_/BA_DEF_DEF_/BA_ (BusType, Baudrate, DBName,
// GenMsgCycleTime, SlE2EDataId, SlE2EMode, VFrameFormat for 29-bit ids), VAL_ value tables.
#pragma once

#include <stdexcept>
#include <string>

#include "shadowlean/sl_can.h"
#include "sl_board_spec.h"

namespace sl {

/// The board's CAN ids (DBC style), Data IDs and modes, as the core's sender takes them.
sl_can_ids_t can_ids(const BoardSpec &b);

/// Version string written into the DBC's VERSION line.
constexpr const char *kDbcGeneratorVersion = "sl-dbc 1.1";

/// DBC text for board `b`. Throws std::invalid_argument when the board cannot be
/// described (a CAN id that is not 11-bit or DBC-style 29-bit, equal ids, or more
/// targets per rotation than PoleLean.TargetId can number).
std::string make_dbc(const BoardSpec &b);

} // namespace sl
