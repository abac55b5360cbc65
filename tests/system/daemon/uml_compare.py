#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Host side of the user-mode Linux test: candump's recording of vcan0 against the
daemon's own --can-log of the same runs, field by field (id, 11/29-bit, DLC, data, order;
not the timestamps), plus the VehicleMotion input of the real-time run.

    uml_compare.py OUTDIR BOARD.dbc

VehicleMotion frames on the bus (id and 11/29-bit format from the DBC) are the test's input,
not the daemon's output.

OUTDIR holds candump.log, daemon_fast.log, daemon_rt.log, targets_rt.jsonl (uml_guest.sh).
"""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402

MARKERS = {"SYNC": b"SYNC", "MID": b"MID", "END": b"END"}


def key(f):
    return (f[2], f[3], f[4])


def main(argv):
    out = argv[1]
    motion = next(fr for fr in scd.load_dbc(argv[2]).frames if fr.name == "VehicleMotion")
    motion_id, motion_eff = motion.arbitration_id.id, bool(motion.arbitration_id.extended)
    rec = scd.read_candump(os.path.join(out, "candump.log"))
    seg, cur = {}, None
    for f in rec:
        if f[2] == 0x7FF and not f[3]:
            name = {v: k for k, v in MARKERS.items()}.get(bytes(f[4]))
            if name:
                cur = name
                seg.setdefault(name, [])
                continue
        if cur is not None:
            seg[cur].append(f)
    errors = []
    for marker, log, what in (("SYNC", "daemon_fast.log", "run 1 (fast)"),
                              ("MID", "daemon_rt.log", "run 2 (realtime)")):
        bus = [f for f in seg.get(marker, []) if not (f[2] == motion_id and f[3] == motion_eff)]
        mine = scd.read_candump(os.path.join(out, log))
        n_motion = len(seg.get(marker, [])) - len(bus)
        if not mine:
            errors.append(f"{what}: the daemon's log is empty")
        if len(bus) != len(mine):
            errors.append(f"{what}: candump recorded {len(bus)} frames, the daemon logged {len(mine)}")
        for i, (a, b) in enumerate(zip(bus, mine)):
            if key(a) != key(b):
                errors.append(f"{what}: frame {i + 1}: bus {a[2]:X}#{a[4].hex()} != log {b[2]:X}#{b[4].hex()}")
                break
        print(f"{what}: {len(bus)} frames on vcan0, {len(mine)} in --can-log, "
              f"{n_motion} VehicleMotion frames on the bus")
    # The real-time run used the VehicleMotion input (speed 0.10 m/s -> n_eff 2).
    with open(os.path.join(out, "targets_rt.jsonl")) as fh:
        rots = [json.loads(line) for line in fh][1:]
    used = [r for r in rots if r["motion_valid"]]
    if not used:
        errors.append("run 2: no rotation used the VehicleMotion input")
    elif any(r["speed_mm_s"] != 100 or r["frames_eff"] != 2 for r in used):
        errors.append(f"run 2: motion used as {[(r['speed_mm_s'], r['frames_eff']) for r in used]}, "
                      "want speed 100 mm/s, n_eff 2")
    print(f"run 2: {len(used)} of {len(rots)} rotations used VehicleMotion "
          f"(speed {used[0]['speed_mm_s'] if used else '-'} mm/s, n_eff {used[0]['frames_eff'] if used else '-'})")
    for e in errors:
        print("FAIL:", e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
