#!/usr/bin/python3
"""Decoded leans against the simulator's truth.

    lean_vs_truth.py BOARD.dbc CAN.log TRUTH.gt.csv [--tol DEG] [--az-tol DEG]

Takes the last rotation group of the CAN log (PoleLean frames up to the last Status) and,
for every pole of the truth file's last rotation (its `nominal` row: the azimuth nearest
the pole's visible segment), the PoleLean frame with the nearest Azimuth (within --az-tol,
default 3 deg). Requires Quality FILTERED and |Lean - alpha_deg| <= --tol (default 0.5).
Prints a table; exit 0 when every pole is found and within tolerance.
"""
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import sl_can_decode as scd  # noqa: E402


def main(argv):
    args = argv[1:]
    tol, az_tol = 0.5, 3.0
    pos = []
    i = 0
    while i < len(args):
        if args[i] == "--tol":
            tol = float(args[i + 1])
            i += 2
        elif args[i] == "--az-tol":
            az_tol = float(args[i + 1])
            i += 2
        else:
            pos.append(args[i])
            i += 1
    if len(pos) != 3:
        print(__doc__)
        return 2
    decoded = scd.decode_log(pos[0], pos[1])
    last, cur = [], []
    for _, d in decoded:
        if d is None:
            continue
        if d.name == "PoleLean":
            cur.append(d)
        elif d.name == "Status":
            if cur:
                last = cur
            cur = []
    with open(pos[2]) as fh:
        rows = [r for r in csv.DictReader(fh) if r["nominal"] == "1"]
    if not rows:
        print("FAIL: no nominal rows in the truth file")
        return 1
    last_rot = max(int(r["rotation"]) for r in rows)
    truth = [r for r in rows if int(r["rotation"]) == last_rot]
    bad = 0
    print(f"{'pole':<12} {'azimuth':>8} {'truth':>8} {'decoded':>8} {'error':>7}  quality")
    for r in sorted(truth, key=lambda r: float(r["az_center_deg"])):
        az = float(r["az_center_deg"])
        alpha = float(r["alpha_deg"])
        best = None
        for d in last:
            da = abs(d.phys["Azimuth"] - az) % 360.0
            da = min(da, 360.0 - da)
            if da <= az_tol and (best is None or da < best[0]):
                best = (da, d)
        if best is None:
            print(f"{r['pole_name']:<12} {az:>7.1f}° {alpha:>+7.2f}° {'-':>8}  NOT FOUND")
            bad += 1
            continue
        d = best[1]
        err = d.phys["Lean"] - alpha
        q = scd.QUALITY.get(d.raw["Quality"], "?")
        ok = abs(err) <= tol + 1e-9 and q == "FILTERED"
        bad += 0 if ok else 1
        print(f"{r['pole_name']:<12} {az:>7.1f}° {alpha:>+7.2f}° {d.phys['Lean']:>+7.2f}° {err:>+6.2f}°  {q}"
              f"{'' if ok else '  FAIL'}")
    print(f"lean_vs_truth: {len(truth)} poles, {bad} failures (tolerance {tol} deg)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
