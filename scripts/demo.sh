#!/bin/sh
# demo.sh: the main job, from a fresh Debian machine (installs what is missing).
#
# Today's demo (foundation): the table generator turns each board file into the C tables
# the firmware links and a plot of its chassis shadow; then a pole passing the paper-sim
# vehicle at -10 / 0 / +10 deg (and a few hard cases) goes through the fixed-point
# estimator of the core (sl-alpha), next to the truth. Outputs land in out/demo/.
set -eu
cd "$(dirname "$0")/.."
sh scripts/deps.sh build demo
cmake --preset host-release >/dev/null
cmake --build --preset host-release -j 2 --target sl-tables sl-alpha
BIN=build/host-release/host_tools
OUT=out/demo
mkdir -p "$OUT"

echo
echo "== 1. Board tables (boards/<name>/board.ini -> C tables + shadow plot)"
for b in paper-sim paper-bench robotcar-leaf; do
    "$BIN/tables/sl-tables" "$b" --out "$OUT/$b"
done

echo
echo "== 2. Inclination from the run [r1, r2] of a pole 2.5 m away (core fixed point)"
# The forward model of MATH.md s.2 makes (r1, r2) from a true lean; sl-alpha inverts it.
python3 - "$BIN/alpha/sl-alpha" <<'PY'
import math, subprocess, sys
def rho_of(alpha, theta, beta):
    a, t, b = (math.radians(v) for v in (alpha, theta, beta))
    if a >= b:
        return math.cos(a - b) / math.cos(a + t)
    if a >= (b - t) / 2:
        return 1 / math.cos(a + t)
    return 1 / math.cos(b - a)
cases = [(-10, 26, 0), (0, 26, 0), (10, 26, 0), (10, 26, 3), (-5, 26, 3), (20, 20, 3)]
lines, truth = [], []
for a, t, b in cases:
    r1 = 2.5
    lines.append(f"{r1:.6f} {r1 * rho_of(a, t, b):.6f} {t} {b}")
    truth.append(f"{a:+.3f}")
# hard cases: a run too short for the model (ambiguous), an inverted run (invalid)
lines += ["2.5 2.55 26 0", "2.5 2.4 26 0"]
truth += ["(fold)", "(bad run)"]
out = subprocess.run([sys.argv[1]], input="\n".join(lines) + "\n", capture_output=True,
                     text=True, check=True).stdout.split("\n")
print(f"{'r1 [m]':>8} {'r2 [m]':>9} {'theta':>6} {'beta':>5} {'truth [deg]':>12} {'sl-alpha':>10}")
for line, t, o in zip(lines, truth, out):
    r1, r2, th, be = line.split()
    print(f"{float(r1):8.3f} {float(r2):9.4f} {th:>6} {be:>5} {t:>12} {o:>10}")
PY
echo
echo "demo: tables and plots in $OUT/<board>/ (tables.png)"
