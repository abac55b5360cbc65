#!/bin/sh
# SPDX-License-Identifier: MIT
# uml_motion_test.sh UML_RUN SHADOWLEAND SL_SIM PYTHON SRC_DIR OUT_DIR
# VehicleMotion frames built with AUTOSAR E2E Profile 11 by the test (p11_frames.py) with
# bad CRCs, repeated counters, small and large counter jumps and a reception gap over a real
# vcan0 inside user-mode Linux (uml_motion_guest.sh). On the host: nothing crashed (exit 0);
# every rotation that used motion used the good frames' speed (0.05 m/s -> n_eff 4), never
# the rejected frames' 1.0 m/s (n_eff 1); the daemon's Profile 11 statistics count every
# status the frames were built for: OK, OK_SOME_LOST (step 2 at the board's max delta
# counter 2), ERROR (CRC), REPEATED, WRONG_SEQUENCE (step 4), INITIAL and NO_NEW_DATA (the
# gap; the first frame after it only synchronises, whatever the guest's speed); after the
# sender stopped the window fell back to static (the last rotation: no motion, n_eff 16).
# Exit 77 (ctest skip) when linux.uml is not installed.
set -u
uml_run=$1; daemon=$2; sim=$3; py=$4; src=$(cd "$5" && pwd); out=$6
rm -rf "$out"; mkdir -p "$out"; out=$(cd "$out" && pwd)
dbc="$src/../../../boards/paper-sim/shadowlean.dbc"
# 200 rotations (50 s of radar time): the guest stops the daemon itself (SIGINT) once the
# fallback has been seen, so a slow guest on a loaded host never runs out of capture.
"$sim" "$src/scenes/static_four_poles.ini" -o "$out/scene.colossus" --rotations 200 --quiet || exit 1
"$py" "$src/motion_fault_frames.py" "$dbc" > "$out/frames.txt" || exit 1
SL_UML_TIMEOUT=${SL_UML_TIMEOUT:-150} sh "$uml_run" "$out/vm" sh "$src/uml_motion_guest.sh" "$daemon" \
    "$out/scene.colossus" "$out/frames.txt" "$out"
rc=$?
[ $rc -eq 0 ] || exit $rc
[ "$(cat "$out/motion.rc")" = 0 ] || { echo "FAIL: shadowleand exit $(cat "$out/motion.rc")"; exit 1; }
"$py" - "$out" <<'PY' || exit 1
import json, os, re, sys
out = sys.argv[1]
rots = [json.loads(l) for l in open(os.path.join(out, "motion.jsonl")) if '"type":"rotation"' in l]
err = open(os.path.join(out, "motion.err")).read()
errors = []
used = [r for r in rots if r.get("motion_valid")]
if len(used) < 4:
    errors.append(f"only {len(used)} rotations used the motion input")
bad = [(r["rotation"], r["speed_mm_s"], r["frames_eff"]) for r in used if r["speed_mm_s"] != 50 or r["frames_eff"] != 4]
if bad:
    errors.append(f"rotations used a rejected frame's motion: {bad[:5]}")
last = rots[-1] if rots else {}
if last.get("motion_valid") or last.get("frames_eff") != 16:
    errors.append(f"no fallback to static after the timeout: last rotation {last}")
m = re.findall(r"exit: VehicleMotion E2E \(Profile 11, max delta counter (\d+)\): OK (\d+), OK_SOME_LOST (\d+) "
               r"\(\d+ frames lost\), INITIAL (\d+) .*?, REPEATED (\d+), WRONG_SEQUENCE (\d+), ERROR (\d+) "
               r"\(CRC (\d+), .*\), NO_NEW_DATA (\d+)", err)
if not m:
    errors.append("no VehicleMotion E2E statistics at exit")
else:
    mdc, ok, lost, init, rep, wseq, error, crc, nnd = map(int, m[-1])
    print(f"VehicleMotion over vcan0 (max delta counter {mdc}): OK {ok}, OK_SOME_LOST {lost}, INITIAL {init}, "
          f"REPEATED {rep}, WRONG_SEQUENCE {wseq}, ERROR {error} (CRC {crc}), NO_NEW_DATA {nnd}; "
          f"{len(used)} of {len(rots)} rotations used motion (50 mm/s, n_eff 4), last rotation n_eff {last.get('frames_eff')}")
    if mdc != 2:
        errors.append(f"max delta counter {mdc}, the board file says 2")
    for name, n in (("OK", ok), ("OK_SOME_LOST", lost), ("REPEATED", rep), ("WRONG_SEQUENCE", wseq),
                    ("ERROR (CRC)", crc), ("NO_NEW_DATA", nnd)):
        if n < 1:
            errors.append(f"no frame classified {name}")
    if init < 2:
        errors.append(f"INITIAL {init}: the first frame and the first after the gap must only synchronise")
for e in errors:
    print("FAIL:", e)
sys.exit(1 if errors else 0)
PY
echo "uml_motion: OK"
