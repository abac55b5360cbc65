#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Read a candump log with python-can's CanutilsLogReader (Debian python3-can 4.1) and
compare it field by field with the frame list candump_roundtrip wrote.

    check_pycan.py FRAMES.log FRAMES.expect

python-can reports error frames only when the bus-error class bit (0x80) is set; other
error frames come back as 29-bit frames whose id is the error class: both are accepted.
"""
import sys

import can

FLAG_EFF, FLAG_RTR, FLAG_ERR = 1, 2, 4


def main():
    msgs = list(can.CanutilsLogReader(sys.argv[1]))
    with open(sys.argv[2]) as fh:
        want = [line.split() for line in fh if line.strip()]
    bad = 0
    if len(msgs) != len(want):
        print(f"FAIL: python-can read {len(msgs)} frames, expected {len(want)}")
        return 1
    for i, (m, w) in enumerate(zip(msgs, want)):
        t_us, fid, flags, dlc = int(w[0]), int(w[1]), int(w[2]), int(w[3])
        data = bytes.fromhex(w[4]) if len(w) > 4 else b""
        problems = []
        if abs(round(m.timestamp * 1e6) - t_us) > 1:
            problems.append(f"timestamp {m.timestamp!r}")
        if flags & FLAG_ERR:
            if fid & 0x80:
                if not m.is_error_frame:
                    problems.append("not an error frame")
            elif not (m.is_extended_id and m.arbitration_id == fid and bytes(m.data) == data):
                problems.append("error frame fields")
        else:
            if m.arbitration_id != fid:
                problems.append(f"id {m.arbitration_id:#x} != {fid:#x}")
            if m.is_extended_id != bool(flags & FLAG_EFF):
                problems.append("extended flag")
            if m.is_remote_frame != bool(flags & FLAG_RTR):
                problems.append("remote flag")
            if m.dlc != dlc:
                problems.append(f"dlc {m.dlc} != {dlc}")
            if not m.is_remote_frame and bytes(m.data) != data:
                problems.append(f"data {bytes(m.data).hex()} != {data.hex()}")
        if problems:
            bad += 1
            if bad <= 10:
                print(f"FAIL line {i + 1}: {', '.join(problems)}")
    print(f"check_pycan: {len(msgs)} frames, {bad} mismatches")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
