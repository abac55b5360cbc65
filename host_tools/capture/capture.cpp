// SPDX-License-Identifier: MIT
// capture.cpp: capture I/O for the host tools (see capture.h): a thin C++ wrapper over the
// port's streaming reader (firmware/port/linux/capture_reader.h) plus raw capture writers.
#include "capture.h"

#include "capture_reader.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <deque>

namespace sl {

namespace {

uint32_t be32(const uint8_t *p)
{
    return (static_cast<uint32_t>(p[0]) << 24) | (static_cast<uint32_t>(p[1]) << 16) |
           (static_cast<uint32_t>(p[2]) << 8) | static_cast<uint32_t>(p[3]);
}

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

namespace {
// Format, pcap report and flows of reader `c` into `out` (not the bytes).
void fill_report(const slp_capture_t *c, Capture &out)
{
    const slp_capture_report_t *r = slp_capture_report(c);
    switch (r->format) {
    case SLP_CAPTURE_RAW: out.format = CaptureFormat::Raw; break;
    case SLP_CAPTURE_PCAP: out.format = CaptureFormat::Pcap; break;
    case SLP_CAPTURE_PCAPNG: out.format = CaptureFormat::Pcapng; break;
    }
    if (r->format != SLP_CAPTURE_RAW) {
        out.has_pcap_report = true;
        PcapReport &rep = out.pcap;
        rep.link_type = r->link_type;
        rep.radar_port = r->radar_port;
        rep.port_auto_detected = r->port_auto_detected;
        rep.packets_total = r->packets_total;
        rep.packets_undecoded = r->packets_undecoded;
        rep.ip_fragments = r->ip_fragments;
        rep.packets_truncated = r->packets_truncated;
        rep.segments = r->segments;
        rep.payload_bytes = r->payload_bytes;
        rep.stream_bytes = r->stream_bytes;
        rep.retransmitted_segments = r->retransmitted_segments;
        rep.retransmitted_bytes = r->retransmitted_bytes;
        rep.partial_overlap_segments = r->partial_overlap_segments;
        rep.retransmit_mismatch_bytes = r->retransmit_mismatch_bytes;
        rep.out_of_order_segments = r->out_of_order_segments;
        rep.gaps = r->gaps;
        rep.gap_bytes = r->gap_bytes;
        rep.flows_ignored = r->flows_ignored;
        rep.started_mid_stream = r->started_mid_stream;
        rep.read_error = r->read_error;
        std::vector<slp_capture_flow_t> fl(SLP_CAPTURE_MAX_FLOWS);
        const size_t nf = slp_capture_flows(c, fl.data(), fl.size());
        for (size_t i = 0; i < nf && i < fl.size(); ++i) {
            PcapFlow f;
            f.src = fl[i].src;
            f.dst = fl[i].dst;
            const char *colon = std::strrchr(fl[i].src, ':');
            f.src_port = colon != nullptr ? static_cast<uint16_t>(std::atoi(colon + 1)) : 0;
            colon = std::strrchr(fl[i].dst, ':');
            f.dst_port = colon != nullptr ? static_cast<uint16_t>(std::atoi(colon + 1)) : 0;
            f.packets = fl[i].packets;
            f.payload_bytes = fl[i].payload_bytes;
            f.first_ts_s = static_cast<double>(fl[i].first_ts_us) * 1e-6;
            f.last_ts_s = static_cast<double>(fl[i].last_ts_us) * 1e-6;
            f.syn = fl[i].syn;
            f.fin = fl[i].fin;
            f.rst = fl[i].rst;
            f.selected = fl[i].selected;
            rep.flows.push_back(f);
        }
    }
}

// A break reported by the port's reader, as a Discontinuity: appended to `all`, and to
// `gaps` when bytes are missing (a new session is not a gap).
void record_break(const slp_capture_piece_t &p, std::vector<Discontinuity> &all,
                  std::vector<Discontinuity> &gaps)
{
    Discontinuity d;
    d.kind = p.brk == SLP_CAPTURE_GAP ? Discontinuity::Kind::Gap : Discontinuity::Kind::NewSession;
    d.output_offset = p.output_offset;
    d.stream_offset = p.stream_offset;
    d.missing_bytes = p.missing_bytes;
    d.session = p.session;
    all.push_back(d);
    if (d.kind == Discontinuity::Kind::Gap) {
        gaps.push_back(d);
    }
}
} // namespace

// The port's streaming reader (firmware/port/linux/capture_reader.h) does the reading, the
// format sniffing (once, on bytes already read: pipes and stdin "-" work) and the TCP
// reassembly; this collects its pieces into memory for the tools that want the whole stream.
bool load_capture(const std::string &path, Capture &out, std::string &err, const PcapOptions &opt)
{
    std::vector<uint8_t> bytes;
    uint64_t n = 0;
    const bool ok = read_capture(
        path,
        [&](const uint8_t *data, size_t size) {
            bytes.insert(bytes.end(), data, data + size);
            return true;
        },
        nullptr, out, n, err, opt);
    out.bytes = std::move(bytes);
    return ok;
}

bool read_capture(const std::string &path, const CaptureDataFn &on_data, const CaptureBreakFn &on_break,
                  Capture &info, uint64_t &bytes, std::string &err, const PcapOptions &opt)
{
    info = Capture{};
    bytes = 0;
    slp_capture_opts_t o{};
    o.radar_port = static_cast<uint16_t>(opt.radar_port);
    o.port_explicit = opt.port_explicit;
    char e[512] = {0};
    slp_capture_t *c = slp_capture_open(path.c_str(), &o, e, sizeof e);
    if (c == nullptr) {
        err = e;
        return false;
    }
    bool ok = true;
    for (;;) {
        slp_capture_piece_t pc;
        slp_capture_next(c, &pc);
        if (pc.kind == SLP_CAPTURE_DATA) {
            bytes += pc.size;
            if (!on_data(pc.data, pc.size)) {
                break;
            }
        } else if (pc.kind == SLP_CAPTURE_BREAK) {
            record_break(pc, info.discontinuities, info.pcap.gap_list);
            if (on_break) {
                on_break(info.discontinuities.back());
            }
        } else {
            if (pc.kind == SLP_CAPTURE_ERROR) {
                err = path + ": " + slp_capture_error(c);
                ok = false;
            }
            break;
        }
    }
    std::vector<Discontinuity> gaps = info.pcap.gap_list;
    fill_report(c, info);
    info.pcap.gap_list = gaps;
    slp_capture_close(c);
    return ok;
}

MessageDecoder::MessageDecoder(MsgFn on_msg) : fn_(std::move(on_msg)), reasm_(kHostMaxPayloadBytes)
{
    sl_proto_cfg_t pc{};
    pc.reasm_buf = reasm_.data();
    pc.reasm_size = reasm_.size();
    pc.on_msg = MessageDecoder::on_msg;
    pc.ctx = this;
    (void)sl_proto_init(&p_, &pc);
}

void MessageDecoder::on_msg(void *ctx, const sl_proto_msg_t *m) { static_cast<MessageDecoder *>(ctx)->fn_(*m); }

struct MessageReader::Impl {
    slp_capture_t *c = nullptr;
    std::deque<std::pair<uint8_t, std::vector<uint8_t>>> q;
    MessageDecoder dec{[this](const sl_proto_msg_t &m) {
        std::vector<uint8_t> v(SL_PROTO_HEADER_BYTES + m.payload.size);
        (void)sl_proto_encode_header(v.data(), SL_PROTO_HEADER_BYTES, m.id, static_cast<uint32_t>(m.payload.size));
        if (m.payload.size > 0) {
            std::memcpy(v.data() + SL_PROTO_HEADER_BYTES, m.payload.data, m.payload.size);
        }
        q.emplace_back(m.id, std::move(v));
    }};
    bool eof = false;
    std::string path;
    const uint8_t *mem = nullptr; // open_memory: the stream and how far it has been fed
    size_t mem_size = 0, mem_off = 0;
    const uint8_t *piece = nullptr; // the capture's current DATA piece and how far it has
    size_t piece_size = 0, piece_off = 0; // been fed (valid until the next slp_capture_next)
};

MessageReader::MessageReader() : m_(new Impl) {}

MessageReader::~MessageReader()
{
    if (m_->c != nullptr) {
        slp_capture_close(m_->c);
    }
    delete m_;
}

bool MessageReader::open(const std::string &path, std::string &err, const PcapOptions &opt)
{
    slp_capture_opts_t o{};
    o.radar_port = static_cast<uint16_t>(opt.radar_port);
    o.port_explicit = opt.port_explicit;
    char e[512] = {0};
    m_->c = slp_capture_open(path.c_str(), &o, e, sizeof e);
    if (m_->c == nullptr) {
        err = e;
        return false;
    }
    m_->path = path;
    return true;
}

void MessageReader::open_memory(const uint8_t *data, size_t size)
{
    m_->mem = data;
    m_->mem_size = size;
    m_->path = "(memory)";
}

const sl_proto_stats_t &MessageReader::stats() const { return m_->dec.stats(); }

CaptureFormat MessageReader::format() const
{
    if (m_->c == nullptr) {
        return m_->mem != nullptr ? CaptureFormat::Raw : CaptureFormat::Unknown;
    }
    switch (slp_capture_report(m_->c)->format) {
    case SLP_CAPTURE_RAW: return CaptureFormat::Raw;
    case SLP_CAPTURE_PCAP: return CaptureFormat::Pcap;
    case SLP_CAPTURE_PCAPNG: return CaptureFormat::Pcapng;
    }
    return CaptureFormat::Unknown;
}

bool MessageReader::next(uint8_t &id, std::vector<uint8_t> &msg)
{
    while (m_->q.empty() && !m_->eof && m_->mem != nullptr) {
        // 1 MiB at a time, so that the queue holds one megabyte's messages at most.
        const size_t n = std::min<size_t>(m_->mem_size - m_->mem_off, 1u << 20);
        m_->dec.feed(m_->mem + m_->mem_off, n);
        m_->mem_off += n;
        if (m_->mem_off == m_->mem_size) {
            m_->dec.finish();
            m_->eof = true;
        }
    }
    while (m_->q.empty() && !m_->eof && m_->c != nullptr) {
        if (m_->piece_off < m_->piece_size) {
            // A piece of a raw file is a 16 MiB mapped window: 1 MiB of it at a time too.
            const size_t n = std::min<size_t>(m_->piece_size - m_->piece_off, 1u << 20);
            m_->dec.feed(m_->piece + m_->piece_off, n);
            m_->piece_off += n;
            continue;
        }
        slp_capture_piece_t pc;
        slp_capture_next(m_->c, &pc);
        if (pc.kind == SLP_CAPTURE_DATA) {
            m_->piece = pc.data;
            m_->piece_size = pc.size;
            m_->piece_off = 0;
        } else if (pc.kind == SLP_CAPTURE_BREAK) {
            m_->dec.finish();
        } else {
            m_->dec.finish();
            if (pc.kind == SLP_CAPTURE_ERROR) {
                err_ = m_->path + ": " + slp_capture_error(m_->c);
            }
            m_->eof = true;
        }
    }
    if (m_->q.empty()) {
        return false;
    }
    id = m_->q.front().first;
    msg = std::move(m_->q.front().second);
    m_->q.pop_front();
    return true;
}

bool stream_capture(const std::string &path, sl_proto_t *p, size_t chunk, Capture &info, uint64_t &bytes,
                    std::string &err, const PcapOptions &opt)
{
    const bool ok = read_capture(
        path,
        [&](const uint8_t *data, size_t size) {
            for (size_t off = 0; off < size;) {
                size_t n = size - off;
                if (chunk > 0 && n > chunk) {
                    n = chunk;
                }
                (void)sl_proto_feed(p, data + off, n, 0);
                off += n;
            }
            return true;
        },
        [&](const Discontinuity &) { (void)sl_proto_finish(p); }, info, bytes, err, opt);
    (void)sl_proto_finish(p);
    return ok;
}

bool load_pcap(const std::string &path, Capture &out, std::string &err, const PcapOptions &opt)
{
    return load_capture(path, out, err, opt);
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
