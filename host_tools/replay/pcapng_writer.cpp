// SPDX-License-Identifier: MIT
// pcapng_writer.cpp: see pcapng_writer.h.
#include "pcapng_writer.h"

#include <cerrno>
#include <cstring>
#include <vector>

namespace sl::replay {

namespace {

constexpr uint32_t kShb = 0x0A0D0D0Au;
constexpr uint32_t kIdb = 0x00000001u;
constexpr uint32_t kEpb = 0x00000006u;
constexpr uint16_t kLinkEthernet = 1;
constexpr size_t kEth = 14, kIp = 20, kTcp = 20;

constexpr uint8_t kFin = 0x01, kSyn = 0x02, kPsh = 0x08, kAck = 0x10;

void put16be(uint8_t *p, uint32_t v) { p[0] = uint8_t(v >> 8); p[1] = uint8_t(v); }
void put32be(uint8_t *p, uint32_t v)
{
    p[0] = uint8_t(v >> 24); p[1] = uint8_t(v >> 16); p[2] = uint8_t(v >> 8); p[3] = uint8_t(v);
}
// pcapng blocks are written in host byte order (the byte-order magic tells readers which).
void put_host(std::vector<uint8_t> &b, const void *v, size_t n)
{
    const auto *p = static_cast<const uint8_t *>(v);
    b.insert(b.end(), p, p + n);
}
void put_u16(std::vector<uint8_t> &b, uint16_t v) { put_host(b, &v, 2); }
void put_u32(std::vector<uint8_t> &b, uint32_t v) { put_host(b, &v, 4); }

// RFC 1071 one's-complement sum, folded.
uint32_t csum_add(uint32_t sum, const uint8_t *p, size_t n)
{
    for (size_t i = 0; i + 1 < n; i += 2) sum += uint32_t(p[i]) << 8 | p[i + 1];
    if (n & 1u) sum += uint32_t(p[n - 1]) << 8;
    return sum;
}
uint16_t csum_fold(uint32_t sum)
{
    while (sum >> 16) sum = (sum & 0xFFFFu) + (sum >> 16);
    return uint16_t(~sum & 0xFFFFu);
}

// Locally administered MAC addresses derived from the IP (stable, recognisable).
void mac_of(uint8_t *m, uint32_t ip)
{
    m[0] = 0x02; m[1] = 0x00; put32be(m + 2, ip);
}

} // namespace

PcapngWriter::~PcapngWriter()
{
    std::string err;
    if (f_ != nullptr) finish(err);
}

bool PcapngWriter::write_block(uint32_t type, const uint8_t *body, size_t n)
{
    const size_t pad = (4 - n % 4) % 4;
    const uint32_t total = uint32_t(12 + n + pad);
    static const uint8_t zeros[4] = {0, 0, 0, 0};
    if (std::fwrite(&type, 4, 1, f_) != 1 || std::fwrite(&total, 4, 1, f_) != 1 ||
        (n != 0 && std::fwrite(body, 1, n, f_) != n) ||
        (pad != 0 && std::fwrite(zeros, 1, pad, f_) != pad) ||
        std::fwrite(&total, 4, 1, f_) != 1)
        failed_ = true;
    return !failed_;
}

bool PcapngWriter::open(const std::string &path, const PcapngSession &s, std::string &err)
{
    if (s.mss == 0 || s.mss > 65495) {
        err = "mss must be 1..65495";
        return false;
    }
    s_ = s;
    if (path == "-") {
        f_ = stdout;
        own_ = false;
    } else {
        f_ = std::fopen(path.c_str(), "wb");
        own_ = true;
        if (f_ == nullptr) {
            err = path + ": " + std::strerror(errno);
            return false;
        }
    }
    radar_seq_ = radar_isn_;
    client_seq_ = client_isn_;
    // Section Header Block: byte-order magic, version 1.0, section length unknown (-1),
    // option shb_userappl (4).
    std::vector<uint8_t> b;
    put_u32(b, 0x1A2B3C4Du);
    put_u16(b, 1);
    put_u16(b, 0);
    const int64_t unknown = -1;
    put_host(b, &unknown, 8);
    const char appl[] = "shadowlean sl-replay to-pcapng";
    put_u16(b, 4);
    put_u16(b, uint16_t(sizeof appl - 1));
    put_host(b, appl, sizeof appl - 1);
    while (b.size() % 4) b.push_back(0);
    put_u32(b, 0); // opt_endofopt
    write_block(kShb, b.data(), b.size());
    // Interface Description Block: Ethernet, snaplen 262144, default resolution (us).
    b.clear();
    put_u16(b, kLinkEthernet);
    put_u16(b, 0);
    put_u32(b, 262144u);
    write_block(kIdb, b.data(), b.size());
    if (failed_) err = path + ": write error";
    return !failed_;
}

bool PcapngWriter::frame(bool from_radar, uint8_t flags, const uint8_t *payload, size_t n,
                         uint64_t ts_us)
{
    if (f_ == nullptr || failed_) return false;
    std::vector<uint8_t> pkt(kEth + kIp + kTcp + n);
    uint8_t *eth = pkt.data(), *ip = eth + kEth, *tcp = ip + kIp;
    const uint32_t src = from_radar ? s_.radar_ip : s_.client_ip;
    const uint32_t dst = from_radar ? s_.client_ip : s_.radar_ip;
    mac_of(eth, dst);
    mac_of(eth + 6, src);
    put16be(eth + 12, 0x0800);
    ip[0] = 0x45;
    put16be(ip + 2, uint32_t(kIp + kTcp + n));
    put16be(ip + 4, from_radar ? ip_id_radar_++ : ip_id_client_++);
    put16be(ip + 6, 0x4000); // DF
    ip[8] = 64;
    ip[9] = 6;
    put32be(ip + 12, src);
    put32be(ip + 16, dst);
    put16be(ip + 10, csum_fold(csum_add(0, ip, kIp)));
    put16be(tcp + 0, from_radar ? s_.radar_port : s_.client_port);
    put16be(tcp + 2, from_radar ? s_.client_port : s_.radar_port);
    put32be(tcp + 4, from_radar ? radar_seq_ : client_seq_);
    put32be(tcp + 8, (flags & kAck) ? (from_radar ? client_seq_ : radar_seq_) : 0u);
    tcp[12] = 5u << 4;
    tcp[13] = flags;
    put16be(tcp + 14, 65535);
    if (n != 0) std::memcpy(tcp + kTcp, payload, n);
    uint8_t pseudo[12];
    put32be(pseudo, src);
    put32be(pseudo + 4, dst);
    pseudo[8] = 0;
    pseudo[9] = 6;
    put16be(pseudo + 10, uint32_t(kTcp + n));
    put16be(tcp + 16, csum_fold(csum_add(csum_add(0, pseudo, 12), tcp, kTcp + n)));
    // Sequence space: payload bytes, SYN and FIN count one each.
    const uint32_t adv = uint32_t(n) + ((flags & (kSyn | kFin)) ? 1u : 0u);
    (from_radar ? radar_seq_ : client_seq_) += adv;

    std::vector<uint8_t> b;
    b.reserve(20 + pkt.size() + 4);
    put_u32(b, 0); // interface 0
    put_u32(b, uint32_t(ts_us >> 32));
    put_u32(b, uint32_t(ts_us));
    put_u32(b, uint32_t(pkt.size()));
    put_u32(b, uint32_t(pkt.size()));
    b.insert(b.end(), pkt.begin(), pkt.end());
    while (b.size() % 4) b.push_back(0);
    ++frames_;
    return write_block(kEpb, b.data(), b.size());
}

bool PcapngWriter::handshake(uint64_t ts_us)
{
    return frame(false, kSyn, nullptr, 0, ts_us) && frame(true, kSyn | kAck, nullptr, 0, ts_us) &&
           frame(false, kAck, nullptr, 0, ts_us);
}

bool PcapngWriter::client_send(const uint8_t *data, size_t n, uint64_t ts_us)
{
    return frame(false, kPsh | kAck, data, n, ts_us) && frame(true, kAck, nullptr, 0, ts_us);
}

bool PcapngWriter::radar_send(const uint8_t *data, size_t n, uint64_t ts_us)
{
    while (n > 0) {
        const size_t k = n < s_.mss ? n : s_.mss;
        if (!frame(true, kPsh | kAck, data, k, ts_us)) return false;
        radar_bytes_ += k;
        data += k;
        n -= k;
        if (++unacked_segments_ == 2) {
            unacked_segments_ = 0;
            if (!frame(false, kAck, nullptr, 0, ts_us)) return false;
        }
    }
    return true;
}

bool PcapngWriter::close_session(uint64_t ts_us)
{
    return frame(true, kFin | kAck, nullptr, 0, ts_us) &&
           frame(false, kFin | kAck, nullptr, 0, ts_us) && frame(true, kAck, nullptr, 0, ts_us);
}

bool PcapngWriter::finish(std::string &err)
{
    if (f_ == nullptr) return !failed_;
    if (std::fflush(f_) != 0) failed_ = true;
    if (own_ && std::fclose(f_) != 0) failed_ = true;
    f_ = nullptr;
    if (failed_) err = "write error";
    return !failed_;
}

} // namespace sl::replay
