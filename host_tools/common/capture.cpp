// capture.cpp: raw capture I/O and pcap/pcapng TCP reassembly (see capture.h).
#include "capture.h"

#include <pcap/pcap.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <tuple>

namespace sl {

namespace {

// The 16-byte Colossus signature, used only to auto-detect the radar side of a pcap.
const uint8_t kSignature[16] = {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                                0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE};

uint16_t be16(const uint8_t *p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }
uint32_t be32(const uint8_t *p)
{
    return (static_cast<uint32_t>(p[0]) << 24) | (static_cast<uint32_t>(p[1]) << 16) |
           (static_cast<uint32_t>(p[2]) << 8) | static_cast<uint32_t>(p[3]);
}

std::string addr_str(const uint8_t *a, bool v6, uint16_t port)
{
    char buf[80];
    if (!v6) {
        std::snprintf(buf, sizeof buf, "%u.%u.%u.%u:%u", a[0], a[1], a[2], a[3], port);
    } else {
        std::string s = "[";
        for (int i = 0; i < 16; i += 2) {
            char h[8];
            std::snprintf(h, sizeof h, "%s%x", i ? ":" : "", be16(a + i));
            s += h;
        }
        std::snprintf(buf, sizeof buf, "%s]:%u", s.c_str(), port);
    }
    return buf;
}

struct Segment {
    int64_t rel = 0;     // sequence number unwrapped, relative to the flow's first packet
    uint32_t len = 0;    // captured payload bytes
    uint64_t index = 0;  // capture order
    size_t pool_off = 0; // payload position in FlowState::pool
};

struct FlowState {
    PcapFlow info;
    bool have_seq = false;
    uint32_t last_seq = 0;
    int64_t last_rel = 0;
    bool syn = false;
    int64_t syn_rel = 0;
    bool fin = false;
    int64_t fin_rel = 0; // sequence number of the FIN (= end of data)
    std::vector<Segment> segs;
    std::vector<uint8_t> pool;
    int64_t radar_score = 0; // + radar->client ids after a signature, - client->radar ids
};

// Colossus ids sent by the radar (+1) or by a client (-1); 0 = unknown.
int id_side(uint8_t id)
{
    switch (id) {
    case 1: case 10: case 30: case 31: case 40: case 123: case 127: return 1;
    case 20: case 21: case 22: case 23: case 24: case 25: case 28: case 29: case 50:
    case 51: case 76: case 120: case 121: case 122: case 124: case 140: return -1;
    default: return 0;
    }
}

int64_t score_payload(const uint8_t *p, size_t n)
{
    int64_t s = 0;
    for (size_t i = 0; i + 18 <= n; ++i) {
        if (p[i] == 0x00 && p[i + 1] == 0x01 && std::memcmp(p + i, kSignature, 16) == 0 &&
            p[i + 16] == 1) {
            s += id_side(p[i + 17]);
            i += 17;
        }
    }
    return s;
}

// Covered-interval set [start, end) used to classify segments in arrival order.
class IntervalSet {
public:
    int64_t covered(int64_t a, int64_t b) const
    {
        int64_t n = 0;
        auto it = m_.upper_bound(a);
        if (it != m_.begin()) {
            --it;
        }
        for (; it != m_.end() && it->first < b; ++it) {
            const int64_t lo = std::max(a, it->first), hi = std::min(b, it->second);
            if (hi > lo) {
                n += hi - lo;
            }
        }
        return n;
    }
    void add(int64_t a, int64_t b)
    {
        auto it = m_.upper_bound(a);
        if (it != m_.begin() && std::prev(it)->second >= a) {
            --it;
        }
        while (it != m_.end() && it->first <= b) {
            a = std::min(a, it->first);
            b = std::max(b, it->second);
            it = m_.erase(it);
        }
        m_[a] = b;
    }

private:
    std::map<int64_t, int64_t> m_;
};

using FlowKey = std::tuple<std::string, std::string, uint16_t, uint16_t>; // raw addrs, ports

} // namespace

const char *capture_format_name(CaptureFormat f)
{
    switch (f) {
    case CaptureFormat::Raw: return "raw";
    case CaptureFormat::Pcap: return "pcap";
    case CaptureFormat::Pcapng: return "pcapng";
    case CaptureFormat::Unknown: break;
    }
    return "unknown";
}

CaptureFormat sniff_capture_format(const std::string &path)
{
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) {
        return CaptureFormat::Unknown;
    }
    uint8_t m[4] = {0, 0, 0, 0};
    const size_t n = std::fread(m, 1, 4, f);
    std::fclose(f);
    if (n == 0) {
        return CaptureFormat::Unknown;
    }
    if (n == 4) {
        const uint32_t be = be32(m);
        const uint32_t le = (static_cast<uint32_t>(m[3]) << 24) | (static_cast<uint32_t>(m[2]) << 16) |
                            (static_cast<uint32_t>(m[1]) << 8) | m[0];
        if (be == 0xa1b2c3d4u || le == 0xa1b2c3d4u || be == 0xa1b23c4du || le == 0xa1b23c4du) {
            return CaptureFormat::Pcap;
        }
        if (be == 0x0a0d0d0au) {
            return CaptureFormat::Pcapng;
        }
    }
    return CaptureFormat::Raw;
}

bool load_capture(const std::string &path, Capture &out, std::string &err, const PcapOptions &opt)
{
    out = Capture{};
    const CaptureFormat fmt = sniff_capture_format(path);
    if (fmt == CaptureFormat::Pcap || fmt == CaptureFormat::Pcapng) {
        return load_pcap(path, out, err, opt);
    }
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) {
        err = path + ": " + std::strerror(errno);
        return false;
    }
    out.format = CaptureFormat::Raw;
    uint8_t buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) {
        out.bytes.insert(out.bytes.end(), buf, buf + n);
    }
    const bool bad = std::ferror(f) != 0;
    std::fclose(f);
    if (bad) {
        err = path + ": read error";
        return false;
    }
    return true;
}

bool load_pcap(const std::string &path, Capture &out, std::string &err, const PcapOptions &opt)
{
    out = Capture{};
    out.format = sniff_capture_format(path);
    out.has_pcap_report = true;
    PcapReport &rep = out.pcap;

    char ebuf[PCAP_ERRBUF_SIZE] = {0};
    pcap_t *pc = pcap_open_offline(path.c_str(), ebuf);
    if (pc == nullptr) {
        err = path + ": " + ebuf;
        return false;
    }
    const int dlt = pcap_datalink(pc);
    const char *dname = pcap_datalink_val_to_name(dlt);
    rep.link_type = dname ? dname : std::to_string(dlt);

    std::map<FlowKey, size_t> live; // current session index per 4-tuple
    std::vector<FlowState> flows;
    pcap_pkthdr *h = nullptr;
    const u_char *pkt = nullptr;
    int rc;
    uint64_t index = 0;
    while ((rc = pcap_next_ex(pc, &h, &pkt)) == 1) {
        ++rep.packets_total;
        ++index;
        const uint8_t *p = pkt;
        size_t cap = h->caplen;
        // Link layer -> IP header.
        int ethertype = -1; // -1: look at the IP version nibble
        size_t off = 0;
        switch (dlt) {
        case DLT_EN10MB:
            if (cap < 14) break;
            ethertype = be16(p + 12);
            off = 14;
            while ((ethertype == 0x8100 || ethertype == 0x88a8) && cap >= off + 4) {
                ethertype = be16(p + off + 2);
                off += 4;
            }
            break;
        case DLT_LINUX_SLL:
            if (cap < 16) break;
            ethertype = be16(p + 14);
            off = 16;
            break;
#ifdef DLT_LINUX_SLL2
        case DLT_LINUX_SLL2:
            if (cap < 20) break;
            ethertype = be16(p);
            off = 20;
            break;
#endif
        case DLT_NULL:
        case DLT_LOOP:
            off = 4;
            break;
        case DLT_RAW:
#ifdef DLT_IPV4
        case DLT_IPV4:
        case DLT_IPV6:
#endif
            off = 0;
            break;
        default:
            off = SIZE_MAX;
            break;
        }
        if (off == SIZE_MAX || off >= cap) {
            ++rep.packets_undecoded;
            continue;
        }
        const uint8_t *ip = p + off;
        size_t ipcap = cap - off;
        int ver = ip[0] >> 4;
        if ((ethertype == 0x0800 && ver != 4) || (ethertype == 0x86dd && ver != 6) ||
            (ethertype != -1 && ethertype != 0x0800 && ethertype != 0x86dd)) {
            ++rep.packets_undecoded;
            continue;
        }
        bool v6 = false;
        const uint8_t *src = nullptr, *dst = nullptr;
        const uint8_t *tcp = nullptr;
        size_t l4len = 0; // TCP header + payload length according to the IP header
        if (ver == 4) {
            if (ipcap < 20) { ++rep.packets_undecoded; continue; }
            const size_t ihl = static_cast<size_t>(ip[0] & 0x0F) * 4;
            const size_t tot = be16(ip + 2);
            if (ihl < 20 || tot < ihl || ipcap < ihl) { ++rep.packets_undecoded; continue; }
            if (ip[9] != 6) { ++rep.packets_undecoded; continue; }
            if ((be16(ip + 6) & 0x3FFF) != 0) { ++rep.ip_fragments; continue; }
            src = ip + 12;
            dst = ip + 16;
            tcp = ip + ihl;
            l4len = tot - ihl;
            ipcap -= ihl;
        } else if (ver == 6) {
            if (ipcap < 40) { ++rep.packets_undecoded; continue; }
            v6 = true;
            src = ip + 8;
            dst = ip + 24;
            size_t plen = be16(ip + 4);
            uint8_t nh = ip[6];
            size_t hoff = 40;
            bool frag = false, ok = true;
            while (nh == 0 || nh == 43 || nh == 60 || nh == 51 || nh == 44) {
                if (ipcap < hoff + 8) { ok = false; break; }
                if (nh == 44) { frag = true; break; }
                const size_t el = (nh == 51) ? (static_cast<size_t>(ip[hoff + 1]) + 2) * 4
                                             : (static_cast<size_t>(ip[hoff + 1]) + 1) * 8;
                nh = ip[hoff];
                hoff += el;
                if (plen < hoff - 40) { ok = false; break; }
            }
            if (frag) { ++rep.ip_fragments; continue; }
            if (!ok || nh != 6 || ipcap < hoff) { ++rep.packets_undecoded; continue; }
            tcp = ip + hoff;
            l4len = plen - (hoff - 40);
            ipcap -= hoff;
        } else {
            ++rep.packets_undecoded;
            continue;
        }
        if (ipcap < 20 || l4len < 20) { ++rep.packets_undecoded; continue; }
        const size_t thl = static_cast<size_t>(tcp[12] >> 4) * 4;
        if (thl < 20 || thl > l4len || ipcap < thl) { ++rep.packets_undecoded; continue; }
        const uint16_t sport = be16(tcp), dport = be16(tcp + 2);
        const uint32_t seq = be32(tcp + 4);
        const uint8_t flags = tcp[13];
        const bool f_syn = (flags & 0x02) != 0, f_fin = (flags & 0x01) != 0, f_rst = (flags & 0x04) != 0;
        const size_t payload_len = l4len - thl;
        const size_t payload_cap = std::min(payload_len, ipcap - thl);
        const uint8_t *payload = tcp + thl;

        const size_t alen = v6 ? 16 : 4;
        FlowKey key{std::string(reinterpret_cast<const char *>(src), alen),
                    std::string(reinterpret_cast<const char *>(dst), alen), sport, dport};
        const double ts = static_cast<double>(h->ts.tv_sec) + static_cast<double>(h->ts.tv_usec) * 1e-6;
        auto it = live.find(key);
        // A SYN on a 4-tuple that already carried data starts a new session (port reuse).
        if (it == live.end() || (f_syn && !flows[it->second].segs.empty())) {
            FlowState fs;
            fs.info.src = addr_str(src, v6, sport);
            fs.info.dst = addr_str(dst, v6, dport);
            fs.info.src_port = sport;
            fs.info.dst_port = dport;
            fs.info.first_ts_s = ts;
            flows.push_back(std::move(fs));
            live[key] = flows.size() - 1;
            it = live.find(key);
        }
        FlowState &fl = flows[it->second];
        ++fl.info.packets;
        fl.info.last_ts_s = ts;
        if (!fl.have_seq) {
            fl.have_seq = true;
            fl.last_seq = seq;
            fl.last_rel = 0;
        }
        const int64_t rel = fl.last_rel + static_cast<int32_t>(seq - fl.last_seq);
        fl.last_rel = rel;
        fl.last_seq = seq;
        if (f_syn && !fl.syn) {
            fl.syn = true;
            fl.syn_rel = rel;
            fl.info.syn = true;
        }
        const int64_t data_rel = rel + (f_syn ? 1 : 0);
        if (f_fin) {
            fl.fin = true;
            fl.fin_rel = data_rel + static_cast<int64_t>(payload_len);
            fl.info.fin = true;
        }
        if (f_rst) {
            fl.info.rst = true;
        }
        if (payload_len > 0) {
            if (payload_cap < payload_len) {
                ++rep.packets_truncated;
            }
            if (payload_cap > 0) {
                Segment s;
                s.rel = data_rel;
                s.len = static_cast<uint32_t>(payload_cap);
                s.index = index;
                s.pool_off = fl.pool.size();
                fl.pool.insert(fl.pool.end(), payload, payload + payload_cap);
                fl.segs.push_back(s);
                fl.info.payload_bytes += payload_cap;
                fl.radar_score += score_payload(payload, payload_cap);
            }
        }
    }
    if (rc == PCAP_ERROR) {
        // A capture cut short (tcpdump killed) or corrupt further on: keep what was read.
        rep.read_error = pcap_geterr(pc);
    }
    pcap_close(pc);

    // Which source port is the radar's?
    int radar_port = opt.radar_port;
    bool any = false;
    for (const auto &f : flows) {
        any = any || (f.info.src_port == radar_port && !f.segs.empty());
    }
    if (!any && !opt.port_explicit) {
        int64_t best = 0;
        for (const auto &f : flows) {
            if (f.radar_score > best) {
                best = f.radar_score;
                radar_port = f.info.src_port;
                any = true;
            }
        }
        rep.port_auto_detected = any;
    }
    rep.radar_port = static_cast<uint16_t>(radar_port);
    if (!any) {
        err = path + ": no TCP payload from port " + std::to_string(opt.radar_port) +
              (opt.port_explicit ? "" : " and no flow carrying Colossus radar messages") +
              (rep.read_error.empty() ? "" : " (read error after " + std::to_string(rep.packets_total) +
                                                 " packets: " + rep.read_error + ")");
        for (const auto &f : flows) {
            rep.flows.push_back(f.info);
        }
        return false;
    }

    // Select radar-side sessions: in time order, each one that starts after the previous
    // selected one ended.
    std::vector<size_t> cand;
    for (size_t i = 0; i < flows.size(); ++i) {
        if (flows[i].info.src_port == radar_port && !flows[i].segs.empty()) {
            cand.push_back(i);
        }
    }
    std::stable_sort(cand.begin(), cand.end(), [&](size_t a, size_t b) {
        return flows[a].info.first_ts_s < flows[b].info.first_ts_s;
    });
    std::vector<size_t> sel;
    double end_ts = -1e300;
    for (size_t i : cand) {
        if (flows[i].info.first_ts_s >= end_ts) {
            sel.push_back(i);
            flows[i].info.selected = true;
            end_ts = flows[i].info.last_ts_s;
        } else {
            ++rep.flows_ignored;
        }
    }
    for (const auto &f : flows) {
        if (f.info.src_port == radar_port && !f.segs.empty()) {
            rep.flows.push_back(f.info);
        }
    }
    auto flow_report_index = [&](size_t fi) -> uint32_t {
        uint32_t k = 0;
        for (size_t i = 0; i < flows.size(); ++i) {
            if (flows[i].info.src_port == radar_port && !flows[i].segs.empty()) {
                if (i == fi) return k;
                ++k;
            }
        }
        return 0;
    };

    for (size_t si = 0; si < sel.size(); ++si) {
        FlowState &fl = flows[sel[si]];
        const uint32_t fidx = flow_report_index(sel[si]);
        if (si > 0) {
            Discontinuity d;
            d.kind = Discontinuity::Kind::NewSession;
            d.output_offset = out.bytes.size();
            d.session = fidx;
            out.discontinuities.push_back(d);
        }
        int64_t base;
        if (fl.syn) {
            base = fl.syn_rel + 1;
        } else {
            rep.started_mid_stream = true;
            base = fl.segs.front().rel;
            for (const auto &s : fl.segs) {
                base = std::min(base, s.rel);
            }
        }
        // Classify in arrival order.
        IntervalSet seen;
        int64_t max_end = 0;
        for (auto &s : fl.segs) {
            int64_t a = s.rel - base, b = a + s.len;
            if (a < 0) { // bytes before the ISN: impossible in a sane capture, drop them
                const int64_t cut = std::min<int64_t>(-a, s.len);
                s.pool_off += static_cast<size_t>(cut);
                s.len -= static_cast<uint32_t>(cut);
                s.rel += cut;
                a = 0;
                b = a + s.len;
                if (s.len == 0) continue;
            }
            ++rep.segments;
            rep.payload_bytes += s.len;
            const int64_t cov = seen.covered(a, b);
            if (cov == b - a) {
                ++rep.retransmitted_segments;
            } else {
                if (cov > 0) {
                    ++rep.partial_overlap_segments;
                }
                const int64_t lim = std::min(b, max_end);
                if (a < lim && seen.covered(a, lim) < lim - a) {
                    ++rep.out_of_order_segments;
                }
            }
            rep.retransmitted_bytes += static_cast<uint64_t>(cov);
            seen.add(a, b);
            max_end = std::max(max_end, b);
        }
        // Assemble in stream order.
        std::stable_sort(fl.segs.begin(), fl.segs.end(),
                         [](const Segment &x, const Segment &y) { return x.rel < y.rel; });
        int64_t cursor = 0;
        for (const auto &s : fl.segs) {
            if (s.len == 0) continue;
            const int64_t a = s.rel - base, b = a + s.len;
            if (a > cursor) {
                Discontinuity d;
                d.kind = Discontinuity::Kind::Gap;
                d.output_offset = out.bytes.size();
                d.stream_offset = static_cast<uint64_t>(cursor);
                d.missing_bytes = static_cast<uint64_t>(a - cursor);
                d.session = fidx;
                out.discontinuities.push_back(d);
                rep.gap_list.push_back(d);
                ++rep.gaps;
                rep.gap_bytes += d.missing_bytes;
                cursor = a;
            }
            const uint8_t *src = fl.pool.data() + s.pool_off;
            if (a < cursor) { // overlap with bytes already output: compare
                const int64_t ov = std::min(b, cursor) - a;
                const uint8_t *prev = out.bytes.data() + out.bytes.size() - (cursor - a);
                for (int64_t i = 0; i < ov; ++i) {
                    rep.retransmit_mismatch_bytes += (prev[i] != src[i]) ? 1u : 0u;
                }
            }
            if (b > cursor) {
                out.bytes.insert(out.bytes.end(), src + (cursor - a), src + s.len);
                cursor = b;
            }
        }
        if (fl.fin && fl.fin_rel - base > cursor) { // the tail before the FIN is missing
            Discontinuity d;
            d.kind = Discontinuity::Kind::Gap;
            d.output_offset = out.bytes.size();
            d.stream_offset = static_cast<uint64_t>(cursor);
            d.missing_bytes = static_cast<uint64_t>(fl.fin_rel - base - cursor);
            d.session = fidx;
            out.discontinuities.push_back(d);
            rep.gap_list.push_back(d);
            ++rep.gaps;
            rep.gap_bytes += d.missing_bytes;
        }
    }
    rep.stream_bytes = out.bytes.size();
    return true;
}

void feed_capture(const Capture &cap, sl_proto_t *p, size_t chunk, uint64_t now_us)
{
    const uint8_t *d = cap.bytes.data();
    uint64_t pos = 0;
    auto feed_to = [&](uint64_t end) {
        while (pos < end) {
            uint64_t n = end - pos;
            if (chunk > 0 && n > chunk) {
                n = chunk;
            }
            (void)sl_proto_feed(p, d + pos, static_cast<size_t>(n), now_us);
            pos += n;
        }
    };
    for (const auto &disc : cap.discontinuities) {
        feed_to(std::min<uint64_t>(disc.output_offset, cap.bytes.size()));
        (void)sl_proto_finish(p);
    }
    feed_to(cap.bytes.size());
    (void)sl_proto_finish(p);
}

namespace {
struct IndexCtx {
    std::vector<CaptureMessage> *out;
};
void index_sink(void *ctx, const sl_proto_msg_t *m)
{
    auto *ic = static_cast<IndexCtx *>(ctx);
    CaptureMessage cm;
    cm.offset = m->stream_offset;
    cm.size = static_cast<uint32_t>(SL_PROTO_HEADER_BYTES + m->payload.size);
    cm.id = m->id;
    ic->out->push_back(cm);
}
} // namespace

std::vector<CaptureMessage> index_capture(const Capture &cap, sl_proto_stats_t *stats)
{
    std::vector<CaptureMessage> out;
    std::vector<uint8_t> reasm(kHostMaxPayloadBytes);
    IndexCtx ic{&out};
    sl_proto_cfg_t pc{};
    pc.reasm_buf = reasm.data();
    pc.reasm_size = reasm.size();
    pc.max_payload_bytes = static_cast<uint32_t>(reasm.size());
    pc.on_msg = index_sink;
    pc.ctx = &ic;
    sl_proto_t p;
    (void)sl_proto_init(&p, &pc);
    feed_capture(cap, &p);
    if (stats != nullptr) {
        *stats = p.stats;
    }
    return out;
}

bool write_raw_capture(const std::string &path, const uint8_t *data, size_t size, std::string &err)
{
    RawCaptureWriter w;
    if (!w.open(path, err)) {
        return false;
    }
    w.write(data, size);
    return w.close(err);
}

RawCaptureWriter::~RawCaptureWriter()
{
    std::string e;
    close(e);
}

bool RawCaptureWriter::open(const std::string &path, std::string &err)
{
    std::string e;
    close(e);
    f_ = std::fopen(path.c_str(), "wb");
    if (f_ == nullptr) {
        err = path + ": " + std::strerror(errno);
        return false;
    }
    path_ = path;
    bytes_ = 0;
    failed_ = false;
    return true;
}

bool RawCaptureWriter::write(const uint8_t *data, size_t size)
{
    if (f_ == nullptr || failed_) {
        return false;
    }
    if (size > 0 && std::fwrite(data, 1, size, f_) != size) {
        failed_ = true;
        return false;
    }
    bytes_ += size;
    return true;
}

bool RawCaptureWriter::close(std::string &err)
{
    if (f_ == nullptr) {
        return true;
    }
    const bool flush_ok = std::fflush(f_) == 0;
    const bool close_ok = std::fclose(f_) == 0;
    f_ = nullptr;
    if (failed_ || !flush_ok || !close_ok) {
        err = path_ + ": write error";
        return false;
    }
    return true;
}

} // namespace sl
