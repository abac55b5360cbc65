#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""health_summary.py BOARD.dbc CAN.log: what a CAN consumer sees of the module's health,
decoded with the board's generated DBC only (python3-canmatrix, CRC checked):

    links=3,4 fault=0x0041 faults=CONFIG_MISMATCH,AZIMUTH_DISORDER reconnects=2 rotations=8
    statuses=12 healths=12 unpaired=0 badcrc=0 frames=57 max_frames_per_s=15

links: the LinkState values of every Status frame (distinct, sorted); fault: the OR of every
Health frame's Fault (named with the DBC's value table); reconnects: the last Health's
Reconnects; rotations: the last Status's Rotations; unpaired: Status frames not followed at
once by a Health frame; max_frames_per_s: the most frames in any 1 s of log time.
"""
import sys

sys.path.insert(0, __import__("os").path.join(__import__("os").path.dirname(__file__), "..", "..", "..", "scripts"))
import sl_can_decode as scd  # noqa: E402


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    decoded = [(f, d) for f, d in scd.decode_log(argv[1], argv[2])]
    db = scd.load_dbc(argv[1])
    names = {}
    for fr in db.frames:
        if fr.name == "Health":
            sig = fr.signal_by_name("Fault")
            names = {int(k): v for k, v in sig.values.items()}
    links, fault, reconnects, rotations = set(), 0, 0, 0
    statuses = healths = unpaired = badcrc = 0
    times = []
    prev_status = False
    for f, d in decoded:
        times.append(f[0])
        if d is None:
            continue
        if not d.crc_ok:
            badcrc += 1
        if prev_status and d.name != "Health":
            unpaired += 1
        prev_status = d.name == "Status"
        if d.name == "Status":
            statuses += 1
            links.add(d.raw["LinkState"])
            rotations = d.raw["Rotations"]
        elif d.name == "Health":
            healths += 1
            fault |= d.raw["Fault"]
            reconnects = d.raw["Reconnects"]
    if prev_status:
        unpaired += 1
    lo, best = 0, 0
    for i, t in enumerate(times):
        while times[lo] + 1.0 <= t:
            lo += 1
        best = max(best, i - lo + 1)
    named = [names.get(1 << b, f"BIT{b}") for b in range(16) if fault & (1 << b)]
    print(f"links={','.join(str(x) for x in sorted(links))} fault={fault:#06x} "
          f"faults={','.join(named) or '-'} reconnects={reconnects} rotations={rotations} "
          f"statuses={statuses} healths={healths} unpaired={unpaired} badcrc={badcrc} "
          f"frames={len(times)} max_frames_per_s={best}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
