#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""PoleLean frames against the simulator's in-plane truth: is LeanSigma honest?

    lean_sigma_vs_truth.py BOARD.dbc CAN.log GT.csv [--max-sigmas K] [--saturated-ok]

Every PoleLean frame with Quality VALID or FILTERED carries the in-plane lean (alpha, + = top
towards the radar) of its track at its azimuth. Its truth is the ground-truth row of sl-sim
(GT.csv: alpha_deg per rotation and azimuth) of the last rotation that ended before the
frame, at the azimuth nearest the frame's (within 1 deg). Asserts |Lean - truth| <= K
LeanSigma (default 3) on every such frame, and that frames were compared. A frame whose
LeanSigma is saturated with Clamped set says only "LeanSigma >= 6.2" (the DBC): counted apart,
not compared; with --saturated-ok a log whose PoleLean frames are all such bounds passes (a
stream whose bounds the module cannot check: it says so), else at least one frame must be
compared. Prints the counts and the largest error in degrees and in LeanSigma.
"""
import csv
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402


SIGMA_MAX = 6.2  # LeanSigma's range limit (x0.2, 5 bits)


def main(argv):
    args = [a for a in argv[1:]]
    k = 3.0
    if "--max-sigmas" in args:
        i = args.index("--max-sigmas")
        k = float(args[i + 1])
        del args[i:i + 2]
    saturated_ok = "--saturated-ok" in args
    if saturated_ok:
        args.remove("--saturated-ok")
    if len(args) != 3:
        print(__doc__)
        return 2
    db = scd.load_dbc(args[0])
    rows = {}   # rotation -> [(az_center_deg, alpha_deg)]
    t_end = {}  # rotation -> last azimuth time
    for r in csv.DictReader(open(args[2])):
        rot = int(r["rotation"])
        t = float(r["t_s"])
        t_end[rot] = max(t_end.get(rot, t), t)
        a = float(r["alpha_deg"]) if r["alpha_deg"] not in ("", "nan") else math.nan
        if not math.isnan(a):
            rows.setdefault(rot, []).append((float(r["az_center_deg"]), a))
    ends = sorted((t, rot) for rot, t in t_end.items())
    n = bad = saturated = 0
    worst = worst_sig = 0.0
    for f in scd.read_candump(args[1]):
        d = scd.decode(db, f.can_id, f.is_eff, f.data)
        if d is None or d.name != "PoleLean" or not d.crc_ok:
            continue
        if d.named["Quality"] not in ("VALID", "FILTERED"):
            continue
        before = [rot for t, rot in ends if t < f.t]
        if not before:
            continue
        az = d.phys["Azimuth"]
        cand = [(abs((c - az + 180.0) % 360.0 - 180.0), a) for c, a in rows.get(before[-1], [])]
        cand = [c for c in cand if c[0] <= 1.0]
        if not cand:
            continue
        truth = min(cand)[1]
        err = abs(d.phys["Lean"] - truth)
        sig = d.phys["LeanSigma"]
        if d.raw["Clamped"] and sig >= SIGMA_MAX - 1e-6:
            # "6.2 with Clamped = 1 means >= 6.2" (the DBC): a bound, no claim to check
            saturated += 1
            continue
        n += 1
        worst = max(worst, err)
        ratio = err / sig if sig > 0 else math.inf
        worst_sig = max(worst_sig, ratio)
        if ratio > k:
            bad += 1
            print("FAIL t=%.3f target %d az %.1f: Lean %+.2f, truth %+.2f, LeanSigma %.1f (%.1f sigmas)"
                  % (f.t, d.phys["TargetId"], az, d.phys["Lean"], truth, sig, ratio))
    print("lean_sigma_vs_truth: %d PoleLean frames compared, %d beyond %.1f LeanSigma; max |Lean - truth| "
          "%.2f deg, %.1f LeanSigma; %d with LeanSigma saturated (>= %.1f)"
          % (n, bad, k, worst, worst_sig, saturated, SIGMA_MAX))
    return 1 if bad or n + (saturated if saturated_ok else 0) == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
