#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Export every board's DBC to KCD and ARXML (scripts/sl_dbc_export.py) and read both back
with canmatrix: same messages (id, DLC), every signal with its exported unique name and the
same layout (LSB start bit, length, byte order, sign), scaling (factor, offset) and value
table; KCD also keeps ranges, units and cycle times. ARXML (AUTOSAR 4.1) names are unique in
the file, as AUTOSAR requires, and signed signals stay signed (2C base types). Also checks the DBC attributes the daemon's behaviour defines:
GenMsgSendType and GenMsgCycleTime / SlIdleCycleTime per message.

    dbc_export_roundtrip.py SOURCE_DIR WORK_DIR
"""
import contextlib
import csv
import io
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

with contextlib.redirect_stderr(io.StringIO()):
    import canmatrix.formats as cf

SEND_TYPE = {"PoleLean": "CyclicIfActive", "LeanWarning": "Cyclic", "Status": "Cyclic",
             "Health": "Cyclic", "VehicleMotion": "Cyclic", "PoleTilt": "CyclicIfActive",
             "GroundPlane": "Cyclic", "GroundHazard": "CyclicIfActive"}
CYCLE = {"PoleLean": (250, None), "LeanWarning": (250, None), "Status": (250, 1000),
         "Health": (250, 1000), "VehicleMotion": (20, None), "PoleTilt": (250, None),
         "GroundPlane": (250, None), "GroundHazard": (250, None)}


def load(path):
    with contextlib.redirect_stderr(io.StringIO()):
        return cf.loadp_flat(path)


def load_arxml(path, work):
    """canmatrix 0.9.5's ARXML reader raises on the UNIT-REF that AUTOSAR 4 puts in an
    I-SIGNAL's SW-DATA-DEF-PROPS (its own writer's output, valid AUTOSAR). It reads a copy
    without those references (units are checked on the KCD export instead)."""
    tree = ET.parse(path)
    root = tree.getroot()
    ns = root.tag[1:root.tag.index("}")]
    ET.register_namespace("", ns)
    removed = 0
    for props in root.iter(f"{{{ns}}}SW-DATA-DEF-PROPS-CONDITIONAL"):
        for ref in props.findall(f"{{{ns}}}UNIT-REF"):
            props.remove(ref)
            removed += 1
    copy = os.path.join(work, os.path.basename(path) + ".read.arxml")
    tree.write(copy, xml_declaration=True, encoding="utf-8")
    return load(copy)


def main(src, work):
    errors = []
    os.makedirs(work, exist_ok=True)
    boards = sorted(d for d in os.listdir(os.path.join(src, "boards"))
                    if os.path.exists(os.path.join(src, "boards", d, "shadowlean.dbc")))
    for b in boards:
        dbc_path = os.path.join(src, "boards", b, "shadowlean.dbc")
        prefix = os.path.join(work, b)
        r = subprocess.run([sys.executable, os.path.join(src, "scripts", "sl_dbc_export.py"),
                            dbc_path, prefix, "--formats", "kcd,arxml"], capture_output=True, text=True)
        if r.returncode != 0:
            errors.append(f"{b}: export failed: {r.stderr.strip()}")
            continue
        dbc = load(dbc_path)
        names = {(m, s): e for m, s, e in csv.reader(open(prefix + ".names.csv")) if m != "message"}
        # The DBC's own attributes
        for fr in dbc.frames:
            st = fr.attribute("GenMsgSendType", dbc)
            if st != SEND_TYPE.get(fr.name):
                errors.append(f"{b}: {fr.name} GenMsgSendType {st!r}, want {SEND_TYPE.get(fr.name)!r}")
            cyc, idle = CYCLE[fr.name]
            if int(fr.attribute("GenMsgCycleTime", dbc)) != cyc:
                errors.append(f"{b}: {fr.name} GenMsgCycleTime {fr.attribute('GenMsgCycleTime', dbc)}")
            got_idle = int(fr.attribute("SlIdleCycleTime", dbc) or 0)
            if got_idle != (idle or 0):
                errors.append(f"{b}: {fr.name} SlIdleCycleTime {got_idle}, want {idle or 0}")
        # Every integer base type says how it is encoded (AUTOSAR: 2C signed, NONE unsigned).
        root = ET.parse(prefix + ".arxml").getroot()
        ns = root.tag[1:root.tag.index("}")]
        n_bt = 0
        for bt in root.iter(f"{{{ns}}}SW-BASE-TYPE"):
            name = bt.find(f"{{{ns}}}SHORT-NAME").text
            enc = bt.find(f"{{{ns}}}BASE-TYPE-ENCODING")
            want = "2C" if name.startswith("sint") else "NONE"
            n_bt += 1
            if enc is None or enc.text != want:
                errors.append(f"{b}.arxml: base type {name} encoding "
                              f"{None if enc is None else enc.text}, want {want}")
        if n_bt == 0:
            errors.append(f"{b}.arxml: no SW-BASE-TYPE (not AUTOSAR 4?)")
        for fmt in ("kcd", "arxml"):
            out = load(f"{prefix}.{fmt}") if fmt == "kcd" else load_arxml(f"{prefix}.{fmt}", work)
            by_id = {f.arbitration_id.id: f for f in out.frames}
            all_names = [s.name for f in out.frames for s in f.signals]
            if len(set(all_names)) != len(all_names):
                errors.append(f"{b}.{fmt}: signal names repeat")
            for fr in dbc.frames:
                o = by_id.get(fr.arbitration_id.id)
                if o is None:
                    errors.append(f"{b}.{fmt}: message {fr.name} missing")
                    continue
                if o.size != fr.size:
                    errors.append(f"{b}.{fmt}: {fr.name} DLC {o.size} != {fr.size}")
                if fmt == "kcd" and o.cycle_time != int(fr.attribute("GenMsgCycleTime", dbc)):
                    errors.append(f"{b}.kcd: {fr.name} cycle {o.cycle_time}")
                osig = {s.name: s for s in o.signals}
                if len(osig) != len(fr.signals):
                    errors.append(f"{b}.{fmt}: {fr.name} has {len(osig)} signals, want {len(fr.signals)}")
                for s in fr.signals:
                    e = osig.get(names.get((fr.name, s.name), "?"))
                    if e is None:
                        errors.append(f"{b}.{fmt}: {fr.name}.{s.name} missing (exported name "
                                      f"{names.get((fr.name, s.name))})")
                        continue
                    want = (s.get_startbit(bit_numbering=1, start_little=True), s.size,
                            s.is_little_endian, s.is_signed, float(s.factor), float(s.offset),
                            dict(s.values))
                    got = (e.get_startbit(bit_numbering=1, start_little=True), e.size,
                           e.is_little_endian, e.is_signed, float(e.factor), float(e.offset),
                           dict(e.values))
                    if want != got:
                        errors.append(f"{b}.{fmt}: {fr.name}.{s.name}: {got} != {want}")
                    if fmt == "kcd" and (float(e.min), float(e.max), e.unit) != (
                            float(s.min), float(s.max), s.unit):
                        errors.append(f"{b}.kcd: {fr.name}.{s.name} range/unit "
                                      f"{(e.min, e.max, e.unit)} != {(s.min, s.max, s.unit)}")
        n_sig = sum(len(f.signals) for f in dbc.frames)
        print(f"{b}: {len(dbc.frames)} messages, {n_sig} signals -> KCD and ARXML, read back")
    for e in errors:
        print("FAIL:", e)
    return 1 if errors or not boards else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
