#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Export a board's generated DBC to the formats other CAN tools read (Debian python3-canmatrix).

    sl_dbc_export.py BOARD.dbc OUT_PREFIX [--formats kcd,arxml,json,sym]

writes OUT_PREFIX.kcd, OUT_PREFIX.arxml, ... and OUT_PREFIX.names.csv.

Signal names. In the DBC every message is its own namespace, so the E2E signals (Crc,
Counter) and a few others (Quality, TargetId, Azimuth, LeanSigma, ...) repeat across
messages, as DBC allows. AUTOSAR ARXML names every I-SIGNAL once per file, so a plain
export is rejected by ARXML readers (cantools: duplicate signal names). This export
therefore names every signal <Message>_<Signal> (PoleLean_Crc, Status_Counter, ...) in
every format it writes, so one name means one thing whatever the tool; OUT_PREFIX.names.csv
maps message, DBC signal name and exported name. Layouts, scaling, ranges, units, value
tables, cycle times and comments are carried over unchanged (what each format can hold;
tests/system/can/dbc_export_roundtrip.py reads the files back and compares them with the DBC).
ARXML: the integer base types get their BASE-TYPE-ENCODING (2C / NONE), which canmatrix's
writer leaves out, so signed signals stay signed in AUTOSAR tools.
"""
import argparse
import contextlib
import csv
import io
import sys
import xml.etree.ElementTree as ET

with contextlib.redirect_stderr(io.StringIO()):  # "ldf is not supported" (not in Debian)
    import canmatrix
    import canmatrix.formats

FORMATS = ("kcd", "arxml", "json", "sym")


def unique_names(db):
    """Renames every signal to <Message>_<Signal>; returns [(message, dbc_name, exported)]."""
    rows = []
    for frame in db.frames:
        for sig in frame.signals:
            new = f"{frame.name}_{sig.name}"
            rows.append((frame.name, sig.name, new))
            sig.name = new
    names = [r[2] for r in rows]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise SystemExit(f"sl_dbc_export: names still repeat: {sorted(dup)}")
    return rows


def fix_arxml_base_types(path):
    """canmatrix 0.9.5 writes the integer SW-BASE-TYPEs (sint8..sint64, uint8..uint64)
    without a BASE-TYPE-ENCODING, so readers (canmatrix itself included) take every signal
    as unsigned. AUTOSAR encodes it there: 2C for two's complement, NONE for unsigned.
    Adds it after BASE-TYPE-SIZE. Returns the number of base types fixed."""
    tree = ET.parse(path)
    root = tree.getroot()
    ns = root.tag[1:root.tag.index("}")] if root.tag.startswith("{") else ""
    ET.register_namespace("", ns)
    q = (lambda t: f"{{{ns}}}{t}") if ns else (lambda t: t)
    fixed = 0
    for bt in root.iter(q("SW-BASE-TYPE")):
        name = bt.find(q("SHORT-NAME"))
        if name is None or bt.find(q("BASE-TYPE-ENCODING")) is not None:
            continue
        enc = "2C" if name.text.startswith("sint") else "NONE" if name.text.startswith("uint") else None
        if enc is None:
            continue
        e = ET.Element(q("BASE-TYPE-ENCODING"))
        e.text = enc
        size = bt.find(q("BASE-TYPE-SIZE"))
        bt.insert(list(bt).index(size) + 1 if size is not None else len(bt), e)
        fixed += 1
    tree.write(path, xml_declaration=True, encoding="utf-8")
    return fixed


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dbc")
    ap.add_argument("out_prefix")
    ap.add_argument("--formats", default="kcd,arxml")
    a = ap.parse_args(argv)
    formats = [f for f in a.formats.split(",") if f]
    bad = [f for f in formats if f not in FORMATS]
    if bad:
        ap.error(f"unknown format(s) {bad}; choose from {', '.join(FORMATS)}")
    try:
        db = canmatrix.formats.loadp_flat(a.dbc)
    except (OSError, ValueError) as e:
        print(f"sl_dbc_export: {a.dbc}: {e}", file=sys.stderr)
        return 1
    if db is None or not db.frames:
        print(f"sl_dbc_export: {a.dbc}: no messages", file=sys.stderr)
        return 1
    rows = unique_names(db)
    with open(a.out_prefix + ".names.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["message", "dbc_signal", "exported_signal"])
        w.writerows(rows)
    for f in formats:
        path = f"{a.out_prefix}.{f}"
        with contextlib.redirect_stderr(io.StringIO()):
            # AUTOSAR 4: data types with their base types (3.2.3 carries no signedness)
            canmatrix.formats.dumpp({"": db}, path, arVersion="4.1.0")
        if f == "arxml":
            fix_arxml_base_types(path)
        print(f"{path}: {len(db.frames)} messages, {len(rows)} signals")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
