// SPDX-License-Identifier: MIT
// replay_record.cpp: `sl-replay record`, a radar client that writes the raw stream to a file.
//
// Connects with the Linux radar client (handshake: Configuration, then Start FFT), writes
// every received byte, unmodified, to a .colossus file; at the end (duration or Ctrl-C)
// sends Stop FFT and closes. If the radar drops the connection the client reconnects and
// recording continues (the file then holds the sessions back to back; the decoder resyncs
// over a message cut by the disconnect).
#include "replay.h"

#include "capture.h"

#include "radar_client.h"
#include "port_clock.h"

#include <cinttypes>
#include <cstdio>
#include <memory>
#include <vector>

namespace sl::replay {

namespace {

struct RecordCtx {
    sl::RawCaptureWriter *w = nullptr;
    bool write_failed = false;
    bool verbose = false;
};

void on_bytes(void *ctx, const uint8_t *d, size_t n, uint64_t)
{
    auto *rc = static_cast<RecordCtx *>(ctx);
    if (!rc->w->write(d, n)) {
        rc->write_failed = true;
    }
}

void on_event(void *ctx, slp_radar_event_t ev, slp_radar_reason_t reason, uint64_t)
{
    auto *rc = static_cast<RecordCtx *>(ctx);
    switch (ev) {
    case SLP_RADAR_EV_CONNECTED:
        std::fprintf(stderr, "sl-replay record: connected\n");
        break;
    case SLP_RADAR_EV_CONFIG:
        if (rc->verbose) std::fprintf(stderr, "sl-replay record: configuration received\n");
        break;
    case SLP_RADAR_EV_DISCONNECTED:
        std::fprintf(stderr, "sl-replay record: disconnected (%s), reconnecting\n", slp_radar_reason_str(reason));
        break;
    case SLP_RADAR_EV_CONNECT_FAILED:
        if (rc->verbose) std::fprintf(stderr, "sl-replay record: connect failed (%s)\n", slp_radar_reason_str(reason));
        break;
    case SLP_RADAR_EV_STOPPED:
        break;
    }
}

} // namespace

int record(const RecordOptions &o)
{
    sl::RawCaptureWriter w;
    std::string err;
    if (!w.open(o.out, err)) {
        std::fprintf(stderr, "sl-replay record: %s\n", err.c_str());
        return 1;
    }
    RecordCtx rc;
    rc.w = &w;
    rc.verbose = o.verbose;
    std::vector<uint8_t> reasm(sl::kHostMaxPayloadBytes);
    auto client = std::make_unique<slp_radar_client_t>();
    slp_radar_client_cfg_t cfg;
    slp_radar_client_cfg_defaults(&cfg);
    cfg.host = o.host.c_str();
    cfg.port = o.port;
    cfg.non_contour = o.non_contour;
    cfg.silence_timeout_ms = o.silence_ms;
    cfg.connect_timeout_ms = o.connect_timeout_ms;
    cfg.backoff_max_ms = o.backoff_max_ms;
    cfg.reasm_buf = reasm.data();
    cfg.reasm_size = reasm.size();
    cfg.on_bytes = on_bytes;
    cfg.on_event = on_event;
    cfg.ctx = &rc;
    if (slp_radar_client_init(client.get(), &cfg) != SL_OK) {
        std::fprintf(stderr, "sl-replay record: cannot resolve %s:%u\n", o.host.c_str(), o.port);
        return 1;
    }
    slp_radar_client_start(client.get());
    const uint64_t t0 = slp_now_us();
    const uint64_t t_end = o.duration_s > 0 ? t0 + static_cast<uint64_t>(o.duration_s * 1e6) : UINT64_MAX;
    int status = 0;
    while (!g_stop && !rc.write_failed) {
        const uint64_t now = slp_now_us();
        if (now >= t_end) {
            break;
        }
        const uint64_t left_ms = t_end == UINT64_MAX ? 1000 : (t_end - now + 999) / 1000;
        if (slp_radar_client_poll(client.get(), static_cast<int>(std::min<uint64_t>(left_ms, 1000))) == SL_ERR_PORT) {
            std::fprintf(stderr, "sl-replay record: poll failed\n");
            status = 1;
            break;
        }
    }
    slp_radar_client_stop(client.get(), 500);
    const double secs = static_cast<double>(slp_now_us() - t0) * 1e-6;
    if (!w.close(err) || rc.write_failed) {
        std::fprintf(stderr, "sl-replay record: %s\n", err.empty() ? "write failed" : err.c_str());
        status = 1;
    }
    const slp_radar_client_stats_t &s = client->stats;
    const sl_proto_stats_t &p = client->proto.stats;
    std::printf("recorded %" PRIu64 " bytes to %s in %.2f s: %u messages (%u configuration, %u FFT, "
                "%u keep-alive), decoder %u resyncs / %" PRIu64 " bytes skipped / %u truncated; "
                "%u connects (%u reconnects), %u connect failures, %u EOF, %u errors, %u silent, "
                "stop sent %u\n",
                w.bytes_written(), o.out.c_str(), secs, s.messages, s.configs, s.fft_messages,
                s.keep_alives, p.resyncs, p.bytes_skipped, p.truncated, s.connects, s.reconnects,
                s.connect_failures + s.connect_timeouts, s.disconnects_eof, s.disconnects_error,
                s.silence_timeouts, s.stops_sent);
    if (status == 0 && s.messages == 0) {
        // Nothing recorded is a failure, whatever the reason (no radar, refused, silent).
        std::fprintf(stderr, "sl-replay record: no radar message received from %s:%u (%u connects, %u "
                     "connect failures)\n", o.host.c_str(), static_cast<unsigned>(o.port), s.connects,
                     s.connect_failures + s.connect_timeouts);
        status = 1;
    }
    slp_radar_client_deinit(client.get());
    return status;
}

} // namespace sl::replay
