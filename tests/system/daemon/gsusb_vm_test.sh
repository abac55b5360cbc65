#!/bin/sh
# SPDX-License-Identifier: MIT
# gsusb_vm_test.sh SOURCE_DIR CACHE_DIR OUT_DIR SHADOWLEAND SL_SIM PYTHON [BOARD]
# shadowleand's --gs-usb output against a fake candleLight in the test VM (the harness
# tests/support/vm/qemu_run.sh, the fake device of tests/system/gsusb/fake_candlelight.py; the same cache directory, so
# the kernel package is downloaded once for both tests). On the host afterwards: the frames
# the device received over USB equal the daemon's --can-log field by field, every one was
# confirmed (echo), they decode with the DBC and match the targets, and the kernel driver
# got the device back at exit. When the guest stalled long enough on a loaded host to lose
# frames (transfer and echo timeouts of 1 s), every loss must be counted by reason, the
# device's frames an in-order subsequence of the log, the adapter never down: no timing
# assumption. BOARD (default paper-sim) is the daemon's board; with 29-bit ids
# (paper-sim-29bit) every frame the device received must be an extended frame (bit 31 of the
# gs_usb can_id: an 8-digit id in its log). Exit 77 when qemu-system-x86_64 is missing.
set -eu
SRC=$1; CACHE=$2; OUT=$3; DAEMON=$4; SIM=$5; PY=$6; BOARD=${7:-paper-sim}
GS="$SRC/tests/system/gsusb"
rm -rf "$OUT"; mkdir -p "$OUT"; OUT=$(cd "$OUT" && pwd)
"$SIM" "$SRC/tests/system/daemon/scenes/static_four_poles.ini" -o "$OUT/short.colossus" --quiet
printf 'SL_DAEMON=%s\nSL_GSDIR=%s\nSL_CAPTURE=%s\nSL_BOARD=%s\n' "$DAEMON" "$GS" "$OUT/short.colossus" \
    "$BOARD" > "$OUT/vm.env"
rc=0
sh "$SRC/tests/support/vm/qemu_run.sh" "$SRC" "$CACHE" "$OUT" "$SRC/tests/system/daemon/gsusb_guest.sh" || rc=$?
[ -f "$OUT/daemon.out" ] && sed 's/^/  daemon: /' "$OUT/daemon.out"
[ $rc -eq 0 ] || exit $rc
[ "$(cat "$OUT/rc_daemon" 2>/dev/null)" = 0 ] || { echo "FAIL: shadowleand exit $(cat "$OUT/rc_daemon" 2>/dev/null)"; exit 1; }
"$PY" - "$OUT" "$SRC/tests/system/daemon" "$BOARD" <<'PY'
import os, re, sys
sys.path.insert(0, sys.argv[2] + "/../../../scripts")
import sl_can_decode as scd
out = sys.argv[1]
eff = sys.argv[3].endswith("29bit")
dev = scd.read_candump(os.path.join(out, "dev_daemon.log"))
mine = scd.read_candump(os.path.join(out, "daemon.log"))
key = lambda f: (f[2], f[3], f[4])
errs = []
if not mine:
    errs.append("the daemon logged no frame")
txt = open(os.path.join(out, "daemon.out")).read()
sink = [l for l in txt.splitlines() if "exit: sink gs_usb:" in l]
m = re.search(r"(\d+) sent, (\d+) dropped, (\d+) queued", sink[0]) if sink else None
if m is None:
    errs.append("gs_usb sink: no stats line")
    sent = dropped = queued = -1
else:
    sent, dropped, queued = (int(x) for x in m.groups())
if dropped == 0:
    # The common case: every frame logged was confirmed by the device, in order.
    if [key(f) for f in dev] != [key(f) for f in mine]:
        errs.append(f"device received {len(dev)} frames, daemon logged {len(mine)}; first difference at "
                    f"{next((i for i, (a, b) in enumerate(zip(dev, mine)) if key(a) != key(b)), min(len(dev), len(mine)))}")
    if sent != len(mine) or queued != 0:
        errs.append(f"gs_usb sink: {sink[0]} (want {len(mine)} sent = confirmed, 0 dropped)")
else:
    # A TCG guest on a loaded host can stall the device's USB side for longer than the
    # transfer and echo timeouts (1 s): then frames are lost, and the test checks, without
    # any timing assumption, that each loss is counted by reason and nothing else went
    # wrong: the device got an in-order subsequence of what was logged, every logged frame
    # is accounted for, the adapter never went down, no frame was invalid.
    g = [l for l in txt.splitlines() if "exit: gs_usb:" in l]
    b = re.search(r"(\d+) submitted, (\d+) confirmed, (\d+) unconfirmed; dropped "
                  r"in-flight/down/full/stale/error/invalid (\d+)/(\d+)/(\d+)/(\d+)/(\d+)/(\d+); "
                  r"(\d+) down events", g[0]) if g else None
    if b is None:
        errs.append("frames lost but no gs_usb breakdown line")
    else:
        sub, conf, unconf, infl, down, full, stale, err, inval, downev = (int(x) for x in b.groups())
        it = iter(key(f) for f in mine)
        if not all(k in it for k in (key(f) for f in dev)):
            errs.append("the device received frames not in the daemon's log order")
        if sub + down + full + stale + err + inval + queued != len(mine):
            errs.append(f"accounting: {sub} submitted + drops {down + full + stale + err + inval} != {len(mine)} logged")
        if not (conf <= len(dev) <= sub) or conf != sent:
            errs.append(f"{len(dev)} received, {conf} confirmed, {sub} submitted: inconsistent")
        if down or inval or downev:
            errs.append(f"adapter down {down}/{downev} times or {inval} invalid frames")
        print(f"gs_usb: {dropped} frames lost under load, counted: {g[0].split('gs_usb: ', 1)[1]}")
        open(os.path.join(out, "lost"), "w").write(f"{dropped}\n")
if eff and (not dev or not all(f[3] for f in dev + mine)):
    errs.append("29-bit board: not every frame on USB and in the log is an extended frame")
if open(os.path.join(out, "can0_back")).read().strip() != "1":
    errs.append("the kernel gs_usb driver did not get the device back (no can0 after exit)")
print(f"gs_usb: the fake candleLight received {len(dev)} frames over USB, the daemon logged {len(mine)}")
for e in errs:
    print("FAIL:", e)
sys.exit(1 if errs else 0)
PY
# After counted losses the Status frames say so (CanDropped), and a stalled guest may have
# delayed a rotation past the idle Status period.
lossy=""
[ -f "$OUT/lost" ] && lossy="--dropped-ok --idle-ok"
"$PY" "$SRC/tests/system/daemon/check_can_vs_targets.py" "$SRC/boards/$BOARD/shadowlean.dbc" \
    "$OUT/daemon.log" "$OUT/targets.jsonl" --rotations 24 --min-poles 4 $lossy
