#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""check_results.py OUT_DIR TEST_DIR: judge one run of the gs_usb VM test (host side).

Compares, field by field (id, 11/29-bit, remote, dlc, data), the frames the fake device
received (dev_*.log) with the senders' candump logs of the same run, and asserts the
driver's counters for each scenario. Python 3 standard library only."""
import os
import re
import sys

OUT, HERE = sys.argv[1], sys.argv[2]
failures = []
failed_scenarios = []
passes = 0
scenario = None


def check(cond, what, detail=""):
    global passes
    if cond:
        passes += 1
        print("  ok   %s" % what)
    else:
        failures.append(what)
        if scenario not in failed_scenarios:
            failed_scenarios.append(scenario)
        print("  FAIL %s%s" % (what, (": " + detail) if detail else ""))


def read(name, default=None):
    p = os.path.join(OUT, name)
    if not os.path.exists(p):
        return default
    with open(p, errors="replace") as f:
        return f.read()


def parse_frame(s):
    """can-utils frame text -> (kind, id, dlc, data) with kind in SFF/EFF/ERR."""
    ident, _, rest = s.partition("#")
    if len(ident) == 3:
        kind, fid = "SFF", int(ident, 16)
    elif len(ident) == 8:
        fid = int(ident, 16)
        kind = "ERR" if fid & 0x20000000 else "EFF"
        fid &= 0x1FFFFFFF
    else:
        raise ValueError("bad id in %r" % s)
    if rest[:1] in ("R", "r"):
        return (kind + "-RTR", fid, int(rest[1:] or "0"), b"")
    data = bytes.fromhex(rest.replace(".", ""))
    return (kind, fid, len(data), data)


def frames_of(text):
    out = []
    for line in (text or "").splitlines():
        f = line.split()
        if f:
            out.append(parse_frame(f[-1]))
    return out


def summary(name):
    kv = {}
    for line in (read("sum_%s.txt" % name, "") or "").splitlines():
        k, _, v = line.partition("=")
        try:
            kv[k] = int(v, 0)
        except ValueError:
            kv[k] = v
    return kv


def rc(name):
    t = read("rc_%s" % name)
    return int(t) if t and t.strip().lstrip("-").isdigit() else None


def reply(f):
    kind, fid, dlc, data = f
    mask = 0x7FF if kind.startswith("SFF") else 0x1FFFFFFF
    return (kind, (fid + 1) & mask, dlc, data)


def gen(k):
    """The frames sl-gsusb-send generates (--count), recomputed independently."""
    if k % 3 == 2:
        kind, fid = "EFF", (0x1ABC0000 + k * 0x101) & 0x1FFFFFFF
    else:
        kind, fid = "SFF", (0x100 + k) & 0x7FF
    dlc = k % 9
    return (kind, fid, dlc, bytes(((k * 7 + i * 0x11) & 0xFF) for i in range(dlc)))


def accounting(s):
    dropped = sum(s.get(k, 0) for k in ("unconfirmed", "dropped_in_flight", "dropped_down",
                                          "dropped_full", "dropped_stale", "dropped_error",
                                          "dropped_invalid"))
    return s.get("offered", -1) == s.get("confirmed", 0) + dropped


def ctl_lines(name):
    return (read("ctl_%s.log" % name, "") or "").splitlines()


def show_diff(a, b):
    for i in range(max(len(a), len(b))):
        x = a[i] if i < len(a) else None
        y = b[i] if i < len(b) else None
        if x != y:
            return "first difference at %d: %r vs %r (lengths %d, %d)" % (i, x, y, len(a), len(b))
    return ""


console = read("console.log", "")
if "guest script exit" not in console:
    print(console[-3000:])
    check(False, "the guest script ran to its end")

# ---------------------------------------------------------------------------------------
scenario = "kernel"
print("(a) kernel gs_usb driver + SocketCAN (cansend through the fake device)")
MARKERS = {("SFF", 0x7E0, 4, b"SYNC"), ("SFF", 0x7E0, 3, b"END"), ("SFF", 0x7E1, 4, b"SYNC"),
           ("SFF", 0x7E1, 3, b"END")}
sent = frames_of(open(os.path.join(HERE, "frames_kernel.log")).read())
dev = [f for f in frames_of(read("dev_kernel.log")) if f not in MARKERS]
check(rc("kernel") == 0, "the kernel scenario ran")
check(dev == sent, "the device received exactly the cansend frames (%d)" % len(sent), show_diff(dev, sent))
cd = [f for f in frames_of(read("candump_kernel.log")) if f not in MARKERS]
check(all(f in cd for f in sent), "candump on can0 saw every sent frame (echo)", repr(cd))
check(all(reply(f) in cd for f in sent), "candump on can0 received every reply from the device", repr(cd))
ctl = "\n".join(ctl_lines("kernel"))
check("BITTIMING OUT wValue=0 wIndex=0 prop_seg=6 phase_seg1=7 phase_seg2=2 sjw=1 brp=6" in ctl,
      "the kernel programmed brp 6 prop 6 ph1 7 ph2 2 sjw 1 (500 kbit/s)")
check("mode=START" in ctl, "the kernel started the channel")

# ---------------------------------------------------------------------------------------
scenario = "libusb_log"
print("(b1) libusb driver: candump log in, VID:PID selector, one error frame")
sent = frames_of(open(os.path.join(HERE, "frames_libusb.log")).read())
dev = frames_of(read("dev_libusb_log.log"))
tx = frames_of(read("tx_libusb_log.log"))
rx = frames_of(read("rx_libusb_log.log"))
s = summary("libusb_log")
check(rc("libusb_log") == 0, "sl-gsusb-send exit 0 (every frame confirmed)", "rc=%s" % rc("libusb_log"))
check(dev == sent, "the device received exactly the log's frames, in order (%d)" % len(sent), show_diff(dev, sent))
check(tx == dev, "the sender's confirmed log equals what the device received, field by field", show_diff(tx, dev))
check([f for f in rx if not f[0].startswith("ERR")] == [reply(f) for f in sent],
      "every reply frame came back through the RX path, in order", show_diff(rx, [reply(f) for f in sent]))
check(s.get("confirmed") == len(sent) and s.get("unconfirmed") == 0, "confirmed %s of %d" % (s.get("confirmed"), len(sent)))
check(s.get("rx_error_frames") == 1 and s.get("err_warning") == 1, "the error frame was received and classified",
      "rx_error_frames=%s err_warning=%s" % (s.get("rx_error_frames"), s.get("err_warning")))
check((s.get("brp"), s.get("prop_seg"), s.get("phase_seg1"), s.get("phase_seg2"), s.get("sjw"),
       s.get("sample_point"), s.get("bitrate")) == (6, 6, 7, 2, 1, 875, 500000),
      "libusb bit timing = the kernel's (brp 6, 6/7/2, sjw 1, 87.5 %, 500 kbit/s)")
check(s.get("eps_from_descriptor") == 1 and s.get("ep_in") == 0x81 and s.get("ep_out") == 0x02,
      "bulk endpoints 0x81/0x02 found in the descriptor")
check(s.get("kernel_detaches") == 1 and s.get("kernel_reattaches") == 1,
      "kernel driver detached at open and re-attached at close")
check(read("can0_back_after_b1", "").strip() == "1", "can0 came back after the release (kernel re-probed)")
check(accounting(s), "every frame accounted for")
lines = ctl_lines("libusb_log")
seq = [l.split(" wIndex")[0] + (" " + l.split("mode=")[1].split()[0] if "mode=" in l else "") for l in lines]
want = ["HOST_FORMAT OUT wValue=1", "DEVICE_CONFIG IN wValue=1", "BT_CONST IN wValue=0",
        "MODE OUT wValue=0 RESET", "BITTIMING OUT wValue=0", "MODE OUT wValue=0 START",
        "MODE OUT wValue=0 RESET", "HOST_FORMAT OUT wValue=1"]
check(seq[:len(want)] == want, "control sequence: HOST_FORMAT, DEVICE_CONFIG, BT_CONST, RESET, BITTIMING, "
      "START ... RESET, then the kernel's re-probe", repr(seq))
check(any("byte_order=0x0000beef" in l for l in lines[:1]), "HOST_FORMAT carried 0x0000beef")

# ---------------------------------------------------------------------------------------
scenario = "libusb_gen"
print("(b2) libusb driver: 40 generated frames, bus-port selector")
s = summary("libusb_gen")
expect = [gen(k) for k in range(40)]
dev = frames_of(read("dev_libusb_gen.log"))
tx = frames_of(read("tx_libusb_gen.log"))
rx = frames_of(read("rx_libusb_gen.log"))
check(rc("libusb_gen") == 0, "exit 0", "rc=%s busport=%s" % (rc("libusb_gen"), (read("busport", "") or "").strip()))
check(dev == expect, "the device received the 40 generated frames in order", show_diff(dev, expect))
check(tx == dev, "confirmed log equals what the device received", show_diff(tx, dev))
check(len(rx) == 40, "40 replies received", "got %d" % len(rx))
check(accounting(s) and s.get("confirmed") == 40, "40 confirmed, all accounted for")
print("       max frames in flight: %s" % s.get("max_in_flight"))

# ---------------------------------------------------------------------------------------
scenario = "refuse"
print("(c1) the device refuses BITTIMING")
out = read("out_refuse.txt", "")
check(rc("refuse") == 2, "sl-gsusb-send exit 2 (could not start)", "rc=%s" % rc("refuse"))
check("BITTIMING refused by the device" in out, "clear error message at open", out.strip())
check(frames_of(read("dev_refuse.log", "")) == [], "no frame reached the device")
ctl = "\n".join(ctl_lines("refuse"))
check("BITTIMING OUT wValue=0 wIndex=0 STALL" in ctl and "mode=START" not in ctl,
      "the channel was never started")
print("       message: %s" % out.strip().splitlines()[-1] if out.strip() else "")

# ---------------------------------------------------------------------------------------
scenario = "stall"
print("(c2) the device halts bulk OUT (after frame 3) and bulk IN (after frame 6)")
s = summary("stall")
expect = [gen(k) for k in range(12)]
dev = frames_of(read("dev_stall.log"))
tx = frames_of(read("tx_stall.log"))
check(rc("stall") == 0, "exit 0: every frame confirmed despite the stalls", "rc=%s" % rc("stall"))
check(dev == expect, "the device got each frame exactly once, in order", show_diff(dev, expect))
check(sorted(tx) == sorted(dev), "confirmed frames = received frames", show_diff(tx, dev))
check(s.get("stalls_out", 0) >= 1 and s.get("stalls_in", 0) >= 1,
      "both stalls seen (out %s, in %s)" % (s.get("stalls_out"), s.get("stalls_in")))
check(s.get("clear_halts", 0) >= 2 and s.get("clear_halt_failures") == 0,
      "cleared with clear_halt (%s)" % s.get("clear_halts"))
print("       OUT transfers resent after the clear: %s" % s.get("out_resubmits"))

# ---------------------------------------------------------------------------------------
scenario = "dropecho"
print("(c3) the device drops echoes after frame 2")
s = summary("dropecho")
dev = frames_of(read("dev_dropecho.log"))
tx = frames_of(read("tx_dropecho.log"))
check(rc("dropecho") == 1, "exit 1 (frames unconfirmed), no hang", "rc=%s" % rc("dropecho"))
check(dev == [gen(k) for k in range(15)], "the device received all 15 frames", show_diff(dev, [gen(k) for k in range(15)]))
check(tx == [gen(0), gen(1)], "only the 2 echoed frames are confirmed", repr(tx))
check(s.get("confirmed") == 2 and s.get("unconfirmed") == 13, "13 counted unconfirmed after the echo timeout",
      "confirmed=%s unconfirmed=%s" % (s.get("confirmed"), s.get("unconfirmed")))
check(s.get("max_in_flight") == 10, "the in-flight limit (10) was reached", "max=%s" % s.get("max_in_flight"))
check(accounting(s), "every frame accounted for")

# ---------------------------------------------------------------------------------------
scenario = "vanish"
print("(c4) the device vanishes after frame 8 (UDC unbound) and comes back 0.5 s later")
s = summary("vanish")
dev = frames_of(read("dev_vanish.log"))
tx = frames_of(read("tx_vanish.log"))
allgen = [gen(k) for k in range(80)]
check(rc("vanish") in (0, 1), "sl-gsusb-send finished", "rc=%s" % rc("vanish"))
check(s.get("down_events", 0) >= 1, "the sink went down (%s)" % s.get("down_events"))
lost = sum(s.get(k, 0) for k in ("dropped_down", "dropped_in_flight", "unconfirmed"))
check(lost >= 1, "frames lost while gone are counted (%d: down %s, in flight %s, unconfirmed %s)" % (
    lost, s.get("dropped_down"), s.get("dropped_in_flight"), s.get("unconfirmed")))
check(s.get("reopens", 0) >= 1 and s.get("confirmed_after_reopen", 0) >= 1,
      "reopened after the device came back, frames confirmed again (%s reopens, %s confirmed after)" % (
          s.get("reopens"), s.get("confirmed_after_reopen")))
check(s.get("kernel_detaches", 0) >= 2, "the re-probed kernel driver was detached again")
check(all(f in allgen for f in dev) and all(tx.count(f) <= dev.count(f) for f in tx),
      "every confirmed frame was received by the device")
print("       late/bogus echoes ignored: %s, unknown echo ids: %s, OUT transfers the device did not take: %s" % (
    s.get("echo_mismatch"), s.get("echo_unknown"), s.get("usb_out_timeouts")))
check(accounting(s) and s.get("offered") == 80, "every frame accounted for (offered %s, confirmed %s)" % (
    s.get("offered"), s.get("confirmed")))

for name in failed_scenarios:
    if name is None:
        continue
    print("---- context of the failed scenario '%s'" % name)
    for f in ("out_%s.txt" % name, "sum_%s.txt" % name):
        text = read(f)
        if text:
            print("-- %s (last 25 lines)" % f)
            print("\n".join(text.splitlines()[-25:]))
    glog = (read("gadget.log", "") or "").splitlines()
    start = max([i for i, l in enumerate(glog) if "scenario %s " % name in l] or [0])
    print("-- gadget.log from the scenario start (40 lines)")
    print("\n".join(glog[start:start + 40]))

print("%d checks passed, %d failed%s" % (passes, len(failures), (": " + "; ".join(failures)) if failures else ""))
sys.exit(1 if failures else 0)
