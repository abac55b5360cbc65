// SPDX-License-Identifier: MIT
// replay_pcapng.cpp: `sl-replay to-pcapng RAW --out FILE.pcapng`, a raw capture as the TCP
// session tcpdump would have recorded (see pcapng_writer.h).
//
// Streaming: the raw bytes are read in 64 KiB blocks (a file, a pipe or stdin "-") and
// written out as they come; memory stays bounded whatever the capture's size. The core
// decoder runs beside the copy only to learn each message's time (FFT timestamps) and where
// the first Configuration ends (the client's Start FFT is sent right after it, as a real
// client does); every byte of the input, junk included, goes into the TCP stream unchanged.
#include "pcapng_writer.h"
#include "replay.h"

#include "shadowlean/sl_proto.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <vector>

namespace sl::replay {

namespace {

struct TimeMark {
    uint64_t end;     ///< stream offset just past the message
    uint64_t time_us; ///< its FFT timestamp (UNIX us)
};

struct DecodeState {
    std::deque<TimeMark> marks;
    uint64_t config_end = UINT64_MAX; ///< end offset of the first Configuration
    uint64_t first_time_us = 0;
    bool have_time = false;
};

void on_msg(void *ctx, const sl_proto_msg_t *m)
{
    auto *st = static_cast<DecodeState *>(ctx);
    const uint64_t end = m->stream_offset + SL_PROTO_HEADER_BYTES + m->wire_bytes;
    if (m->id == SL_PROTO_ID_CONFIGURATION && st->config_end == UINT64_MAX) st->config_end = end;
    sl_proto_fft_t fft;
    if ((m->id == SL_PROTO_ID_FFT_DATA || m->id == SL_PROTO_ID_FFT_DATA_16) &&
        sl_proto_parse_fft(m, &fft) == SL_OK) {
        const uint64_t t = sl_proto_fft_time_us(&fft);
        if (!st->have_time) {
            st->have_time = true;
            st->first_time_us = t;
        }
        st->marks.push_back({end, t});
    }
}

} // namespace

int to_pcapng(const PcapngOptions &o)
{
    std::FILE *in = o.input == "-" ? stdin : std::fopen(o.input.c_str(), "rb");
    if (in == nullptr) {
        std::fprintf(stderr, "sl-replay to-pcapng: %s: %s\n", o.input.c_str(), std::strerror(errno));
        return 1;
    }
    PcapngWriter w;
    std::string err;
    if (!w.open(o.out, o.session, err)) {
        std::fprintf(stderr, "sl-replay to-pcapng: %s\n", err.c_str());
        if (in != stdin) std::fclose(in);
        return 1;
    }
    DecodeState st;
    std::vector<uint8_t> reasm(1u << 20);
    sl_proto_t dec;
    sl_proto_cfg_t cfg{};
    cfg.reasm_buf = reasm.data();
    cfg.reasm_size = reasm.size();
    cfg.on_msg = on_msg;
    cfg.ctx = &st;
    sl_proto_init(&dec, &cfg);

    // Bytes read but not yet written: held only until the first timestamp is known (a
    // Configuration precedes the first FFT) or the hold limit is reached.
    constexpr size_t kHoldMax = 8u << 20;
    std::vector<uint8_t> pending;
    uint64_t pending_at = 0; // stream offset of pending[0]
    uint64_t now_us = 0;     // time of the frames being written
    bool started = false, start_sent = false;
    const uint8_t start_cmd_id = o.non_contour ? SL_PROTO_ID_START_NONCONTOUR_FFT
                                               : SL_PROTO_ID_START_FFT;
    uint8_t start_cmd[SL_PROTO_HEADER_BYTES];
    sl_proto_encode_command(start_cmd, sizeof start_cmd, start_cmd_id);

    auto emit = [&](bool final) -> bool {
        if (!started) {
            if (!st.have_time && !final && pending.size() < kHoldMax) return true;
            now_us = st.have_time ? st.first_time_us : 0;
            // The connection opens a millisecond before the first data.
            if (!w.handshake(now_us >= 1000 ? now_us - 1000 : 0)) return false;
            started = true;
        }
        size_t i = 0;
        while (i < pending.size()) {
            const uint64_t at = pending_at + i;
            uint64_t cut = pending_at + pending.size();
            if (!start_sent && st.config_end > at && st.config_end < cut) cut = st.config_end;
            // Advance the clock over every message that ends inside this piece.
            while (!st.marks.empty() && st.marks.front().end <= cut) {
                if (st.marks.front().time_us > now_us) now_us = st.marks.front().time_us;
                st.marks.pop_front();
            }
            const size_t n = size_t(cut - at);
            if (!w.radar_send(pending.data() + i, n, now_us)) return false;
            i += n;
            if (!start_sent && cut == st.config_end) {
                if (!w.client_send(start_cmd, sizeof start_cmd, now_us)) return false;
                start_sent = true;
            }
        }
        pending_at += pending.size();
        pending.clear();
        return true;
    };

    std::vector<uint8_t> block(64u << 10);
    bool ok = true;
    for (;;) {
        const size_t n = std::fread(block.data(), 1, block.size(), in);
        if (n == 0) break;
        sl_proto_feed(&dec, block.data(), n, 0);
        pending.insert(pending.end(), block.begin(), block.begin() + long(n));
        if (!emit(false)) {
            ok = false;
            break;
        }
        if (g_stop) break;
    }
    const bool read_error = std::ferror(in) != 0;
    sl_proto_finish(&dec);
    if (in != stdin) std::fclose(in);
    if (ok) ok = emit(true) && w.close_session(now_us);
    if (!w.finish(err) || !ok) {
        std::fprintf(stderr, "sl-replay to-pcapng: %s: %s\n", o.out.c_str(),
                     err.empty() ? "write error" : err.c_str());
        return 1;
    }
    if (read_error) {
        std::fprintf(stderr, "sl-replay to-pcapng: %s: read error\n", o.input.c_str());
        return 1;
    }
    const sl_proto_stats_t *s = &dec.stats;
    std::fprintf(stderr,
                 "sl-replay to-pcapng: %llu radar bytes (%llu in messages, %llu junk) -> %llu "
                 "frames in %s\n",
                 (unsigned long long)w.radar_bytes(), (unsigned long long)s->bytes_delivered,
                 (unsigned long long)s->bytes_skipped, (unsigned long long)w.frames(),
                 o.out.c_str());
    if (s->bytes_delivered == 0) {
        std::fprintf(stderr, "sl-replay to-pcapng: %s holds no radar message\n", o.input.c_str());
        return 1;
    }
    return 0;
}

} // namespace sl::replay
