#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Compare what candump recorded on vcan0 with what the SocketCAN sink says it sent.

    uml_sink_compare.py CANDUMP.log SENT.log PRODUCED_A.log

- candump.log minus the harness's marker frames (id 0x7FF) must equal sent.log frame by
  frame (id, 11/29-bit, RTR, DLC, data; time stamps differ);
- the first frames of candump.log must equal produced_a.log, the candump-log sink's
  record of everything phase A handed to both sinks.
Both files are read with python-can's CanutilsLogReader (independent of the C++ reader).
"""
import sys

import can


def frames(path, skip_markers=False):
    out = []
    for m in can.CanutilsLogReader(path):
        if skip_markers and not m.is_extended_id and m.arbitration_id == 0x7FF:
            continue
        out.append((m.arbitration_id, m.is_extended_id, m.is_remote_frame, m.dlc,
                    b"" if m.is_remote_frame else bytes(m.data)))
    return out


def fmt(f):
    fid, ext, rtr, dlc, data = f
    return f"{fid:0{8 if ext else 3}X}#" + (f"R{dlc}" if rtr else data.hex().upper())


def compare(name, got, want):
    if got == want:
        print(f"{name}: {len(got)} frames identical")
        return True
    print(f"FAIL {name}: {len(got)} frames recorded, {len(want)} expected")
    for i, (g, w) in enumerate(zip(got, want)):
        if g != w:
            print(f"  first difference at frame {i + 1}: recorded {fmt(g)}, expected {fmt(w)}")
            break
    return False


def main():
    rec = frames(sys.argv[1], skip_markers=True)
    sent = frames(sys.argv[2])
    produced = frames(sys.argv[3])
    ok = compare("candump vs sink on_sent log", rec, sent)
    ok &= compare("candump vs candump-log sink (phase A)", rec[: len(produced)], produced)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
