#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The shadowlean CAN Wireshark dissector (packaging/wireshark/shadowlean_can.lua) with
Debian's tshark on SocketCAN pcap files (link type 227) written here:

  1. the AUTOSAR E2E Profile 11 vectors of implementations that are not this project's
     (the `autosar-e2e` Rust crate, src/profiles/profile11.rs, and the `autosar-e2e` Python
     package, zariiii9003/autosar-e2e test/test_p01.py): 8 zero bytes, Data ID 0x123,
     11A CC 00 / 91 01, 11C 2A 10 / 77 11 verify (computed CRC = the vector), and their
     negative vectors (CC 10 in 11A, 77 21 in 11C) are ERROR;
  1b. the project's per-message vectors (8 zero bytes but the counter 0 / 1, each message's
     Data ID from the paper-sim DBC; Health 0x0355 in 11C from paper-sim-29bit's), the same
     table as unit_canmsg and the Python suite;
  2. the daemon's demo log (paper-sim DBC): every frame a shadowlean message, CRC good,
     INITIAL then OK per message, every signal equal to the Python package's decode;
  3. can_gen_frames' frames for paper-sim-29bit (29-bit ids, Health in Profile 11C): the
     same, on extended frames;
  4. a repetition, a lost frame and a corrupted CRC are REPEATED, WRONG_SEQUENCE (or
     OK_SOME_LOST with shadowlean.max_delta_counter 3) and ERROR;
  5. a DBC that cannot be read is reported by name, and no frame is claimed.

    wireshark_can_dissector_test.py --tshark T --dissector LUA --src SRC --gen CAN_GEN_FRAMES --work DIR
"""
import argparse
import os
import shutil
import struct
import subprocess
import sys

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def write_pcap(path, frames):
    """frames: [(can_id, eff, data)] -> pcap, link type 227 (CAN id big-endian, bit 31 EFF)."""
    with open(path, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 227))
        for i, (cid, eff, data) in enumerate(frames):
            rec = struct.pack(">IBBBB", cid | (0x80000000 if eff else 0), len(data), 0, 0, 0)
            rec += bytes(data).ljust(8, b"\0")
            f.write(struct.pack("<IIII", 1700000000 + i // 1000, (i % 1000) * 1000, len(rec), len(rec)) + rec)


def tshark(args, pcap, dbc, extra=()):
    cmd = [args.tshark, "-n", "-X", "lua_script:" + args.dissector, "-o", "shadowlean.dbc:" + dbc,
           "-r", pcap, "-T", "fields", "-E", "separator=/t", "-E", "occurrence=a", "-E", "aggregator=|"]
    cmd += list(extra)
    for f in ("shadowlean.message", "shadowlean.crc.status", "shadowlean.crc.computed",
              "shadowlean.e2e.status", "shadowlean.signal"):
        cmd += ["-e", f]
    r = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, HOME=args.work))
    if r.returncode != 0:
        sys.exit("tshark failed: " + r.stderr)
    rows = []
    for line in r.stdout.splitlines():
        c = line.split("\t")
        rows.append({"msg": c[0], "crc": c[1], "crc_calc": c[2], "e2e": c[3],
                     "signals": dict(s.split(" ")[0].split("=", 1) for s in c[4].split("|") if s)})
    return rows


VECTOR_DBC = """VERSION ""

BU_: X

BO_ 291 Vec11A: 8 X
 SG_ Crc : 0|8@1+ (1,0) [0|255] "" X
 SG_ Counter : 8|4@1+ (1,0) [0|14] "" X

BO_ 292 Vec11C: 8 X
 SG_ Crc : 0|8@1+ (1,0) [0|255] "" X
 SG_ Counter : 8|4@1+ (1,0) [0|14] "" X

BA_DEF_ BO_  "SlE2EDataId" INT 0 65535;
BA_DEF_ BO_  "SlE2EMode" ENUM  "Both","Nibble";
BA_ "SlE2EDataId" BO_ 291 291;
BA_ "SlE2EMode" BO_ 291 0;
BA_ "SlE2EDataId" BO_ 292 291;
BA_ "SlE2EMode" BO_ 292 1;
"""


def compare_with_package(rows, decoded, what):
    """Dissector rows against the Python package's decode of the same frames."""
    bad = []
    seen = set()
    for i, (row, d) in enumerate(zip(rows, decoded)):
        want_e2e = "OK" if d.name in seen else "INITIAL"
        seen.add(d.name)
        if row["msg"] != d.name or row["crc"] != "good" or row["e2e"] != want_e2e:
            bad.append(f"frame {i + 1}: {row['msg']} crc {row['crc']} {row['e2e']}, want {d.name} good {want_e2e}")
            continue
        for k, v in d.phys.items():
            got = row["signals"].get(k)
            if got is None or abs(float(got) - v) > 1e-6:
                bad.append(f"frame {i + 1} {d.name}.{k}: dissector {got}, package {v}")
    check(len(rows) == len(decoded) and not bad,
          f"{what}: {len(rows)} frames, message, CRC good, INITIAL/OK and every signal as the Python package"
          + ("" if not bad else ": " + "; ".join(bad[:3])))


def main():
    ap = argparse.ArgumentParser()
    for k in ("tshark", "dissector", "src", "gen", "work"):
        ap.add_argument("--" + k, required=True)
    args = ap.parse_args()
    if not args.tshark or not os.path.exists(args.tshark):
        print("tshark not installed (Debian package tshark)")
        return 1
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    sys.path.insert(0, os.path.join(args.src, "python"))
    import shadowlean as sl

    # 1. Independent Profile 11 vectors.
    vdbc = os.path.join(args.work, "vectors.dbc")
    with open(vdbc, "w") as fh:
        fh.write(VECTOR_DBC)
    vec = [(0x123, "cc00000000000000", "good", "INITIAL", 0xCC), (0x123, "9101000000000000", "good", "OK", 0x91),
           (0x123, "cc10000000000000", "bad", "ERROR", None),
           (0x124, "2a10000000000000", "good", "INITIAL", 0x2A), (0x124, "7711000000000000", "good", "OK", 0x77),
           (0x124, "7721000000000000", "bad", "ERROR", None)]
    pcap = os.path.join(args.work, "vectors.pcap")
    write_pcap(pcap, [(cid, False, bytes.fromhex(h)) for cid, h, _, _, _ in vec])
    rows = tshark(args, pcap, vdbc)
    for (cid, h, crc, e2e, want), row in zip(vec, rows):
        calc_ok = want is None or int(row["crc_calc"], 0) == want
        check(len(rows) == len(vec) and row["crc"] == crc and row["e2e"] == e2e and calc_ok,
              f"Profile 11 vector {'11A' if cid == 0x123 else '11C'} Data ID 0x123 {h}: CRC {row['crc']}"
              f" (computed {row['crc_calc']}), {row['e2e']}")

    # 1b. Per-message vectors.
    dbc = os.path.join(args.src, "boards", "paper-sim", "shadowlean.dbc")
    db = sl.load_dbc(dbc)
    table = {"PoleLean": (0x03, 0x5E), "LeanWarning": (0xAC, 0xF1), "Status": (0xC9, 0x94),
             "VehicleMotion": (0xEF, 0xB2), "Health": (0x8A, 0xD7), "PoleTilt": (0x25, 0x78),
             "GroundPlane": (0x40, 0x1D), "GroundHazard": (0x69, 0x34)}
    frames = [(fr.arbitration_id.id, False, bytes([table[fr.name][c], c]) + bytes(6), fr.name, c)
              for fr in db.frames for c in (0, 1)]
    pcap = os.path.join(args.work, "messages.pcap")
    write_pcap(pcap, [f[:3] for f in frames])
    rows = tshark(args, pcap, dbc)
    bad = [f"{n} counter {c}: {r}" for (_, _, _, n, c), r in zip(frames, rows)
           if r["msg"] != n or r["crc"] != "good" or r["e2e"] != ("INITIAL" if c == 0 else "OK")]
    check(len(rows) == 2 * len(table) and not bad, f"per-message vectors ({len(table)} messages x counter 0, 1) verify" +
          ("" if not bad else ": " + "; ".join(bad[:3])))
    h = next(fr for fr in sl.load_dbc(os.path.join(args.src, "boards", "paper-sim-29bit", "shadowlean.dbc")).frames
             if fr.name == "Health")
    pcap = os.path.join(args.work, "health11c.pcap")
    write_pcap(pcap, [(h.arbitration_id.id, True, bytes.fromhex(x)) for x in ("5c30000000000000", "0131000000000000")])
    rows = tshark(args, pcap, os.path.join(args.src, "boards", "paper-sim-29bit", "shadowlean.dbc"))
    check([(r["crc"], r["e2e"]) for r in rows] == [("good", "INITIAL"), ("good", "OK")],
          f"Health 11C (Data ID 0x0355, 29-bit id) vectors 5C 30 / 01 31 verify: {[(r['crc'], r['e2e']) for r in rows]}")

    # 2. The daemon's demo log.
    frames = sl.read_candump(os.path.join(args.src, "tests", "system", "daemon", "golden", "demo_three_poles.candump"))
    pcap = os.path.join(args.work, "demo.pcap")
    write_pcap(pcap, [(f.can_id, f.is_eff, f.data) for f in frames])
    compare_with_package(tshark(args, pcap, dbc), [sl.decode(db, f.can_id, f.is_eff, f.data) for f in frames],
                         "demo log (paper-sim)")

    # 3. 29-bit ids, Health in 11C.
    b29 = "paper-sim-29bit"
    dbc29 = os.path.join(args.src, "boards", b29, "shadowlean.dbc")
    log = os.path.join(args.work, "gen29.log")
    subprocess.run([args.gen, b29, "600", "7", log, log + ".expect"], check=True, capture_output=True)
    db29 = sl.load_dbc(dbc29)
    frames = sl.read_candump(log)
    check(frames and all(f.is_eff for f in frames), f"{b29}: {len(frames)} generated frames, all 29-bit")
    pcap = os.path.join(args.work, "gen29.pcap")
    write_pcap(pcap, [(f.can_id, f.is_eff, f.data) for f in frames])
    compare_with_package(tshark(args, pcap, dbc29), [sl.decode(db29, f.can_id, f.is_eff, f.data) for f in frames],
                         f"{b29} (29-bit ids, Health 11C)")

    # 4. Repetition, lost frame, corrupted CRC.
    status = [f for f in sl.read_candump(os.path.join(args.src, "tests", "system", "daemon", "golden",
                                                      "demo_three_poles.candump"))
              if sl.decode(db, f.can_id, f.is_eff, f.data).name == "Status"]
    bad = bytearray(status[4].data)
    bad[0] ^= 0x5A
    seq = [status[0], status[1], status[1], status[3], status[4]._replace(data=bytes(bad)), status[4]]
    pcap = os.path.join(args.work, "faults.pcap")
    write_pcap(pcap, [(f.can_id, f.is_eff, f.data) for f in seq])
    got = [r["e2e"] for r in tshark(args, pcap, dbc)]
    want = ["INITIAL", "OK", "REPEATED", "WRONG_SEQUENCE", "ERROR", "OK"]
    check(got == want, f"faults, max delta counter 1: {got}")
    got = [r["e2e"] for r in tshark(args, pcap, dbc, ["-o", "shadowlean.max_delta_counter:3"])]
    want[3] = "OK_SOME_LOST"
    check(got == want, f"faults, max delta counter 3: {got}")

    # 5. No DBC.
    r = subprocess.run([args.tshark, "-n", "-X", "lua_script:" + args.dissector, "-o",
                        "shadowlean.dbc:/nonexistent/board.dbc", "-r", pcap, "-T", "fields", "-e",
                        "shadowlean.message"], capture_output=True, text=True, env=dict(os.environ, HOME=args.work))
    check("cannot open DBC /nonexistent/board.dbc" in r.stderr and not r.stdout.strip(),
          "a missing DBC is reported by name and claims no frame")
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
