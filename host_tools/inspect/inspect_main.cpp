// SPDX-License-Identifier: MIT
// sl-inspect: decode a capture (.colossus raw stream or pcap/pcapng, sniffed by content)
// through the core decoder (sl_proto) and scan assembly (sl_scan) and report what is in it.
//
//   sl-inspect CAPTURE [--json] [--rotations] [--port P] [--chunk N]
//
// Exit status: 0 decoded (whatever the damage, which is reported), 1 unreadable input or
// no radar message in it (the report is still printed), 2 usage error.
#include "capture.h"
#include "sl_cli.h"

#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_scan.h"

#include <nlohmann/json.hpp>

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

using json = nlohmann::ordered_json;

struct FrameInfo {
    uint32_t rotation;
    uint16_t valid, missing, duplicates, out_of_order;
    uint8_t end;
    uint64_t t_first_us, t_last_us;
};

struct Inspect {
    sl_scan_t scan{};
    std::map<int, uint64_t> by_id;
    uint64_t configs = 0, config_malformed = 0, config_differs = 0;
    bool have_config = false;
    sl_proto_config_t config{};
    std::vector<uint8_t> config_payload; // of the first Configuration
    uint64_t fft = 0, fft8 = 0, fft16 = 0, fft_malformed = 0;
    uint64_t bins_min = UINT64_MAX, bins_max = 0;
    bool have_t = false;
    uint64_t t_first = 0, t_last = 0, t_min = UINT64_MAX, t_max = 0, t_backwards = 0;
    uint64_t az_min = UINT64_MAX, az_max = 0;
    std::vector<FrameInfo> frames;
    uint64_t frames_complete = 0;
    uint64_t end_counts[4] = {0, 0, 0, 0};
};

const char *end_name(unsigned e)
{
    switch (e) {
    case SL_SCAN_END_WRAP: return "wrap";
    case SL_SCAN_END_SWEEP_GAP: return "sweep_gap";
    case SL_SCAN_END_CONFIG: return "config";
    case SL_SCAN_END_FLUSH: return "flush";
    default: return "?";
    }
}

void on_frame(void *ctx, const sl_scan_frame_t *f)
{
    auto *in = static_cast<Inspect *>(ctx);
    FrameInfo fi{f->rotation, f->stats.valid, f->stats.missing, f->stats.duplicates,
                 f->stats.out_of_order, f->end, f->t_first_us, f->t_last_us};
    in->frames.push_back(fi);
    if (f->stats.missing == 0 && f->stats.valid == f->azimuths) {
        ++in->frames_complete;
    }
    if (f->end < 4) {
        ++in->end_counts[f->end];
    }
}

void on_msg(void *ctx, const sl_proto_msg_t *m)
{
    auto *in = static_cast<Inspect *>(ctx);
    ++in->by_id[m->id];
    if (m->id == SL_PROTO_ID_CONFIGURATION) {
        ++in->configs;
        sl_proto_config_t c{};
        if (sl_proto_parse_config(m, &c) != SL_OK) {
            ++in->config_malformed;
        } else if (!in->have_config) {
            in->have_config = true;
            in->config_payload.assign(m->payload.data, m->payload.data + m->payload.size);
            in->config = c;
            in->config.protobuf = sl_bytes_t{nullptr, c.protobuf.size}; // view would dangle
        } else if (m->payload.size != in->config_payload.size() ||
                   std::memcmp(m->payload.data, in->config_payload.data(), m->payload.size) != 0) {
            ++in->config_differs;
        }
    } else if (m->id == SL_PROTO_ID_FFT_DATA || m->id == SL_PROTO_ID_FFT_DATA_16) {
        ++in->fft;
        sl_proto_fft_t f{};
        if (sl_proto_parse_fft(m, &f) != SL_OK) {
            ++in->fft_malformed;
        } else {
            (m->id == SL_PROTO_ID_FFT_DATA ? in->fft8 : in->fft16)++;
            in->bins_min = std::min<uint64_t>(in->bins_min, f.bins);
            in->bins_max = std::max<uint64_t>(in->bins_max, f.bins);
            in->az_min = std::min<uint64_t>(in->az_min, f.azimuth_ticks);
            in->az_max = std::max<uint64_t>(in->az_max, f.azimuth_ticks);
            const uint64_t t = sl_proto_fft_time_us(&f);
            if (!in->have_t) {
                in->have_t = true;
                in->t_first = t;
            } else if (t < in->t_last) {
                ++in->t_backwards;
            }
            in->t_last = t;
            in->t_min = std::min(in->t_min, t);
            in->t_max = std::max(in->t_max, t);
        }
    }
    (void)sl_scan_on_msg(&in->scan, m);
}

float f32_from_bits(uint32_t u)
{
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}

std::string utc_str(uint64_t t_us)
{
    const time_t s = static_cast<time_t>(t_us / 1000000u);
    struct tm tmv {};
    gmtime_r(&s, &tmv);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%06uZ", tmv.tm_year + 1900,
                  tmv.tm_mon + 1, tmv.tm_mday, tmv.tm_hour, tmv.tm_min, tmv.tm_sec,
                  static_cast<unsigned>(t_us % 1000000u));
    return buf;
}

json pcap_json(const sl::PcapReport &r)
{
    json j;
    j["link_type"] = r.link_type;
    j["read_error"] = r.read_error.empty() ? json(nullptr) : json(r.read_error);
    j["radar_port"] = r.radar_port;
    j["port_auto_detected"] = r.port_auto_detected;
    j["packets_total"] = r.packets_total;
    j["packets_undecoded"] = r.packets_undecoded;
    j["ip_fragments"] = r.ip_fragments;
    j["packets_truncated"] = r.packets_truncated;
    j["segments"] = r.segments;
    j["payload_bytes"] = r.payload_bytes;
    j["stream_bytes"] = r.stream_bytes;
    j["retransmitted_segments"] = r.retransmitted_segments;
    j["retransmitted_bytes"] = r.retransmitted_bytes;
    j["partial_overlap_segments"] = r.partial_overlap_segments;
    j["retransmit_mismatch_bytes"] = r.retransmit_mismatch_bytes;
    j["out_of_order_segments"] = r.out_of_order_segments;
    j["gaps"] = r.gaps;
    j["gap_bytes"] = r.gap_bytes;
    json gl = json::array();
    for (const auto &g : r.gap_list) {
        gl.push_back({{"session", g.session}, {"stream_offset", g.stream_offset},
                      {"output_offset", g.output_offset}, {"missing_bytes", g.missing_bytes}});
    }
    j["gap_list"] = gl;
    j["started_mid_stream"] = r.started_mid_stream;
    j["flows_ignored"] = r.flows_ignored;
    json fl = json::array();
    for (const auto &f : r.flows) {
        fl.push_back({{"src", f.src}, {"dst", f.dst}, {"packets", f.packets},
                      {"payload_bytes", f.payload_bytes}, {"first_ts_s", f.first_ts_s},
                      {"last_ts_s", f.last_ts_s}, {"syn", f.syn}, {"fin", f.fin}, {"rst", f.rst},
                      {"selected", f.selected}});
    }
    j["flows"] = fl;
    return j;
}

void usage(FILE *out)
{
    std::fprintf(out,
                 "usage: sl-inspect CAPTURE [--json] [--rotations] [--port P] [--chunk N]\n"
                 "  CAPTURE      raw .colossus stream or pcap/pcapng (sniffed by content)\n"
                 "  --json       print one JSON object instead of text\n"
                 "  --rotations  list every rotation (frame) too\n"
                 "  --port P     pcap: TCP source port of the radar (default 6317; when absent\n"
                 "               the radar side is auto-detected unless --port is given)\n"
                 "  --chunk N    feed the decoder N bytes at a time (default: whole pieces)\n");
}

} // namespace

int main(int argc, char **argv)
{
    std::string path;
    bool as_json = false, rotations = false;
    sl::PcapOptions popt;
    size_t chunk = 0;
    const int info = sl_cli_info(argc, argv, "sl-inspect", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if ((a == "--port" || a == "--chunk") && i + 1 >= argc) {
            return sl_cli_bad_value("sl-inspect", a.c_str(), "needs a value", usage);
        }
        if (a == "--json") {
            as_json = true;
        } else if (a == "--rotations") {
            rotations = true;
        } else if (a == "--port" && i + 1 < argc) {
            popt.radar_port = std::atoi(argv[++i]);
            popt.port_explicit = true;
            if (popt.radar_port <= 0 || popt.radar_port > 65535) {
                return sl_cli_bad_value("sl-inspect", "--port", "must be 1..65535", usage);
            }
        } else if (a == "--chunk" && i + 1 < argc) {
            chunk = static_cast<size_t>(std::strtoull(argv[++i], nullptr, 10));
        } else if (a.size() > 1 && a[0] == '-') { // "-" is stdin
            return sl_cli_unknown("sl-inspect", argv[i], usage);
        } else if (path.empty()) {
            path = a;
        } else {
            return sl_cli_unknown("sl-inspect", argv[i], usage);
        }
    }
    if (path.empty()) {
        return sl_cli_usage_error("sl-inspect", "missing CAPTURE", usage);
    }

    auto in = std::make_unique<Inspect>();
    auto frame = std::make_unique<sl_scan_frame_t>();
    sl_scan_cfg_t sc{};
    sc.roi_bins = SL_CFG_ROI_BINS;
    sc.pow16_shift = 8;
    sc.on_frame = on_frame;
    sc.ctx = in.get();
    if (sl_scan_init(&in->scan, &sc, frame.get(), nullptr) != SL_OK) {
        std::fprintf(stderr, "sl-inspect: sl_scan_init failed\n");
        return 1;
    }
    std::vector<uint8_t> reasm(sl::kHostMaxPayloadBytes);
    sl_proto_cfg_t pc{};
    pc.reasm_buf = reasm.data();
    pc.reasm_size = reasm.size();
    pc.max_payload_bytes = static_cast<uint32_t>(reasm.size());
    pc.on_msg = on_msg;
    pc.ctx = in.get();
    sl_proto_t proto;
    sl_proto_init(&proto, &pc);
    // Streamed through the port's reader: bounded memory whatever the capture's size.
    sl::Capture cap;
    uint64_t cap_bytes = 0;
    std::string err;
    if (!sl::stream_capture(path, &proto, chunk, cap, cap_bytes, err, popt)) {
        std::fprintf(stderr, "sl-inspect: %s\n", err.c_str());
        return 1;
    }
    sl_scan_flush(&in->scan);
    const sl_proto_stats_t &ps = proto.stats;
    const sl_scan_stats_t &ss = in->scan.stats;

    json j;
    j["schema"] = "shadowlean-inspect/1"; // docs/schema/inspect.schema.json, docs/JSON_OUTPUTS.md
    j["file"] = path;
    j["format"] = sl::capture_format_name(cap.format);
    j["bytes"] = cap_bytes;
    if (in->have_config) {
        const auto &c = in->config;
        json jc;
        jc["azimuths"] = c.azimuths;
        jc["bin_size_100um"] = c.bin_size_100um;
        jc["bin_size_um"] = sl_proto_config_bin_size_um(&c);
        jc["range_bins"] = c.range_bins;
        jc["encoder_size"] = c.encoder_size;
        jc["rotation_mhz"] = c.rotation_mhz;
        jc["packet_rate"] = c.packet_rate;
        jc["range_gain"] = f32_from_bits(c.range_gain_f32);
        jc["range_offset_m"] = f32_from_bits(c.range_offset_f32);
        jc["data_width"] = c.has_data_width ? json(c.data_width) : json(nullptr);
        jc["range_resolution_m"] = c.has_range_res ? json(f32_from_bits(c.range_res_m_f32)) : json(nullptr);
        jc["protobuf_bytes"] = c.protobuf.size;
        jc["protobuf_malformed"] = c.protobuf_malformed;
        j["configuration"] = jc;
    } else {
        j["configuration"] = nullptr;
    }
    j["configurations"] = {{"count", in->configs}, {"malformed", in->config_malformed},
                           {"differing", in->config_differs}};
    json byid = json::object();
    for (const auto &kv : in->by_id) {
        byid[std::to_string(kv.first)] = kv.second;
    }
    j["messages"] = {{"total", ps.messages}, {"by_id", byid}};
    json jf;
    jf["total"] = in->fft;
    jf["fft8"] = in->fft8;
    jf["fft16"] = in->fft16;
    jf["malformed"] = in->fft_malformed;
    jf["bins_min"] = in->fft8 + in->fft16 ? json(in->bins_min) : json(nullptr);
    jf["bins_max"] = in->fft8 + in->fft16 ? json(in->bins_max) : json(nullptr);
    jf["azimuth_ticks_min"] = in->fft8 + in->fft16 ? json(in->az_min) : json(nullptr);
    jf["azimuth_ticks_max"] = in->fft8 + in->fft16 ? json(in->az_max) : json(nullptr);
    jf["sweep_gaps"] = ss.sweep_gaps;
    if (in->have_t) {
        jf["time_first_us"] = in->t_first;
        jf["time_last_us"] = in->t_last;
        jf["time_min_us"] = in->t_min;
        jf["time_max_us"] = in->t_max;
        jf["time_first_utc"] = utc_str(in->t_first);
        jf["duration_s"] = static_cast<double>(in->t_max - in->t_min) * 1e-6;
    } else {
        jf["time_first_us"] = nullptr;
        jf["time_last_us"] = nullptr;
        jf["time_min_us"] = nullptr;
        jf["time_max_us"] = nullptr;
        jf["time_first_utc"] = nullptr;
        jf["duration_s"] = nullptr;
    }
    jf["time_backwards"] = in->t_backwards;
    j["fft"] = jf;
    json jr;
    jr["frames"] = in->frames.size();
    jr["complete"] = in->frames_complete;
    jr["incomplete"] = in->frames.size() - in->frames_complete;
    jr["azimuths_stored"] = ss.azimuths;
    jr["missing_azimuths"] = ss.missing;
    jr["duplicate_azimuths"] = ss.duplicates;
    jr["out_of_order"] = ss.out_of_order;
    jr["late_dropped"] = ss.late_dropped;
    jr["bad_azimuth"] = ss.bad_azimuth;
    jr["no_config"] = ss.no_config;
    jr["config_changes"] = ss.config_changes;
    jr["config_rejected"] = ss.config_rejected;
    jr["end_reasons"] = {{"wrap", in->end_counts[0]}, {"sweep_gap", in->end_counts[1]},
                         {"config", in->end_counts[2]}, {"flush", in->end_counts[3]}};
    if (rotations) {
        json list = json::array();
        for (const auto &f : in->frames) {
            list.push_back({{"rotation", f.rotation}, {"valid", f.valid}, {"missing", f.missing},
                            {"duplicates", f.duplicates}, {"out_of_order", f.out_of_order},
                            {"end", end_name(f.end)}, {"time_first_us", f.t_first_us},
                            {"time_last_us", f.t_last_us}});
        }
        jr["list"] = list;
    }
    j["rotations"] = jr;
    j["decoder"] = {{"bytes_in", ps.bytes_in},         {"bytes_delivered", ps.bytes_delivered},
                    {"bytes_skipped", ps.bytes_skipped}, {"resyncs", ps.resyncs},
                    {"bad_version", ps.bad_version},   {"oversize", ps.oversize},
                    {"too_big", ps.too_big},           {"truncated", ps.truncated}};
    if (cap.has_pcap_report) {
        j["pcap"] = pcap_json(cap.pcap);
    }

    // A capture without a single radar message is an error (the report is printed anyway).
    const int status = ps.messages > 0 ? SL_EXIT_OK : SL_EXIT_ERROR;
    if (status != SL_EXIT_OK) {
        std::fprintf(stderr, "sl-inspect: %s: no radar message\n", path.c_str());
    }
    if (as_json) {
        std::printf("%s\n", j.dump(2).c_str());
        return status;
    }

    // Text report.
    std::printf("%s: %s, %" PRIu64 " bytes\n", path.c_str(), sl::capture_format_name(cap.format), cap_bytes);
    if (cap.has_pcap_report) {
        const auto &r = cap.pcap;
        std::printf("pcap: link %s, %" PRIu64 " packets (%" PRIu64 " undecoded, %" PRIu64
                    " IP fragments), radar port %u%s\n",
                    r.link_type.c_str(), r.packets_total, r.packets_undecoded, r.ip_fragments,
                    r.radar_port, r.port_auto_detected ? " (auto-detected)" : "");
        if (!r.read_error.empty()) {
            std::printf("  read error (file cut short or corrupt; packets before it used): %s\n", r.read_error.c_str());
        }
        for (const auto &f : r.flows) {
            std::printf("  flow %s -> %s: %" PRIu64 " packets, %" PRIu64 " payload bytes%s%s%s%s\n",
                        f.src.c_str(), f.dst.c_str(), f.packets, f.payload_bytes, f.syn ? ", SYN" : "",
                        f.fin ? ", FIN" : "", f.rst ? ", RST" : "", f.selected ? " [selected]" : " [ignored]");
        }
        std::printf("  reassembly: %" PRIu64 " segments, %" PRIu64 " retransmitted (%" PRIu64
                    " bytes, %" PRIu64 " differing), %" PRIu64 " partial overlaps, %" PRIu64
                    " out of order, %" PRIu64 " gaps (%" PRIu64 " bytes missing), %" PRIu64
                    " truncated packets%s\n",
                    r.segments, r.retransmitted_segments, r.retransmitted_bytes,
                    r.retransmit_mismatch_bytes, r.partial_overlap_segments, r.out_of_order_segments,
                    r.gaps, r.gap_bytes, r.packets_truncated,
                    r.started_mid_stream ? ", capture starts mid-stream (no SYN)" : "");
        for (const auto &g : r.gap_list) {
            std::printf("    gap: %" PRIu64 " bytes missing at stream offset %" PRIu64
                        " (output offset %" PRIu64 ")\n",
                        g.missing_bytes, g.stream_offset, g.output_offset);
        }
    }
    if (in->have_config) {
        const auto &c = in->config;
        std::printf("configuration: %u azimuths, %u bins of %u um, encoder %u, %.3f Hz, %u packets/s, "
                    "gain %g, offset %g m",
                    c.azimuths, c.range_bins, sl_proto_config_bin_size_um(&c), c.encoder_size,
                    c.rotation_mhz / 1000.0, c.packet_rate,
                    static_cast<double>(f32_from_bits(c.range_gain_f32)),
                    static_cast<double>(f32_from_bits(c.range_offset_f32)));
        if (c.has_data_width) std::printf(", data width %d", c.data_width);
        std::printf(" (%" PRIu64 " received, %" PRIu64 " differing)\n", in->configs, in->config_differs);
    } else {
        std::printf("configuration: none\n");
    }
    std::printf("messages: %u:", ps.messages);
    for (const auto &kv : in->by_id) {
        std::printf(" id %d x %" PRIu64, kv.first, kv.second);
    }
    std::printf("\n");
    std::printf("fft: %" PRIu64 " (8-bit %" PRIu64 ", 16-bit %" PRIu64 ", malformed %" PRIu64 ")",
                in->fft, in->fft8, in->fft16, in->fft_malformed);
    if (in->fft8 + in->fft16 > 0) {
        std::printf(", bins %" PRIu64 "..%" PRIu64 ", sweep gaps %u", in->bins_min, in->bins_max, ss.sweep_gaps);
    }
    std::printf("\n");
    if (in->have_t) {
        std::printf("time: %s .. +%.6f s (%" PRIu64 " .. %" PRIu64 " us), %" PRIu64 " steps backwards\n",
                    utc_str(in->t_min).c_str(), static_cast<double>(in->t_max - in->t_min) * 1e-6,
                    in->t_min, in->t_max, in->t_backwards);
    }
    std::printf("rotations: %zu frames, %" PRIu64 " complete; azimuths missing %u, duplicate %u, "
                "out of order %u, late dropped %u, bad %u, before config %u; ends: wrap %" PRIu64
                ", sweep gap %" PRIu64 ", config %" PRIu64 ", flush %" PRIu64 "\n",
                in->frames.size(), in->frames_complete, ss.missing, ss.duplicates, ss.out_of_order,
                ss.late_dropped, ss.bad_azimuth, ss.no_config, in->end_counts[0], in->end_counts[1],
                in->end_counts[2], in->end_counts[3]);
    if (rotations) {
        for (const auto &f : in->frames) {
            std::printf("  rotation %u: %u valid, %u missing, %u dup, %u late, end %s, %" PRIu64
                        " .. %" PRIu64 " us\n",
                        f.rotation, f.valid, f.missing, f.duplicates, f.out_of_order, end_name(f.end),
                        f.t_first_us, f.t_last_us);
        }
    }
    std::printf("decoder: %" PRIu64 " bytes in, %" PRIu64 " delivered, %" PRIu64 " skipped, %u resyncs "
                "(bad version %u, oversize %u, too big %u), %u truncated\n",
                ps.bytes_in, ps.bytes_delivered, ps.bytes_skipped, ps.resyncs, ps.bad_version,
                ps.oversize, ps.too_big, ps.truncated);
    return status;
}
