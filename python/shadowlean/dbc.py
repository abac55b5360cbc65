# SPDX-License-Identifier: MIT
"""The board's generated DBC, read with Debian's python3-canmatrix, and frame decoding.

Nothing about the layout is written here: message names, signals, scaling, value tables,
the E2E Profile 11 Data ID and mode (message attributes SlE2EDataId and SlE2EMode), the
frame format (29-bit ids: DBC ids with bit 31 set, attribute VFrameFormat) and the counter
modulo (the Counter signal's maximum + 1) all come from the DBC."""
import contextlib
import io
from dataclasses import dataclass, field

# canmatrix prints "ldf is not supported" (no ldfparser in Debian) and the like on import:
# formats this package does not use.
with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
    import canmatrix
    import canmatrix.formats

from .e2e import MODE_NIBBLE, e2e_crc, mode_of

# Value-table names for the text reports (the DBC's VAL_ tables carry the same names).
LINK = {0: "DISCONNECTED", 1: "CONNECTING", 2: "WAIT_CONFIG", 3: "STREAMING", 4: "SILENT"}
LEVEL = {0: "NONE", 1: "CAUTION", 2: "DANGER"}
QUALITY = {0: "VALID", 1: "AMBIGUOUS", 2: "OUT_OF_MODEL", 3: "INVALID", 4: "FILTERED"}
GROUND_QUALITY = {0: "NONE", 1: "COARSE", 2: "GOOD"}
HAZARD_KIND = {0: "FLAT", 1: "DROP", 2: "STEP"}


def load_dbc(path):
    """The DBC as a canmatrix CanMatrix. Raises ValueError when it holds no message."""
    with contextlib.redirect_stderr(io.StringIO()):
        db = canmatrix.formats.loadp_flat(path)
    if db is None or not db.frames:
        raise ValueError(f"{path}: no CAN message in this DBC")
    return db


@dataclass
class Decoded:
    """One decoded frame. phys: signal -> physical value; raw: signal -> raw integer;
    named: signal -> value-table name (where the DBC has one). crc_ok: the Profile 11 CRC
    matches (Data ID and mode of this message); nibble_ok: in mode 11C, bits 12..15 carry
    the Data ID's bits 8..11 (always True in 11A); reencode_ok: canmatrix encodes the raw
    values back to the same bytes; length_ok: the payload has the message's DLC (otherwise
    nothing decoded)."""
    name: str
    can_id: int
    phys: dict = field(default_factory=dict)
    raw: dict = field(default_factory=dict)
    named: dict = field(default_factory=dict)
    crc_ok: bool = False
    reencode_ok: bool = False
    length_ok: bool = False
    nibble_ok: bool = False
    data_id: int = 0
    mode: str = "both"
    counter: int = -1


def frame_of(db, can_id, eff):
    """The DBC's frame for an id, or None."""
    try:
        return db.frame_by_id(canmatrix.ArbitrationId(can_id, extended=eff))
    except Exception:  # canmatrix raises various errors for ids it does not know
        return None


def counter_modulo(fr):
    """Counter values run 0..modulo-1: the DBC's Counter signal maximum + 1 (15)."""
    s = fr.signal_by_name("Counter")
    return int(s.max) + 1 if s is not None else 0


def decode(db, can_id, eff, data):
    """Decode one frame; None when the DBC does not know the id. A payload of the wrong
    length (or a remote frame, data None) gives a Decoded with length_ok False and no
    signals."""
    fr = frame_of(db, can_id, eff)
    if fr is None:
        return None
    d = Decoded(fr.name, can_id)
    d.data_id = int(fr.attributes.get("SlE2EDataId", 0))
    d.mode = mode_of(fr.attributes.get("SlE2EMode", "Both"))
    if data is None or len(data) != fr.size:
        return d
    d.length_ok = True
    sig = fr.decode(bytes(data))
    for k, v in sig.items():
        d.raw[k] = int(v.raw_value)
        d.phys[k] = float(v.phys_value)
        if v.named_value is not None:
            d.named[k] = v.named_value
    d.counter = d.raw.get("Counter", -1)
    d.crc_ok = data[0] == e2e_crc(d.data_id, data, d.mode)
    d.nibble_ok = d.mode != MODE_NIBBLE or (data[1] >> 4) == ((d.data_id >> 8) & 0x0F)
    d.reencode_ok = bytes(fr.encode({k: v.raw_value for k, v in sig.items()})) == bytes(data)
    return d


def decode_frames(db, frames):
    """[(Frame, Decoded or None)] for an iterable of Frame."""
    return [(f, decode(db, f.can_id, f.is_eff, f.data)) for f in frames]


def decode_log(dbc_path, log_path):
    """Every frame of a candump -L log, decoded with the DBC: [(Frame, Decoded or None)]."""
    from .candump import read_candump
    return decode_frames(load_dbc(dbc_path), read_candump(log_path))
