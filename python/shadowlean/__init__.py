# SPDX-License-Identifier: MIT
"""shadowlean: decode and verify the CAN frames of a shadowlean module.

Everything comes from the board's generated DBC (boards/<b>/shadowlean.dbc, installed as
/usr/share/shadowlean/dbc/<board>.dbc): message layouts, scaling, value tables and each
message's E2E Profile 11 Data ID and mode (attributes SlE2EDataId, SlE2EMode). Decoding uses Debian's python3-canmatrix,
live buses python3-can; nothing here shares code with the C encoder.

    import shadowlean as sl
    db = sl.load_dbc("/usr/share/shadowlean/dbc/paper-sim.dbc")
    mon = sl.E2EMonitor(db)
    for frame in sl.read_candump("can.log"):          # or sl.frames_from_bus(bus)
        d = sl.decode(db, frame.can_id, frame.is_eff, frame.data)
        status = mon.check(d, frame.data)             # "OK", "REPEATED", "ERROR", ...

Command line: python3 -m shadowlean --help
"""
from .candump import Frame, read_candump, parse_candump_line
from .dbc import (GROUND_QUALITY, HAZARD_KIND, LEVEL, LINK, QUALITY, Decoded, counter_modulo, decode,
                  decode_frames, decode_log, frame_of, load_dbc)
from .e2e import (E2E_ERRORS, E2E_STATUSES, MODE_BOTH, MODE_NIBBLE, E2EMonitor, E2EStats,
                  crc8_0x1d, crc8_j1850, e2e_crc, protect)
from .bus import frame_from_message, frames_from_bus, message_from_frame, open_bus
from .report import format_ground, ground, groups, print_frames, print_ground, print_summary, print_table
from ._version import __version__

__all__ = [
    "Frame", "read_candump", "parse_candump_line",
    "GROUND_QUALITY", "HAZARD_KIND", "LEVEL", "LINK", "QUALITY", "Decoded", "counter_modulo", "decode", "decode_frames",
    "decode_log", "frame_of", "load_dbc",
    "E2E_ERRORS", "E2E_STATUSES", "MODE_BOTH", "MODE_NIBBLE", "E2EMonitor", "E2EStats",
    "crc8_0x1d", "crc8_j1850", "e2e_crc", "protect",
    "frame_from_message", "frames_from_bus", "message_from_frame", "open_bus",
    "format_ground", "ground", "groups", "print_frames", "print_ground", "print_summary", "print_table",
    "__version__",
]
