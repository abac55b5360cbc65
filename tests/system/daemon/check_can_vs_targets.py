#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Every CAN frame shadowleand wrote decodes with the board's generated DBC
(python3-canmatrix) and carries exactly what the pipeline computed (--targets-out).

    check_can_vs_targets.py BOARD.dbc CAN.log TARGETS.jsonl [--link STATE] [--idle-ok] [--no-fault]
                            [--rotations N] [--min-poles N]

Independent of the C encoder: layout and scaling come only from the DBC, the CRC is
recomputed here, the expected frames are derived from the JSON records with the mapping
documented in sl_pipeline.h. Checks:
- every frame: id known to the DBC, DLC 8, Crc = the E2E Profile 11 CRC (SlE2EDataId,
  SlE2EMode; the Python package's decoder), Counter = previous + 1 mod 15 per message, canmatrix re-encodes the
  decoded raw values to the same bytes;
- frames come in rotation groups PoleLean* LeanWarning [GroundPlane GroundHazard*] Status
  Health, one per JSON
  rotation record, in order (Status + Health without a group are idle Status frames:
  allowed with --idle-ok, rejected otherwise); every Status is followed at once by its
  Health; with --no-fault every rotation group's Health has Fault 0 (a clean stream);
- the ground (the daemon's pipeline has it on): one GroundPlane in every rotation group or
  in none, right after LeanWarning; GroundHazard frames only right after it (or another
  GroundHazard), Kind DROP or STEP, in increasing Sector order; Quality NONE carries 0s;
- PoleLean: one per confirmed track (live, updated, hits >= confirm_hits, not last updated
  by a SLANT target, whose PoleTilt comes alone) in slot order:
  TargetId = id mod 16, Azimuth = az x 360 / azimuths + yaw (+-0.1 deg), Quality
  (FILTERED when valid_hits > 0, else from the incline flag), Lean / LeanSigma (+-half an
  LSB, or clamped with Clamped = 1; 0 unless FILTERED), RangeInner / RangeOuter = r1 / r2
  (+-half an LSB, 0.01 m: the encoder rounds the um values once, to 0.02 m);
- LeanWarning: the most severe confirmed track (level, then valid, then |alpha|), or
  HasTarget = 0; Level, TargetId, Azimuth, Lean, Range, LeanSigma, Quality as above;
- Status: Rotations = records so far, AzimuthsMissing = sum of `missing`, CanDropped 0
  (--dropped-ok: any value, never decreasing: frames an output lost and counted),
  LinkState in --link (comma list; default STREAMING = 3).
Prints a summary; exit 0 when everything matches.
"""
import argparse
import math
import json
import sys

sys.path.insert(0, __import__("os").path.join(__import__("os").path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402

# Ranges are rounded once on the way to CAN (sl_can.h takes um; the encoder rounds to the
# signal's step): within half an LSB, no extra slack.
QUALITY_OF_FLAG = {1: 1, 3: 2}  # incline AMBIGUOUS -> AMBIGUOUS, OUT_OF_DOMAIN -> OUT_OF_MODEL; else INVALID


def quality(track):
    if track["valid_hits"] > 0:
        return 4
    return QUALITY_OF_FLAG.get(track["last_flag"], 3)


def az_deg(hdr, az):
    return (az * 36000 // hdr["azimuths"] + hdr["radar_yaw_cdeg"]) / 100.0 % 360.0


def ang_diff(a, b):
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def check_ground(w, g, errors, seen):
    """The ground's frames of one rotation group (see the module's docstring)."""
    names = [d.name for d in g]
    planes = [i for i, n in enumerate(names) if n == "GroundPlane"]
    seen.add(len(planes))
    if len(seen) > 1 or len(planes) > 1:
        errors.append(f"{w}: {len(planes)} GroundPlane frames (one in every rotation or in none)")
    sectors = []
    for i, d in enumerate(g):
        if d.name == "GroundPlane":
            if i == 0 or names[i - 1] != "LeanWarning":
                errors.append(f"{w}: GroundPlane not right after LeanWarning")
            if d.raw["Quality"] == 0 and any(v != 0 for k, v in d.raw.items()
                                             if k not in ("Crc", "Counter", "Quality", "Clamped")):
                errors.append(f"{w}: GroundPlane NONE with values {d.raw}")
        elif d.name == "GroundHazard":
            if i == 0 or names[i - 1] not in ("GroundPlane", "GroundHazard"):
                errors.append(f"{w}: GroundHazard not after its rotation's GroundPlane")
            if d.raw["Kind"] not in (1, 2):
                errors.append(f"{w}: GroundHazard Kind {d.raw['Kind']}, want DROP or STEP")
            sectors.append(d.raw["Sector"])
    if sectors != sorted(set(sectors)):
        errors.append(f"{w}: GroundHazard sectors {sectors}, want increasing")


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dbc", metavar="BOARD.dbc")
    ap.add_argument("log", metavar="CAN.log")
    ap.add_argument("jsonl", metavar="TARGETS.jsonl")
    ap.add_argument("--link", default="3", help="accepted LinkState values, comma list (default 3)")
    ap.add_argument("--rotations", type=int, help="exact number of rotation groups")
    ap.add_argument("--min-poles", type=int, default=0, help="most PoleLean frames in a rotation >= N")
    ap.add_argument("--idle-ok", action="store_true", help="idle Status + Health pairs may appear")
    ap.add_argument("--no-fault", action="store_true", help="every Health frame has Fault = 0")
    ap.add_argument("--dropped-ok", action="store_true",
                    help="Status CanDropped may count lost frames (never decreasing)")
    a = ap.parse_args(argv[1:])
    opts = {"--link": a.link, "--rotations": a.rotations, "--min-poles": a.min_poles}
    flags = {f for f, on in (("--idle-ok", a.idle_ok), ("--no-fault", a.no_fault),
                             ("--dropped-ok", a.dropped_ok)) if on}
    dbc, log, jsonl = a.dbc, a.log, a.jsonl
    db = scd.load_dbc(dbc)
    frames = scd.read_candump(log)
    with open(jsonl) as fh:
        recs = [json.loads(line) for line in fh if line.strip()]
    hdr = recs[0]
    assert hdr["type"] == "header", "first JSON line must be the header"
    rots = [r for r in recs[1:] if r["type"] == "rotation"]
    errors = []
    counters = {}
    last_name = None
    groups = []
    cur = []
    idle = 0
    after_status = None  # "group" / "idle": the Status just seen, its Health must follow
    for n, (t, iface, cid, eff, data) in enumerate(frames, 1):
        d = scd.decode(db, cid, eff, data)
        where = f"frame {n} (id 0x{cid:X})"
        if d is None:
            errors.append(f"{where}: id unknown to the DBC")
            continue
        if data is None or len(data) != 8:
            errors.append(f"{where}: {d.name} without 8 data bytes")
            continue
        if not d.crc_ok:
            errors.append(f"{where}: {d.name} CRC mismatch")
        if not d.reencode_ok:
            errors.append(f"{where}: {d.name} does not re-encode to the same bytes")
        prev = counters.get(d.name)
        if prev is not None and d.raw["Counter"] != (prev + 1) % 15:
            errors.append(f"{where}: {d.name} Counter {d.raw['Counter']} after {prev}")
        counters[d.name] = d.raw["Counter"]
        if after_status is not None:
            # Health follows every Status at once (rotation group or idle Status)
            if d.name != "Health":
                errors.append(f"{where}: {d.name} after a Status, want Health")
            elif after_status == "group":
                # --no-fault: a clean stream, no Fault bit in any rotation's Health
                if "--no-fault" in flags and d.raw["Fault"] != 0:
                    errors.append(f"{where}: Health Fault {d.raw['Fault']:#x} in a rotation group")
                cur.append(d)
                groups.append(cur)
                cur = []
            after_status = None
            if d.name == "Health":
                continue
        if d.name == "Health":
            errors.append(f"{where}: Health without a Status before it")
            continue
        if d.name == "Status":
            if not cur:
                idle += 1
                if "--idle-ok" not in flags:
                    errors.append(f"{where}: Status frame outside a rotation group")
                after_status = "idle"
                continue
            cur.append(d)
            after_status = "group"
        else:
            cur.append(d)
    if after_status == "group":
        errors.append("no Health after the last Status")
        groups.append(cur)
        cur = []
    if cur:
        errors.append(f"{len(cur)} frames after the last Status frame")
    if len(groups) != len(rots):
        errors.append(f"{len(groups)} rotation groups on CAN, {len(rots)} rotation records")
    if opts["--rotations"] is not None and len(rots) != int(opts["--rotations"]):
        errors.append(f"{len(rots)} rotations, want {opts['--rotations']}")
    confirm = hdr["confirm_hits"]
    missing = 0
    n_poles = 0
    max_poles = 0
    last_tilt = {}
    last_dropped = 0
    ground_seen = set()  # whether rotation groups had a GroundPlane: one kind only
    for k, (g, r) in enumerate(zip(groups, rots)):
        w = f"rotation {r['rotation']}"
        missing += r["missing"]
        confirmed = [t for t in r["tracks"] if t["hits"] >= confirm and t.get("confirmed", 1)]
        # (not for a track updated by a pole leaning across the beam, SL_TARGET_SLANT: no
        # one azimuth holds its run; its PoleTilt comes alone)
        want_pl = [t for t in confirmed if t["updated"] and not t.get("last_slant", 0)]
        slant_ids = {t["id"] % 16 for t in confirmed if t["updated"] and t.get("last_slant", 0)}
        poles = [d for d in g if d.name == "PoleLean"]
        # PoleTilt (only with a motion input): each right after its track's PoleLean, or
        # alone for a track updated by a SLANT target.
        tilted_before = set(last_tilt)  # tracks with a fit sent earlier keep sending it
        tilts = {}
        for i, d in enumerate(g):
            if d.name == "PoleTilt":
                after_lean = i > 0 and g[i - 1].name == "PoleLean" and g[i - 1].raw["TargetId"] == d.raw["TargetId"]
                if not after_lean and d.raw["TargetId"] not in slant_ids:
                    errors.append(f"{w}: PoleTilt of target {d.raw['TargetId']} not right after its PoleLean")
                if after_lean and d.raw["TargetId"] in slant_ids:
                    errors.append(f"{w}: PoleLean of target {d.raw['TargetId']} updated by a SLANT target")
                tilts[d.raw["TargetId"]] = d
                last_tilt[d.raw["TargetId"]] = d
        for tid in sorted(slant_ids & tilted_before):
            if tid not in tilts:
                errors.append(f"{w}: no PoleTilt for target {tid}, updated by a SLANT target after a fit")
        g = [d for d in g if d.name != "PoleTilt"]
        check_ground(w, g, errors, ground_seen)
        g = [d for d in g if d.name not in ("GroundPlane", "GroundHazard")]
        rest = [d.name for d in g if d.name not in ("PoleLean", "PoleTilt")]
        if rest != ["LeanWarning", "Status", "Health"]:
            errors.append(f"{w}: frames {[d.name for d in g]}, want PoleLean* LeanWarning "
                          "[GroundPlane GroundHazard*] Status Health")
            continue
        if len(poles) != len(want_pl):
            errors.append(f"{w}: {len(poles)} PoleLean frames, {len(want_pl)} confirmed tracks seen")
        n_poles += len(poles)
        max_poles = max(max_poles, len(poles))
        for d, t in zip(poles, want_pl):
            q = quality(t)
            ww = f"{w} track {t['id']}"
            lean = t["alpha_cdeg"] / 100.0 if q == 4 else 0.0
            sigma = t["sigma_cdeg"] / 100.0 if q == 4 else 0.0
            clamp = lean > 51.1 or lean < -51.2 or sigma > 6.2
            checks = [
                ("TargetId", d.raw["TargetId"] == t["id"] % 16, t["id"] % 16),
                ("Quality", d.raw["Quality"] == q, q),
                ("Azimuth", ang_diff(d.phys["Azimuth"], az_deg(hdr, t["az"])) <= 0.1 + 1e-9, az_deg(hdr, t["az"])),
                ("Lean", abs(d.phys["Lean"] - max(-51.2, min(51.1, lean))) <= 0.05 + 1e-9, lean),
                ("LeanSigma", abs(d.phys["LeanSigma"] - min(6.2, sigma)) <= 0.1 + 1e-9, sigma),
                ("RangeInner", abs(d.phys["RangeInner"] - min(10.22, t["r1_um"] / 1e6)) <= 0.01 + 1e-9, t["r1_um"] / 1e6),
                ("RangeOuter", abs(d.phys["RangeOuter"] - min(10.22, t["r2_um"] / 1e6)) <= 0.01 + 1e-9, t["r2_um"] / 1e6),
                ("Clamped", d.raw["Clamped"] == int(clamp or t["r2_um"] > 10220000), int(clamp)),
            ]
            for name, ok, want in checks:
                if not ok:
                    errors.append(f"{ww}: PoleLean {name} = {d.phys.get(name)}, want {want}")
        # LeanWarning: the most severe confirmed track (live, any update time).
        worst = None
        for t in confirmed:
            if worst is None or t["level"] > worst["level"] or (
                    t["level"] == worst["level"] and t["valid_hits"] > 0 and
                    (worst["valid_hits"] == 0 or abs(t["alpha_cdeg"]) > abs(worst["alpha_cdeg"]))):
                worst = t
        lw = g[-3]
        # The latest fit of every confirmed track (a track not seen on this rotation keeps
        # its fit and sends no PoleTilt; straight paths only: the frame's vehicle-frame
        # values are then still current).
        live_ids = {t["id"] % 16 for t in confirmed}
        fitted = {tid: d for tid, d in last_tilt.items() if d.raw["Quality"] == 0 and tid in live_ids}
        if fitted:
            # A FITTED drive-by fit replaces the in-plane lean in LeanWarning (sl_pipeline.h):
            # the tilt towards the vehicle's path, recomputed here from the PoleTilt frame.
            if lw.raw["HasTarget"] != 1:
                errors.append(f"{w}: LeanWarning without a target while tracks are fitted")
            d = fitted.get(lw.raw["TargetId"])
            if d is not None:
                ty = math.tan(math.radians(d.phys["Tilt"])) * math.sin(math.radians(d.phys["TiltDirection"]))
                lean = math.degrees(math.atan(-ty if d.phys["BaseY"] >= 0 else ty))
                if abs(lw.phys["Lean"] - lean) > 0.6 or lw.raw["Quality"] != 4:
                    errors.append(f"{w}: LeanWarning Lean {lw.phys['Lean']} quality {lw.raw['Quality']}, "
                                  f"want the fitted tilt towards the path {lean:.2f} FILTERED")
        elif worst is None:
            if lw.raw["HasTarget"] != 0 or lw.raw["Level"] != 0:
                errors.append(f"{w}: LeanWarning HasTarget {lw.raw['HasTarget']} Level {lw.raw['Level']}, want 0 0")
        else:
            q = quality(worst)
            lean = worst["alpha_cdeg"] / 100.0 if q == 4 else 0.0
            sigma = worst["sigma_cdeg"] / 100.0 if q == 4 else 0.0
            checks = [
                ("HasTarget", lw.raw["HasTarget"] == 1, 1),
                ("Level", lw.raw["Level"] == worst["level"], worst["level"]),
                ("TargetId", lw.raw["TargetId"] == worst["id"] % 16, worst["id"] % 16),
                ("Quality", lw.raw["Quality"] == q, q),
                ("Azimuth", ang_diff(lw.phys["Azimuth"], az_deg(hdr, worst["az"])) <= 0.05 + 1e-9, az_deg(hdr, worst["az"])),
                ("Lean", abs(lw.phys["Lean"] - lean) <= 0.025 + 1e-9, lean),
                ("LeanSigma", abs(lw.phys["LeanSigma"] - min(6.3, sigma)) <= 0.05 + 1e-9, sigma),
                ("Range", abs(lw.phys["Range"] - worst["r1_um"] / 1e6) <= 0.005 + 1e-9, worst["r1_um"] / 1e6),
            ]
            for name, ok, want in checks:
                if not ok:
                    errors.append(f"{w}: LeanWarning {name} = {lw.phys.get(name)}, want {want}")
        st = g[-2]
        if st.raw["Rotations"] != k + 1:
            errors.append(f"{w}: Status Rotations {st.raw['Rotations']}, want {k + 1}")
        if st.raw["AzimuthsMissing"] != missing:
            errors.append(f"{w}: Status AzimuthsMissing {st.raw['AzimuthsMissing']}, want {missing}")
        if "--dropped-ok" in flags:
            if st.raw["CanDropped"] < last_dropped:
                errors.append(f"{w}: Status CanDropped {st.raw['CanDropped']} after {last_dropped}")
            last_dropped = st.raw["CanDropped"]
        elif st.raw["CanDropped"] != 0:
            errors.append(f"{w}: Status CanDropped {st.raw['CanDropped']}")
        if st.raw["LinkState"] not in [int(x) for x in opts["--link"].split(",")]:
            errors.append(f"{w}: Status LinkState {st.raw['LinkState']}, want {opts['--link']}")
    if max_poles < int(opts["--min-poles"]):
        errors.append(f"at most {max_poles} PoleLean frames per rotation, want >= {opts['--min-poles']}")
    for e in errors[:25]:
        print("FAIL:", e)
    print(f"check_can_vs_targets: {len(frames)} frames, {len(rots)} rotations, {n_poles} PoleLean "
          f"(up to {max_poles} per rotation), {idle} idle Status; "
          f"{'OK' if not errors else f'{len(errors)} errors'}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
