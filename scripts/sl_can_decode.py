#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Decode shadowlean CAN frames from a candump log with a board's generated DBC: a thin
wrapper over the Python package `shadowlean` (python/shadowlean, installed by the
python3-shadowlean package), the project's one DBC decoder. The daemon tests, the DBC
layout check (tests/system/can/check_dbc_decode.py) and scripts/demo.sh import it from here.

Library (re-exported from the package):
    db = load_dbc(path)
    frames = read_candump(path)            # [Frame(t, iface, can_id, is_eff, data)]
    d = decode(db, can_id, is_eff, data)   # Decoded(name, phys{}, raw{}, named{}, crc_ok, ...)
    e2e_crc(data_id, data, mode)           # the E2E Profile 11 CRC of a frame

Command line (the same as `python3 -m shadowlean decode LOG --dbc BOARD.dbc ...`):
    sl_can_decode.py BOARD.dbc LOG              every frame, decoded
    sl_can_decode.py BOARD.dbc LOG --summary    one line per Status frame (link, LeanWarning)
    sl_can_decode.py BOARD.dbc LOG --table [--last K]   PoleLean rows per rotation
"""
import os
import sys

_here = os.path.dirname(os.path.abspath(__file__))
if os.path.isdir(os.path.join(_here, "..", "python", "shadowlean")):
    sys.path.insert(0, os.path.join(_here, "..", "python"))  # the source tree's package

from shadowlean import (LEVEL, LINK, QUALITY, Decoded, Frame, decode, e2e_crc,  # noqa: E402,F401
                        decode_log, frame_of, groups, load_dbc, print_summary, print_table,
                        read_candump)
from shadowlean.__main__ import main as _main  # noqa: E402


def main(argv):
    if len(argv) < 3 or argv[1].startswith("-") or argv[2].startswith("-"):
        print(__doc__, file=sys.stderr)
        return 2
    return _main(["decode", argv[2], "--dbc", argv[1]] + argv[3:])


if __name__ == "__main__":
    sys.exit(main(sys.argv))
