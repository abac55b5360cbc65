#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""reference_numpy.py: a straightforward NumPy implementation of the detection front end,
the side-by-side reference for sl-bench (host_tools/bench/compare.sh).

    reference_numpy.py CAPTURE [--loop N] [--roi BINS] [--threshold T] [--n N]
                       [--near BINS] [--win BINS] [--azimuths 400] [--encoder 5600]
                       [--repeat N]

The same steps as the core pipeline, on the same raw Colossus capture, read whole into
memory first (then --loop N copies, as sl-bench does):
  1. parse messages: walk the 22-byte headers (signature, version, id, big-endian length);
  2. ROI copy: the first ROI bins of every 8-bit FFT message (id 30) into one array;
  3. threshold: power >= T;
  4. n-frame consistency: per (azimuth, bin), occupied in each of the last n rotations
     (a sliding sum over rotations of the thresholded frames);
  5. run extraction: runs of stable-occupied bins starting inside [near, win) per azimuth.
It prints the capture bytes, the wall-clock time of steps 1-5 (best of --repeat runs) and
MB/s (1 MB = 1e6 bytes). Defaults match sl-bench on paper-sim: ROI 160 bins (what detection
reads), threshold 40, n 16, near 39, win 135. Debian python3-numpy (scripts/deps.sh test).
"""
import argparse
import sys
import time

import numpy as np

SIG = bytes([0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
             0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE])


def parse(data):
    """Offsets, ids and payload lengths of every message (junk skipped byte-wise)."""
    offs, ids, lens = [], [], []
    i, n = 0, len(data)
    while i + 22 <= n:
        if data[i:i + 16] != SIG:
            j = data.find(SIG, i + 1)
            if j < 0:
                break
            i = j
            continue
        ln = int.from_bytes(data[i + 18:i + 22], "big")
        if i + 22 + ln > n:
            break
        offs.append(i)
        ids.append(data[i + 17])
        lens.append(ln)
        i += 22 + ln
    return np.array(offs, dtype=np.int64), np.array(ids, dtype=np.uint8), np.array(lens, dtype=np.int64)


def run(data, buf, a):
    offs, ids, lens = parse(data)                              # 1. messages
    fft = (ids == 30) & (lens >= 14 + a.roi)
    po = offs[fft] + 22                                        # payload offsets
    ticks = (buf[po[:, None] + np.array([4, 5])].astype(np.int64) * [256, 1]).sum(axis=1)
    dat = (buf[po[:, None] + np.array([0, 1])].astype(np.int64) * [256, 1]).sum(axis=1)
    rows = buf[(po + dat)[:, None] + np.arange(a.roi)]         # 2. ROI copy (gather)
    occ = rows >= a.threshold                                  # 3. threshold
    az = ticks * a.azimuths // a.encoder
    rot = np.concatenate([[0], np.cumsum(np.diff(az) < 0)])    # a new rotation at each wrap
    frames = np.zeros((rot[-1] + 1 if len(rot) else 0, a.azimuths, a.roi), dtype=bool)
    frames[rot, az] = occ
    # 4. consistency: occupied in each of the last n rotations (sliding sum)
    cs = np.cumsum(frames, axis=0, dtype=np.int16)
    win = cs.copy()
    win[a.n:] -= cs[:-a.n]
    stable = (win == a.n)
    stable[:a.n - 1] = False
    # 5. runs of stable-occupied bins starting inside [near, win)
    s = stable[:, :, a.near:].astype(np.int8)
    d = np.diff(s, axis=2, prepend=0)
    r_i, az_i, start = np.nonzero(d == 1)
    keep = start + a.near < a.win
    return int(keep.sum()), frames.shape[0], int(fft.sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("capture")
    ap.add_argument("--loop", type=int, default=1)
    ap.add_argument("--roi", type=int, default=160)
    ap.add_argument("--threshold", type=int, default=40)
    ap.add_argument("--n", type=int, default=16)
    ap.add_argument("--near", type=int, default=39)
    ap.add_argument("--win", type=int, default=135)
    ap.add_argument("--azimuths", type=int, default=400)
    ap.add_argument("--encoder", type=int, default=5600)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    with open(a.capture, "rb") as f:
        one = f.read()
    data = one * a.loop
    buf = np.frombuffer(data, dtype=np.uint8)
    best = 1e30
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        runs, rots, msgs = run(data, buf, a)
        best = min(best, time.perf_counter() - t0)
    print(f"capture: {a.capture} (x{a.loop})")
    print(f"bytes: {len(data)}")
    print(f"fft_messages: {msgs}")
    print(f"rotations: {rots}")
    print(f"stable_runs: {runs}")
    print(f"wall_s: {best:.6f}")
    print(f"MB_per_s: {len(data) / best / 1e6:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
