#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Decode shadowlean CAN frames from a candump log with a board's generated DBC
(Debian python3-canmatrix), independently of the C code. The project's one Python DBC
decoder: the daemon tests, the DBC layout check (tests/system/can/check_dbc_decode.py) and
scripts/demo.sh all use it.

Library:
    db = load_dbc(path)
    frames = read_candump(path)            # [(t_s, iface, can_id, is_eff, bytes)]
    d = decode(db, can_id, is_eff, data)   # Decoded(name, phys{}, raw{}, named{}, crc_ok, ...)
    check_e2e(...)                         # CRC-8 SAE J1850 over [SlE2EDataId, data[1..7]]

Command line:
    sl_can_decode.py BOARD.dbc LOG              every frame, decoded
    sl_can_decode.py BOARD.dbc LOG --summary    one line per Status frame (link, LeanWarning)
    sl_can_decode.py BOARD.dbc LOG --table [--last K]   PoleLean rows per rotation
"""
import contextlib
import io
import re
import sys
from dataclasses import dataclass, field

with contextlib.redirect_stderr(io.StringIO()):  # "arxml is not supported" etc.
    import canmatrix
    import canmatrix.formats

LINE = re.compile(r"^\((\d+)\.(\d+)\)\s+(\S+)\s+([0-9A-Fa-f]{3}|[0-9A-Fa-f]{8})#([0-9A-Fa-f.]*|R\d?)\s*[RT]?\s*$")
LINK = {0: "DISCONNECTED", 1: "CONNECTING", 2: "WAIT_CONFIG", 3: "STREAMING", 4: "SILENT"}
LEVEL = {0: "NONE", 1: "CAUTION", 2: "DANGER"}
QUALITY = {0: "VALID", 1: "AMBIGUOUS", 2: "OUT_OF_MODEL", 3: "INVALID", 4: "FILTERED"}


def crc8_j1850(data):
    reg = 0xFF
    for b in data:
        reg ^= b
        for _ in range(8):
            reg = ((reg << 1) ^ 0x1D) & 0xFF if reg & 0x80 else (reg << 1) & 0xFF
    return reg ^ 0xFF


assert crc8_j1850(b"123456789") == 0x4B


def load_dbc(path):
    return canmatrix.formats.loadp_flat(path)


def read_candump(path):
    """Frames of a candump -L log: (t_s, iface, id, is_eff, data bytes). Raises on a bad line."""
    out = []
    fh = sys.stdin if path == "-" else open(path)
    with fh:
        for n, line in enumerate(fh, 1):
            if not line.strip():
                continue
            m = LINE.match(line.strip())
            if not m:
                raise ValueError(f"{path}:{n}: not a candump -L line: {line.strip()!r}")
            sec, frac, iface, cid, payload = m.groups()
            t = int(sec) + int(frac) / 10 ** len(frac)
            ident = int(cid, 16)
            eff = len(cid) == 8
            if payload.startswith("R"):
                data = None
            else:
                payload = payload.replace(".", "")
                data = bytes.fromhex(payload)
            out.append((t, iface, ident, eff, data))
    return out


@dataclass
class Decoded:
    name: str
    can_id: int
    phys: dict = field(default_factory=dict)   # signal -> float
    raw: dict = field(default_factory=dict)    # signal -> int
    named: dict = field(default_factory=dict)  # signal -> value-table name
    crc_ok: bool = False
    reencode_ok: bool = False


def frame_of(db, can_id, eff):
    try:
        return db.frame_by_id(canmatrix.ArbitrationId(can_id, extended=eff))
    except Exception:
        return None


def decode(db, can_id, eff, data):
    """Decode one frame; None when the DBC does not know the id."""
    fr = frame_of(db, can_id, eff)
    if fr is None:
        return None
    d = Decoded(fr.name, can_id)
    if data is None or len(data) != fr.size:
        return d
    sig = fr.decode(bytes(data))
    for k, v in sig.items():
        d.raw[k] = int(v.raw_value)
        d.phys[k] = float(v.phys_value)
        if v.named_value is not None:
            d.named[k] = v.named_value
    data_id = int(fr.attributes.get("SlE2EDataId", 0))
    d.crc_ok = data[0] == crc8_j1850(bytes([data_id]) + bytes(data[1:]))
    d.reencode_ok = bytes(fr.encode({k: v.raw_value for k, v in sig.items()})) == bytes(data)
    return d


def decode_log(dbc_path, log_path):
    db = load_dbc(dbc_path)
    return [(f, decode(db, f[2], f[3], f[4])) for f in read_candump(log_path)]


def groups(decoded):
    """Rotation groups: (status, warning, [poles]) per Status frame (idle ones: no warning)."""
    out, poles, warn = [], [], None
    for _, d in decoded:
        if d is None:
            continue
        if d.name == "PoleLean":
            poles.append(d)
        elif d.name == "LeanWarning":
            warn = d
        elif d.name == "Status":
            out.append((d, warn, poles))
            poles, warn = [], None
    return out


def print_summary(decoded, out=sys.stdout):
    """One line per Status frame (E2E counter, link state, Rotations, the LeanWarning of the
    rotation, PoleLean count); runs of identical lines are collapsed."""
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


def print_table(decoded, out=sys.stdout, last=None):
    """The warnings as a table: one row per PoleLean frame, grouped by rotation."""
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


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    decoded = decode_log(argv[1], argv[2])
    if "--summary" in argv[3:]:
        print_summary(decoded)
        return 0
    if "--table" in argv[3:]:
        last = int(argv[argv.index("--last") + 1]) if "--last" in argv else None
        print_table(decoded, last=last)
        return 0
    for f, d in decoded:
        if d is None:
            print(f"{f[0]:.6f} {f[2]:X} (unknown id)")
            continue
        sigs = " ".join(f"{k}={d.named.get(k, round(v, 3))}" for k, v in d.phys.items()
                        if k not in ("Crc", "Counter"))
        print(f"{f[0]:.6f} {d.name:<11} ctr={d.raw.get('Counter')} crc={'ok' if d.crc_ok else 'BAD'} {sigs}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
