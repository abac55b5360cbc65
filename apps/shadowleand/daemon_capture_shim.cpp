// daemon_capture_shim.cpp: the C interface of daemon_capture.h over sl::load_capture.
#include "daemon_capture.h"

#include "capture.h"

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

extern "C" int sld_capture_load(const char *path, sld_capture_t *cap, char *err, size_t err_size)
{
    std::memset(cap, 0, sizeof *cap);
    try {
        sl::Capture c;
        std::string e;
        if (!sl::load_capture(path, c, e)) {
            std::snprintf(err, err_size, "%s", e.c_str());
            return -1;
        }
        cap->size = c.bytes.size();
        cap->bytes = static_cast<uint8_t *>(std::malloc(cap->size > 0 ? cap->size : 1));
        cap->n_breaks = c.discontinuities.size();
        cap->breaks = static_cast<uint64_t *>(std::malloc((cap->n_breaks > 0 ? cap->n_breaks : 1) * sizeof(uint64_t)));
        if (cap->bytes == nullptr || cap->breaks == nullptr) {
            sld_capture_free(cap);
            std::snprintf(err, err_size, "%s: out of memory", path);
            return -1;
        }
        if (cap->size > 0) {
            std::memcpy(cap->bytes, c.bytes.data(), cap->size);
        }
        for (size_t i = 0; i < cap->n_breaks; i++) {
            cap->breaks[i] = c.discontinuities[i].output_offset;
        }
        std::snprintf(cap->format, sizeof cap->format, "%s", sl::capture_format_name(c.format));
        if (c.has_pcap_report) {
            const sl::PcapReport &r = c.pcap;
            std::snprintf(cap->report, sizeof cap->report,
                          "radar port %u%s, %" PRIu64 " packets, %" PRIu64 " segments, %" PRIu64
                          " stream bytes, %" PRIu64 " retransmitted, %" PRIu64 " out of order, %" PRIu64
                          " gaps (%" PRIu64 " bytes)%s%s%s",
                          r.radar_port, r.port_auto_detected ? " (auto-detected)" : "", r.packets_total,
                          r.segments, r.stream_bytes, r.retransmitted_segments, r.out_of_order_segments,
                          r.gaps, r.gap_bytes, r.started_mid_stream ? ", starts mid-stream" : "",
                          r.read_error.empty() ? "" : ", read error: ", r.read_error.c_str());
        }
        return 0;
    } catch (const std::exception &ex) {
        sld_capture_free(cap);
        std::snprintf(err, err_size, "%s: %s", path, ex.what());
        return -1;
    }
}

extern "C" void sld_capture_free(sld_capture_t *cap)
{
    std::free(cap->bytes);
    std::free(cap->breaks);
    cap->bytes = nullptr;
    cap->breaks = nullptr;
    cap->size = 0;
    cap->n_breaks = 0;
}
