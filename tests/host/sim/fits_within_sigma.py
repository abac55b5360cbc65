#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""fits_within_sigma.py OBS_LOG [--max-sigmas K]

Reads `sl-eval driveby --obs-log` (one JSON line per fit along the passes: the pass's truth
psi / phi, the fit's quality q (0 = FITTED), psi_fit +- psi_sig, phi_fit +- phi_sig) and
checks that every FITTED fit holds the truth within K (default 3) of its stated sigmas:
|psi_fit - psi| <= K psi_sig, and the direction within K phi_sig unless the fit reports it
as not determined (phi_sig >= 180). Prints the count and the worst ratio; exit 1 when a fit
is outside, or when there is no FITTED fit at all (nothing was checked)."""
import json
import sys


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    k = 3.0
    if len(argv) >= 4 and argv[2] == "--max-sigmas":
        k = float(argv[3])
    n = 0
    worst = 0.0
    bad = []
    with open(argv[1], encoding="utf-8") as f:
        for line in f:
            d = json.loads(line)
            if d["q"] != 0:
                continue
            n += 1
            e_psi = abs(d["psi_fit"] - d["psi"]) / max(d["psi_sig"], 0.01)
            e_phi = 0.0
            if d["phi_sig"] < 180.0:
                dphi = (d["phi_fit"] - d["phi"] + 180.0) % 360.0 - 180.0
                e_phi = abs(dphi) / max(d["phi_sig"], 0.01)
            m = max(e_psi, e_phi)
            worst = max(worst, m)
            if m > k:
                bad.append(d)
    for d in bad:
        print("outside %.1f sigma: v %.1f psi %.1f phi %.1f offset %+.1f: psi %.2f +- %.2f, "
              "direction %.1f +- %.1f" % (k, d["v"], d["psi"], d["phi"], d["off"], d["psi_fit"],
                                          d["psi_sig"], d["phi_fit"], d["phi_sig"]))
    print("fits_within_sigma: %d FITTED fits, worst %.2f sigma, %d beyond %.1f" %
          (n, worst, len(bad), k))
    return 1 if bad or n == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
