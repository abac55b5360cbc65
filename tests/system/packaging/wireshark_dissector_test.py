#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The Colossus Wireshark dissector against the module's own decoder.

Two real Oxford scans become a raw capture (sl-replay from-oxford); a copy gets junk
between messages (zero runs, a partial signature, headers with version 2). Each is turned
into a pcapng TCP session by `sl-replay to-pcapng` (from the file, and through a pipe on
stdin/stdout, which must give the same bytes), then:
  - sl-inspect (the module's pcap reader + core decoder) decodes the pcapng to the same
    messages and decoder counters as the raw capture: nothing lost, nothing added;
  - tshark with packaging/wireshark/colossus.lua finds the same messages per id, plus the
    client's Start FFT, and accounts for exactly the junk bytes the core decoder skipped;
    the Configuration and FFT fields equal what the scans hold; IP/TCP checksums verify.
"""
import argparse, collections, json, os, shutil, subprocess, sys

SIG = bytes([0, 1, 3, 3, 7, 7, 0xF, 0xF, 0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE])
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, **kw)
    if r.returncode != 0:
        sys.exit("command failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stderr.decode()))
    return r.stdout


def inspect(args, path):
    return json.loads(run([args.inspect, path, "--json"]))


def tshark_fields(args, path, fields, extra=()):
    cmd = [args.tshark, "-n", "-X", "lua_script:" + args.dissector, "-r", path, "-T", "fields"]
    cmd += list(extra)
    for f in fields:
        cmd += ["-e", f]
    rows = []
    for line in run(cmd, env=dict(os.environ, HOME=args.work)).decode().splitlines():
        rows.append([c.split(",") if c else [] for c in line.split("\t")])
    return rows


def main():
    ap = argparse.ArgumentParser()
    for k in ("replay", "inspect", "tshark", "dissector", "oxford", "work"):
        ap.add_argument("--" + k, required=True)
    args = ap.parse_args()
    if not args.tshark or not os.path.exists(args.tshark):
        print("tshark not installed (Debian package tshark)")
        return 1
    shutil.rmtree(args.work, ignore_errors=True)
    png = os.path.join(args.work, "png")
    os.makedirs(png)
    src = os.path.join(args.oxford, "radar")
    scans = sorted(p for p in os.listdir(src) if p.endswith(".png"))[:2]
    for p in scans:
        shutil.copy(os.path.join(src, p), png)
    raw = os.path.join(args.work, "ox.colossus")
    run([args.replay, "from-oxford", png, "--out", raw])

    # Junk after every 100th message: 7 zero bytes + 12 bytes of signature, then a whole
    # header with version 2 (the decoder must skip all of it, byte-wise resync).
    data = open(raw, "rb").read()
    out, i, k = bytearray(), 0, 0
    while i < len(data):
        n = 22 + int.from_bytes(data[i + 18:i + 22], "big")
        out += data[i:i + n]
        i += n
        k += 1
        if k % 100 == 0:
            out += b"\0" * 7 + SIG[:12] + SIG + bytes([2, 30, 0, 0, 0, 4])
    junk = os.path.join(args.work, "junk.colossus")
    open(junk, "wb").write(out)

    for name, path in (("clean", raw), ("junk", junk)):
        pcap = path.replace(".colossus", ".pcapng")
        run([args.replay, "to-pcapng", path, "--out", pcap, "--mss", "1000"])
        piped = run([args.replay, "to-pcapng", "-", "--out", "-", "--mss", "1000"],
                    stdin=open(path, "rb"))
        check(piped == open(pcap, "rb").read(), name + ": stdin -> stdout gives the same pcapng")

        a, b = inspect(args, path), inspect(args, pcap)
        check(b["format"] == "pcapng", name + ": sl-inspect reads it as pcapng")
        check(a["messages"] == b["messages"], name + ": same messages in raw and pcapng %s" %
              b["messages"]["by_id"])
        check(a["decoder"] == b["decoder"], name + ": same decoder counters (skipped %d)" %
              b["decoder"]["bytes_skipped"])
        check(b["pcap"]["gaps"] == 0 and b["pcap"]["retransmitted_segments"] == 0,
              name + ": one clean TCP session")

        rows = tshark_fields(args, pcap, ["colossus.id", "colossus.junk_len"])
        ids = collections.Counter(x for r in rows for x in r[0])
        want = collections.Counter({k: v for k, v in a["messages"]["by_id"].items()})
        want["21"] += 1  # the client's Start FFT
        check(ids == want, name + ": tshark message ids %s == decoder %s" % (dict(ids), dict(want)))
        skipped = sum(int(x) for r in rows for x in r[1])
        check(skipped == a["decoder"]["bytes_skipped"],
              name + ": tshark junk bytes %d == decoder skipped %d" %
              (skipped, a["decoder"]["bytes_skipped"]))

    # Field values, on the clean capture.
    pcap = raw.replace(".colossus", ".pcapng")
    a = inspect(args, raw)
    cfg = tshark_fields(args, pcap, ["colossus.cfg.azimuths", "colossus.cfg.bin_size",
                                     "colossus.cfg.range_bins", "colossus.cfg.encoder_size"],
                        ["-Y", "colossus.id == 10"])
    c = a["configuration"]
    check(len(cfg) == 1 and [v[0] for v in cfg[0]] ==
          [str(c["azimuths"]), str(c["bin_size_100um"]), str(c["range_bins"]), str(c["encoder_size"])],
          "Configuration fields %s" % (cfg[0] if cfg else None))
    fft = tshark_fields(args, pcap, ["colossus.fft.azimuth", "colossus.fft.bins",
                                     "colossus.fft.seconds", "colossus.fft.nanoseconds"],
                        ["-Y", "colossus.id == 30"])
    az = [int(x) for r in fft for x in r[0]]
    check(az == [13 + 14 * (i % 400) for i in range(800)], "FFT azimuths are the scans' 13 + 14 i")
    bins = {int(x) for r in fft for x in r[1]}
    check(bins == {c["range_bins"]}, "every FFT holds %s bins" % bins)
    t0 = int(fft[0][2][0]) * 1000000 + int(fft[0][3][0]) // 1000
    check(t0 == a["fft"]["time_first_us"], "first FFT time %d us == sl-inspect's" % t0)
    exp = run([args.tshark, "-n", "-o", "tcp.check_checksum:TRUE", "-o", "ip.check_checksum:TRUE",
               "-X", "lua_script:" + args.dissector, "-r", pcap, "-q", "-z", "expert"],
              env=dict(os.environ, HOME=args.work)).decode()
    check("Bad checksum" not in exp and "Errors" not in exp, "no checksum or protocol errors")

    # A file without any radar message is an error, not an empty pcapng.
    empty = os.path.join(args.work, "none.colossus")
    open(empty, "wb").write(b"no radar here\n" * 100)
    r = subprocess.run([args.replay, "to-pcapng", empty, "--out", empty + ".pcapng"],
                       capture_output=True)
    check(r.returncode == 1 and b"no radar message" in r.stderr,
          "to-pcapng on a file without radar messages exits 1 and says so")
    r = subprocess.run([args.replay, "to-pcapng", os.path.join(args.work, "missing")],
                       capture_output=True)
    check(r.returncode == 2, "to-pcapng without --out is a usage error (2)")
    print("%d failure(s)" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
