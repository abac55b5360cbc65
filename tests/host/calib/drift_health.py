#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Health.ThetaDrift and Fault bit THETA_DRIFT against a step of theta, from a candump log.

    drift_health.py BOARD.dbc CAN.log STEP_ROTATION MAX_ROTATIONS [--expect-deg D]

Decodes the log with the board's DBC (canmatrix). The Health frame sent with the Status
whose Rotations = k + 1 belongs to capture rotation k. Passes when THETA_DRIFT is never set
before STEP_ROTATION, is set at the latest MAX_ROTATIONS rotations after it (and stays set
to the end), and (with --expect-deg) the last ThetaDrift is within 0.5 deg of D.
With STEP_ROTATION = -1: a capture without a step; passes when THETA_DRIFT is never set.
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402


def main(argv):
    dbc, log, step, max_rot = argv[1], argv[2], int(argv[3]), int(argv[4])
    expect = float(argv[argv.index("--expect-deg") + 1]) if "--expect-deg" in argv else None
    rot = None
    rows = []
    for _, d in scd.decode_log(dbc, log):
        if d is None:
            continue
        if d.name == "Status":
            rot = d.raw["Rotations"] - 1
        elif d.name == "Health" and rot is not None and rot >= 0:
            rows.append((rot, (d.raw["Fault"] >> 9) & 1, d.phys["ThetaDrift"], d.crc_ok and d.reencode_ok))
    if not rows:
        print("drift_health: no Health frames")
        return 1
    if not all(r[3] for r in rows):
        print("drift_health: a Health frame fails E2E or re-encoding")
        return 1
    first = next((r for r, f, _, _ in rows if f), None)
    last = rows[-1]
    print("drift_health: %d Health frames; THETA_DRIFT first at rotation %s; last ThetaDrift %+.1f deg"
          % (len(rows), first, last[2]))
    if step < 0:
        return 0 if first is None else 1
    if first is None or first < step:
        print("drift_health: FAIL: THETA_DRIFT %s" % ("never raised" if first is None else
                                                      "raised before the step (false alarm)"))
        return 1
    if first - step > max_rot:
        print("drift_health: FAIL: raised %d rotations after the step (> %d)" % (first - step, max_rot))
        return 1
    if not all(f for r, f, _, _ in rows if r >= first):
        print("drift_health: FAIL: THETA_DRIFT dropped again")
        return 1
    if expect is not None and abs(last[2] - expect) > 0.5:
        print("drift_health: FAIL: ThetaDrift %+.1f deg, expected %+.1f" % (last[2], expect))
        return 1
    print("drift_health: raised %d rotations after the step (bound %d)" % (first - step, max_rot))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
