# SPDX-License-Identifier: MIT
"""The results tables of docs/RESULTS.md and README.md, from the sl-eval JSON outputs in
docs/results/ (used by sl_docs_gen.py results; the commands that write each file are in
RUNS below and in docs/RESULTS.md)."""

# file -> (the command that writes it, from a host build, the ctest that guards the behaviour)
RUNS = {
    "table1": ("sl-eval table1 --extract both --threads 1 --quiet --json-out docs/results/table1.json",
               "sim_table1_must_show, sim_table1_pipeline"),
    "realistic": ("sl-eval realistic --extract both --threads 1 --quiet --json-out docs/results/realistic.json",
                  "sim_realistic_pipeline, sim_extraction_smear_robust"),
    "realistic_power": ("sl-eval realistic --power-scale --extract pipeline --threads 1 --quiet "
                        "--json-out docs/results/realistic_power.json", "sim_extraction_smear_robust"),
    "realistic_hard_quick": ("sl-eval realistic --hard --extract both --quick --range-bins 160 --threads 1 --quiet "
                             "--json-out docs/results/realistic_hard_quick.json", "sim_hard_acceptance"),
    "realistic_hard": ("sl-eval realistic --hard --extract both --threads 1 --quiet "
                       "--json-out docs/results/realistic_hard.json", "sim_hard_acceptance"),
    "driveby_noise_free": ("sl-eval driveby --quiet --json-out docs/results/driveby_noise_free.json",
                           "sim_driveby_tilt_sweep"),
    "driveby_realistic_96": ("sl-eval driveby --realistic --speeds 1,3 --offset 3 --offset -3 --psi 5 --psi 10 "
                             "--psi 20 --json-out docs/results/driveby_realistic_96.json",
                             "sim_driveby_tilt_along_the_path, sim_driveby_tilt_realistic"),
    "driveby_realistic_96_power": ("sl-eval driveby --realistic --power-scale --speeds 1,3 --offset 3 --offset -3 "
                                   "--psi 5 --psi 10 --psi 20 --json-out docs/results/driveby_realistic_96_power.json",
                                   "sim_driveby_tilt_along_the_path"),
    "driveby_realistic": ("sl-eval driveby --realistic --json-out docs/results/driveby_realistic.json",
                          "sim_driveby_tilt_realistic"),
    "terrain": ("sl-eval terrain ../../../../scenes/ground_attitude.ini ../../../../scenes/ground_kerb.ini "
                "../../../../scenes/ground_dropoff.ini ../../../../scenes/ground_flat_drive.ini --threads 1 "
                "--json-out docs/results/terrain.json", "sim_ground_terrain"),
    "driveby_realistic_3ms": ("sl-eval driveby --realistic --speeds 3 --offset 3 --offset -3 --psi 5 --psi 10 --psi 20 "
                              "--json-out docs/results/driveby_realistic_3ms.json", "sim_driveby_tilt_realistic_3ms"),
}


def f(x, nd=2, sign=False):
    if x is None:
        return "-"
    return (f"{x:+.{nd}f}" if sign else f"{x:.{nd}f}")


def ms(e, nd=2):
    return f"{f(e.get('mean'), nd, True)} / {f(e.get('std'), nd)}"


def table(head, rows):
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def cmd(name):
    return f"`{RUNS[name][0]}`"


# ------------------------------------------------------------------------------ headline
def headline(res):
    rows = []
    t1 = res.get("table1")
    if t1:
        cap = next(c for c in t1["pipeline"]["captures"] if c["capture"] == "real_res" and not c["radius_from_width"])
        worst_m = max(abs(a["error"]["mean"]) for a in cap["angles"])
        worst_s = max(a["error"]["std"] for a in cap["angles"])
        det = min(a["detection_rate"] for a in cap["angles"])
        rows.append(["simulation: the paper's vehicle passing a 1 cm pole at 3 m (Table I, real resolution)",
                     "lean error, core pipeline, worst of -10/0/+10 deg: \\|mean\\| / std; detection",
                     f"{worst_m:.2f} / {worst_s:.2f} deg; {100 * det:.0f} %", "`sl-eval table1 --extract both`",
                     "`sim_table1_pipeline`"])
    re_ = res.get("realistic")
    if re_ and re_.get("pipeline"):
        pr = re_["pipeline"]["rows"]
        worst_m = max(abs(r["raw"]["mean"] - r["true_deg"]) for r in pr)
        worst_s = max(r["raw"]["std"] for r in pr)
        amb = max(r["summary"]["ambiguous_rate"] for r in pr if r.get("summary"))
        rows.append(["simulation: the paper's bench with smear, speckle, noise (Table II, poles at 2.2-2.6 m)",
                     "lean error, core pipeline, worst of -10..+10 deg: \\|mean\\| / std",
                     f"{worst_m:.2f} / {worst_s:.2f} deg (AMBIGUOUS up to {100 * amb:.0f} %)",
                     "`sl-eval realistic --extract both`", "`sim_realistic_pipeline`"])
    for name, label, test in (
            ("driveby_noise_free", "simulated drive-bys, noise-free (576 passes, 1-3 m/s)", "`sim_driveby_tilt_sweep`"),
            ("driveby_realistic_96", "simulated drive-bys, smear and speckle (1 and 3 m/s)",
             "`sim_driveby_tilt_along_the_path`"),
            ("driveby_realistic_3ms", "simulated drive-bys, smear and speckle, 3 m/s", "`sim_driveby_tilt_realistic_3ms`")):
        d = res.get(name)
        if not d:
            continue
        s, b = d["summary"], d["bounds"]
        rows.append([label, f"3D tilt, poles tilted >= 5 deg: FITTED within {b['psi_deg']:g} deg tilt / "
                     f"{b['phi_deg']:g} deg direction", f"{s['within_bounds']} of {s['checked']}",
                     "`sl-eval driveby" + (" --realistic`" if d["condition"] == "realistic" else "`"), test])
    te = {r["scene"]: r for r in res.get("terrain", {}).get("scenes", [])}
    if te:
        att = [te[n] for n in ("ground_attitude.ini", "ground_kerb.ini", "ground_flat_drive.ini") if n in te]
        pr = max(max(r["pitch_err_max_deg"], r["roll_err_max_deg"]) for r in att) if att else None
        d = te.get("ground_dropoff.ini", {})
        fl = te.get("ground_flat_drive.ini", {})
        k = te.get("ground_kerb.ini", {})
        rows.append(["simulation, CTS350-X physics: the ground from the shadow's edge (parked with attitude, "
                     "a 0.1 m kerb, a 0.2 m drop-off at 1 m/s, 10 min of flat driving with clutter and poles)",
                     "pitch/roll error, max; kerb found as STEP; the vehicle's front to the drop-off at the first "
                     "DROP; false hazards in 10 min",
                     f"{f(pr)} deg; {'yes' if k.get('terrain_pieces_found') else 'no'}; "
                     f"{f(d.get('drop_true_m'))} m; {fl.get('false_hazard_onsets', '-')}",
                     "`sl-eval terrain`", "`sim_ground_terrain`"])
    return table(["condition", "metric", "result", "command", "test"], rows)


# --------------------------------------------------------------------------- per condition
def table1_tables(t1):
    ang = t1["angles_deg"]
    head = ["condition"] + [f"{a:+d} deg" for a in ang]
    out = ["Bounding box on the pole's true azimuth (`--extract bbox`); mean / std of the error, deg "
           f"({t1['rotations_per_pass']} rotations per pass). \"Paper\": the seed paper's Table I.", ""]
    rows = []
    for r in t1["rows"]:
        rows.append([f"{r['condition']}: paper"] + [ms(x, 3) for x in r["paper"]])
        rows.append([f"{r['condition']}: paper's processing ({r['paper_processing']})"] + [ms(x, 3) for x in r["ours"]])
        rows.append([f"{r['condition']}: ours ({r['improved_b_processing']})"] + [ms(x, 3) for x in r["improved_b"]])
    out.append(table(head, rows))
    out += ["", "The core pipeline on the same captures (`--extract pipeline`: mask, detection, corrections, "
            "estimate; the vehicle's speed passed in); mean / std of the error, deg, and the detection rate:", ""]
    rows = []
    for c in t1["pipeline"]["captures"]:
        if c["radius_from_width"]:
            continue
        rows.append([c["capture"]] + [f"{ms(a['error'])}, {100 * a['detection_rate']:.0f} %" for a in c["angles"]])
    out.append(table(head, rows))
    me = t1.get("model_error_deg")
    if me:
        out += ["", "The closed form's own error on exact bounds for a pole seen obliquely (deg, "
                f"{'/'.join(str(a) for a in ang)}): " + "; ".join(" / ".join(f"{x:+.3f}" for x in row) for row in me[:1])
                + " (the floor of the ideal row)."]
    return "\n".join(out)


def realistic_tables(re_):
    rows_ = re_["rows"]
    head = ["path"] + [f"{r['true_deg']:+g} deg" for r in (rows_ or re_["pipeline"]["rows"])]
    cond = ("The harder bench (two-component smear with a front skirt, per-frame speckle, azimuth jitter, "
            "segmented poles, installation tolerances)" if re_.get("condition") == "hard" else
            "Smear, speckle, noise floor and leakage")
    scale = " on the sensor's value scale" if "power" in re_.get("extraction", "") else ""
    out = [f"{cond}{scale}; {re_['positions']} positions x {re_['reps']} repetitions "
           f"x {re_['frames']} frames per angle; poles at 2.2-2.6 m. Estimated lean, mean / std, deg:", ""]
    rows = []
    if rows_:
        rows.append(["paper (the real sensor)"] + [ms(r["paper"]) for r in rows_])
        rows.append(["the paper's processing (error)"] + [ms(r["paper_processing"]) for r in rows_])
        rows.append(["research path, host float (error)"] + [ms(r["improved"]) for r in rows_])
    p = re_.get("pipeline")
    if p:
        rows.append(["core pipeline: estimate"] + [ms(r["raw"]) for r in p["rows"]])
        rows.append(["core pipeline: error"] + [
            f"{f(r['raw']['mean'] - r['true_deg'], 2, True)} / {f(r['raw']['std'])}" for r in p["rows"]])
        rows.append(["core pipeline: median / p90 \\|error\\|"] + [
            f"{f(r['summary']['median_abs'])} / {f(r['summary']['p90_abs'])}" for r in p["rows"]])
        rows.append(["core pipeline: missed / AMBIGUOUS"] + [
            f"{100 * r['summary']['missed_rate']:.0f} / {100 * r['summary']['ambiguous_rate']:.0f} %" for r in p["rows"]])
    out.append(table(head, rows))
    if p:
        learned = (f"{p['r2_offset_um'] / 1000:+.1f} mm from {p['resid_samples']} residuals"
                   if p["r2_offset_um"] != 0 else
                   f"none ({p['resid_samples']} residuals, too few to calibrate)")
        out += ["", f"Core pipeline: board {p['board']}, n = {p['mask_frames']}; the walk-end offset of r2 learned on "
                f"the upright calibration poles: {learned}."
                + (" The paper's rows are its estimates on the real sensor, ours on the simulator." if rows_ else "")]
    return "\n".join(out)


def driveby_tables(d, title):
    s, b = d["summary"], d["bounds"]
    out = [f"{title}: board {d['board']}, {d['condition']}, value scale {d['value_scale']}, "
           f"{s['passes']} passes; bounds for psi >= 5 deg: {b['psi_deg']:g} deg tilt, {b['phi_deg']:g} deg direction.", ""]
    by = {}
    for p in d["passes"]:
        k = (p["speed_mps"], p["psi_deg"])
        by.setdefault(k, []).append(p)
    rows = []
    for (v, psi), ps in sorted(by.items()):
        fit = [p for p in ps if p["quality"] == "FITTED"]
        errs = sorted(abs(p["psi_err_deg"]) for p in fit)
        med = errs[len(errs) // 2] if errs else None
        q = {}
        for p in ps:
            q[p["quality"]] = q.get(p["quality"], 0) + 1
        rows.append([f"{v:g}", f"{psi:g}", len(ps), len(fit), q.get("AMBIGUOUS", 0),
                     sum(n for k, n in q.items() if k not in ("FITTED", "AMBIGUOUS")),
                     sum(1 for p in ps if p["within_bounds"]) if psi >= 5 else "-",
                     f(med), f(max(errs) if errs else None)])
    out.append(table(["speed m/s", "psi deg", "passes", "FITTED", "AMBIGUOUS", "other", "within bounds",
                      "median \\|psi err\\| FITTED", "max \\|psi err\\| FITTED"], rows))
    out += ["", f"psi >= 5 deg: **{s['within_bounds']} of {s['checked']}** within the bounds; largest error of a "
            f"checked FITTED pass {f(s['max_abs_err_psi_deg'])} deg tilt, {f(s['max_abs_err_phi_deg'], 1)} deg "
            f"direction; base offset within {f(s['max_abs_err_offset_m'])} m. Of the {s['ambiguous_checked']} "
            f"AMBIGUOUS passes, {s['ambiguous_inseparable']} hold observations whose mirror no 3-sigma rule can tell "
            "from the truth even if exact."]
    if "answered" in s:  # the AMBIGUOUS passes' two readings (PoleTilt AMBIGUOUS + MIRROR)
        out += ["", f"Answered (FITTED within the bounds, or AMBIGUOUS with the truth one of its two readings "
                f"within them): **{s['answered']} of {s['checked']}**; of the AMBIGUOUS passes the truth is the "
                f"best reading in {s['ambiguous_truth_best']}, the other in {s['ambiguous_truth_other']}; "
                f"{s['fitted_outside']} FITTED outside the bounds. Passes whose observations separate the mirror "
                f"(separation at the truth >= 9): **{s['separated_answered']} of {s['separated']}** answered; "
                f"{s['separated_fitted']} of them ended FITTED, {s['separated_ambiguous']} AMBIGUOUS."]
    return "\n".join(out)


def reproduce(res):
    rows = [[f"`docs/results/{n}.json`", f"`{RUNS[n][0]}`", RUNS[n][1]] for n in RUNS if n in res]
    missing = [n for n in RUNS if n not in res]
    out = table(["file", "command (from `build/host/host_tools/eval/`)", "ctests"], rows)
    if missing:
        out += "\n\nNot in the repository (run the command to produce it): " + ", ".join(
            f"`{RUNS[n][0]}`" for n in missing) + "."
    return out


def render(res):
    """[(page, part, body)] for sl_docs_gen.py. A part whose JSON is not in docs/results/
    names the command that writes it."""
    h = headline(res)
    parts = [("README.md", "results-headline", h), ("docs/RESULTS.md", "results-headline", h)]
    sections = [("table1", "results-table1", table1_tables),
                ("realistic", "results-realistic", realistic_tables),
                ("realistic_power", "results-realistic-power", realistic_tables),
                ("realistic_hard_quick", "results-hard", realistic_tables),
                ("realistic_hard", "results-hard-full", realistic_tables)]
    for name, title in (("driveby_noise_free", "Noise-free sweep"),
                        ("driveby_realistic_96", "Smear and speckle, 1 and 3 m/s"),
                        ("driveby_realistic_96_power", "The same on the sensor's value scale (0.5 dB per value)"),
                        ("driveby_realistic_3ms", "Smear and speckle, 3 m/s, poles 3 m either side"),
                        ("driveby_realistic", "Smear and speckle, the whole sweep")):
        sections.append((name, "results-" + name.replace("_", "-"),
                         lambda d, t=title: driveby_tables(d, t)))
    for name, part, fn in sections:
        if name in res:
            body = fn(res[name])
        else:
            body = (f"Not in docs/results/ yet: {cmd(name)} writes it (then "
                    "`python3 scripts/sl_docs_gen.py results`).")
        parts.append(("docs/RESULTS.md", part, body))
    parts.append(("docs/RESULTS.md", "results-reproduce", reproduce(res)))
    return parts
