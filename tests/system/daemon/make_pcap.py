#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Wrap a raw Colossus capture into a pcap of one TCP session (radar 10.0.0.2:6317 ->
client 10.0.0.1:40000, Ethernet/IPv4), the way tcpdump would have recorded it, with
the usual damage of a real recording: every 50th segment retransmitted, every 37th pair
of segments swapped (out of order), plus the client's empty ACKs and the handshake.

    make_pcap.py RAW OUT.pcap [--mss 1448]
"""
import struct
import sys


def csum(b):
    if len(b) % 2:
        b += b"\0"
    s = sum(struct.unpack(f"!{len(b) // 2}H", b))
    while s >> 16:
        s = (s & 0xFFFF) + (s >> 16)
    return ~s & 0xFFFF


def packet(src, dst, sport, dport, seq, ack, flags, payload):
    tcp = struct.pack("!HHIIBBHHH", sport, dport, seq & 0xFFFFFFFF, ack & 0xFFFFFFFF, 5 << 4, flags,
                      65535, 0, 0)
    pseudo = struct.pack("!4s4sBBH", src, dst, 0, 6, len(tcp) + len(payload))
    c = csum(pseudo + tcp + payload)
    tcp = tcp[:16] + struct.pack("!H", c) + tcp[18:]
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(tcp) + len(payload), 0, 0x4000, 64, 6, 0, src, dst)
    ip = ip[:10] + struct.pack("!H", csum(ip)) + ip[12:]
    eth = b"\x02\0\0\0\0\x01" + b"\x02\0\0\0\0\x02" + b"\x08\x00"
    return eth + ip + tcp + payload


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    mss = int(argv[argv.index("--mss") + 1]) if "--mss" in argv else 1448
    data = open(argv[1], "rb").read()
    radar, client = bytes([10, 0, 0, 2]), bytes([10, 0, 0, 1])
    rp, cp = 6317, 40000
    isn_r, isn_c = 1000, 5000
    pkts = []
    t = [1700000000.0]

    def add(p):
        t[0] += 0.0001
        pkts.append((t[0], p))

    add(packet(client, radar, cp, rp, isn_c, 0, 0x02, b""))           # SYN
    add(packet(radar, client, rp, cp, isn_r, isn_c + 1, 0x12, b""))   # SYN ACK
    add(packet(client, radar, cp, rp, isn_c + 1, isn_r + 1, 0x10, b""))
    segs = [(off, data[off:off + mss]) for off in range(0, len(data), mss)]
    order = list(range(len(segs)))
    for i in range(36, len(order) - 1, 37):
        order[i], order[i + 1] = order[i + 1], order[i]
    for k, i in enumerate(order):
        off, pay = segs[i]
        add(packet(radar, client, rp, cp, isn_r + 1 + off, isn_c + 1, 0x18, pay))
        if k % 50 == 49:
            add(packet(radar, client, rp, cp, isn_r + 1 + off, isn_c + 1, 0x18, pay))  # retransmission
        if k % 20 == 19:
            add(packet(client, radar, cp, rp, isn_c + 1, isn_r + 1 + off + len(pay), 0x10, b""))
    add(packet(radar, client, rp, cp, isn_r + 1 + len(data), isn_c + 1, 0x11, b""))  # FIN
    with open(argv[2], "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 262144, 1))
        for ts, p in pkts:
            sec = int(ts)
            usec = int(round((ts - sec) * 1e6))
            f.write(struct.pack("<IIII", sec, usec, len(p), len(p)))
            f.write(p)
    print(f"make_pcap: {len(data)} bytes in {len(segs)} segments, {len(pkts)} packets -> {argv[2]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
