#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Black-box check of sl-alpha against an independent oracle (Python standard library only).

Generates N seeded random input lines (valid cases over the whole supported domain, cases
near the ambiguity bound and near rho = 10, and invalid/unparsable lines), runs sl-alpha
with --sigma-r/--sigma-theta, and checks every output line:
  - valid: |alpha - oracle| <= 0.01 deg, printed with exactly 3 decimals; sigma within
    0.005 deg + 1e-4 relative (+ print rounding) of the linearised oracle (MATH.md s.3);
  - `ambiguous` / `invalid` classification equal to the oracle's, except within 1e-6
    relative of a bound (ambiguity bound, rho = 10, domain limits), where either is accepted;
  - the stderr summary counts; exit status 0; and exit status 1 when stdout is /dev/full.
The oracle is MATH.md s.2 written here from scratch (branch 2 via acos, not atan2).
Usage: check_alpha.py SL_ALPHA [--seed S] [--lines N]
"""
import argparse
import math
import random
import re
import subprocess
import sys

THETA = (1.0, 60.0)
BETA = (-10.0, 15.0)
WEDGE = (1.0, 75.0)
RHO_MAX = 10.0
SIGMA_R_M = 0.0126
SIGMA_THETA_DEG = 0.2
REL = 1e-6


def near(x, bound):
    return abs(x - bound) <= REL * max(abs(bound), 1.0)


def oracle(fields):
    """(expected, alternative-or-None, alpha, sigma) for one line's fields."""
    if fields is None:
        return "invalid", None, None, None
    r1, r2, th, be = fields
    alt = None
    w = th + be
    for v, (lo, hi) in ((th, THETA), (be, BETA), (w, WEDGE)):
        if near(v, lo) or near(v, hi):
            alt = "any"
        if v < lo or v > hi:
            return "invalid", alt, None, None
    if not (r1 > 0 and r1 < r2):
        return "invalid", alt, None, None
    rho = r2 / r1
    t, b = math.radians(th), math.radians(be)
    amb = 1.0 / math.cos((t + b) / 2.0)
    if near(rho, RHO_MAX) or near(rho, amb):
        alt = "any"
    if rho > RHO_MAX:
        return "invalid", alt, None, None
    if rho < amb:
        return "ambiguous", alt, None, None
    if rho >= 1.0 / math.cos(t + b):
        n = rho * math.cos(t) - math.cos(b)
        d = rho * math.sin(t) + math.sin(b)
        alpha = math.degrees(math.atan2(n, d))
        q = n * n + d * d
        da_drho = math.sin(t + b) / q
        da_dth = rho * (rho - math.cos(t + b)) / q
    else:
        alpha = math.degrees(math.acos(1.0 / rho) - t)
        da_drho = 1.0 / (rho * math.sqrt(rho * rho - 1.0))
        da_dth = 1.0
    s_rho = SIGMA_R_M / r1 * math.sqrt(1.0 + rho * rho)
    sigma = math.degrees(math.hypot(da_drho * s_rho, da_dth * math.radians(SIGMA_THETA_DEG)))
    return "value", alt, alpha, sigma


def make_cases(rng, n):
    cases = []  # (line, fields or None)
    garbage = ["", "   ", "1 2 3", "1 2 3 4 5", "a b c d", "2 2.5 26 x", "2,0 2.5 26 3",
               "1e999 2 26 3", "nan 2 26 3", "2 inf 26 3", "0x 2 3 4", "#comment"]
    for _ in range(n):
        u = rng.random()
        if u < 0.04:
            line = rng.choice(garbage)
            cases.append((line, None))
            continue
        th = rng.uniform(*THETA)
        be = rng.uniform(*BETA)
        if th + be < WEDGE[0]:
            be = rng.uniform(WEDGE[0] - th, BETA[1])
        r1 = math.exp(rng.uniform(math.log(0.3), math.log(60.0)))
        amb = 1.0 / math.cos(math.radians(th + be) / 2.0)
        v = rng.random()
        if v < 0.10:
            rho = amb * rng.uniform(0.99, 1.01)          # around the ambiguity bound
        elif v < 0.13:
            rho = rng.uniform(1.0, amb)                   # below it
        elif v < 0.16:
            rho = rng.uniform(9.9, 10.1)                  # around the maximum
        elif v < 0.90:
            rho = math.exp(rng.uniform(math.log(amb), math.log(RHO_MAX)))
        else:
            kind = rng.randrange(6)                       # invalid / out of domain
            if kind == 0:
                rho = rng.uniform(0.2, 1.0)               # r1 >= r2
            elif kind == 1:
                rho, r1 = 1.0, 0.0 if rng.random() < 0.5 else r1
            elif kind == 2:
                th = rng.choice([rng.uniform(0.0, 0.99), rng.uniform(60.01, 89.0)])
                rho = 2.0
            elif kind == 3:
                be = rng.choice([rng.uniform(-30.0, -10.01), rng.uniform(15.01, 30.0)])
                rho = 2.0
            elif kind == 4:
                rho = rng.uniform(10.01, 100.0)
            else:
                r1 = -r1
                rho = 1.5
        r2 = r1 * rho
        fields = (r1, r2, th, be)
        line = " ".join(repr(x) for x in fields)
        if rng.random() < 0.05:
            line = "  " + line.replace(" ", "\t") + " "   # blanks of any kind are fine
        cases.append((line, fields))
    return cases


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sl_alpha")
    ap.add_argument("--seed", type=int, default=20240611)
    ap.add_argument("--lines", type=int, default=5000)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    cases = make_cases(rng, a.lines)
    text = "".join(line + "\n" for line, _ in cases)
    cmd = [a.sl_alpha, "--sigma-r", repr(SIGMA_R_M), "--sigma-theta", repr(SIGMA_THETA_DEG)]
    p = subprocess.run(cmd, input=text, capture_output=True, text=True)
    fails = []
    if p.returncode != 0:
        fails.append("exit status %d (stderr: %s)" % (p.returncode, p.stderr.strip()))
    out = p.stdout.split("\n")
    if out and out[-1] == "":
        out.pop()
    if len(out) != len(cases):
        fails.append("%d output lines for %d input lines" % (len(out), len(cases)))
    num = re.compile(r"^-?\d+\.\d{3}$")
    sig = re.compile(r"^\d+\.\d{2}$")
    max_err = 0.0
    max_sig_err = 0.0
    counts = {"value": 0, "ambiguous": 0, "invalid": 0}
    unparsable = sum(1 for _, f in cases if f is None)
    for i, ((line, fields), got) in enumerate(zip(cases, out)):
        want, alt, alpha, sigma = oracle(fields)
        toks = got.split()
        kind = "value" if toks and num.match(toks[0]) else got
        counts[kind if kind in counts else "invalid"] += 1
        if kind != want and alt is None:
            fails.append("line %d %r: got %r, want %s" % (i + 1, line, got, want))
            continue
        if kind != want:
            continue  # at a bound: either answer
        if want == "value":
            if len(toks) != 2 or not sig.match(toks[1]):
                fails.append("line %d %r: malformed %r" % (i + 1, line, got))
                continue
            err = abs(float(toks[0]) - alpha)
            max_err = max(max_err, err)
            if err > 0.01:
                fails.append("line %d %r: alpha %s, oracle %.6f" % (i + 1, line, toks[0], alpha))
            serr = abs(float(toks[1]) - sigma)
            max_sig_err = max(max_sig_err, serr)
            if serr > 0.005 + 1e-4 * sigma + 1e-9:
                fails.append("line %d %r: sigma %s, oracle %.6f" % (i + 1, line, toks[1], sigma))
    summary = "sl-alpha: %d lines: %d valid, %d ambiguous, %d invalid (%d unparsable)" % (
        len(cases), counts["value"], counts["ambiguous"], counts["invalid"], unparsable)
    if summary not in p.stderr:
        fails.append("summary %r not in stderr %r" % (summary, p.stderr.strip()))
    # An output error must give exit status 1.
    with open("/dev/full", "w") as full:
        q = subprocess.run(cmd, input=text, stdout=full, stderr=subprocess.PIPE, text=True)
    if q.returncode != 1:
        fails.append("stdout=/dev/full: exit status %d, want 1" % q.returncode)
    print("%s; max |alpha error| %.5f deg, max |sigma error| %.5f deg" %
          (summary, max_err, max_sig_err))
    for f in fails[:20]:
        print("FAIL:", f)
    if len(fails) > 20:
        print("... %d failures in all" % len(fails))
    if counts["value"] < a.lines // 2 or counts["ambiguous"] < a.lines // 50:
        print("FAIL: too few valid/ambiguous cases generated")
        return 1
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
