#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""VehicleMotion frames with faults, as cansend arguments (one per line), from the board's
DBC (python3-canmatrix encodes, the CRC is computed here). One cycle of 30 lines:
- good frames: Speed 0.05 m/s, E2E counters that advance by 1, except a jump of 3 every
  4 good frames (2 frames "lost": accepted, counted as a counter jump);
- every 3rd line a bad-CRC frame (CRC byte XOR 0x5A) carrying Speed 1.0 m/s: must be
  rejected, never used (it would make n_eff 1);
- every 10th line a repetition of the previous good counter with Speed 1.0 m/s: rejected.

    motion_fault_frames.py BOARD.dbc > frames.txt
"""
import decimal
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402


def frame(fr, data_id, speed, ctr, bad_crc=False):
    phys = {"Speed": decimal.Decimal(speed), "YawRate": 0, "SpeedValid": 1, "YawRateValid": 1,
            "Counter": ctr, "Crc": 0}
    raw = {s.name: s.phys2raw(phys.get(s.name, 0)) for s in fr.signals}
    data = bytearray(fr.encode(raw))
    data[0] = scd.crc8_j1850(bytes([data_id]) + bytes(data[1:]))
    if bad_crc:
        data[0] ^= 0x5A
    ident = fr.arbitration_id.id
    return (f"{ident:08X}#{data.hex().upper()}" if fr.arbitration_id.extended
            else f"{ident:03X}#{data.hex().upper()}")


def main(argv):
    db = scd.load_dbc(argv[1])
    fr = next(f for f in db.frames if f.name == "VehicleMotion")
    data_id = int(fr.attributes["SlE2EDataId"])
    ctr, good, last_good = 0, 0, 0
    for line in range(1, 31):
        if line % 10 == 0:
            # repetition of the last good frame's counter: rejected (not ctr - 1, which after
            # a jump is a forward step the receiver rightly accepts)
            print(frame(fr, data_id, "1.0", last_good))
        elif line % 3 == 0:
            print(frame(fr, data_id, "1.0", ctr, bad_crc=True))  # bad CRC: rejected
        else:
            print(frame(fr, data_id, "0.05", ctr))
            last_good = ctr
            good += 1
            ctr = (ctr + (3 if good % 4 == 0 else 1)) % 15  # a counter jump every 4 good frames
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
