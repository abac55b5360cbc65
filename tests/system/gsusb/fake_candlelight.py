#!/usr/bin/python3 -u
# SPDX-License-Identifier: MIT
"""Fake gs_usb (candleLight) USB device on Linux FunctionFS, for the gs_usb VM test.

Usage: fake_candlelight.py FFS_DIR OUT_DIR CTL_FILE UDC_FILE UDC_NAME

Adapted from the project's reference gs_gadget.py. Python 3 standard library only.
Runs inside the test VM (dummy_hcd + configfs gadget), presenting a 48 MHz candleLight
(1d50:606f, interface 0 vendor class, bulk IN 0x81 / OUT 0x02). It answers the vendor
requests, echoes every frame it receives (transmit confirmation) and injects one RX reply
frame (id + 1, same data) per frame.

The scenario and the behaviour come from CTL_FILE ("scenario=NAME" and "mode=MODE" lines),
re-read whenever it changes, so one gadget process serves every scenario of one VM boot:
  normal            echo + reply
  normal+err        as normal, plus one error frame (controller TX warning) after frame 1
  refuse:N          stall vendor request N (1 = BITTIMING) every time
  stall             halt bulk OUT after frame 3 and bulk IN after frame 6 (once each)
  drop-echo:K       echo (and reply to) only the first K frames
  vanish:K:MS       after frame K unbind the UDC (the device disappears from the bus),
                    re-bind it MS milliseconds later
Per scenario it writes OUT_DIR/dev_NAME.log (every frame received, candump -L format) and
OUT_DIR/ctl_NAME.log (every vendor request, decoded)."""
import errno
import os
import queue
import struct
import sys
import threading
import time

FFS, OUT, CTL, UDC_FILE, UDC_NAME = sys.argv[1:6]
FCLK = 48_000_000
FEATURES = 0x1 | 0x2 | 0x8  # LISTEN_ONLY | LOOP_BACK | ONE_SHOT: no HW_TIMESTAMP, no PAD
REQ = {0: "HOST_FORMAT", 1: "BITTIMING", 2: "MODE", 3: "BERR", 4: "BT_CONST",
       5: "DEVICE_CONFIG", 6: "TIMESTAMP", 7: "IDENTIFY", 14: "GET_STATE"}
CAN_EFF = 0x80000000
CAN_RTR = 0x40000000
CAN_ERR = 0x20000000

lock = threading.Lock()
state = {"mtime": None, "scenario": "boot", "mode": "normal", "frames": 0, "echoed": 0,
         "dev": None, "ctl": None, "vanished": False, "stalled_out": False, "stalled_in": False}


def log(*a):
    print("[gadget %.3f]" % time.monotonic(), *a, flush=True)


def open_logs(name):
    for k in ("dev", "ctl"):
        if state[k] is not None:
            state[k].close()
    state["dev"] = open(os.path.join(OUT, "dev_%s.log" % name), "a", buffering=1)
    state["ctl"] = open(os.path.join(OUT, "ctl_%s.log" % name), "a", buffering=1)


def reload_ctl():
    """Re-read the control file when it changed (called with `lock` held)."""
    try:
        st = os.stat(CTL)
    except OSError:
        return
    key = (st.st_mtime_ns, st.st_size, st.st_ino)
    if key == state["mtime"]:
        return
    state["mtime"] = key
    kv = {}
    with open(CTL) as f:
        for line in f:
            if "=" in line:
                k, v = line.strip().split("=", 1)
                kv[k] = v
    name = kv.get("scenario", "boot")
    state.update(scenario=name, mode=kv.get("mode", "normal"), frames=0, echoed=0,
                 vanished=False, stalled_out=False, stalled_in=False)
    open_logs(name)
    log("scenario", name, "mode", state["mode"])


def mode():
    parts = state["mode"].split(":")
    return parts[0], [int(x) for x in parts[1:]]


def fmt_frame(can_id, dlc, data):
    if can_id & CAN_ERR:
        s = "%08X#" % (can_id & 0x3FFFFFFF)
    elif can_id & CAN_EFF:
        s = "%08X#" % (can_id & 0x1FFFFFFF)
    else:
        s = "%03X#" % (can_id & 0x7FF)
    if can_id & CAN_RTR:
        return s + ("R%d" % dlc if 0 < dlc <= 8 else "R")
    return s + data[:min(dlc, 8)].hex().upper()


def candump_line(can_id, dlc, data):
    t = time.time()
    return "(%010d.%06d) fakedev %s" % (int(t), int((t % 1) * 1e6), fmt_frame(can_id, dlc, data))


# ---------------------------------------------------------------------------------------
# FunctionFS descriptors (v2: full speed + high speed, one vendor interface, 2 bulk eps)

def intf_desc():
    return struct.pack("<BBBBBBBBB", 9, 4, 0, 0, 2, 0xFF, 0xFF, 0xFF, 1)


def ep_desc(addr, mps):
    return struct.pack("<BBBBHB", 7, 5, addr, 2, mps, 0)


def descriptors():
    fs = intf_desc() + ep_desc(0x81, 64) + ep_desc(0x02, 64)
    hs = intf_desc() + ep_desc(0x81, 512) + ep_desc(0x02, 512)
    body = struct.pack("<III", 1 | 2, 3, 3) + fs + hs  # flags HAS_FS|HAS_HS, counts
    return struct.pack("<II", 3, 8 + len(body)) + body  # FUNCTIONFS_DESCRIPTORS_MAGIC_V2


def strings():
    body = struct.pack("<II", 1, 1) + struct.pack("<H", 0x0409) + b"gs_usb\0"
    return struct.pack("<II", 2, 8 + len(body)) + body


ep0 = os.open(os.path.join(FFS, "ep0"), os.O_RDWR)
os.write(ep0, descriptors())
os.write(ep0, strings())
ep_in = os.open(os.path.join(FFS, "ep1"), os.O_RDWR)   # first endpoint: bulk IN
ep_out = os.open(os.path.join(FFS, "ep2"), os.O_RDWR)  # second: bulk OUT
log("descriptors written; ep files:", sorted(os.listdir(FFS)))
to_host = queue.Queue()  # bulk IN writer queue: the OUT reader never blocks on IN
HALT_IN = b"HALT"


def bulk_in_loop():
    while True:
        pkt = to_host.get()
        if pkt is HALT_IN:
            # Wrong direction on an IN endpoint = set halt. dummy_hcd refuses (EAGAIN) while
            # a request is still queued on the endpoint: try again shortly.
            for attempt in range(100):
                try:
                    os.read(ep_in, 1)
                except OSError as e:
                    if e.errno == errno.EAGAIN:
                        time.sleep(0.01)
                        continue
                    log("bulk IN halted (%s) after %d attempt(s)" % (e.strerror, attempt + 1))
                break
            continue
        try:
            os.write(ep_in, pkt)
        except OSError as e:
            log("bulk IN write failed (%s): dropped" % e.strerror)


def frame_pkt(echo_id, can_id, dlc, ch, flags, data):
    return struct.pack("<IIBBBB", echo_id, can_id, dlc, ch, flags, 0) + data[:8].ljust(8, b"\0")


def vanish(after_ms):
    """Unbind the UDC (the device disappears), re-bind it after_ms later."""
    time.sleep(0.05)
    log("VANISH: unbinding the UDC")
    with open(UDC_FILE, "w") as f:
        f.write("\n")
    while not to_host.empty():
        to_host.get_nowait()
    time.sleep(after_ms / 1000.0)
    with open(UDC_FILE, "w") as f:
        f.write(UDC_NAME + "\n")
    log("VANISH: UDC re-bound")


def bulk_out_loop():
    while True:
        try:
            pkt = os.read(ep_out, 512)
        except OSError as e:
            time.sleep(0.05)  # endpoint disabled (unbound, reset): wait for it to come back
            continue
        if len(pkt) < 12:
            log("short bulk OUT packet", pkt.hex())
            continue
        echo_id, can_id, dlc, ch, flags, _ = struct.unpack_from("<IIBBBB", pkt)
        data = pkt[12:12 + min(dlc, 8)]
        with lock:
            reload_ctl()
            state["frames"] += 1
            n = state["frames"]
            m, args = mode()
            state["dev"].write(candump_line(can_id, dlc, data) + "\n")
            log("%s frame %d len=%d echo_id=%d %s" % (state["scenario"], n, len(pkt), echo_id,
                                                      fmt_frame(can_id, dlc, data)))
            echo = not (m == "drop-echo" and n > args[0])
            halt_out = m == "stall" and n == 3 and not state["stalled_out"]
            halt_in = m == "stall" and n == 6 and not state["stalled_in"]
            do_vanish = m == "vanish" and n == args[0] and not state["vanished"]
            if halt_out:
                state["stalled_out"] = True
            if halt_in:
                state["stalled_in"] = True
            if do_vanish:
                state["vanished"] = True
        if echo:
            to_host.put(pkt[:20])  # echo = "transmitted on the bus"
            mask = 0x1FFFFFFF if can_id & CAN_EFF else 0x7FF
            rx_id = (((can_id & mask) + 1) & mask) | (can_id & (CAN_EFF | CAN_RTR))
            to_host.put(frame_pkt(0xFFFFFFFF, rx_id, dlc, ch, 0, data))
            if m == "normal+err" and n == 1:
                # controller problem: CAN_ERR_CRTL, data[1] = CAN_ERR_CRTL_TX_WARNING
                to_host.put(frame_pkt(0xFFFFFFFF, CAN_ERR | 0x04, 8, ch, 0, b"\x00\x08" + b"\0" * 6))
        if halt_in:
            to_host.put(HALT_IN)
        if halt_out:
            try:
                os.write(ep_out, b"")  # wrong direction on an OUT endpoint = set halt
            except OSError as e:
                log("bulk OUT halted (%s)" % e.strerror)
        if do_vanish:
            threading.Thread(target=vanish, args=(args[1],), daemon=True).start()


threading.Thread(target=bulk_in_loop, daemon=True).start()
threading.Thread(target=bulk_out_loop, daemon=True).start()

EV = {0: "BIND", 1: "UNBIND", 2: "ENABLE", 3: "DISABLE", 4: "SETUP", 5: "SUSPEND", 6: "RESUME"}


def ctl_log(text):
    with lock:
        state["ctl"].write(text + "\n")


# ep0 calls fail with EIDRM when the host cancels a setup request (a new one arrived, or the
# UDC was unbound and bound again: scenario "vanish") and ESHUTDOWN while the function is
# disabled: the request is gone, so read the next event (FunctionFS, f_fs.c). Any other
# error ends the fake device, as before.
EP0_RETRY = (errno.EIDRM, errno.ESHUTDOWN, errno.EINTR, errno.EAGAIN)


def ep0_events():
    while True:
        try:
            yield os.read(ep0, 12 * 4)
        except OSError as e:
            if e.errno not in EP0_RETRY:
                raise
            log("ep0 read: %s (request cancelled), reading the next event" % e.strerror)


for buf in ep0_events():
    for off in range(0, len(buf), 12):
        rt, req, wval, widx, wlen, etype = struct.unpack_from("<BBHHHB", buf, off)
        if etype != 4:
            log("event", EV.get(etype, etype))
            continue
        name = REQ.get(req, "req%d" % req)
        with lock:
            reload_ctl()
            m, args = mode()
        refused = m == "refuse" and req == args[0]
        if rt & 0x80:  # device-to-host
            data = None
            if not refused and req == 5:
                data = struct.pack("<BBBBII", 0, 0, 0, 0, 2, 1)  # icount 0: 1 channel, sw 2, hw 1
            elif not refused and req == 4:
                data = struct.pack("<10I", FEATURES, FCLK, 1, 16, 1, 8, 4, 1, 1024, 1)
            if data is None:
                ctl_log("%s IN wValue=%d wIndex=%d STALL" % (name, wval, widx))
                try:
                    os.read(ep0, 0)  # wrong direction = stall
                except OSError:
                    pass
                continue
            try:
                os.write(ep0, data[:wlen])
            except OSError as e:
                if e.errno not in EP0_RETRY:
                    raise
                log("ep0 data stage: %s (request cancelled)" % e.strerror)
                continue
            ctl_log("%s IN wValue=%d wIndex=%d len=%d" % (name, wval, widx, wlen))
        else:
            if refused or req not in (0, 1, 2, 7):
                ctl_log("%s OUT wValue=%d wIndex=%d STALL" % (name, wval, widx))
                try:
                    os.write(ep0, b"")
                except OSError:
                    pass
                continue
            try:
                data = os.read(ep0, wlen) if wlen else os.read(ep0, 0)
            except OSError as e:
                if e.errno not in EP0_RETRY:
                    raise
                log("ep0 data stage: %s (request cancelled)" % e.strerror)
                continue
            extra = ""
            if req == 0 and len(data) >= 4:
                extra = "byte_order=0x%08x" % struct.unpack("<I", data[:4])[0]
            elif req == 1 and len(data) >= 20:
                p, s1, s2, sjw, brp = struct.unpack("<5I", data[:20])
                extra = ("prop_seg=%d phase_seg1=%d phase_seg2=%d sjw=%d brp=%d bitrate=%d" %
                         (p, s1, s2, sjw, brp, FCLK // (brp * (1 + p + s1 + s2))))
            elif req == 2 and len(data) >= 8:
                md, flags = struct.unpack("<II", data[:8])
                extra = "mode=%s flags=0x%x" % ({0: "RESET", 1: "START"}.get(md, md), flags)
            ctl_log("%s OUT wValue=%d wIndex=%d %s" % (name, wval, widx, extra))
