# SPDX-License-Identifier: MIT
"""Text reports of decoded frames: every frame, one line per Status, the warnings table."""
import sys

from .dbc import GROUND_QUALITY, HAZARD_KIND, LEVEL, LINK, QUALITY


def groups(decoded):
    """Rotation groups [(status, warning, [poles])], one per Status frame: the LeanWarning
    and PoleLean frames sent before it (idle Status frames: warning None)."""
    out, poles, warn = [], [], None
    for _, d in decoded:
        if d is None or not d.length_ok:
            continue
        if d.name == "PoleLean":
            poles.append(d)
        elif d.name == "LeanWarning":
            warn = d
        elif d.name == "Status":
            out.append((d, warn, poles))
            poles, warn = [], None
    return out


def ground(decoded):
    """The ground per rotation [(plane, [hazards])]: each GroundPlane frame with the
    GroundHazard frames sent after it (one per confirmed DROP / STEP sector)."""
    out = []
    for _, d in decoded:
        if d is None or not d.length_ok:
            continue
        if d.name == "GroundPlane":
            out.append((d, []))
        elif d.name == "GroundHazard" and out:
            out[-1][1].append(d)
    return out


def format_ground(plane, hazards):
    """One line: the plane (quality, height, pitch, roll with their sigmas), then every
    hazard (kind, azimuth, height relative to the plane, distance)."""
    q = GROUND_QUALITY.get(plane.raw["Quality"], "?")
    if plane.raw["Quality"] == 0:
        line = f"{q:<6} no plane"
    else:
        p = plane.phys
        line = (f"{q:<6} height {p['Height']:.3f}±{p['HeightSigma']:.3f} m  pitch {p['Pitch']:+.2f}"
                f"±{p['PitchSigma']:.2f}°  roll {p['Roll']:+.2f}±{p['RollSigma']:.2f}°")
    for h in hazards:
        line += (f"  {HAZARD_KIND.get(h.raw['Kind'], '?')} az {h.phys['Azimuth']:.1f}° "
                 f"{h.phys['HeightDiff']:+.3f} m at {h.phys['Distance']:.2f} m")
    return line


def print_ground(decoded, out=None):
    """One line per GroundPlane frame (format_ground)."""
    out = out or sys.stdout
    for plane, hazards in ground(decoded):
        out.write(format_ground(plane, hazards) + "\n")


def format_frame(f, d, e2e=None):
    """One line: time, message, counter, CRC (and E2E status), signals (value names)."""
    if d is None:
        return f"{f.t:.6f} {f.can_id:X} (unknown id)"
    if not d.length_ok:
        n = "RTR" if f.data is None else f"{len(f.data)} bytes"
        return f"{f.t:.6f} {d.name:<13} wrong length ({n})"
    sigs = " ".join(f"{k}={d.named.get(k, round(v, 3))}" for k, v in d.phys.items()
                    if k not in ("Crc", "Counter"))
    tail = "" if e2e is None or e2e == "OK" else f" e2e={e2e}"
    return f"{f.t:.6f} {d.name:<13} ctr={d.counter:<2} crc={'ok' if d.crc_ok else 'BAD'}{tail} {sigs}"


def print_frames(decoded, out=None, monitor=None):
    """Every frame, one line each; with an E2EMonitor, its verdict on each frame."""
    out = out or sys.stdout
    for f, d in decoded:
        e2e = monitor.check(d, f.data, f.t) if monitor is not None else None
        out.write(format_frame(f, d, e2e) + "\n")


def print_summary(decoded, out=None):
    """One line per Status frame (E2E counter, link state, Rotations, the LeanWarning of the
    rotation, PoleLean count); runs of identical lines are collapsed."""
    out = out or sys.stdout
    out.write(f"{'ctr':>3} {'link':<12} {'rot':>4}  {'LeanWarning':<44} {'PoleLean':>8}\n")
    prev, same = None, 0
    for st, warn, poles in groups(decoded):
        if warn is None:
            w = "(idle Status: no rotation)"
        elif not warn.raw["HasTarget"]:
            w = f"{LEVEL.get(warn.raw['Level'], '?'):<8} no confirmed target"
        else:
            w = (f"{LEVEL.get(warn.raw['Level'], '?'):<8} target {warn.raw['TargetId']:>2} "
                 f"az {warn.phys['Azimuth']:>5.1f}° lean {warn.phys['Lean']:>+6.2f}°")
        key = (st.raw["LinkState"], w, len(poles))
        if key == prev and warn is not None:
            same += 1
            continue
        if same:
            out.write(f"{'':>3} {'':<12} {'':>4}  ... {same} more rotation(s) alike\n")
        prev, same = key, 0
        out.write(f"{st.raw['Counter']:>3} {LINK.get(st.raw['LinkState'], '?'):<12} {st.raw['Rotations']:>4}  "
                  f"{w:<44} {len(poles):>8}\n")
    if same:
        out.write(f"{'':>3} {'':<12} {'':>4}  ... {same} more rotation(s) alike\n")


def print_table(decoded, out=None, last=None):
    """The warnings as a table: one row per PoleLean frame, grouped by rotation."""
    out = out or sys.stdout
    out.write(f"{'rot':>4} {'link':<12} {'warning':<8} {'id':>3} {'azimuth':>8} {'lean':>8} "
              f"{'sigma':>6} {'r1 [m]':>7} {'r2 [m]':>7} {'quality':<9}\n")
    g = [x for x in groups(decoded) if x[1] is not None]
    for st, warn, poles in (g if last is None else g[-last:]):
        rot = st.raw["Rotations"]
        link = LINK.get(st.raw["LinkState"], "?")
        level = LEVEL.get(warn.raw["Level"], "?")
        wid = warn.raw["TargetId"] if warn.raw["HasTarget"] else None
        if not poles:
            out.write(f"{rot:>4} {link:<12} {level:<8} {'-':>3}\n")
        for p in poles:
            mark = level if p.raw["TargetId"] == wid else ""
            out.write(f"{rot:>4} {link:<12} {mark:<8} {p.raw['TargetId']:>3} "
                      f"{p.phys['Azimuth']:>7.1f}° {p.phys['Lean']:>+7.1f}° {p.phys['LeanSigma']:>5.1f}° "
                      f"{p.phys['RangeInner']:>7.2f} {p.phys['RangeOuter']:>7.2f} "
                      f"{QUALITY.get(p.raw['Quality'], '?'):<9}\n")


def print_e2e(monitor, out=None):
    """The E2E Profile 11 status counts per message (ERROR split into its reasons)."""
    out = out or sys.stdout
    out.write(f"E2E Profile 11, max delta counter {monitor.max_delta_counter}"
              + (f", timeout {monitor.timeout:g} s" if monitor.timeout is not None else "") + "\n")
    out.write(f"{'message':<14} {'OK':>5} {'SOME_LOST':>9} {'INITIAL':>7} {'REPEATED':>8} "
              f"{'WRONG_SEQ':>9} {'ERROR':>5} {'crc':>4} {'length':>6} {'counter':>7} "
              f"{'nibble':>6} {'lost':>5} {'NO_DATA':>7}\n")
    for name in sorted(monitor.stats):
        s = monitor.stats[name]
        out.write(f"{name:<14} {s.ok:>5} {s.ok_some_lost:>9} {s.initial:>7} {s.repeated:>8} "
                  f"{s.wrong_sequence:>9} {s.error:>5} {s.crc_errors:>4} {s.bad_length:>6} "
                  f"{s.bad_counter:>7} {s.bad_nibble:>6} {s.lost_frames:>5} {s.no_new_data:>7}\n")
    if monitor.unknown:
        out.write(f"unknown ids: {monitor.unknown} frame(s)\n")
