# SPDX-License-Identifier: MIT
"""E2E protection of every shadowlean message (include/shadowlean/sl_can.h, the DBC's
comment): byte 0 = CRC-8 SAE J1850 (poly 0x1D, init 0xFF, final XOR 0xFF, not reflected)
over [Data ID, data bytes 1..7]; bits 8..11 = Counter, 0..14 per message type, modulo 15,
15 never sent. A receiver accepts delta = (counter - previous) mod 15 of 1, counts
delta >= 2 as a jump (delta - 1 frames lost) and rejects delta 0 (repetition), counter 15
and CRC mismatches. E2EMonitor applies exactly these rules, one sequence per message."""
from dataclasses import dataclass


def crc8_j1850(data):
    """CRC-8 SAE J1850 of a byte string (check value: b"123456789" -> 0x4B)."""
    reg = 0xFF
    for b in data:
        reg ^= b
        for _ in range(8):
            reg = ((reg << 1) ^ 0x1D) & 0xFF if reg & 0x80 else (reg << 1) & 0xFF
    return reg ^ 0xFF


def e2e_crc(data_id, data):
    """The CRC byte a frame must carry: CRC-8 over [data_id, data[1:8]]."""
    return crc8_j1850(bytes([data_id & 0xFF]) + bytes(data[1:8]))


# Statuses E2EMonitor.check returns; every one but "ok" and "jump" rejects the frame.
E2E_ERRORS = ("length", "crc", "counter_invalid", "repeated", "unknown_id")


@dataclass
class E2EStats:
    """Per message (the same counts as the C receiver's sl_can_e2e_stats_t)."""
    accepted: int = 0
    bad_length: int = 0
    crc_errors: int = 0
    bad_counter: int = 0
    repeated: int = 0
    counter_jumps: int = 0
    lost_frames: int = 0

    def errors(self):
        """Frames rejected or lost: 0 for a clean sequence."""
        return self.bad_length + self.crc_errors + self.bad_counter + self.repeated + self.lost_frames


class E2EMonitor:
    """Checks a stream of decoded frames: CRC and one counter sequence per message name.
    The modulo of each message comes from its DBC Counter signal (db given) or is 15."""

    def __init__(self, db=None, modulo=15):
        self._db = db
        self._default_modulo = modulo
        self._last = {}        # name -> last accepted counter
        self._mod = {}         # name -> counter modulo
        self.stats = {}        # name -> E2EStats
        self.unknown = 0       # frames whose id the DBC does not know

    def _modulo(self, name):
        if name in self._mod:
            return self._mod[name]
        self._mod[name] = self._lookup_modulo(name)
        return self._mod[name]

    def _lookup_modulo(self, name):
        if self._db is not None:
            from .dbc import counter_modulo
            for fr in self._db.frames:
                if fr.name == name:
                    m = counter_modulo(fr)
                    if m:
                        return m
        return self._default_modulo

    def reset(self, name=None):
        """Forget the counter sequence (of one message, or of all): after a reception gap."""
        if name is None:
            self._last.clear()
        else:
            self._last.pop(name, None)

    def check(self, decoded, data=None):
        """One frame (a dbc.Decoded or None for an unknown id). Returns "ok", "jump"
        (accepted, frames lost before it) or an error of E2E_ERRORS."""
        if decoded is None:
            self.unknown += 1
            return "unknown_id"
        st = self.stats.setdefault(decoded.name, E2EStats())
        if not decoded.length_ok:
            st.bad_length += 1
            return "length"
        if not decoded.crc_ok:
            st.crc_errors += 1
            return "crc"
        mod = self._modulo(decoded.name)
        c = decoded.counter
        if c < 0 or c >= mod:
            st.bad_counter += 1
            return "counter_invalid"
        status = "ok"
        if decoded.name in self._last:
            delta = (c - self._last[decoded.name]) % mod
            if delta == 0:
                st.repeated += 1
                return "repeated"
            if delta > 1:
                st.counter_jumps += 1
                st.lost_frames += delta - 1
                status = "jump"
        self._last[decoded.name] = c
        st.accepted += 1
        return status

    def errors(self):
        """Total of rejected and lost frames over all messages (unknown ids not counted)."""
        return sum(s.errors() for s in self.stats.values())
