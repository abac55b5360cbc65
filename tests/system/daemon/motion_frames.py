#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""VehicleMotion frames as cansend arguments (one per line), E2E counters 0..14, from the
board's DBC (python3-canmatrix encodes the raw values; the E2E Profile 11 protection is
built with p11_frames.py from the DBC's SlE2EDataId and SlE2EMode).

    motion_frames.py BOARD.dbc SPEED_M_S YAW_DEG_S > frames.txt
"""
import decimal
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
sys.path.insert(0, os.path.dirname(__file__))
import sl_can_decode as scd  # noqa: E402
from p11_frames import p11_protect  # noqa: E402


def main(argv):
    db = scd.load_dbc(argv[1])
    fr = next(f for f in db.frames if f.name == "VehicleMotion")
    data_id = int(fr.attributes["SlE2EDataId"])
    nibble = str(fr.attributes.get("SlE2EMode", "Both")).strip('"') in ("Nibble", "1")
    for ctr in range(15):
        phys = {"Speed": decimal.Decimal(argv[2]), "YawRate": decimal.Decimal(argv[3]),
                "SpeedValid": 1, "YawRateValid": 1, "Counter": 0, "Crc": 0}
        raw = {s.name: s.phys2raw(phys.get(s.name, 0)) for s in fr.signals}
        data = p11_protect(fr.encode(raw), data_id, ctr, nibble)
        ident = fr.arbitration_id.id
        print(f"{ident:08X}#{data.hex().upper()}" if fr.arbitration_id.extended
              else f"{ident:03X}#{data.hex().upper()}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
