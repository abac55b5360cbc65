# SPDX-License-Identifier: MIT
"""E2E protection of every shadowlean message: AUTOSAR E2E Profile 11 with its default
offsets (include/shadowlean/sl_can.h, the DBC's comment). Byte 0 = CRC-8 (polynomial
0x1D, start value 0x00, not reflected, no final XOR) over the message's 16-bit Data ID
(DBC attribute SlE2EDataId): its low byte, then its high byte (mode 11A "both") or 0x00
(mode 11C "nibble", attribute SlE2EMode), then data bytes 1..7. Bits 8..11 = Counter,
0..14 per message type, modulo 15, 15 never sent; in mode 11C bits 12..15 carry the
Data ID's bits 8..11.

E2EMonitor classifies each frame with the Profile 11 check statuses: OK (counter step 1),
OK_SOME_LOST (step 2..max_delta_counter), REPEATED (step 0), WRONG_SEQUENCE (a larger
step), ERROR (length, CRC, Data ID nibble or counter 15), INITIAL (the first frame of a
message, or the first after a reception gap: nothing to compare its counter with); one
sequence per message. With a timeout, a gap of more than `timeout` seconds (frame times)
since a message's last accepted frame is one NO_NEW_DATA, counted when the next frame
arrives, and restarts its sequence, as the module's VehicleMotion receiver does."""
from dataclasses import dataclass

MODE_BOTH = "both"      # Profile 11A
MODE_NIBBLE = "nibble"  # Profile 11C


def crc8_0x1d(data, crc=0x00):
    """CRC-8, polynomial 0x1D, not reflected: the register `crc` after `data`, with no
    start value or final XOR applied (Profile 11 starts at 0x00 and applies none)."""
    reg = crc & 0xFF
    for b in data:
        reg ^= b
        for _ in range(8):
            reg = ((reg << 1) ^ 0x1D) & 0xFF if reg & 0x80 else (reg << 1) & 0xFF
    return reg


def crc8_j1850(data):
    """CRC-8 SAE J1850 (start 0xFF, final XOR 0xFF; check value: b"123456789" -> 0x4B)."""
    return crc8_0x1d(data, 0xFF) ^ 0xFF


def e2e_crc(data_id, data, mode=MODE_BOTH):
    """The Profile 11 CRC a frame must carry in byte 0: over [Data ID low byte, high byte
    (11A) or 0x00 (11C), data[1:8]]. In 11C data[1]'s high nibble is taken as it is."""
    hi = 0 if mode == MODE_NIBBLE else (data_id >> 8) & 0xFF
    return crc8_0x1d(bytes([data_id & 0xFF, hi]) + bytes(data[1:8]))


def protect(data_id, data, counter, mode=MODE_BOTH):
    """8 bytes protected as a Profile 11 sender does: the counter in bits 8..11, the Data
    ID nibble in bits 12..15 (11C only), the CRC in byte 0."""
    d = bytearray(data)
    d[1] = (d[1] & 0xF0) | (counter & 0x0F)
    if mode == MODE_NIBBLE:
        d[1] = (d[1] & 0x0F) | (((data_id >> 8) & 0x0F) << 4)
    d[0] = e2e_crc(data_id, d, mode)
    return bytes(d)


def mode_of(attribute):
    """The mode from a DBC SlE2EMode value (enum name or index); 11A when absent."""
    return MODE_NIBBLE if str(attribute).strip('"') in ("Nibble", "1") else MODE_BOTH


# Statuses E2EMonitor.check returns. OK and OK_SOME_LOST carry new data; INITIAL starts
# a sequence; the others reject the frame.
E2E_STATUSES = ("OK", "OK_SOME_LOST", "INITIAL", "REPEATED", "WRONG_SEQUENCE", "ERROR")
E2E_ERRORS = ("REPEATED", "WRONG_SEQUENCE", "ERROR", "UNKNOWN_ID")


@dataclass
class E2EStats:
    """Per message: frames per status and why frames were ERROR (the C receiver's
    sl_can_e2e_rx_t stats)."""
    ok: int = 0
    ok_some_lost: int = 0
    initial: int = 0
    repeated: int = 0
    wrong_sequence: int = 0
    error: int = 0
    no_new_data: int = 0
    bad_length: int = 0
    crc_errors: int = 0
    bad_nibble: int = 0
    bad_counter: int = 0
    lost_frames: int = 0

    @property
    def accepted(self):
        return self.ok + self.ok_some_lost + self.initial

    def errors(self):
        """Frames rejected or lost: 0 for a clean sequence."""
        return self.error + self.repeated + self.wrong_sequence + self.lost_frames


class E2EMonitor:
    """Checks a stream of decoded frames: the Profile 11 check, one counter sequence per
    message name. The modulo of each message comes from its DBC Counter signal (db given)
    or is 15; `max_delta_counter` (1..14) is the largest step that is OK_SOME_LOST."""

    def __init__(self, db=None, modulo=15, max_delta_counter=1, timeout=None):
        if not 1 <= max_delta_counter <= 14:
            raise ValueError(f"max_delta_counter {max_delta_counter}: 1..14")
        if timeout is not None and not timeout > 0:
            raise ValueError(f"timeout {timeout}: > 0 seconds")
        self.timeout = timeout
        self._last_t = {}      # name -> time of the last accepted (OK, OK_SOME_LOST, INITIAL) frame
        self._db = db
        self._default_modulo = modulo
        self.max_delta_counter = max_delta_counter
        self._last = {}        # name -> counter of the last frame with a valid CRC
        self._mod = {}         # name -> counter modulo
        self.stats = {}        # name -> E2EStats
        self.unknown = 0       # frames whose id the DBC does not know

    def _modulo(self, name):
        if name not in self._mod:
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

    def _error(self, st, reason):
        setattr(st, reason, getattr(st, reason) + 1)
        st.error += 1
        return "ERROR"

    def check(self, decoded, data=None, t=None):
        """One frame (a dbc.Decoded, or None for an unknown id) received at time `t`
        (seconds; needed for the timeout): its status, one of E2E_STATUSES, or
        "UNKNOWN_ID"."""
        if decoded is None:
            self.unknown += 1
            return "UNKNOWN_ID"
        st = self.stats.setdefault(decoded.name, E2EStats())
        last_t = self._last_t.get(decoded.name)
        if self.timeout is not None and t is not None and last_t is not None and t - last_t > self.timeout:
            st.no_new_data += 1  # a reception gap: the counter sequence means nothing now
            self._last.pop(decoded.name, None)
            self._last_t.pop(decoded.name, None)
        status = self._check(st, decoded)
        if status in ("OK", "OK_SOME_LOST", "INITIAL") and t is not None:
            self._last_t[decoded.name] = t
        return status

    def _check(self, st, decoded):
        if not decoded.length_ok:
            return self._error(st, "bad_length")
        if not decoded.crc_ok:
            return self._error(st, "crc_errors")
        if not decoded.nibble_ok:
            return self._error(st, "bad_nibble")
        mod = self._modulo(decoded.name)
        c = decoded.counter
        if c < 0 or c >= mod:
            return self._error(st, "bad_counter")
        last = self._last.get(decoded.name)
        self._last[decoded.name] = c  # the state follows every frame with a valid CRC
        if last is None:
            st.initial += 1
            return "INITIAL"
        delta = (c - last) % mod
        if delta == 0:
            st.repeated += 1
            return "REPEATED"
        st.lost_frames += delta - 1
        if delta == 1:
            st.ok += 1
            return "OK"
        if delta <= self.max_delta_counter:
            st.ok_some_lost += 1
            return "OK_SOME_LOST"
        st.wrong_sequence += 1
        return "WRONG_SEQUENCE"

    def errors(self):
        """Total of rejected and lost frames over all messages (unknown ids not counted)."""
        return sum(s.errors() for s in self.stats.values())
