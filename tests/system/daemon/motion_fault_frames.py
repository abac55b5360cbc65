#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""VehicleMotion frames with faults, one per line: a cansend argument and the Profile 11
check status a receiver with max delta counter 2 gives it in sequence. The layout comes
from the board's DBC (python3-canmatrix encodes the signals); the E2E protection is built
here with p11_frames.py (AUTOSAR library chaining, the DBC's SlE2EDataId / SlE2EMode).
One pass of 13 lines; its counter steps add up to 15, so passes repeat seamlessly:
- good frames, Speed 0.05 m/s, counter step 1: OK;
- a good frame after a step of 2 (one frame lost): OK_SOME_LOST, used;
- a bad-CRC frame (CRC byte XOR 0x5A) carrying Speed 1.0 m/s: ERROR, never used;
- a repetition of the last good counter carrying 1.0 m/s: REPEATED, never used;
- a frame after a step of 4 carrying 1.0 m/s: WRONG_SEQUENCE, never used (the sequence
  continues from it: the next good frame is OK).
A receiver that used any rejected frame would see 1.0 m/s.

    motion_fault_frames.py BOARD.dbc > frames.txt
"""
import decimal
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
sys.path.insert(0, os.path.dirname(__file__))
import sl_can_decode as scd  # noqa: E402
from p11_frames import p11_protect  # noqa: E402

# (kind, counter step from the last frame with a valid CRC, speed, expected status)
PASS = [
    ("good", 1, "0.05", "OK"),
    ("good", 1, "0.05", "OK"),
    ("bad_crc", 1, "1.0", "ERROR"),
    ("good", 1, "0.05", "OK"),
    ("repeat", 0, "1.0", "REPEATED"),
    ("good", 1, "0.05", "OK"),
    ("good", 2, "0.05", "OK_SOME_LOST"),
    ("jump", 4, "1.0", "WRONG_SEQUENCE"),
    ("good", 1, "0.05", "OK"),
    ("good", 1, "0.05", "OK"),
    ("good", 1, "0.05", "OK"),
    ("good", 1, "0.05", "OK"),
    ("good", 1, "0.05", "OK"),
]
assert sum(step for kind, step, _, _ in PASS if kind != "bad_crc") == 15


def frame(fr, data_id, nibble, speed, ctr, bad_crc=False):
    phys = {"Speed": decimal.Decimal(speed), "YawRate": 0, "SpeedValid": 1, "YawRateValid": 1,
            "Counter": 0, "Crc": 0}
    raw = {s.name: s.phys2raw(phys.get(s.name, 0)) for s in fr.signals}
    data = bytearray(p11_protect(fr.encode(raw), data_id, ctr, nibble))
    if bad_crc:
        data[0] ^= 0x5A
    ident = fr.arbitration_id.id
    return (f"{ident:08X}#{data.hex().upper()}" if fr.arbitration_id.extended
            else f"{ident:03X}#{data.hex().upper()}")


def main(argv):
    db = scd.load_dbc(argv[1])
    fr = next(f for f in db.frames if f.name == "VehicleMotion")
    data_id = int(fr.attributes["SlE2EDataId"])
    nibble = str(fr.attributes.get("SlE2EMode", "Both")).strip('"') in ("Nibble", "1")
    ctr = 14  # the first pass starts at counter 0
    for kind, step, speed, status in PASS:
        c = (ctr + (step if kind != "bad_crc" else 1)) % 15
        print(frame(fr, data_id, nibble, speed, c, bad_crc=kind == "bad_crc"), status)
        if kind != "bad_crc":
            ctr = c
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
