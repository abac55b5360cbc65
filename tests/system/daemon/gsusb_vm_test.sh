#!/bin/sh
# SPDX-License-Identifier: MIT
# gsusb_vm_test.sh SOURCE_DIR CACHE_DIR OUT_DIR SHADOWLEAND SL_SIM PYTHON
# shadowleand's --gs-usb output against a fake candleLight in the test VM (the harness
# tests/support/vm/qemu_run.sh, the fake device of tests/system/gsusb/fake_candlelight.py; the same cache directory, so
# the kernel package is downloaded once for both tests). On the host afterwards: the frames
# the device received over USB equal the daemon's --can-log field by field, every one was
# confirmed (echo), they decode with the DBC and match the targets, and the kernel driver
# got the device back at exit. Exit 77 when qemu-system-x86_64 is missing.
set -eu
SRC=$1; CACHE=$2; OUT=$3; DAEMON=$4; SIM=$5; PY=$6
GS="$SRC/tests/system/gsusb"
rm -rf "$OUT"; mkdir -p "$OUT"; OUT=$(cd "$OUT" && pwd)
"$SIM" "$SRC/tests/system/daemon/scenes/static_four_poles.ini" -o "$OUT/short.colossus" --quiet
printf 'SL_DAEMON=%s\nSL_GSDIR=%s\nSL_CAPTURE=%s\n' "$DAEMON" "$GS" "$OUT/short.colossus" > "$OUT/vm.env"
rc=0
sh "$SRC/tests/support/vm/qemu_run.sh" "$SRC" "$CACHE" "$OUT" "$SRC/tests/system/daemon/gsusb_guest.sh" || rc=$?
[ -f "$OUT/daemon.out" ] && sed 's/^/  daemon: /' "$OUT/daemon.out"
[ $rc -eq 0 ] || exit $rc
[ "$(cat "$OUT/rc_daemon" 2>/dev/null)" = 0 ] || { echo "FAIL: shadowleand exit $(cat "$OUT/rc_daemon" 2>/dev/null)"; exit 1; }
"$PY" - "$OUT" "$SRC/tests/system/daemon" <<'PY'
import os, sys
sys.path.insert(0, sys.argv[2] + "/../../../scripts")
import sl_can_decode as scd
out = sys.argv[1]
dev = scd.read_candump(os.path.join(out, "dev_daemon.log"))
mine = scd.read_candump(os.path.join(out, "daemon.log"))
key = lambda f: (f[2], f[3], f[4])
errs = []
if not mine:
    errs.append("the daemon logged no frame")
if [key(f) for f in dev] != [key(f) for f in mine]:
    errs.append(f"device received {len(dev)} frames, daemon logged {len(mine)}; first difference at "
                f"{next((i for i, (a, b) in enumerate(zip(dev, mine)) if key(a) != key(b)), min(len(dev), len(mine)))}")
txt = open(os.path.join(out, "daemon.out")).read()
sink = [l for l in txt.splitlines() if "exit: sink gs_usb:" in l]
if not sink or f"{len(mine)} sent, 0 dropped" not in sink[0]:
    errs.append(f"gs_usb sink: {sink[0] if sink else 'no stats line'} (want {len(mine)} sent = confirmed, 0 dropped)")
if open(os.path.join(out, "can0_back")).read().strip() != "1":
    errs.append("the kernel gs_usb driver did not get the device back (no can0 after exit)")
print(f"gs_usb: the fake candleLight received {len(dev)} frames over USB, the daemon logged {len(mine)}")
for e in errs:
    print("FAIL:", e)
sys.exit(1 if errs else 0)
PY
"$PY" "$SRC/tests/system/daemon/check_can_vs_targets.py" "$SRC/boards/paper-sim/shadowlean.dbc" \
    "$OUT/daemon.log" "$OUT/targets.jsonl" --rotations 24 --min-poles 4
