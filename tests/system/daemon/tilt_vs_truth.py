#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Decoded PoleTilt frames against the simulator's truth.

    tilt_vs_truth.py BOARD.dbc CAN.log TRUTH.gt.csv [--psi-tol DEG] [--phi-tol DEG]
                     [--base-tol M] [--min-psi DEG]

Every PoleTilt frame must decode with the board's DBC (scripts/sl_can_decode.py, canmatrix)
with a good E2E CRC. Rotation k of the capture is the CAN group whose Status says Rotations =
k + 1. A frame is matched to the pole whose truth base (in the vehicle frame at the frame's
rotation: the axis point at radar height (-along_m, offset_m) minus H tan(psi) (cos phi,
sin phi), with the radar at the vehicle origin as on paper-sim) is nearest to (BaseX, BaseY),
within --base-tol (default 0.5 m). For every pole of the truth file the LAST matched frame
with Quality FITTED is compared: |Tilt - psi_deg| <= --psi-tol (default 1.0) and, for poles
with psi_deg >= --min-psi (default 5), the circular |TiltDirection - phi_deg| <= --phi-tol
(default 10). With --ambiguous-ok a pole without a FITTED frame may instead have AMBIGUOUS
ones (the fit's honest answer when few observations do not separate the mirror hypotheses):
the last one and the MIRROR frame of the same TargetId that follows it in the rotation are
its two readings, and the truth must be one of them (Tilt and TiltDirection as above).
Always: every AMBIGUOUS frame is followed directly by a MIRROR frame of its TargetId and
every MIRROR frame follows one (docs/CAN_REFERENCE.md, "Two readings of the 3D tilt"); a
LeanWarning about such a target carries the lean over the path (atan(-sign(BaseY) tan(Tilt)
sin(TiltDirection)), within 0.5 deg) of one of the readings whose path-lean sigma (from
TiltSigma and DirectionSigma, as the module computes it) is within the tracker's 3 deg
limit, the larger when they all lean over the path; with none such, anything (the track's
own values). Readings whose sigma is within 0.3 deg of the limit (the frames' rounding)
leave the rotation unchecked.
Exit 0 when every pole passes.

With --max-sigmas K the check is the frames' honesty instead: EVERY FITTED frame matched to
a pole must hold the truth within K of its own sigmas, |Tilt - psi_deg| <= K TiltSigma and,
unless the direction is reported as not determined (DirectionSigma 63), the direction within
K DirectionSigma; a pole without a FITTED frame passes, as a log without PoleTilt frames
does (no answer is not a wrong one).
"""
import csv
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402

TQ = {0: "FITTED", 1: "AMBIGUOUS", 2: "INSUFFICIENT_MOTION", 3: "TOO_FEW", 4: "INCONSISTENT",
      5: "MIRROR"}


def main(argv):
    opts = {"--psi-tol": 1.0, "--phi-tol": 10.0, "--base-tol": 0.5, "--min-psi": 5.0,
            "--height": 2.58, "--max-sigmas": 0.0}
    pos, i, args = [], 0, argv[1:]
    amb_ok = "--ambiguous-ok" in args
    args = [a for a in args if a != "--ambiguous-ok"]
    while i < len(args):
        if args[i] in opts:
            opts[args[i]] = float(args[i + 1])
            i += 2
        else:
            pos.append(args[i])
            i += 1
    if len(pos) != 3:
        print(__doc__)
        return 2
    H = opts["--height"]
    decoded = scd.decode_log(pos[0], pos[1])
    # Rotation groups with their PoleTilt frames.
    groups, tilts = [], []
    n_tilt = n_warn_checked = 0
    prev = None  # the PoleTilt frame before this one
    pairs, warning = {}, None  # this rotation's AMBIGUOUS + MIRROR pairs by TargetId; LeanWarning

    def path_lean(f):
        ty = math.tan(math.radians(f.phys["Tilt"])) * math.sin(math.radians(f.phys["TiltDirection"]))
        return math.degrees(math.atan(-ty if f.phys["BaseY"] >= 0 else ty))

    def path_lean_sigma(f):  # sl_tiltobs.c, lean_sigma_cdeg
        t = math.tan(math.radians(f.phys["Tilt"]))
        phi = math.radians(f.phys["TiltDirection"])
        tn, tp = abs(t * math.sin(phi)), abs(t * math.cos(phi))
        along = math.radians(f.phys["TiltSigma"]) * (1 + t * t)
        a1, a2 = along, 0.0
        if f.raw["DirectionSigma"] < 63 and t > 0:
            a1, a2 = along * tn / t, math.radians(f.phys["DirectionSigma"]) * tp
        return math.degrees(math.hypot(a1, a2) / (1 + tn * tn))
    for _, d in decoded:
        if d is None:
            continue
        if d.name == "PoleTilt":
            n_tilt += 1
            if not d.crc_ok or not d.reencode_ok:
                print("FAIL: a PoleTilt frame does not pass the DBC's E2E CRC / re-encoding")
                return 1
            amb_before = prev is not None and prev.raw["Quality"] == 1
            if (d.raw["Quality"] == 5) != (amb_before and prev.raw["TargetId"] == d.raw["TargetId"]) \
                    or (amb_before and d.raw["Quality"] != 5):
                print(f"FAIL: PoleTilt frame {n_tilt}: AMBIGUOUS and MIRROR frames not paired")
                return 1
            if d.raw["Quality"] == 5:
                pairs[d.raw["TargetId"]] = (prev, d)
            prev = d
            tilts.append(d)
        elif d.name == "LeanWarning":
            warning = d
        elif d.name == "Status":
            groups.append((d.raw["Rotations"] - 1, tilts))
            tilts = []
            two = pairs.get(warning.raw["TargetId"]) if warning is not None else None
            sig = [path_lean_sigma(f) for f in two] if two else []
            if two and warning.raw["HasTarget"] == 1 and warning.raw["Quality"] == 4 and \
                    all(f.raw["Clamped"] == 0 for f in two) and all(abs(s - 3.0) > 0.3 for s in sig):
                leans = sorted(path_lean(f) for f, s in zip(two, sig) if s < 3.0)
                lean = warning.phys["Lean"]
                n_warn_checked += 1 if leans else 0
                if leans and (min(abs(lean - x) for x in leans) > 0.5 or
                              (leans[0] > 0 and abs(lean - leans[-1]) > 0.5)):
                    print(f"FAIL: LeanWarning Lean {lean:.2f} of an AMBIGUOUS target, its usable readings' "
                          f"path leans {', '.join(f'{x:.2f}' for x in leans)}")
                    return 1
            pairs, warning = {}, None
    if prev is not None and prev.raw["Quality"] == 1:
        print("FAIL: the last PoleTilt frame is AMBIGUOUS without its MIRROR frame")
        return 1
    if n_tilt == 0 and opts["--max-sigmas"] <= 0.0:
        print("FAIL: no PoleTilt frame in the log")
        return 1
    with open(pos[2]) as fh:
        rows = [r for r in csv.DictReader(fh) if r["nominal"] == "1"]
    truth = {}  # pole -> {rotation: row}
    for r in rows:
        truth.setdefault(r["pole_name"], {})[int(r["rotation"])] = r

    def base_of(r):
        psi, phi = math.radians(float(r["psi_deg"])), math.radians(float(r["phi_deg"]))
        return (-float(r["along_m"]) - H * math.tan(psi) * math.cos(phi),
                float(r["offset_m"]) - H * math.tan(psi) * math.sin(phi))

    # The truth of each pole at any rotation: the nearest rotation it has a row for.
    def row_at(name, rot):
        rs = truth[name]
        k = min(rs, key=lambda q: abs(q - rot))
        return rs[k], abs(k - rot)

    last, last_amb, fitted = {}, {}, {}
    for rot, frames in groups:
        amb_of = {}  # TargetId -> the pole its AMBIGUOUS frame of this rotation matched
        for d in frames:
            if d.raw["Quality"] == 5:  # MIRROR: the other reading of the AMBIGUOUS frame before it
                name = amb_of.get(d.raw["TargetId"])
                if name is not None:
                    last_amb[name] = last_amb[name][:4] + (d,)
                continue
            best = None
            for name in truth:
                r, gap = row_at(name, rot)
                if gap > 0:
                    continue  # the pole is not in the shadow on this rotation
                bx, by = base_of(r)
                e = math.hypot(d.phys["BaseX"] - bx, d.phys["BaseY"] - by)
                if best is None or e < best[0]:
                    best = (e, name, r)
            if best is None or best[0] > opts["--base-tol"]:
                continue
            if d.raw["Quality"] == 0:
                last[best[1]] = (rot, best[2], d, best[0])
                fitted.setdefault(best[1], []).append((rot, best[2], d))
            elif d.raw["Quality"] == 1:
                last_amb[best[1]] = (rot, best[2], d, best[0], None)
                amb_of[d.raw["TargetId"]] = best[1]
    if opts["--max-sigmas"] > 0.0:
        return sigma_check(truth, fitted, opts["--max-sigmas"], n_tilt)
    bad = 0
    print(f"PoleTilt frames: {n_tilt}; LeanWarning frames about an AMBIGUOUS target checked: {n_warn_checked}")
    print(f"{'pole':<10} {'rot':>4} {'psi':>6} {'Tilt':>6} {'err':>6} {'phi':>7} {'Dir':>5} {'err':>6} "
          f"{'base err':>8} quality")
    for name in sorted(truth):
        amb = name not in last and amb_ok and name in last_amb
        if name not in last and not amb:
            print(f"{name:<10} no FITTED PoleTilt frame near the pole  FAIL")
            bad += 1
            continue
        rot, r, d, eb = (last_amb[name] if amb else last[name])[:4]
        psi, phi = float(r["psi_deg"]), float(r["phi_deg"])

        def errors(f):
            e_psi = f.phys["Tilt"] - psi
            e_phi = (f.phys["TiltDirection"] - phi + 180.0) % 360.0 - 180.0
            return e_psi, e_phi, abs(e_psi) <= opts["--psi-tol"] + 1e-9 and (
                psi < opts["--min-psi"] or abs(e_phi) <= opts["--phi-tol"] + 1e-9)
        e_psi, e_phi, ok = errors(d)
        other = last_amb[name][4] if amb else None
        if amb and not ok and other is not None and errors(other)[2]:
            d = other  # the truth is the other reading
            e_psi, e_phi, ok = errors(d)
        bad += 0 if ok else 1
        print(f"{name:<10} {rot + 1:>4} {psi:>6.2f} {d.phys['Tilt']:>6.1f} {e_psi:>+6.2f} {phi:>7.1f} "
              f"{d.phys['TiltDirection']:>5.0f} {e_phi:>+6.1f} {eb:>7.2f}m {TQ[d.raw['Quality']]}"
              f"{'' if ok else '  FAIL'}")
    print(f"tilt_vs_truth: {len(truth)} poles, {bad} failures (psi {opts['--psi-tol']} deg, "
          f"direction {opts['--phi-tol']} deg)")
    return 1 if bad else 0


def sigma_check(truth, fitted, k, n_tilt):
    """Every FITTED frame within k of its own sigmas (see the module's doc)."""
    bad, n, worst = 0, 0, 0.0
    for name in sorted(truth):
        for rot, r, d in fitted.get(name, []):
            n += 1
            psi, phi = float(r["psi_deg"]), float(r["phi_deg"])
            e_psi = abs(d.phys["Tilt"] - psi) / max(d.phys["TiltSigma"], 0.1)
            e_phi = 0.0
            if d.raw["DirectionSigma"] < 63:
                dphi = (d.phys["TiltDirection"] - phi + 180.0) % 360.0 - 180.0
                e_phi = abs(dphi) / max(d.phys["DirectionSigma"], 1.0)
            worst = max(worst, e_psi, e_phi)
            if e_psi > k or e_phi > k:
                bad += 1
                print(f"{name} rotation {rot + 1}: Tilt {d.phys['Tilt']:.1f} +- {d.phys['TiltSigma']:.1f}, "
                      f"direction {d.phys['TiltDirection']:.0f} +- {d.phys['DirectionSigma']:.0f}; truth "
                      f"{psi:.2f}, {phi:.1f}  FAIL")
        if name not in fitted:
            print(f"{name}: no FITTED frame")
    print(f"tilt_vs_truth: {n_tilt} PoleTilt frames, {n} FITTED near the {len(truth)} poles, worst "
          f"{worst:.1f} sigma, {bad} beyond {k:g}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
