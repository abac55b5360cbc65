# SPDX-License-Identifier: MIT
"""Unit tests of the shadowlean Python package (unittest, Debian's /usr/bin/python3).

Input: the boards' generated DBCs and the candump logs the daemon wrote for the demo scene
and the real Oxford scans (tests/system/daemon/golden). Environment: SL_SOURCE_DIR (the checkout),
SL_PYTHON_PATH (where the package is imported from: the source tree or an install root)."""
import contextlib
import io
import os
import subprocess
import sys
import tempfile
import unittest

SRC = os.environ.get("SL_SOURCE_DIR") or os.path.join(os.path.dirname(__file__), "..", "..")
PYPATH = os.environ.get("SL_PYTHON_PATH") or os.path.join(SRC, "python")
sys.path.insert(0, PYPATH)

import shadowlean as sl  # noqa: E402
from shadowlean.__main__ import main as cli  # noqa: E402

GOLDEN = os.path.join(SRC, "tests", "system", "daemon", "golden")
LOGS = {  # log -> board whose DBC the daemon used
    "demo_three_poles.candump": "paper-sim",
    "oxford_robotcar.candump": "robotcar-leaf",
}


def dbc_of(board):
    return os.path.join(SRC, "boards", board, "shadowlean.dbc")


def run_cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = cli(argv)
        except SystemExit as e:  # argparse: --help, --version, usage errors
            rc = e.code
    return rc, out.getvalue(), err.getvalue()


def with_crc(db, name, data):
    """data with byte 0 set to the E2E CRC of message `name` (for crafted frames)."""
    fr = next(f for f in db.frames if f.name == name)
    data = bytearray(data)
    data[0] = sl.e2e_crc(int(fr.attributes["SlE2EDataId"]), data)
    return bytes(data)


class Crc(unittest.TestCase):
    def test_check_values(self):
        # SAE J1850 (start 0xFF, XOR 0xFF) and the Profile 11 form (start 0x00, no XOR).
        self.assertEqual(sl.crc8_j1850(b"123456789"), 0x4B)
        self.assertEqual(sl.crc8_0x1d(b"123456789"), 0x37)

    def test_independent_profile_11_vectors(self):
        # Vectors of two implementations that are not this one: the `autosar-e2e` Rust
        # crate (src/profiles/profile11.rs) and the `autosar-e2e` Python package
        # (zariiii9003/autosar-e2e, test/test_p01.py): 8 zero bytes, Data ID 0x123.
        zero = bytes(8)
        self.assertEqual(sl.protect(0x123, zero, 0, sl.MODE_BOTH), bytes.fromhex("cc00000000000000"))
        self.assertEqual(sl.protect(0x123, zero, 1, sl.MODE_BOTH), bytes.fromhex("9101000000000000"))
        self.assertEqual(sl.protect(0x123, zero, 0, sl.MODE_NIBBLE), bytes.fromhex("2a10000000000000"))
        self.assertEqual(sl.protect(0x123, zero, 1, sl.MODE_NIBBLE), bytes.fromhex("7711000000000000"))
        # The Python package's negative vectors: a counter bit flipped under an 11A CRC,
        # a nibble of 2 instead of 1 under 11C.
        self.assertNotEqual(sl.e2e_crc(0x123, bytes.fromhex("cc10000000000000")), 0xCC)
        self.assertNotEqual(sl.e2e_crc(0x123, bytes.fromhex("7721000000000000"), sl.MODE_NIBBLE), 0x77)

    def test_every_message_matches_its_vectors(self):
        # 8 zero bytes but the counter (0, then 1), each message's Data ID from the board's
        # DBC in its mode; the same table as unit_canmsg and the dissector test (CRC bytes
        # from tests/system/daemon/p11_frames.py, the AUTOSAR library chaining).
        vectors = {"PoleLean": (0x03, 0x5E), "LeanWarning": (0xAC, 0xF1), "Status": (0xC9, 0x94),
                   "VehicleMotion": (0xEF, 0xB2), "Health": (0x8A, 0xD7), "PoleTilt": (0x25, 0x78),
                   "GroundPlane": (0x40, 0x1D), "GroundHazard": (0x69, 0x34)}
        db = sl.load_dbc(dbc_of("paper-sim"))
        self.assertEqual(sorted(fr.name for fr in db.frames), sorted(vectors))
        for fr in db.frames:
            data_id = int(fr.attributes["SlE2EDataId"])
            for ctr in (0, 1):
                self.assertEqual(sl.protect(data_id, bytes(8), ctr)[0], vectors[fr.name][ctr], fr.name)
        self.assertEqual(sl.protect(0x0355, bytes(8), 0, sl.MODE_NIBBLE), bytes.fromhex("5c30000000000000"))
        self.assertEqual(sl.protect(0x0355, bytes(8), 1, sl.MODE_NIBBLE), bytes.fromhex("0131000000000000"))

    def test_pole_tilt_mirror_reading_decodes_by_name(self):
        # The other reading of an AMBIGUOUS tilt: Quality 5 MIRROR, its values as any reading's
        # (TargetId 2, Tilt 15.9 deg, TiltDirection 110 deg, BaseY -2.5 m).
        db = sl.load_dbc(dbc_of("paper-sim"))
        fr = next(f for f in db.frames if f.name == "PoleTilt")
        raw = (5 << 12) | (2 << 16) | (159 << 20) | (110 << 28) | ((-50 & 0xFF) << 56)
        d = sl.decode(db, fr.arbitration_id.id, False, with_crc(db, "PoleTilt", raw.to_bytes(8, "little")))
        self.assertTrue(d.crc_ok and d.reencode_ok)
        self.assertEqual(d.named["Quality"], "MIRROR")
        self.assertEqual(d.raw["TargetId"], 2)
        self.assertAlmostEqual(d.phys["Tilt"], 15.9)
        self.assertAlmostEqual(d.phys["TiltDirection"], 110.0)
        self.assertAlmostEqual(d.phys["BaseY"], -2.5)

    def test_ground_frames_decode_as_the_core_encoded_them(self):
        # The bytes unit_canmsg pins for the C encoder (counter 0): GroundPlane GOOD, 2.58 m,
        # pitch +1.5 deg, roll -1.0 deg, sigmas 10 mm / 0.2 / 0.25 deg; GroundHazard DROP in
        # sector 3 at 33.8 deg, 0.2 m lower, 3.46 m away, sigma 30 mm.
        db = sl.load_dbc(dbc_of("paper-sim"))
        ids = {fr.name: fr.arbitration_id.id for fr in db.frames}
        p = sl.decode(db, ids["GroundPlane"], False, bytes.fromhex("1b20855a82f30529"))
        self.assertTrue(p.length_ok and p.crc_ok and p.reencode_ok)
        self.assertEqual((p.name, p.named["Quality"], p.raw["Clamped"], p.counter), ("GroundPlane", "GOOD", 0, 0))
        for sig, want in (("Height", 2.58), ("Pitch", 1.5), ("Roll", -1.0), ("HeightSigma", 0.01),
                          ("PitchSigma", 0.2), ("RollSigma", 0.25)):
            self.assertAlmostEqual(p.phys[sig], want, places=6, msg=sig)
        h = sl.decode(db, ids["GroundHazard"], False, bytes.fromhex("eb108354605f2b06"))
        self.assertTrue(h.length_ok and h.crc_ok and h.reencode_ok)
        self.assertEqual((h.name, h.named["Kind"], h.raw["Sector"]), ("GroundHazard", "DROP", 3))
        for sig, want in (("Azimuth", 33.8), ("HeightDiff", -0.2), ("Distance", 3.46), ("Sigma", 0.03)):
            self.assertAlmostEqual(h.phys[sig], want, places=6, msg=sig)
        self.assertEqual(sl.HAZARD_KIND[h.raw["Kind"]], "DROP")
        self.assertIn("DROP az 33.8° -0.200 m at 3.46 m", sl.format_ground(p, [h]))
        # A GroundPlane payload under the GroundHazard id fails the CRC (its Data ID differs).
        self.assertFalse(sl.decode(db, ids["GroundHazard"], False, bytes.fromhex("1b20855a82f30529")).crc_ok)
        # A STEP with its numbers at the signals' limits, Clamped set: decoded as such.
        raw = (2 << 12) | (1 << 14) | (63 << 16) | (3599 << 22) | (1023 << 34) | (2047 << 45) | (255 << 56)
        h = sl.decode(db, ids["GroundHazard"], False, with_crc(db, "GroundHazard", raw.to_bytes(8, "little")))
        self.assertTrue(h.crc_ok and h.reencode_ok)
        self.assertEqual((h.named["Kind"], h.raw["Clamped"], h.raw["Sector"]), ("STEP", 1, 63))
        for sig, want in (("Azimuth", 359.9), ("HeightDiff", 5.115), ("Distance", 20.47), ("Sigma", 1.275)):
            self.assertAlmostEqual(h.phys[sig], want, places=6, msg=sig)

    def test_worked_example_of_sl_can_h(self):
        # Status, Data ID 0x0053 (11A), bytes 1..7 = 30 02 00 00 00 00 00 -> CRC 0x93.
        self.assertEqual(sl.e2e_crc(0x0053, bytes.fromhex("0030020000000000")), 0x93)

    def test_both_data_id_bytes_change_the_crc(self):
        frame = bytes.fromhex("0030020000000000")
        self.assertNotEqual(sl.e2e_crc(0x0053, frame), sl.e2e_crc(0x0051, frame))
        self.assertNotEqual(sl.e2e_crc(0x0053, frame), sl.e2e_crc(0x0153, frame))
        # 11C leaves the high byte out of the CRC (it travels in the frame instead).
        self.assertEqual(sl.e2e_crc(0x0053, frame, sl.MODE_NIBBLE), sl.e2e_crc(0x0153, frame, sl.MODE_NIBBLE))


class Candump(unittest.TestCase):
    def test_formats(self):
        f = sl.parse_candump_line("(1700000000.250000) can0 621#0400000000000060\n")
        self.assertEqual(f, sl.Frame(1700000000.25, "can0", 0x621, False, bytes.fromhex("0400000000000060")))
        f = sl.parse_candump_line("(1.5) vcan1 1ABCDEF0#01.02")
        self.assertEqual((f.can_id, f.is_eff, f.data, f.t), (0x1ABCDEF0, True, b"\x01\x02", 1.5))
        f = sl.parse_candump_line("(2.000001) can0 300#R")
        self.assertIsNone(f.data)
        self.assertIsNone(sl.parse_candump_line("   \n"))

    def test_bad_line_names_file_and_line(self):
        with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as fh:
            fh.write("(1.0) can0 621#0400000000000060\nthis is not candump\n")
        try:
            with self.assertRaisesRegex(ValueError, r":2: not a candump -L line"):
                sl.read_candump(fh.name)
            rc, _, err = run_cli(["decode", fh.name, "--dbc", dbc_of("paper-sim")])
            self.assertEqual(rc, 1)
            self.assertIn(":2:", err)
        finally:
            os.unlink(fh.name)


class GoldenLogs(unittest.TestCase):
    """The daemon's own frames: every one known to the board's DBC, CRC and counters clean."""

    def test_every_frame_decodes_and_verifies(self):
        for log, board in LOGS.items():
            with self.subTest(log=log):
                db = sl.load_dbc(dbc_of(board))
                frames = sl.read_candump(os.path.join(GOLDEN, log))
                self.assertGreater(len(frames), 10)
                mon = sl.E2EMonitor(db)
                counters = {}
                for f, d in sl.decode_frames(db, frames):
                    self.assertIsNotNone(d, f"{log}: id {f.can_id:X} not in the DBC")
                    self.assertTrue(d.length_ok and d.crc_ok and d.reencode_ok, f"{log}: {f}")
                    self.assertIn(mon.check(d, f.data), ("INITIAL", "OK"))
                    # counters run 0, 1, ... per message from the daemon's start, modulo 15
                    n = counters.get(d.name, 0)
                    self.assertEqual(d.counter, n % 15, f"{log}: {d.name} #{n}")
                    counters[d.name] = n + 1
                self.assertEqual(mon.errors(), 0)
                # one Status per rotation, each followed by its Health
                self.assertEqual(counters.get("Status"), counters.get("Health"))
                self.assertGreaterEqual(counters.get("Status", 0), 5)

    def test_one_ground_plane_per_rotation(self):
        # The daemon's ground (on by default): one GroundPlane per rotation, before its Status;
        # the demo's flat ground under paper-sim's radar at 2.58 m: GOOD, level, no hazard.
        for log, board in LOGS.items():
            with self.subTest(log=log):
                decoded = sl.decode_log(dbc_of(board), os.path.join(GOLDEN, log))
                names = [d.name for _, d in decoded]
                self.assertEqual(names.count("GroundPlane"), names.count("LeanWarning"))
                self.assertEqual(names.count("GroundPlane"), len(sl.groups(decoded)))
                for i, n in enumerate(names):
                    if n == "GroundPlane":  # after the rotation's LeanWarning, its hazards, Status
                        self.assertEqual(names[i - 1], "LeanWarning")
                        rest = [x for x in names[i + 1:] if x != "GroundHazard"]
                        self.assertEqual(rest[0], "Status")
        ground = sl.ground(sl.decode_log(dbc_of("paper-sim"), os.path.join(GOLDEN, "demo_three_poles.candump")))
        self.assertGreaterEqual(len(ground), 20)
        for plane, hazards in ground:
            self.assertEqual(plane.named["Quality"], "GOOD")
            self.assertAlmostEqual(plane.phys["Height"], 2.58, delta=0.05)
            self.assertAlmostEqual(plane.phys["Pitch"], 0.0, delta=0.3)
            self.assertAlmostEqual(plane.phys["Roll"], 0.0, delta=0.3)
            self.assertEqual(hazards, [])

    def test_demo_scene_warns_of_the_right_pole(self):
        decoded = sl.decode_log(dbc_of("paper-sim"), os.path.join(GOLDEN, "demo_three_poles.candump"))
        st, warn, poles = sl.groups(decoded)[-1]
        self.assertEqual(sl.LINK[st.raw["LinkState"]], "STREAMING")
        # scenes/demo_three_poles.ini: +12 deg at 90 deg, +6 at 180, -6 at 270
        self.assertEqual(sorted(round(p.phys["Azimuth"]) for p in poles), [90, 180, 270])
        self.assertEqual(warn.named.get("Level", sl.LEVEL[warn.raw["Level"]]), "DANGER")
        self.assertAlmostEqual(warn.phys["Azimuth"], 90.0, delta=1.0)
        self.assertAlmostEqual(warn.phys["Lean"], 12.0, delta=2.0)


class E2E(unittest.TestCase):
    """The Profile 11 check statuses on the daemon's Status frames."""

    def setUp(self):
        self.db = sl.load_dbc(dbc_of("paper-sim"))
        self.frames = [f for f in sl.read_candump(os.path.join(GOLDEN, "demo_three_poles.candump"))]
        self.status_id = sl.frame_of(self.db, 0x5C2, False).arbitration_id.id
        self.status = [f for f in self.frames if f.can_id == self.status_id]

    def verdicts(self, frames, max_delta_counter=1):
        mon = sl.E2EMonitor(self.db, max_delta_counter=max_delta_counter)
        return [mon.check(sl.decode(self.db, f.can_id, f.is_eff, f.data), f.data) for f in frames], mon

    def test_lost_frames_are_some_lost_or_wrong_sequence_by_the_max_delta(self):
        v, mon = self.verdicts(self.status[:3] + self.status[5:7])
        self.assertEqual(v, ["INITIAL", "OK", "OK", "WRONG_SEQUENCE", "OK"])
        self.assertEqual(mon.stats["Status"].lost_frames, 2)
        self.assertEqual(mon.errors(), 3)  # the rejected frame and the two lost
        v, mon = self.verdicts(self.status[:3] + self.status[5:7], max_delta_counter=3)
        self.assertEqual(v, ["INITIAL", "OK", "OK", "OK_SOME_LOST", "OK"])
        self.assertEqual(mon.errors(), 2)

    def test_repetition_is_rejected(self):
        v, mon = self.verdicts(self.status[:3] + [self.status[2]] + self.status[3:4])
        self.assertEqual(v, ["INITIAL", "OK", "OK", "REPEATED", "OK"])
        self.assertEqual(mon.stats["Status"].repeated, 1)

    def test_flipped_bit_fails_the_crc(self):
        f = self.status[1]
        bad = f._replace(data=bytes([f.data[0]]) + bytes([f.data[1] ^ 0x40]) + f.data[2:])
        v, mon = self.verdicts([self.status[0], bad, self.status[2]], max_delta_counter=2)
        self.assertEqual(v, ["INITIAL", "ERROR", "OK_SOME_LOST"])
        self.assertEqual(mon.stats["Status"].crc_errors, 1)

    def test_frame_copied_to_another_id_fails_the_crc(self):
        # A Status payload sent with the PoleLean id: the Data ID differs, so the CRC fails.
        f = self.status[1]._replace(can_id=sl.frame_of(self.db, 0x5C0, False).arbitration_id.id)
        v, _ = self.verdicts([f])
        self.assertEqual(v, ["ERROR"])

    def test_counter_15_is_invalid_even_with_a_good_crc(self):
        f = self.status[1]
        data = bytearray(f.data)
        data[1] = (data[1] & 0xF0) | 15
        v, mon = self.verdicts([f._replace(data=with_crc(self.db, "Status", data))])
        self.assertEqual(v, ["ERROR"])
        self.assertEqual(mon.stats["Status"].bad_counter, 1)

    def test_nibble_mode_checks_the_sent_data_id_bits(self):
        # Health in mode 11C (Data ID 0x0355): bits 12..15 must carry 3.
        dec = sl.dbc.Decoded("Health", 0x5C3, length_ok=True, data_id=0x0355, mode=sl.MODE_NIBBLE)
        mon = sl.E2EMonitor()
        good = sl.protect(0x0355, bytes(8), 4, sl.MODE_NIBBLE)
        bad = bytes([sl.e2e_crc(0x0355, b"\x00\x25" + bytes(6), sl.MODE_NIBBLE), 0x25]) + bytes(6)
        for data, want in ((good, "INITIAL"), (bad, "ERROR")):
            d = sl.dbc.Decoded(**{**dec.__dict__})
            d.counter = data[1] & 0x0F
            d.crc_ok = data[0] == sl.e2e_crc(0x0355, data, sl.MODE_NIBBLE)
            d.nibble_ok = (data[1] >> 4) == 3
            self.assertEqual(mon.check(d, data), want)
        self.assertEqual(mon.stats["Health"].bad_nibble, 1)

    def test_reception_gap_is_no_new_data_and_restarts_the_sequence(self):
        # With a 0.5 s timeout (the module's VehicleMotion receiver's): Status frames 250 ms
        # apart are in sequence; after a 2 s gap even a repetition is INITIAL, as after a
        # start (nothing to check it against), and the gap is one NO_NEW_DATA.
        mon = sl.E2EMonitor(self.db, timeout=0.5)
        seq = [(self.status[0], 0.0), (self.status[1], 0.25), (self.status[1], 2.25), (self.status[2], 2.5)]
        v = [mon.check(sl.decode(self.db, f.can_id, f.is_eff, f.data), f.data, t) for f, t in seq]
        self.assertEqual(v, ["INITIAL", "OK", "INITIAL", "OK"])
        self.assertEqual(mon.stats["Status"].no_new_data, 1)
        self.assertEqual(mon.errors(), 0)
        with self.assertRaises(ValueError):
            sl.E2EMonitor(self.db, timeout=0)

    def test_wrong_length_and_unknown_id(self):
        f = self.status[1]
        v, mon = self.verdicts([f._replace(data=f.data[:7]), f._replace(can_id=0x7FF), f._replace(data=None)])
        self.assertEqual(v, ["ERROR", "UNKNOWN_ID", "ERROR"])
        self.assertEqual(mon.stats["Status"].bad_length, 2)
        self.assertEqual(mon.unknown, 1)

    def test_counter_wraps_modulo_15(self):
        # 16 Status frames sent in a row: 0..14, 0 -- accepted; the modulo comes from the DBC.
        msgs = self.status[:16]
        self.assertEqual([sl.decode(self.db, f.can_id, False, f.data).counter for f in msgs][-2:], [14, 0])
        v, mon = self.verdicts(msgs)
        self.assertEqual(v, ["INITIAL"] + ["OK"] * 15)


class PythonCanBus(unittest.TestCase):
    """Live decoding through python-can, on its virtual interface (no kernel CAN needed)."""

    def test_virtual_bus_gives_the_same_frames_as_the_log(self):
        import can
        log = os.path.join(GOLDEN, "demo_three_poles.candump")
        frames = sl.read_candump(log)[:60]
        chan = f"sl-test-{os.getpid()}"
        with can.Bus(interface="virtual", channel=chan) as tx, \
                sl.open_bus(chan, interface="virtual") as rx:
            for f in frames:
                tx.send(sl.message_from_frame(f))
            got = list(sl.frames_from_bus(rx, count=len(frames), timeout=0.5, idle_limit=10.0))
        self.assertEqual([(g.can_id, g.is_eff, g.data) for g in got],
                         [(f.can_id, f.is_eff, f.data) for f in frames])
        db = sl.load_dbc(dbc_of("paper-sim"))
        mon = sl.E2EMonitor(db)
        for g in got:
            self.assertIn(mon.check(sl.decode(db, g.can_id, g.is_eff, g.data), g.data), ("INITIAL", "OK"))

    def test_live_cli_decodes_and_checks_a_bus(self):
        # `python3 -m shadowlean live` on a python-can virtual bus: the frames are queued on
        # the receiving bus before the CLI reads it (no timing), then --count stops it.
        import can
        import shadowlean.__main__ as m
        frames = sl.read_candump(os.path.join(GOLDEN, "demo_three_poles.candump"))[:40]
        chan = f"sl-cli-{os.getpid()}"
        rx = can.Bus(interface="virtual", channel=chan)
        marker = sl.Frame(0.0, "can0", 0x7FF, False, b"SYNC")  # not in the DBC: not counted
        with can.Bus(interface="virtual", channel=chan) as tx:
            for f in [marker] + frames + [marker]:
                tx.send(sl.message_from_frame(f))
        opened = []
        real_open = m.open_bus
        m.open_bus = lambda channel, interface: opened.append((channel, interface)) or rx
        try:
            rc, out, err = run_cli(["live", "--dbc", dbc_of("paper-sim"), "--channel", "can7",
                                    "--count", str(len(frames)), "--check"])
        finally:
            m.open_bus = real_open
        self.assertEqual(opened, [("can7", "socketcan")])
        self.assertEqual(rc, 0, err)
        self.assertEqual(sum(1 for x in out.splitlines() if "crc=ok" in x), len(frames))
        self.assertEqual(sum(1 for x in out.splitlines() if "(unknown id)" in x), 1)  # stops at N
        self.assertRegex(out, r"\nStatus\s+\d+\s+0\s+1\s+0\s+0\s+0\s+0\s+0\s+0\s+0\s+0\s+0\n")

    def test_idle_limit_ends_a_silent_bus(self):
        chan = f"sl-idle-{os.getpid()}"
        with sl.open_bus(chan, interface="virtual") as rx:
            self.assertEqual(list(sl.frames_from_bus(rx, timeout=0.05, idle_limit=0.1)), [])

    def test_python_can_reads_the_log_like_the_package(self):
        import can
        log = os.path.join(GOLDEN, "oxford_robotcar.candump")
        ours = sl.read_candump(log)
        theirs = [sl.frame_from_message(m) for m in can.CanutilsLogReader(log)]
        self.assertEqual([(f.can_id, f.data) for f in ours], [(f.can_id, f.data) for f in theirs])
        self.assertEqual([round(f.t, 6) for f in ours], [round(f.t, 6) for f in theirs])


class Cli(unittest.TestCase):
    def test_decode_check_ok(self):
        rc, out, err = run_cli(["decode", os.path.join(GOLDEN, "demo_three_poles.candump"),
                                "--dbc", dbc_of("paper-sim"), "--check"])
        self.assertEqual(rc, 0, err)
        self.assertIn("crc=ok", out)
        self.assertNotIn("crc=BAD", out)
        self.assertRegex(out, r"\nStatus\s+\d+\s+0\s+1\s+0\s+0\s+0\s+0\s+0\s+0\s+0\s+0\s+0\n")

    def test_decode_check_fails_on_a_corrupt_log(self):
        lines = open(os.path.join(GOLDEN, "demo_three_poles.candump")).read().splitlines()
        # drop line 5 (a Status frame: a counter jump) and corrupt a data nibble of line 8
        del lines[4]
        head, data = lines[7].rsplit("#", 1)
        lines[7] = head + "#" + data[:3] + ("0" if data[3] != "0" else "1") + data[4:]
        with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as fh:
            fh.write("\n".join(lines) + "\n")
        try:
            rc, out, err = run_cli(["decode", fh.name, "--dbc", dbc_of("paper-sim"), "--check"])
        finally:
            os.unlink(fh.name)
        self.assertEqual(rc, 1)
        self.assertIn("crc=BAD", out)
        self.assertIn("e2e=WRONG_SEQUENCE", out)
        self.assertIn("E2E check failed", err)

    def test_summary_and_table(self):
        log = os.path.join(GOLDEN, "demo_three_poles.candump")
        rc, out, _ = run_cli(["decode", log, "--dbc", dbc_of("paper-sim"), "--table", "--last", "1"])
        self.assertEqual(rc, 0)
        self.assertEqual(len(out.splitlines()), 4)  # header + the three poles
        self.assertIn("DANGER", out)
        rc, out, _ = run_cli(["decode", log, "--dbc", dbc_of("paper-sim"), "--summary"])
        self.assertEqual(rc, 0)
        self.assertIn("more rotation(s) alike", out)
        rc, out, _ = run_cli(["decode", log, "--dbc", dbc_of("paper-sim"), "--ground", "--check"])
        self.assertEqual(rc, 0)
        lines = out.splitlines()
        self.assertTrue(lines[0].startswith("GOOD   height 2."), lines[0])
        self.assertIn("GroundPlane", out)  # the E2E counts of --check follow

    def test_no_frame_of_the_dbc_is_an_error(self):
        with tempfile.NamedTemporaryFile("w", suffix=".log", delete=False) as fh:
            fh.write("(1.0) can0 7FF#0011223344556677\n")
        try:
            rc, _, err = run_cli(["decode", fh.name, "--dbc", dbc_of("paper-sim")])
        finally:
            os.unlink(fh.name)
        self.assertEqual(rc, 1)
        self.assertIn("no frame of this DBC", err)

    def test_conventions(self):
        rc, out, _ = run_cli(["--help"])
        self.assertEqual(rc, 0)
        self.assertIn("decode", out)
        rc, out, _ = run_cli(["--version"])
        self.assertEqual((rc, out.strip()), (0, f"shadowlean {sl.__version__}"))
        self.assertRegex(sl.__version__, r"^\d+\.\d+\.\d+$")
        rc, _, err = run_cli(["decode", "x.log", "--dbc", "y.dbc", "--bogus"])
        self.assertEqual(rc, 2)
        self.assertIn("--bogus", err)
        rc, _, err = run_cli([])
        self.assertEqual(rc, 2)
        # A max delta counter outside Profile 11's 1..14 is a usage error, not a silent clamp.
        rc, _, err = run_cli(["decode", "x.log", "--dbc", "y.dbc", "--check", "--max-delta-counter", "15"])
        self.assertEqual(rc, 2)
        self.assertIn("1..14", err)
        rc, _, err = run_cli(["decode", "/nonexistent.log", "--dbc", dbc_of("paper-sim")])
        self.assertEqual(rc, 1)
        self.assertIn("/nonexistent.log", err)
        rc, _, err = run_cli(["live", "--dbc", dbc_of("paper-sim"), "--channel", "sl-no-such-can0",
                              "--count", "1"])
        self.assertEqual(rc, 1)
        self.assertIn("cannot open", err)

    def test_module_runs_and_imports_without_noise(self):
        # python3 -m shadowlean as a user runs it: nothing from canmatrix's import on stderr.
        env = dict(os.environ, PYTHONPATH=PYPATH)
        r = subprocess.run([sys.executable, "-m", "shadowlean", "decode",
                            os.path.join(GOLDEN, "oxford_robotcar.candump"), "--dbc",
                            dbc_of("robotcar-leaf"), "--check"], env=env, capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stderr, "")
        self.assertIn("Status", r.stdout)


if __name__ == "__main__":
    unittest.main()
