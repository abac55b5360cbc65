# SPDX-License-Identifier: MIT
"""Live CAN through Debian's python3-can: SocketCAN (can0, vcan0), or any python-can
interface (virtual for tests). python-can is imported only when a bus is used."""
from .candump import Frame


def open_bus(channel="can0", interface="socketcan", **kwargs):
    """A python-can bus, e.g. open_bus("vcan0") or open_bus("t", interface="virtual")."""
    import can
    return can.Bus(channel=channel, interface=interface, **kwargs)


def frame_from_message(msg, iface=None):
    """A Frame from a python-can Message (error frames: None)."""
    if msg.is_error_frame:
        return None
    data = None if msg.is_remote_frame else bytes(msg.data[:msg.dlc])
    return Frame(float(msg.timestamp), iface or str(msg.channel or ""), int(msg.arbitration_id),
                 bool(msg.is_extended_id), data)


def message_from_frame(f):
    """A python-can Message from a Frame (to replay a log onto a bus)."""
    import can
    return can.Message(timestamp=f.t, arbitration_id=f.can_id, is_extended_id=f.is_eff,
                       is_remote_frame=f.data is None, data=f.data or b"",
                       dlc=len(f.data) if f.data is not None else 0)


def frames_from_bus(bus, count=None, timeout=1.0, idle_limit=None):
    """Frames received on a python-can bus, as they arrive. Stops after `count` frames,
    or after `idle_limit` seconds without a frame (None: never). `timeout` is the poll
    interval of bus.recv."""
    n = 0
    idle = 0.0
    while count is None or n < count:
        msg = bus.recv(timeout)
        if msg is None:
            idle += timeout
            if idle_limit is not None and idle >= idle_limit:
                return
            continue
        idle = 0.0
        f = frame_from_message(msg, getattr(bus, "channel_info", None))
        if f is None:
            continue
        n += 1
        yield f
