// SPDX-License-Identifier: MIT
// sl-bench-proto: throughput of the Colossus decoder (sl_proto) + scan assembly (sl_scan).
//
//   sl-bench-proto [capture] [--rotations N] [--azimuths N] [--bins N] [--width 1|2]
//                  [--roi N] [--chunk BYTES[,BYTES...]] [--repeat N] [--mode scan|proto]
//
// Without a capture it builds a stream in memory (tests/support/golden/sl_golden.c: config, then
// N rotations x azimuths FFT messages of `bins` noisy bins, keep-alives every 400 messages),
// default 16 x 400 x 3768 8-bit bins (about 24 MB). With a capture (raw .colossus, pcap or
// pcapng, see host_tools/capture/capture.h) it decodes that instead.
//
// For each chunk size (default 1448 = one TCP MSS, 16384, 65536 = typical recv() sizes,
// and 0 = the whole buffer in one call) it feeds the stream from memory to a fresh decoder
// whose callback is sl_scan_proto_sink (mode scan, default) or a counter (mode proto), and
// prints bytes, messages, azimuths, zero-copy vs reassembled messages and the best wall-clock
// MB/s over --repeat runs. Wall-clock numbers are for information only.
//
// Instruction counts: host_tools/bench_proto/callgrind.sh runs this binary under
// `valgrind --tool=callgrind --toggle-collect=sl_bench_run` (only the decode loop is counted,
// not the stream generation nor the one-time sl_scan_init) and divides by the "azimuths:" line printed here.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "capture.h"
#include "sl_cli.h"
#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_scan.h"
#include "sl_golden.h"

namespace {

struct Counter {
    uint64_t messages = 0;
    uint64_t fft = 0;
};

void count_msg(void *ctx, const sl_proto_msg_t *m)
{
    auto *c = static_cast<Counter *>(ctx);
    c->messages++;
    if (m->id == SL_PROTO_ID_FFT_DATA || m->id == SL_PROTO_ID_FFT_DATA_16) {
        c->fft++;
    }
}

sl_scan_frame_t g_frames[2];
uint64_t g_rows_seen = 0;

void count_azimuth(void *ctx, const sl_scan_frame_t *f, uint16_t idx)
{
    (void)ctx;
    (void)f;
    (void)idx;
    g_rows_seen++;
}

struct Result {
    sl_proto_stats_t proto{};
    sl_scan_stats_t scan{};
    Counter counter{};
};

} // namespace

// Decoder + scan state, static as in firmware (frames: 2 x ~210 KB).
static uint8_t g_reasm[1u << 20];
static sl_proto_t g_p;
static sl_scan_t g_s;
static Counter g_counter;

// One-time setup (not measured: sl_scan_init clears both frames once per session).
static void bench_setup(bool with_scan, uint16_t roi)
{
    g_counter = Counter{};
    sl_proto_cfg_t pc{};
    pc.reasm_buf = g_reasm;
    pc.reasm_size = sizeof g_reasm;
    pc.max_payload_bytes = 1000000;
    if (with_scan) {
        sl_scan_cfg_t sc{};
        sc.roi_bins = roi;
        sc.pow16_shift = 8;
        sc.on_azimuth = count_azimuth;
        if (sl_scan_init(&g_s, &sc, &g_frames[0], &g_frames[1]) != SL_OK) {
            std::abort();
        }
        pc.on_msg = sl_scan_proto_sink;
        pc.ctx = &g_s;
    } else {
        pc.on_msg = count_msg;
        pc.ctx = &g_counter;
    }
    if (sl_proto_init(&g_p, &pc) != SL_OK) {
        std::abort();
    }
}

// The measured loop: feed `n` bytes in `chunk`-byte calls, finish, flush.
// extern "C" + noinline so callgrind can restrict collection to it by name.
extern "C" __attribute__((noinline)) void sl_bench_run(const uint8_t *data, size_t n, size_t chunk,
                                                      bool with_scan, Result *out)
{
    if (chunk == 0) {
        chunk = n;
    }
    for (size_t i = 0; i < n; i += chunk) {
        const size_t k = (n - i < chunk) ? n - i : chunk;
        (void)sl_proto_feed(&g_p, data + i, k, 0);
    }
    (void)sl_proto_finish(&g_p);
    if (with_scan) {
        sl_scan_flush(&g_s);
        out->scan = g_s.stats;
    }
    out->proto = g_p.stats;
    out->counter = g_counter;
}

static void usage(FILE *out)
{
    std::fprintf(out,
                 "usage: sl-bench-proto [capture] [--rotations N] [--azimuths N] [--bins N]\n"
                 "       [--width 1|2] [--roi N] [--chunk B[,B...]] [--repeat N] [--mode scan|proto]\n");
}

int main(int argc, char **argv)
{
    std::string capture;
    sl_golden_params_t g = sl_golden_defaults();
    g.rotations = 16;
    g.keep_alive_every = 400;
    unsigned roi = SL_CFG_ROI_BINS;
    unsigned repeat = 5;
    bool with_scan = true;
    std::vector<size_t> chunks = {1448, 16384, 65536, 0};
    const int info = sl_cli_info(argc, argv, "sl-bench-proto", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        auto next = [&]() -> const char * {
            if (i + 1 >= argc) {
                std::exit(sl_cli_bad_value("sl-bench-proto", a.c_str(), "needs a value", usage));
            }
            return argv[++i];
        };
        if (a == "--rotations") {
            g.rotations = (uint16_t)std::atoi(next());
        } else if (a == "--azimuths") {
            g.azimuths = (uint16_t)std::atoi(next());
        } else if (a == "--bins") {
            g.range_bins = (uint16_t)std::atoi(next());
        } else if (a == "--width") {
            g.bytes_per_bin = (uint8_t)std::atoi(next());
        } else if (a == "--roi") {
            roi = (unsigned)std::atoi(next());
        } else if (a == "--repeat") {
            repeat = (unsigned)std::atoi(next());
        } else if (a == "--mode") {
            with_scan = std::string(next()) != "proto";
        } else if (a == "--chunk") {
            chunks.clear();
            std::string list = next();
            size_t pos = 0;
            while (pos <= list.size()) {
                const size_t comma = list.find(',', pos);
                chunks.push_back((size_t)std::strtoull(list.substr(pos, comma - pos).c_str(), nullptr, 10));
                if (comma == std::string::npos) {
                    break;
                }
                pos = comma + 1;
            }
        } else if (!a.empty() && a[0] != '-' && capture.empty()) {
            capture = a;
        } else {
            return sl_cli_unknown("sl-bench-proto", argv[i], usage);
        }
    }
    if (roi == 0 || roi > SL_CFG_ROI_BINS) {
        return sl_cli_bad_value("sl-bench-proto", "--roi", "must be 1..SL_CFG_ROI_BINS", usage);
    }
    if (repeat == 0) {
        return sl_cli_bad_value("sl-bench-proto", "--repeat", "must be at least 1", usage);
    }

    std::vector<uint8_t> bytes;
    if (!capture.empty()) {
        sl::Capture cap;
        std::string err;
        if (!sl::load_capture(capture, cap, err)) {
            std::fprintf(stderr, "sl-bench-proto: %s: %s\n", capture.c_str(), err.c_str());
            return 1;
        }
        bytes = std::move(cap.bytes);
        std::printf("input: %s (%s)\n", capture.c_str(), sl::capture_format_name(cap.format));
    } else {
        bytes.resize(sl_golden_size(&g));
        if (sl_golden_build(bytes.data(), bytes.size(), &g) != bytes.size()) {
            std::fprintf(stderr, "sl-bench-proto: bad stream parameters\n");
            return 2;
        }
        std::printf("input: generated, %u rotations x %u azimuths x %u bins, %u-bit\n", g.rotations,
                    g.azimuths, g.range_bins, 8u * g.bytes_per_bin);
    }
    std::printf("mode: %s, roi_bins: %u\n", with_scan ? "decoder + scan" : "decoder only", roi);
    std::printf("bytes: %zu\n", bytes.size());

    for (size_t chunk : chunks) {
        Result r;
        double best_s = 1e30;
        for (unsigned k = 0; k < repeat; k++) {
            bench_setup(with_scan, (uint16_t)roi);
            const auto t0 = std::chrono::steady_clock::now();
            sl_bench_run(bytes.data(), bytes.size(), chunk, with_scan, &r);
            const auto t1 = std::chrono::steady_clock::now();
            const double s = std::chrono::duration<double>(t1 - t0).count();
            if (s < best_s) {
                best_s = s;
            }
        }
        const uint64_t az = with_scan ? r.scan.azimuths : r.counter.fft;
        std::printf("chunk: %zu\n", chunk == 0 ? bytes.size() : chunk);
        std::printf("  messages: %u (fft %u, zero-copy %u, reassembled %u), skipped bytes: %llu\n",
                    r.proto.messages, r.proto.fft8 + r.proto.fft16, r.proto.zero_copy,
                    r.proto.reassembled, (unsigned long long)r.proto.bytes_skipped);
        if (with_scan) {
            std::printf("  frames: %u, missing: %u, duplicates: %u\n", r.scan.frames, r.scan.missing,
                        r.scan.duplicates);
        }
        std::printf("azimuths: %llu\n", (unsigned long long)az);
        std::printf("  wall: %.3f ms, %.1f MB/s, %.1f ns/azimuth (best of %u)\n", best_s * 1e3,
                    (double)bytes.size() / best_s / 1e6, az ? best_s * 1e9 / (double)az : 0.0,
                    repeat);
    }
    return 0;
}
