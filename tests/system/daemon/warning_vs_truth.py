#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""LeanWarning frames of a static one-pole scene against its true lean.

    warning_vs_truth.py BOARD.dbc CAN.log TRUE_LEAN [CAUTION DANGER]

Every LeanWarning frame with a target must decode with a good CRC, and its Level must not
exceed the highest level of a lean within 3 of the frame's LeanSigma of the true lean,
either way (issue 11: never a warning above the true lean's by more than the reported
sigma; levels by the board's rule: CAUTION at |lean| >= CAUTION deg, DANGER for a lean
towards the radar of DANGER deg or more; defaults 5 and 10, paper-sim and paper-bench).
Prints the frame count, the highest level and the largest |Lean - truth| in LeanSigma.
Exit 0 when every frame passes (a scene whose pole is never reported passes: a miss is not
a false warning).
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402

LEVELS = {"NONE": 0, "CAUTION": 1, "DANGER": 2}


def level_of(lean, caution=5.0, danger=10.0):
    """The board's rule: DANGER for a lean towards of `danger` deg or more, CAUTION at
    |lean| >= `caution`."""
    if lean >= danger:
        return 2
    return 1 if abs(lean) >= caution else 0


def allowed_level(truth, sigma, caution=5.0, danger=10.0):
    """The highest level of a lean within 3 sigma of `truth`, either way."""
    return max(level_of(truth - 3.0 * sigma, caution, danger),
               level_of(truth + 3.0 * sigma, caution, danger))


def warning_frames(db, log):
    """(frame, decoded) for every LeanWarning frame of candump `log` with a target; a frame
    with a bad CRC is printed and yielded as (frame, None)."""
    for f in scd.read_candump(log):
        d = scd.decode(db, f.can_id, f.is_eff, f.data)
        if d is None or d.name != "LeanWarning":
            continue
        if not d.crc_ok:
            print("bad CRC:", f)
            yield f, None
            continue
        if int(d.raw["HasTarget"]) == 0:
            continue
        yield f, d


def main(argv):
    if len(argv) not in (4, 6):
        print(__doc__)
        return 2
    db = scd.load_dbc(argv[1])
    truth = float(argv[3])
    caution, danger = (float(argv[4]), float(argv[5])) if len(argv) == 6 else (5.0, 10.0)
    frames = bad = top = 0
    worst_sig = 0.0
    for f, d in warning_frames(db, argv[2]):
        if d is None:
            bad += 1
            continue
        frames += 1
        lean, sig = d.phys["Lean"], d.phys["LeanSigma"]
        level = LEVELS[d.named["Level"]]
        top = max(top, level)
        worst_sig = max(worst_sig, abs(lean - truth) / sig if sig > 0 else float("inf"))
        if level > allowed_level(truth, sig, caution, danger):
            bad += 1
            print("FAIL (true lean %+.1f): Level=%s Lean=%+.2f LeanSigma=%.2f at t=%.3f"
                  % (truth, d.named["Level"], lean, sig, f.t))
    print("warning_vs_truth: %d frames, highest level %d, %d above the true level; max |Lean - "
          "truth| %.1f LeanSigma" % (frames, top, bad, worst_sig))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
