# SPDX-License-Identifier: MIT
"""candump -L logs (can-utils' log format, also written by shadowleand --can-log):

    (1700000000.250000) can0 621#0400000000000060
    (1700000000.250000) can0 12345678#00         29-bit id: 8 hex digits
    (1700000000.250000) can0 123#R               remote frame (data None)

A line that is not in this format is an error naming the file and line."""
import re
import sys
from typing import NamedTuple, Optional

_LINE = re.compile(r"^\((\d+)\.(\d+)\)\s+(\S+)\s+([0-9A-Fa-f]{3}|[0-9A-Fa-f]{8})#(R\d?|[0-9A-Fa-f.]*)\s*[RT]?\s*$")


class Frame(NamedTuple):
    """One CAN frame: time in seconds, interface name, id, 29-bit flag, payload (None: RTR)."""
    t: float
    iface: str
    can_id: int
    is_eff: bool
    data: Optional[bytes]


def parse_candump_line(line):
    """A Frame from one candump -L line; None for a blank line; ValueError when malformed."""
    s = line.strip()
    if not s:
        return None
    m = _LINE.match(s)
    if not m:
        raise ValueError(f"not a candump -L line: {s!r}")
    sec, frac, iface, cid, payload = m.groups()
    t = int(sec) + int(frac) / 10 ** len(frac)
    if payload.startswith("R"):
        data = None
    else:
        payload = payload.replace(".", "")
        if len(payload) % 2:
            raise ValueError(f"odd number of hex digits: {s!r}")
        data = bytes.fromhex(payload)
    return Frame(t, iface, int(cid, 16), len(cid) == 8, data)


def read_candump(path):
    """Every frame of a candump -L log ("-": stdin) as a list of Frame. Raises ValueError
    "<path>:<line>: ..." on a malformed line, OSError when the file cannot be read."""
    out = []
    fh = sys.stdin if path == "-" else open(path, encoding="ascii", errors="replace")
    with fh:
        for n, line in enumerate(fh, 1):
            try:
                f = parse_candump_line(line)
            except ValueError as e:
                raise ValueError(f"{path}:{n}: {e}") from None
            if f is not None:
                out.append(f)
    return out
