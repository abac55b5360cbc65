#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Per pole, the rotations with a PoleLean at the pole's bearing; PoleLean frames where no
pole stands. Decoded with the board's DBC (python3-canmatrix), independently of the C code.

    clutter_count.py BOARD.dbc CAN.log TRUTH.gt.csv [--az-tol DEG] [--stray-tol DEG] [--json OUT]

Rotation k of the capture is the CAN rotation group whose Status says Rotations = k + 1.
A pole counts as tracked in rotation k when a PoleLean frame of that group lies within
--az-tol (default 3 deg) of the pole's `nominal` azimuth of rotation k. A PoleLean frame is
stray when it lies farther than --stray-tol (default 5 deg) from every azimuth on which a
pole of the truth file is visible in that rotation. Prints one line; --json writes
{"tracked": {pole: rotations}, "truth": {pole: rotations in the truth}, "stray": N,
"rotations": N, "polelean": N, "candidates_dropped": max CandidatesDropped or null}.
"""
import argparse
import csv
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402


def adist(a, b):
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dbc", metavar="BOARD.dbc")
    ap.add_argument("log", metavar="CAN.log")
    ap.add_argument("truth", metavar="TRUTH.gt.csv")
    ap.add_argument("--az-tol", type=float, default=3.0, metavar="DEG")
    ap.add_argument("--stray-tol", type=float, default=5.0, metavar="DEG")
    ap.add_argument("--json", metavar="OUT")
    a = ap.parse_args(argv[1:])
    opt = {"--az-tol": a.az_tol, "--stray-tol": a.stray_tol, "--json": a.json}
    pos = [a.dbc, a.log, a.truth]
    decoded = scd.decode_log(pos[0], pos[1])
    dropped = None
    for _, d in decoded:
        if d is not None and d.name == "Health" and "CandidatesDropped" in d.raw:
            dropped = max(dropped or 0, d.raw["CandidatesDropped"])
    groups = [(st.raw["Rotations"] - 1, poles)
              for st, warn, poles in scd.groups(decoded) if warn is not None]
    nominal, visible = {}, {}
    with open(pos[2]) as fh:
        for r in csv.DictReader(fh):
            k = int(r["rotation"])
            visible.setdefault(k, []).append(float(r["az_center_deg"]))
            if r["nominal"] == "1":
                nominal.setdefault(r["pole_name"], {})[k] = float(r["az_center_deg"])
    tracked = {name: 0 for name in nominal}
    stray = 0
    total = 0
    for rot, poles in groups:
        total += len(poles)
        for name, rows in nominal.items():
            az = rows.get(rot)
            if az is not None and any(adist(d.phys["Azimuth"], az) <= opt["--az-tol"] for d in poles):
                tracked[name] += 1
        vis = visible.get(rot, [])
        for d in poles:
            if not any(adist(d.phys["Azimuth"], a) <= opt["--stray-tol"] for a in vis):
                stray += 1
    res = {"tracked": tracked, "truth": {n: len(r) for n, r in nominal.items()},
           "stray": stray, "rotations": len(groups), "polelean": total,
           "candidates_dropped": dropped}
    print("clutter_count: " + ", ".join(f"{n} {tracked[n]}/{res['truth'][n]}" for n in sorted(tracked)) +
          f"; stray PoleLean {stray} of {total} over {len(groups)} rotations; "
          f"CandidatesDropped {dropped}")
    if opt["--json"]:
        with open(opt["--json"], "w") as fh:
            json.dump(res, fh)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
