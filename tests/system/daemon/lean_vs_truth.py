#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Decoded leans against the simulator's truth.

    lean_vs_truth.py BOARD.dbc CAN.log TRUTH.gt.csv [--tol DEG] [--az-tol DEG] [--all-frames]

Rotation k of the capture is the CAN rotation group whose Status says Rotations = k + 1
(sl-sim captures start at azimuth 0). For every pole of the truth file, the LATEST rotation
in which a PoleLean frame lies within --az-tol (default 3 deg) of the pole's `nominal`
azimuth is compared: Quality FILTERED and |Lean - alpha_deg| <= --tol (default 0.5). For a
static scene that is the last rotation; for a moving one, the last rotation the pole was
still in the shadow. --all-frames: also every earlier PoleLean frame of the pole must be
within --tol (the worst is printed as "worst"). Prints a table; exit 0 when every pole is
found and within tolerance.
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dbc", metavar="BOARD.dbc")
    ap.add_argument("log", metavar="CAN.log")
    ap.add_argument("truth", metavar="TRUTH.gt.csv")
    ap.add_argument("--tol", type=float, default=0.5, metavar="DEG")
    ap.add_argument("--az-tol", type=float, default=3.0, metavar="DEG")
    ap.add_argument("--all-frames", action="store_true")
    a = ap.parse_args(argv[1:])
    tol, az_tol, pos = a.tol, a.az_tol, [a.dbc, a.log, a.truth]
    groups = [(st.raw["Rotations"] - 1, poles)
              for st, warn, poles in scd.groups(scd.decode_log(pos[0], pos[1])) if warn is not None]
    with open(pos[2]) as fh:
        rows = [r for r in csv.DictReader(fh) if r["nominal"] == "1"]
    if not rows:
        print("FAIL: no nominal rows in the truth file")
        return 1
    truth = {}  # pole -> {rotation: row}
    for r in rows:
        truth.setdefault(r["pole_name"], {})[int(r["rotation"])] = r
    bad = 0
    print(f"{'pole':<12} {'rot':>4} {'azimuth':>8} {'truth':>8} {'decoded':>8} {'error':>7}  quality")
    for name in sorted(truth, key=lambda n: float(next(iter(truth[n].values()))["az_center_deg"])):
        found = None
        worst = None  # (|error|, rotation, row, frame) over every frame (--all-frames)
        for rot, poles in reversed(groups):
            r = truth[name].get(rot)
            if r is None:
                continue
            az = float(r["az_center_deg"])
            best = None
            for d in poles:
                da = abs(d.phys["Azimuth"] - az) % 360.0
                da = min(da, 360.0 - da)
                if da <= az_tol and (best is None or da < best[0]):
                    best = (da, d)
            if best is not None:
                e = abs(best[1].phys["Lean"] - float(r["alpha_deg"]))
                if worst is None or e > worst[0]:
                    worst = (e, rot, r, best[1])
                if found is None:
                    found = (rot, r, best[1])
                if not a.all_frames:
                    break
        if found is None:
            print(f"{name:<12} {'-':>4} {'':>8} {'':>8} {'-':>8}  NOT FOUND")
            bad += 1
            continue
        rot, r, d = found
        alpha = float(r["alpha_deg"])
        err = d.phys["Lean"] - alpha
        q = scd.QUALITY.get(d.raw["Quality"], "?")
        ok = abs(err) <= tol + 1e-9 and q == "FILTERED"
        bad += 0 if ok else 1
        print(f"{name:<12} {rot + 1:>4} {float(r['az_center_deg']):>7.1f}° {alpha:>+7.2f}° {d.phys['Lean']:>+7.2f}° "
              f"{err:>+6.2f}°  {q}{'' if ok else '  FAIL'}")
        if a.all_frames:
            e, wrot, wr, wd = worst
            wok = e <= tol + 1e-9
            bad += 0 if wok else 1
            werr = wd.phys["Lean"] - float(wr["alpha_deg"])
            print(f"{'  worst':<12} {wrot + 1:>4} {float(wr['az_center_deg']):>7.1f}° "
                  f"{float(wr['alpha_deg']):>+7.2f}° {wd.phys['Lean']:>+7.2f}° {werr:>+6.2f}°"
                  f"{'' if wok else '  FAIL'}")
    print(f"lean_vs_truth: {len(truth)} poles, {bad} failures (tolerance {tol} deg)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
