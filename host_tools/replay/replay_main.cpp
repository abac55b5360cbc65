// SPDX-License-Identifier: MIT
// sl-replay: radar emulator, recorder and Oxford converter.
//
//   sl-replay serve CAPTURE [--port P] [--bind ADDR] [--rate realtime|max] [--loop] ...
//   sl-replay record --radar HOST:PORT --out FILE [--duration S] [--non-contour]
//   sl-replay from-oxford DIR --out FILE [--bin-size-m 0.0432]
//   sl-replay to-pcapng RAW --out FILE.pcapng [--mss N] ...
#include "replay.h"

#include "capture.h"
#include "oxford.h"
#include "sl_cli.h"

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <signal.h>
#include <string>

namespace sl::replay {

volatile std::sig_atomic_t g_stop = 0;

namespace {
void on_signal(int) { g_stop = 1; }
} // namespace

void install_signal_handlers()
{
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; // no SA_RESTART: poll() returns EINTR and the loops see g_stop
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    signal(SIGPIPE, SIG_IGN);
}

} // namespace sl::replay

namespace {

using namespace sl::replay;

void usage(FILE *out)
{
    std::fprintf(out,
        "usage:\n"
        "  sl-replay serve CAPTURE [options]   emulate a radar on TCP, replaying CAPTURE\n"
        "      --port P            TCP port (default 6317; 0 = any free port, printed)\n"
        "      --bind ADDR         listen address (default 127.0.0.1, loopback only)\n"
        "      --rate realtime|max pace by the FFT timestamps (default) or as fast as read\n"
        "      --loop              restart the capture at its end (timestamps and sweep\n"
        "                          counters shifted to stay monotonic)\n"
        "      --keepalive-ms N    keep-alive period (default 1000, 0 = none)\n"
        "      --max-clients N     concurrent connections (default 3; more are closed)\n"
        "      --queue-bytes N     per-client output queue (default 4194304)\n"
        "      --max-gap-ms N      realtime: longer timestamp gaps shortened (default 1000)\n"
        "      --junk-every N      inject junk after every N-th FFT message (3 patterns:\n"
        "                          7 bytes, a 12-byte partial signature, a 26-byte header\n"
        "                          with version 2), for decoder tests\n"
        "      --split K           send every message in K writes (first cut in the header)\n"
        "      --close-after N     close a connection after N FFT messages (radar restart);\n"
        "                          the next connection continues where it stopped\n"
        "      --stall-after N     go silent on a connection after N FFT messages (no data,\n"
        "                          no keep-alive, socket open); the next connection continues\n"
        "      --cut-after N       after N FFT messages send half of the next one, then close\n"
        "                          (FIN); the next connection resends it whole\n"
        "      --rst-after N       the same, ending with a TCP RST once the client has\n"
        "                          acknowledged every byte sent before it\n"
        "      --keepalive-only    accept Start FFT, send only keep-alives (no FFT data)\n"
        "      --trickle-bps N     send at most N bytes per second, one at a time (slowloris)\n"
        "      --config-azimuths N, --config-encoder N, --config-bin-size-m M\n"
        "                          serve a Configuration with this geometry (mismatch tests)\n"
        "      --shuffle N         reorder FFT messages within blocks of N (fixed seed)\n"
        "      --timeout S         exit by itself after S seconds\n"
        "      -v                  log connections\n"
        "  sl-replay record --radar HOST:PORT --out FILE [options]\n"
        "      --duration S        stop after S seconds (default: Ctrl-C)\n"
        "      --non-contour       start with id 140 instead of 21\n"
        "      --silence-ms N      reconnect when nothing arrives for N ms (default 3000)\n"
        "  sl-replay from-oxford DIR --out FILE [--bin-size-m 0.0432]\n"
        "      DIR/radar/*.png (or DIR/*.png), Oxford Radar RobotCar polar PNGs\n"
        "      --encoder-size N --rotation-mhz N --packet-rate N (defaults 5600 4000 1600)\n"
        "  sl-replay to-pcapng RAW --out FILE.pcapng [options]\n"
        "      a raw capture (or - for stdin) as one TCP session radar:6317 -> client, as\n"
        "      tcpdump records it (handshake, Start FFT, MSS segments, ACKs, FIN); every\n"
        "      byte kept; time from the FFT timestamps; --out - writes to stdout\n"
        "      --mss N (1448) --radar-ip A (192.168.0.1) --client-ip A (192.168.0.2)\n"
        "      --radar-port P (6317) --client-port P (50000) --non-contour (140, not 21)\n");
}

bool parse_u64(const char *s, uint64_t &v)
{
    char *end = nullptr;
    errno = 0;
    const unsigned long long x = std::strtoull(s, &end, 10);
    if (errno != 0 || end == s || *end != '\0' || s[0] == '-') {
        return false;
    }
    v = x;
    return true;
}

bool parse_double(const char *s, double &v)
{
    char *end = nullptr;
    v = std::strtod(s, &end);
    return end != s && *end == '\0';
}

// "host:port", "[v6]:port"
bool split_host_port(const std::string &hp, std::string &host, uint16_t &port)
{
    std::string p;
    if (!hp.empty() && hp[0] == '[') {
        const auto e = hp.find("]:");
        if (e == std::string::npos) return false;
        host = hp.substr(1, e - 1);
        p = hp.substr(e + 2);
    } else {
        const auto e = hp.rfind(':');
        if (e == std::string::npos) {
            host = hp;
            port = 6317;
            return !host.empty();
        }
        host = hp.substr(0, e);
        p = hp.substr(e + 1);
    }
    uint64_t v = 0;
    if (host.empty() || !parse_u64(p.c_str(), v) || v == 0 || v > 65535) return false;
    port = static_cast<uint16_t>(v);
    return true;
}

#define NEED_ARG()                                                                           \
    do {                                                                                     \
        if (i + 1 >= argc) {                                                                 \
            return sl_cli_bad_value("sl-replay", a.c_str(), "needs a value", usage);         \
        }                                                                                    \
    } while (0)

// The value of option `a` was given but is out of range or does not parse.
#define BAD_VALUE() sl_cli_bad_value("sl-replay", a.c_str(), "bad value", usage)

int cmd_serve(int argc, char **argv)
{
    ServeOptions o;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        uint64_t v = 0;
        if (a == "--port") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v > 65535) return BAD_VALUE();
            o.port = static_cast<int>(v);
        } else if (a == "--bind") {
            NEED_ARG();
            o.bind = argv[++i];
        } else if (a == "--rate") {
            NEED_ARG();
            const std::string r = argv[++i];
            if (r == "realtime") o.realtime = true;
            else if (r == "max") o.realtime = false;
            else return BAD_VALUE();
        } else if (a == "--loop") {
            o.loop = true;
        } else if (a == "--keepalive-ms") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v > 3600000) return BAD_VALUE();
            o.keepalive_ms = static_cast<uint32_t>(v);
        } else if (a == "--max-clients") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v == 0 || v > 1000) return BAD_VALUE();
            o.max_clients = static_cast<unsigned>(v);
        } else if (a == "--queue-bytes") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v < 65536) return BAD_VALUE();
            o.queue_bytes = static_cast<size_t>(v);
        } else if (a == "--max-gap-ms") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v > 3600000) return BAD_VALUE();
            o.max_gap_ms = static_cast<uint32_t>(v);
        } else if (a == "--junk-every") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v)) return BAD_VALUE();
            o.junk_every = v;
        } else if (a == "--split") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v > 64) return BAD_VALUE();
            o.split = static_cast<unsigned>(v);
        } else if (a == "--cut-after" || a == "--rst-after") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v == 0) return BAD_VALUE();
            o.cut_after = v;
            o.cut_rst = a == "--rst-after";
        } else if (a == "--keepalive-only") {
            o.keepalive_only = true;
        } else if (a == "--trickle-bps") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v == 0 || v > 1000000) return BAD_VALUE();
            o.trickle_bps = static_cast<uint32_t>(v);
        } else if (a == "--config-azimuths" || a == "--config-encoder") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v > 65535) return BAD_VALUE();
            (a == "--config-azimuths" ? o.config_azimuths : o.config_encoder) = static_cast<int>(v);
        } else if (a == "--config-bin-size-m") {
            NEED_ARG();
            if (!parse_double(argv[++i], o.config_bin_size_m) || !(o.config_bin_size_m > 0) ||
                o.config_bin_size_m > 6.5) return BAD_VALUE();
        } else if (a == "--shuffle") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v < 2 || v > 100000) return BAD_VALUE();
            o.shuffle = static_cast<unsigned>(v);
        } else if (a == "--close-after") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v)) return BAD_VALUE();
            o.close_after = v;
        } else if (a == "--stall-after") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v)) return BAD_VALUE();
            o.stall_after = v;
        } else if (a == "--timeout") {
            NEED_ARG();
            if (!parse_double(argv[++i], o.timeout_s) || o.timeout_s < 0) return BAD_VALUE();
        } else if (a == "-v") {
            o.verbose = true;
        } else if (a.size() > 1 && a[0] == '-') { // "-" is stdin
            return sl_cli_unknown("sl-replay", argv[i], usage);
        } else if (o.capture.empty()) {
            o.capture = a;
        } else {
            return sl_cli_unknown("sl-replay", argv[i], usage);
        }
    }
    if (o.capture.empty()) {
        return sl_cli_usage_error("sl-replay", "serve: missing CAPTURE", usage);
    }
    install_signal_handlers();
    return serve(o);
}

int cmd_record(int argc, char **argv)
{
    RecordOptions o;
    std::string radar;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        uint64_t v = 0;
        if (a == "--radar") {
            NEED_ARG();
            radar = argv[++i];
        } else if (a == "--out") {
            NEED_ARG();
            o.out = argv[++i];
        } else if (a == "--duration") {
            NEED_ARG();
            if (!parse_double(argv[++i], o.duration_s) || o.duration_s < 0) return BAD_VALUE();
        } else if (a == "--non-contour") {
            o.non_contour = true;
        } else if (a == "--silence-ms") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v > 3600000) return BAD_VALUE();
            o.silence_ms = static_cast<uint32_t>(v);
        } else if (a == "-v") {
            o.verbose = true;
        } else {
            return sl_cli_unknown("sl-replay", argv[i], usage);
        }
    }
    if (radar.empty()) {
        return sl_cli_usage_error("sl-replay", "record: missing --radar HOST:PORT", usage);
    }
    if (o.out.empty()) {
        return sl_cli_usage_error("sl-replay", "record: missing --out FILE", usage);
    }
    if (!split_host_port(radar, o.host, o.port)) {
        return sl_cli_bad_value("sl-replay", "--radar", "needs HOST:PORT", usage);
    }
    install_signal_handlers();
    return record(o);
}

int cmd_from_oxford(int argc, char **argv)
{
    std::string dir, out;
    sl::OxfordOptions opt;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        uint64_t v = 0;
        if (a == "--out") {
            NEED_ARG();
            out = argv[++i];
        } else if (a == "--bin-size-m") {
            NEED_ARG();
            if (!parse_double(argv[++i], opt.bin_size_m)) return BAD_VALUE();
        } else if (a == "--encoder-size" || a == "--rotation-mhz" || a == "--packet-rate") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v == 0 || v > 65535) return BAD_VALUE();
            (a == "--encoder-size" ? opt.encoder_size : a == "--rotation-mhz" ? opt.rotation_mhz : opt.packet_rate) =
                static_cast<uint16_t>(v);
        } else if (!a.empty() && a[0] == '-') {
            return sl_cli_unknown("sl-replay", argv[i], usage);
        } else if (dir.empty()) {
            dir = a;
        } else {
            return sl_cli_unknown("sl-replay", argv[i], usage);
        }
    }
    if (dir.empty()) {
        return sl_cli_usage_error("sl-replay", "from-oxford: missing OXFORD_DIR", usage);
    }
    if (out.empty()) {
        return sl_cli_usage_error("sl-replay", "from-oxford: missing --out FILE", usage);
    }
    std::vector<uint8_t> bytes;
    sl::OxfordReport rep;
    std::string err;
    if (!sl::oxford_to_colossus(dir, opt, bytes, rep, err)) {
        std::fprintf(stderr, "sl-replay from-oxford: %s\n", err.c_str());
        return 1;
    }
    if (!sl::write_raw_capture(out, bytes.data(), bytes.size(), err)) {
        std::fprintf(stderr, "sl-replay from-oxford: %s\n", err.c_str());
        return 1;
    }
    std::printf("%s: %u scans of %u azimuths x %u bins (bin size %u x 0.1 mm) -> %" PRIu64
                " FFT messages, %" PRIu64 " bytes in %s\n",
                rep.png_dir.c_str(), rep.scans, rep.azimuths, rep.range_bins, rep.bin_size_100um, rep.rows,
                rep.bytes, out.c_str());
    std::printf("rows with valid != 255: %" PRIu64 "; azimuth >= encoder size: %" PRIu64
                "; timestamp not increasing: %" PRIu64 "; negative timestamp: %" PRIu64
                "; time %" PRId64 " .. %" PRId64 " us\n",
                rep.invalid_rows, rep.azimuth_out_of_range, rep.time_not_increasing, rep.negative_time,
                rep.first_time_us, rep.last_time_us);
    return 0;
}

bool parse_ipv4(const char *s, uint32_t &ip)
{
    unsigned a, b, c, d;
    char tail;
    if (std::sscanf(s, "%u.%u.%u.%u%c", &a, &b, &c, &d, &tail) != 4 || a > 255 || b > 255 ||
        c > 255 || d > 255)
        return false;
    ip = a << 24 | b << 16 | c << 8 | d;
    return true;
}

int cmd_to_pcapng(int argc, char **argv)
{
    PcapngOptions o;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        uint64_t v = 0;
        if (a == "--out") {
            NEED_ARG();
            o.out = argv[++i];
        } else if (a == "--mss") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v == 0 || v > 65495) return BAD_VALUE();
            o.session.mss = static_cast<uint32_t>(v);
        } else if (a == "--radar-ip" || a == "--client-ip") {
            NEED_ARG();
            if (!parse_ipv4(argv[++i], a == "--radar-ip" ? o.session.radar_ip : o.session.client_ip)) {
                return sl_cli_bad_value("sl-replay", a.c_str(), "bad IPv4 address", usage);
            }
        } else if (a == "--radar-port" || a == "--client-port") {
            NEED_ARG();
            if (!parse_u64(argv[++i], v) || v == 0 || v > 65535) return BAD_VALUE();
            (a == "--radar-port" ? o.session.radar_port : o.session.client_port) =
                static_cast<uint16_t>(v);
        } else if (a == "--non-contour") {
            o.non_contour = true;
        } else if (a.size() > 1 && a[0] == '-') {
            return sl_cli_unknown("sl-replay", argv[i], usage);
        } else if (o.input.empty()) {
            o.input = a;
        } else {
            return sl_cli_unknown("sl-replay", argv[i], usage);
        }
    }
    if (o.input.empty()) {
        return sl_cli_usage_error("sl-replay", "to-pcapng: missing CAPTURE", usage);
    }
    if (o.out.empty()) {
        return sl_cli_usage_error("sl-replay", "to-pcapng: missing --out FILE", usage);
    }
    install_signal_handlers();
    return to_pcapng(o);
}

} // namespace

int main(int argc, char **argv)
{
    // --help/--version at top level (argv[1]) and after a subcommand (its own arguments).
    const int info = sl_cli_info(argc < 2 ? argc : 2, argv, "sl-replay", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    if (argc < 2) {
        return sl_cli_usage_error("sl-replay", "missing command (serve, record, from-oxford or to-pcapng)",
                                  usage);
    }
    const std::string cmd = argv[1];
    if (cmd != "serve" && cmd != "record" && cmd != "from-oxford" && cmd != "to-pcapng") {
        return sl_cli_unknown("sl-replay", argv[1], usage);
    }
    const int sub = sl_cli_info(argc - 1, argv + 1, "sl-replay", usage);
    if (sub != SL_CLI_CONTINUE) {
        return sub;
    }
    if (cmd == "serve") return cmd_serve(argc, argv);
    if (cmd == "record") return cmd_record(argc, argv);
    if (cmd == "from-oxford") return cmd_from_oxford(argc, argv);
    return cmd_to_pcapng(argc, argv);
}
