#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Decode a candump log with a generated DBC (Debian python3-canmatrix 0.9.5) and compare
every signal with the encoder inputs written by can_gen_frames.

    check_dbc_decode.py BOARD.dbc FRAMES.log FRAMES.expect

Independent of the C code on purpose: the log is read with python-can's CanutilsLogReader,
the layout comes only from the DBC, frames are decoded and their CRC recomputed by the
project's Python DBC decoder (scripts/sl_can_decode.py, canmatrix), and the expected raw
values are derived from the inputs with exact Decimal arithmetic. Checks per frame:
- the DBC knows the id, DLC 8;
- every signal: decoded physical value within one LSB of the (clamped) input, and the
  raw value equal to round-half-up(input / factor) clamped to the DBC [min|max];
- Clamped / Saturated equals "some input had to be clamped";
- Crc = the E2E Profile 11 CRC (SlE2EDataId, SlE2EMode); Counter = n-th frame of that
  message mod 15;
- canmatrix re-encodes the decoded raw values to exactly the same 8 bytes.
Exit status 0 when all frames pass; prints the first mismatches otherwise.
"""
import decimal
import os
import sys
from decimal import Decimal as D

import can

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402

decimal.getcontext().prec = 40


def round_half_up(x):
    return int((x + D("0.5")).to_integral_value(rounding=decimal.ROUND_FLOOR))


def dec(v):
    return D(str(v))


# message -> signal -> (input key, input units per physical unit, kind)
MAP = {
    "PoleLean": {
        "TargetId": ("target_id", 1, "id"),
        "Quality": ("quality", 1, "quality"),
        "Azimuth": ("azimuth_cdeg", 100, "angle"),
        "Lean": ("lean_cdeg", 100, "num"),
        "LeanSigma": ("lean_sigma_cdeg", 100, "num"),
        "RangeInner": ("range_inner_um", 1000000, "num"),
        "RangeOuter": ("range_outer_um", 1000000, "num"),
    },
    "LeanWarning": {
        "Level": ("level", 1, "level"),
        "HasTarget": ("has_target", 1, "flag"),
        "TargetId": ("target_id", 1, "id"),
        "Quality": ("quality", 1, "quality"),
        "Azimuth": ("azimuth_cdeg", 100, "angle"),
        "Lean": ("lean_cdeg", 100, "num"),
        "Range": ("range_um", 1000000, "num"),
        "LeanSigma": ("lean_sigma_cdeg", 100, "num"),
    },
    "Status": {
        "LinkState": ("link_state", 1, "link"),
        "Rotations": ("rotations", 1, "num"),
        "AzimuthsMissing": ("azimuths_missing", 1, "num"),
        "DecoderResyncs": ("decoder_resyncs", 1, "num"),
        "CanDropped": ("can_dropped", 1, "num"),
    },
    "Health": {
        "Fault": ("fault", 1, "fault"),
        "Reconnects": ("reconnects", 1, "num"),
        "CandidatesDropped": ("candidates_dropped", 1, "num"),
        "ThetaDrift": ("theta_drift_cdeg", 100, "num"),
    },
    "PoleTilt": {
        "TargetId": ("target_id", 1, "id"),
        "Quality": ("quality", 1, "tquality"),
        "Tilt": ("tilt_cdeg", 100, "num"),
        "TiltDirection": ("direction_cdeg", 100, "angle"),
        "TiltSigma": ("tilt_sigma_cdeg", 100, "num"),
        "DirectionSigma": ("direction_sigma_cdeg", 100, "num"),
        "BaseX": ("base_x_um", 1000000, "num"),
        "BaseY": ("base_y_um", 1000000, "num"),
    },
    "GroundPlane": {
        "Quality": ("quality", 1, "gquality"),
        "Height": ("height_mm", 1000, "num"),
        "Pitch": ("pitch_cdeg", 100, "num"),
        "Roll": ("roll_cdeg", 100, "num"),
        "HeightSigma": ("height_sigma_mm", 1000, "num"),
        "PitchSigma": ("pitch_sigma_cdeg", 100, "num"),
        "RollSigma": ("roll_sigma_cdeg", 100, "num"),
    },
    "GroundHazard": {
        "Kind": ("kind", 1, "gkind"),
        "Sector": ("sector", 1, "id"),
        "Azimuth": ("azimuth_cdeg", 100, "angle"),
        "HeightDiff": ("height_diff_mm", 1000, "num"),
        "Distance": ("distance_um", 1000000, "num"),
        "Sigma": ("sigma_mm", 1000, "num"),
    },
    "VehicleMotion": {
        "Speed": ("speed_mm_s", 1000, "num"),
        "YawRate": ("yaw_rate_cdeg_s", 100, "num"),
        "SpeedValid": ("speed_valid", 1, "flag"),
        "YawRateValid": ("yaw_rate_valid", 1, "flag"),
    },
}
FLAG = {"PoleLean": "Clamped", "LeanWarning": "Clamped", "Status": "Saturated", "PoleTilt": "Clamped",
        "GroundPlane": "Clamped", "GroundHazard": "Clamped"}
# GroundPlane Quality NONE (0) and GroundHazard Kind FLAT (0), also as the clamped form of an
# unknown value, carry no numbers (sent as 0); the first field of each decides.
NO_NUMBERS = {"GroundPlane": "Quality", "GroundHazard": "Kind"}
# PoleTilt: qualities other than FITTED (0) / AMBIGUOUS (1) carry no numbers (sent as 0).
TILT_VALUE_FIELDS = {"Tilt", "TiltDirection", "TiltSigma", "DirectionSigma", "BaseX", "BaseY"}
TARGET_FIELDS = {"TargetId", "Quality", "Azimuth", "Lean", "Range", "LeanSigma"}


def expected_raw(sig, kind, value):
    """(expected raw value, was clamped) for one signal and its input value."""
    f = dec(sig.factor)
    rmin = int(dec(sig.min) / f)
    rmax = int(dec(sig.max) / f)
    if kind == "flag":
        return int(value), False
    if kind == "fault":
        return int(value) & 0x7FF, False  # bits 11..15 reserved: never sent
    if kind in ("id", "quality", "level", "link", "tquality", "gquality", "gkind"):
        v = int(value)
        if v <= rmax:
            return v, False
        return {"id": rmax, "quality": 3, "level": 2, "link": 0, "tquality": 4, "gquality": 0,
                "gkind": 0}[kind], True
    if kind == "angle":
        a = value - 360 * (value / 360).to_integral_value(rounding=decimal.ROUND_FLOOR)
        turn = int(D(360) / f)
        return round_half_up(a / f) % turn, False
    raw = round_half_up(value / f)
    if raw < rmin:
        return rmin, True
    if raw > rmax:
        return rmax, True
    return raw, False


def main():
    if len(sys.argv) != 4:
        print(__doc__)
        return 2
    db = scd.load_dbc(sys.argv[1])
    msgs = list(can.CanutilsLogReader(sys.argv[2]))
    with open(sys.argv[3]) as fh:
        expects = [line.split() for line in fh if line.strip()]
    if len(msgs) != len(expects):
        print(f"FAIL: {len(msgs)} frames in the log, {len(expects)} expectations")
        return 1
    errors = []
    counters = {}
    nclamped = 0
    lsb_max = {}
    for i, (msg, ex) in enumerate(zip(msgs, expects)):
        name, inputs = ex[0], dict(kv.split("=", 1) for kv in ex[1:])
        where = f"frame {i + 1} ({name} id 0x{msg.arbitration_id:X})"
        fr = scd.frame_of(db, msg.arbitration_id, msg.is_extended_id)
        if fr is None or fr.name != name:
            errors.append(f"{where}: DBC has {fr.name if fr else 'no frame'} for this id")
            continue
        data = bytes(msg.data)
        if msg.dlc != 8 or len(data) != 8:
            errors.append(f"{where}: dlc {msg.dlc}")
            continue
        d = scd.decode(db, msg.arbitration_id, msg.is_extended_id, data)
        # E2E
        if not d.crc_ok:
            errors.append(f"{where}: Crc {data[0]:#x} does not match the recomputed CRC-8")
        n = counters.get(name, 0)
        counters[name] = n + 1
        if d.raw["Counter"] != n % 15:
            errors.append(f"{where}: Counter {d.raw['Counter']}, want {n % 15}")
        # signals
        any_clamped = False
        has_target = name != "LeanWarning" or inputs["has_target"] == "1"
        numbers = True
        for sname, (key, scale, kind) in MAP[name].items():
            if not numbers:
                if d.raw[sname] != 0:
                    errors.append(f"{where}: {sname} raw {d.raw[sname]}, want 0 (no numbers)")
                continue
            sig = fr.signal_by_name(sname)
            f = dec(sig.factor)
            if name == "PoleTilt" and sname in TILT_VALUE_FIELDS and int(inputs["quality"]) not in (0, 1):
                want_raw, cl, value = 0, False, D(0)
                if d.raw[sname] != 0:
                    errors.append(f"{where}: {sname} raw {d.raw[sname]}, want 0 (quality {inputs['quality']})")
                continue
            if not has_target and sname in TARGET_FIELDS:
                # no target: every target field 0, Quality INVALID (3) so that nobody
                # gating on VALID/FILTERED reads a lean
                want_raw, cl, value = (3 if sname == "Quality" else 0), False, D(0)
            else:
                value = D(int(inputs[key])) / scale
                want_raw, cl = expected_raw(sig, kind, value)
            any_clamped |= cl
            if NO_NUMBERS.get(name) == sname and want_raw == 0:
                numbers = False
            if d.raw[sname] != want_raw:
                errors.append(f"{where}: {sname} raw {d.raw[sname]}, want {want_raw} "
                              f"(input {inputs.get(key)})")
                continue
            phys = dec(d.phys[sname])
            if kind in ("num", "angle"):
                ref = value
                if kind == "angle":
                    ref = value - 360 * (value / 360).to_integral_value(rounding=decimal.ROUND_FLOOR)
                    diff = abs(phys - ref)
                    diff = min(diff, 360 - diff)
                else:
                    ref = min(max(ref, dec(sig.min)), dec(sig.max))
                    diff = abs(phys - ref)
                if diff > f:
                    errors.append(f"{where}: {sname} = {phys}, input {ref}: more than one LSB")
                lsb_max[(name, sname)] = max(lsb_max.get((name, sname), D(0)), diff / f)
        if name in FLAG:
            got_flag = d.raw[FLAG[name]]
            if got_flag != int(any_clamped):
                errors.append(f"{where}: {FLAG[name]} = {got_flag}, want {int(any_clamped)}")
        nclamped += int(any_clamped)
        # canmatrix packs the decoded raw values back to the same bytes
        if not d.reencode_ok:
            errors.append(f"{where}: canmatrix does not re-encode the decoded values to {data.hex()}")
        if len(errors) > 20:
            break
    for e in errors[:20]:
        print("FAIL:", e)
    worst = ", ".join(f"{m}.{s} {float(v):.3f}" for (m, s), v in sorted(lsb_max.items()))
    print(f"check_dbc_decode: {len(msgs)} frames ({', '.join(f'{k} {v}' for k, v in sorted(counters.items()))}), "
          f"{nclamped} with clamped values; worst |decoded - input| in LSB: {worst}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
