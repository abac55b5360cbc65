# SPDX-License-Identifier: MIT
"""python3 -m shadowlean: decode and verify shadowlean CAN frames with a board's DBC.

  python3 -m shadowlean decode LOG --dbc BOARD.dbc [--summary | --table [--last K] | --ground]
                             [--check]
  python3 -m shadowlean live --dbc BOARD.dbc [--channel vcan0] [--interface socketcan]
                             [--count N] [--idle-exit S] [--check]

Exit status: 0 ok, 1 error (file unreadable or malformed, bus cannot be opened, no frame
the DBC knows, or with --check any frame the E2E Profile 11 check does not accept (ERROR:
CRC, Data ID nibble, counter 15, wrong length; REPEATED; WRONG_SEQUENCE) or frames lost),
2 usage. --max-delta-counter N (1..14, default 1): counter steps 2..N are OK_SOME_LOST;
--timeout S: a gap of more than S seconds in a message is NO_NEW_DATA (not an error) and
restarts its sequence."""
import argparse
import sys

from . import __version__
from .bus import frames_from_bus, open_bus
from .candump import read_candump
from .dbc import decode, decode_frames, load_dbc
from .e2e import E2EMonitor
from .report import format_frame, print_e2e, print_frames, print_ground, print_summary, print_table

PROG = "python3 -m shadowlean"


def _parser():
    p = argparse.ArgumentParser(
        prog=PROG, description="Decode and verify (E2E CRC and counters) the CAN frames of a "
        "shadowlean module with the board's generated DBC.",
        epilog="Exit status: 0 ok, 1 error (or E2E errors with --check), 2 usage.")
    p.add_argument("--version", action="version", version=f"shadowlean {__version__}")
    sub = p.add_subparsers(dest="cmd", metavar="COMMAND")
    d = sub.add_parser("decode", help="decode a candump -L log (\"-\": stdin)",
                       description="Decode every frame of a candump -L log.")
    d.add_argument("log", metavar="LOG")
    d.add_argument("--dbc", required=True, help="the board's DBC (boards/<b>/shadowlean.dbc, "
                   "installed as /usr/share/shadowlean/dbc/<board>.dbc)")
    g = d.add_mutually_exclusive_group()
    g.add_argument("--summary", action="store_true", help="one line per Status frame")
    g.add_argument("--table", action="store_true", help="PoleLean rows per rotation")
    g.add_argument("--ground", action="store_true", help="one line per GroundPlane frame: "
                   "the plane and the rotation's GroundHazard frames")
    d.add_argument("--last", type=int, metavar="K", help="--table: only the last K rotations")
    d.add_argument("--check", action="store_true",
                   help="E2E Profile 11 check per message (CRC, Data ID nibble, counter "
                   "sequence); the status counts at the end; exit 1 on any error")
    d.add_argument("--max-delta-counter", type=int, default=1, metavar="N",
                   help="--check: largest counter step still OK_SOME_LOST (1..14, default 1)")
    d.add_argument("--timeout", type=float, metavar="S",
                   help="--check: a gap of more than S seconds in a message is NO_NEW_DATA "
                   "and restarts its sequence (default: none)")
    v = sub.add_parser("live", help="decode frames from a live bus (python-can)",
                       description="Decode frames as they arrive on a CAN bus (python-can).")
    v.add_argument("--dbc", required=True, help="the board's DBC")
    v.add_argument("--channel", default="can0", help="bus channel (default can0)")
    v.add_argument("--interface", default="socketcan",
                   help="python-can interface (default socketcan; virtual for tests)")
    v.add_argument("--count", type=int, metavar="N", help="stop after N frames of the DBC "
                   "(other ids are printed but not counted)")
    v.add_argument("--idle-exit", type=float, metavar="S", help="stop after S seconds without a frame")
    v.add_argument("--check", action="store_true", help="as for decode")
    v.add_argument("--max-delta-counter", type=int, default=1, metavar="N", help="as for decode")
    v.add_argument("--timeout", type=float, metavar="S", help="as for decode")
    return p


def _decode(a):
    db = load_dbc(a.dbc)
    decoded = decode_frames(db, read_candump(a.log))
    known = sum(1 for _, x in decoded if x is not None)
    mon = E2EMonitor(db, max_delta_counter=a.max_delta_counter, timeout=a.timeout) if a.check else None
    if a.summary:
        print_summary(decoded)
    elif a.table:
        print_table(decoded, last=a.last)
    elif a.ground:
        print_ground(decoded)
    else:
        print_frames(decoded, monitor=mon)
    if mon is not None and (a.summary or a.table or a.ground):
        for f, x in decoded:
            mon.check(x, f.data, f.t)
    if known == 0:
        print(f"{PROG}: {a.log}: no frame of this DBC ({len(decoded)} frames)", file=sys.stderr)
        return 1
    return _verdict(mon)


def _verdict(mon):
    if mon is None:
        return 0
    print_e2e(mon)
    if mon.errors():
        print(f"{PROG}: E2E check failed: {mon.errors()} frame(s) rejected or lost", file=sys.stderr)
        return 1
    return 0


def _live(a):
    db = load_dbc(a.dbc)
    mon = E2EMonitor(db, max_delta_counter=a.max_delta_counter, timeout=a.timeout) if a.check else None
    try:
        bus = open_bus(a.channel, a.interface)
    except Exception as e:  # python-can raises OSError, CanError, ValueError...
        print(f"{PROG}: cannot open {a.interface} bus {a.channel}: {e}", file=sys.stderr)
        return 1
    known = 0
    try:
        for f in frames_from_bus(bus, timeout=0.2, idle_limit=a.idle_exit):
            d = decode(db, f.can_id, f.is_eff, f.data)
            known += d is not None
            e2e = mon.check(d, f.data, f.t) if mon is not None else None
            print(format_frame(f, d, e2e), flush=True)
            if a.count is not None and known >= a.count:
                break
    except KeyboardInterrupt:
        pass
    finally:
        bus.shutdown()
    if known == 0:
        print(f"{PROG}: no frame of this DBC received", file=sys.stderr)
        return 1
    return _verdict(mon)


def main(argv=None):
    a = _parser().parse_args(argv)
    if a.cmd is None:
        _parser().print_usage(sys.stderr)
        print(f"{PROG}: a COMMAND is needed (decode, live)", file=sys.stderr)
        return 2
    if a.timeout is not None and not a.timeout > 0:
        _parser().print_usage(sys.stderr)
        print(f"{PROG}: --timeout {a.timeout}: seconds > 0", file=sys.stderr)
        return 2
    if not 1 <= a.max_delta_counter <= 14:
        _parser().print_usage(sys.stderr)
        print(f"{PROG}: --max-delta-counter {a.max_delta_counter}: 1..14", file=sys.stderr)
        return 2
    if a.cmd == "decode" and a.last is not None and not a.table:
        _parser().print_usage(sys.stderr)
        print(f"{PROG}: --last needs --table", file=sys.stderr)
        return 2
    try:
        return _decode(a) if a.cmd == "decode" else _live(a)
    except (OSError, ValueError) as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
