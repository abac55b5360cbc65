// SPDX-License-Identifier: MIT
// replay_serve.cpp: `sl-replay serve`, a radar emulator that replays a capture.
//
// Behaves like a Navtech radar (NAVTECH_PROTOCOL.md s.1): sends the capture's Configuration
// on connect (and on a Configuration Request, id 20), a keep-alive every second, streams the
// capture's FFT messages (ids 30/31, byte for byte as captured) to a connection only after it
// sent Start FFT (21 or 140), stops on Stop FFT (22); at most 3 connections, each with its own
// state; a 4th is accepted and closed at once. Other message ids of the capture (keep-alives,
// health, ...) are not replayed.
//
// Each connection plays the capture from its start (or from where an injected fault left
// off, see --close-after / --stall-after), paced by the FFT timestamps (gaps longer than
// --max-gap-ms shortened to it, backwards steps sent at once) or as fast as the client reads.
// Single-threaded, non-blocking, poll(): a slow client only affects itself (bounded queue:
// realtime drops and counts messages that do not fit, max rate stops producing for it).
#include "replay.h"

#include "capture.h"

#include "shadowlean/sl_proto.h"

#include "sl_port_linux.h"

#include <arpa/inet.h>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <deque>
#include <memory>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>
#include <vector>

namespace sl::replay {

namespace {

struct FftEntry {
    uint64_t offset = 0; // of the whole message in the capture
    uint32_t size = 0;
    int64_t ts_ns = 0;   // capture timestamp
    uint16_t sweep = 0;
    int64_t play_us = 0; // playback time since the first FFT message (gaps clamped)
};

struct Source {
    sl::Capture cap;
    std::vector<uint8_t> config;
    std::vector<FftEntry> fft;
    int64_t cycle_play_us = 0; // one pass of the capture, for --loop
    int64_t cycle_ts_ns = 0;   // timestamp shift per pass
    uint16_t cycle_sweep = 0;  // sweep counter shift per pass
    uint64_t not_replayed = 0; // messages other than Configuration and FFT
};

void put_le32(uint8_t *p, uint32_t v)
{
    p[0] = static_cast<uint8_t>(v);
    p[1] = static_cast<uint8_t>(v >> 8);
    p[2] = static_cast<uint8_t>(v >> 16);
    p[3] = static_cast<uint8_t>(v >> 24);
}

bool load_source(const ServeOptions &o, Source &src, std::string &err)
{
    if (!sl::load_capture(o.capture, src.cap, err)) {
        return false;
    }
    const auto msgs = sl::index_capture(src.cap);
    uint32_t packet_rate = 0;
    for (const auto &m : msgs) {
        const uint8_t *p = src.cap.bytes.data() + m.offset;
        sl_proto_msg_t pm{};
        pm.id = m.id;
        pm.payload.data = p + SL_PROTO_HEADER_BYTES;
        pm.payload.size = m.size - SL_PROTO_HEADER_BYTES;
        if (m.id == SL_PROTO_ID_CONFIGURATION) {
            sl_proto_config_t c{};
            if (src.config.empty() && sl_proto_parse_config(&pm, &c) == SL_OK) {
                src.config.assign(p, p + m.size);
                packet_rate = c.packet_rate;
            }
        } else if (m.id == SL_PROTO_ID_FFT_DATA || m.id == SL_PROTO_ID_FFT_DATA_16) {
            sl_proto_fft_t f{};
            if (sl_proto_parse_fft(&pm, &f) != SL_OK) {
                ++src.not_replayed;
                continue;
            }
            FftEntry e;
            e.offset = m.offset;
            e.size = m.size;
            e.ts_ns = static_cast<int64_t>(f.seconds) * 1000000000 + f.split_ns;
            e.sweep = f.sweep_counter;
            if (!src.fft.empty()) {
                const FftEntry &prev = src.fft.back();
                int64_t d_us = (e.ts_ns - prev.ts_ns) / 1000;
                d_us = std::max<int64_t>(0, std::min<int64_t>(d_us, static_cast<int64_t>(o.max_gap_ms) * 1000));
                e.play_us = prev.play_us + d_us;
            }
            src.fft.push_back(e);
        } else {
            ++src.not_replayed;
        }
    }
    if (src.config.empty()) {
        err = o.capture + ": no valid Configuration message (id 10) in the capture";
        return false;
    }
    if (o.config_azimuths >= 0 || o.config_encoder >= 0 || o.config_bin_size_m > 0) {
        // Fault injection: serve another geometry than the capture's.
        sl_proto_msg_t pm{};
        pm.id = SL_PROTO_ID_CONFIGURATION;
        pm.payload.data = src.config.data() + SL_PROTO_HEADER_BYTES;
        pm.payload.size = src.config.size() - SL_PROTO_HEADER_BYTES;
        sl_proto_config_t c{};
        if (sl_proto_parse_config(&pm, &c) != SL_OK) {
            err = "cannot re-parse the Configuration";
            return false;
        }
        if (o.config_azimuths >= 0) c.azimuths = static_cast<uint16_t>(o.config_azimuths);
        if (o.config_encoder >= 0) c.encoder_size = static_cast<uint16_t>(o.config_encoder);
        if (o.config_bin_size_m > 0) {
            c.bin_size_100um = static_cast<uint16_t>(o.config_bin_size_m * 10000.0 + 0.5);
            const float f = static_cast<float>(o.config_bin_size_m);
            uint32_t bits = 0;
            std::memcpy(&bits, &f, sizeof bits);
            c.has_range_res = true;
            c.range_res_m_f32 = bits;
        }
        std::vector<uint8_t> out(256);
        const sl_ssize_t k = sl_proto_encode_config(out.data(), out.size(), &c, sl_bytes_t{nullptr, 0});
        if (k <= 0) {
            err = "cannot re-encode the Configuration";
            return false;
        }
        out.resize(static_cast<size_t>(k));
        src.config = out;
    }
    if (o.shuffle > 1) {
        // Fault injection: the transport reorders messages within blocks of `shuffle`
        // (each keeps its own azimuth, sweep counter and timestamp; pacing by position).
        uint64_t x = 0x9E3779B97F4A7C15ULL;
        for (size_t b = 0; b < src.fft.size(); b += o.shuffle) {
            const size_t e = std::min(src.fft.size(), b + o.shuffle);
            for (size_t i = e - 1; i > b; --i) {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                const size_t j = b + static_cast<size_t>(x % (i - b + 1));
                std::swap(src.fft[i].offset, src.fft[j].offset);
                std::swap(src.fft[i].size, src.fft[j].size);
                std::swap(src.fft[i].ts_ns, src.fft[j].ts_ns);
                std::swap(src.fft[i].sweep, src.fft[j].sweep);
            }
        }
    }
    if (src.fft.empty()) {
        err = o.capture + ": no FFT data message in the capture";
        return false;
    }
    const int64_t dt_us = packet_rate > 0 ? 1000000 / packet_rate : 625;
    src.cycle_play_us = src.fft.back().play_us + dt_us;
    src.cycle_ts_ns = std::max<int64_t>(src.fft.back().ts_ns - src.fft.front().ts_ns, 0) + dt_us * 1000;
    src.cycle_sweep = static_cast<uint16_t>(src.fft.back().sweep - src.fft.front().sweep + 1u);
    return true;
}

// Junk patterns injected by --junk-every, cycled: random-looking bytes with a partial
// signature inside, a 12-byte signature prefix, a whole header with version 2 (rejected).
std::vector<uint8_t> junk_pattern(uint64_t k)
{
    switch (k % 3) {
    case 0:
        return {0xA5, 0x5A, 0x00, 0x01, 0x03, 0x99, 0x42};
    case 1:
        return std::vector<uint8_t>(sl_proto_signature, sl_proto_signature + 12);
    default: {
        std::vector<uint8_t> v(sl_proto_signature, sl_proto_signature + SL_PROTO_SIGNATURE_BYTES);
        const uint8_t tail[] = {2, 30, 0, 0, 0, 4, 1, 2, 3, 4};
        v.insert(v.end(), tail, tail + sizeof tail);
        return v;
    }
    }
}

struct Server;

struct Client {
    Server *srv = nullptr;
    int fd = -1;
    uint64_t serial = 0;
    std::string peer;
    sl_proto_t dec{};
    uint8_t reasm[1024] = {};
    std::deque<std::vector<uint8_t>> q;
    size_t q_off = 0;   // bytes of q.front() already sent
    size_t q_bytes = 0; // bytes queued and not yet sent
    bool streaming = false, stalled = false, close_when_drained = false, dead = false;
    bool rst_on_close = false;
    uint64_t next_byte_us = 0; // --trickle-bps: when the next byte may go
    const char *why = "";
    uint64_t cursor = 0; // FFT index over all passes (pass = cursor / N)
    uint64_t anchor_wall_us = 0;
    int64_t anchor_play_us = 0;
    uint64_t next_ka_us = 0;
    uint64_t fft_sent = 0, fft_dropped = 0, ka_sent = 0, ka_skipped = 0, junk_runs = 0, junk_bytes = 0;
    uint64_t bytes_out = 0, starts = 0, stops = 0, config_requests = 0, other_cmds = 0;
};

struct Server {
    const ServeOptions &o;
    Source &src;
    uint64_t resume = 0; // where the next connection starts (set by injected faults)
    uint64_t accepted = 0, refused = 0, closed_by_fault = 0, stalls = 0;
    uint64_t total_fft = 0, total_dropped = 0;
    std::vector<std::unique_ptr<Client>> clients;
    Server(const ServeOptions &opt, Source &s) : o(opt), src(s) {}
};

uint64_t n_fft(const Client &c) { return c.srv->src.fft.size(); }

bool has_more(const Client &c) { return c.srv->o.loop || c.cursor < n_fft(c); }

int64_t play_of(const Client &c, uint64_t cursor)
{
    const Source &s = c.srv->src;
    const uint64_t n = s.fft.size();
    return static_cast<int64_t>(cursor / n) * s.cycle_play_us + s.fft[cursor % n].play_us;
}

uint64_t due_of(const Client &c, uint64_t cursor)
{
    const int64_t d = play_of(c, cursor) - c.anchor_play_us;
    return c.anchor_wall_us + static_cast<uint64_t>(std::max<int64_t>(d, 0));
}

void enqueue(Client &c, std::vector<uint8_t> bytes)
{
    c.q_bytes += bytes.size();
    c.q.push_back(std::move(bytes));
}

// Queue a message, in several writes with --split (the first cut inside the header).
void enqueue_message(Client &c, const uint8_t *p, size_t len, uint64_t k)
{
    const unsigned parts = c.srv->o.split;
    if (parts < 2 || len < 2) {
        enqueue(c, std::vector<uint8_t>(p, p + len));
        return;
    }
    std::vector<size_t> cuts;
    cuts.push_back(std::min<size_t>(1 + (k * 7 + c.serial) % 21, len - 1));
    for (unsigned j = 2; j < parts; ++j) {
        const size_t cut = cuts.back() + (len - cuts.back()) / (parts - j + 1);
        if (cut > cuts.back() && cut < len) {
            cuts.push_back(cut);
        }
    }
    size_t a = 0;
    for (size_t cut : cuts) {
        enqueue(c, std::vector<uint8_t>(p + a, p + cut));
        a = cut;
    }
    enqueue(c, std::vector<uint8_t>(p + a, p + len));
}

void enqueue_config(Client &c)
{
    const auto &cfg = c.srv->src.config;
    enqueue_message(c, cfg.data(), cfg.size(), 0);
}

void enqueue_fft(Client &c)
{
    const Source &s = c.srv->src;
    const uint64_t n = s.fft.size();
    const uint64_t pass = c.cursor / n;
    const FftEntry &e = s.fft[c.cursor % n];
    const uint8_t *p = s.cap.bytes.data() + e.offset;
    if (pass == 0) {
        enqueue_message(c, p, e.size, c.fft_sent);
    } else {
        // --loop: shift the timestamp (little-endian seconds + ns) and the sweep counter.
        std::vector<uint8_t> m(p, p + e.size);
        const int64_t ts = e.ts_ns + static_cast<int64_t>(pass) * s.cycle_ts_ns;
        uint8_t *pl = m.data() + SL_PROTO_HEADER_BYTES;
        put_le32(pl + 6, static_cast<uint32_t>(ts / 1000000000));
        put_le32(pl + 10, static_cast<uint32_t>(ts % 1000000000));
        const uint16_t sw = static_cast<uint16_t>(e.sweep + pass * s.cycle_sweep);
        pl[2] = static_cast<uint8_t>(sw >> 8);
        pl[3] = static_cast<uint8_t>(sw);
        enqueue_message(c, m.data(), m.size(), c.fft_sent);
    }
    ++c.fft_sent;
    ++c.srv->total_fft;
    const ServeOptions &o = c.srv->o;
    if (o.junk_every > 0 && c.fft_sent % o.junk_every == 0) {
        auto j = junk_pattern(c.junk_runs++);
        c.junk_bytes += j.size();
        enqueue(c, std::move(j));
    }
}

void log_client(const Client &c, const char *what)
{
    std::fprintf(stderr,
                 "sl-replay: client %" PRIu64 " %s %s: fft sent %" PRIu64 ", dropped %" PRIu64
                 ", keep-alives %" PRIu64 " (skipped %" PRIu64 "), junk %" PRIu64 " runs/%" PRIu64
                 " bytes, %" PRIu64 " bytes out, starts %" PRIu64 ", stops %" PRIu64 ", position %" PRIu64 "\n",
                 c.serial, c.peer.c_str(), what, c.fft_sent, c.fft_dropped, c.ka_sent, c.ka_skipped,
                 c.junk_runs, c.junk_bytes, c.bytes_out, c.starts, c.stops, c.cursor);
}

void kill_client(Client &c, const char *why)
{
    if (c.dead) {
        return;
    }
    c.dead = true;
    c.why = why;
    if (c.fd >= 0) {
        close(c.fd);
        c.fd = -1;
    }
    log_client(c, why);
}

// Faults injected after each FFT message sent to this connection.
bool check_faults(Client &c)
{
    const ServeOptions &o = c.srv->o;
    if (o.cut_after > 0 && c.fft_sent >= o.cut_after && has_more(c)) {
        // Half of the next message, then the connection ends (FIN or RST); the next
        // connection starts with that message, whole.
        const Source &s = c.srv->src;
        const FftEntry &e = s.fft[c.cursor % n_fft(c)];
        const uint8_t *p = s.cap.bytes.data() + e.offset;
        enqueue(c, std::vector<uint8_t>(p, p + e.size / 2));
        c.close_when_drained = true;
        c.rst_on_close = o.cut_rst;
        c.srv->resume = c.cursor;
        return true;
    }
    if (o.close_after > 0 && c.fft_sent >= o.close_after) {
        c.close_when_drained = true;
        c.srv->resume = c.cursor;
        return true;
    }
    if (o.stall_after > 0 && c.fft_sent >= o.stall_after) {
        c.stalled = true;
        c.srv->resume = c.cursor;
        ++c.srv->stalls;
        std::fprintf(stderr, "sl-replay: client %" PRIu64 " stalled after %" PRIu64 " FFT messages (--stall-after)\n",
                     c.serial, c.fft_sent);
        return true;
    }
    return false;
}

// Queue whatever is due; returns the next time this client needs attention (or UINT64_MAX).
uint64_t produce(Client &c, uint64_t now)
{
    if (c.dead || c.stalled) {
        return UINT64_MAX;
    }
    const ServeOptions &o = c.srv->o;
    uint64_t wake = UINT64_MAX;
    if (o.keepalive_ms > 0 && !c.close_when_drained) {
        if (now >= c.next_ka_us) {
            if (c.q_bytes + SL_PROTO_HEADER_BYTES <= o.queue_bytes) {
                uint8_t ka[SL_PROTO_HEADER_BYTES];
                (void)sl_proto_encode_keep_alive(ka, sizeof ka);
                enqueue(c, std::vector<uint8_t>(ka, ka + sizeof ka));
                ++c.ka_sent;
            } else {
                ++c.ka_skipped;
            }
            c.next_ka_us += static_cast<uint64_t>(o.keepalive_ms) * 1000u;
            if (c.next_ka_us <= now) {
                c.next_ka_us = now + static_cast<uint64_t>(o.keepalive_ms) * 1000u;
            }
        }
        wake = c.next_ka_us;
    }
    if (!c.streaming || c.close_when_drained || o.keepalive_only) {
        return wake;
    }
    if (o.realtime) {
        while (has_more(c) && due_of(c, c.cursor) <= now) {
            const FftEntry &e = c.srv->src.fft[c.cursor % n_fft(c)];
            if (c.q_bytes + e.size > o.queue_bytes) {
                ++c.fft_dropped;
                ++c.srv->total_dropped;
                ++c.cursor;
                continue;
            }
            enqueue_fft(c);
            ++c.cursor;
            if (check_faults(c)) {
                return c.stalled ? UINT64_MAX : wake;
            }
        }
        if (has_more(c)) {
            wake = std::min(wake, due_of(c, c.cursor));
        }
    } else {
        int budget = 64; // then let poll() serve the others
        while (has_more(c) && c.q_bytes < o.queue_bytes && budget-- > 0) {
            enqueue_fft(c);
            ++c.cursor;
            if (check_faults(c)) {
                return c.stalled ? UINT64_MAX : wake;
            }
        }
        if (has_more(c) && c.q_bytes < o.queue_bytes) {
            wake = now; // more to do at once; when the queue is full, POLLOUT wakes us
        }
    }
    return wake;
}

void flush(Client &c)
{
    const uint32_t bps = c.srv->o.trickle_bps;
    while (!c.dead && !c.q.empty()) {
        const auto &front = c.q.front();
        size_t len = front.size() - c.q_off;
        if (bps > 0) {
            // --trickle-bps: one byte at a time, at most bps per second.
            const uint64_t now = sl_port_now_us();
            if (now < c.next_byte_us) {
                return;
            }
            c.next_byte_us = now + 1000000u / bps;
            len = 1;
        }
        const ssize_t n = send(c.fd, front.data() + c.q_off, len, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n < 0) {
            if (errno == EINTR) {
                continue;
            }
            if (errno == EAGAIN || errno == EWOULDBLOCK) {
                return;
            }
            kill_client(c, "send error");
            return;
        }
        c.q_off += static_cast<size_t>(n);
        c.q_bytes -= static_cast<size_t>(n);
        c.bytes_out += static_cast<uint64_t>(n);
        if (c.q_off == front.size()) {
            c.q.pop_front();
            c.q_off = 0;
        }
    }
    if (!c.dead && c.q.empty() && c.close_when_drained) {
        ++c.srv->closed_by_fault;
        if (c.rst_on_close) {
            const linger lg{1, 0}; // close() sends a RST
            setsockopt(c.fd, SOL_SOCKET, SO_LINGER, &lg, sizeof lg);
            kill_client(c, "reset (--rst-after)");
        } else {
            shutdown(c.fd, SHUT_RDWR);
            kill_client(c, "closed (--close-after / --cut-after)");
        }
    }
}

void on_command(void *ctx, const sl_proto_msg_t *m)
{
    Client &c = *static_cast<Client *>(ctx);
    if (c.dead || c.stalled) {
        return;
    }
    const uint64_t now = sl_port_now_us();
    switch (m->id) {
    case SL_PROTO_ID_START_FFT:
    case SL_PROTO_ID_START_NONCONTOUR_FFT:
        ++c.starts;
        if (!c.streaming) {
            c.streaming = true;
            c.anchor_wall_us = now;
            c.anchor_play_us = has_more(c) ? play_of(c, c.cursor) : 0;
        }
        break;
    case SL_PROTO_ID_STOP_FFT:
        ++c.stops;
        c.streaming = false;
        break;
    case SL_PROTO_ID_CONFIG_REQUEST:
        ++c.config_requests;
        enqueue_config(c);
        break;
    default:
        ++c.other_cmds;
        break;
    }
}

void read_client(Client &c)
{
    uint8_t buf[4096];
    for (;;) {
        const ssize_t n = recv(c.fd, buf, sizeof buf, MSG_DONTWAIT);
        if (n > 0) {
            sl_proto_feed(&c.dec, buf, static_cast<size_t>(n), 0);
            if (c.dead) {
                return;
            }
            continue;
        }
        if (n == 0) {
            kill_client(c, "disconnected");
            return;
        }
        if (errno == EINTR) {
            continue;
        }
        if (errno != EAGAIN && errno != EWOULDBLOCK) {
            kill_client(c, "receive error");
        }
        return;
    }
}

std::string peer_name(const sockaddr_storage &ss)
{
    char host[NI_MAXHOST] = "?", serv[NI_MAXSERV] = "?";
    getnameinfo(reinterpret_cast<const sockaddr *>(&ss), sizeof ss, host, sizeof host, serv, sizeof serv,
                NI_NUMERICHOST | NI_NUMERICSERV);
    return std::string(host) + ":" + serv;
}

void accept_all(Server &s, int lfd, uint64_t now)
{
    for (;;) {
        sockaddr_storage ss{};
        socklen_t sl = sizeof ss;
        const int fd = accept4(lfd, reinterpret_cast<sockaddr *>(&ss), &sl, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0) {
            if (errno == EINTR) {
                continue;
            }
            return; // EAGAIN, or a transient error (EMFILE, ECONNABORTED, ...)
        }
        size_t live = 0;
        for (const auto &c : s.clients) {
            live += c->dead ? 0 : 1;
        }
        if (live >= s.o.max_clients) {
            ++s.refused;
            std::fprintf(stderr, "sl-replay: refused %s (%zu clients already)\n", peer_name(ss).c_str(), live);
            close(fd);
            continue;
        }
        const int one = 1;
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        auto c = std::make_unique<Client>();
        c->srv = &s;
        c->fd = fd;
        c->serial = ++s.accepted;
        c->peer = peer_name(ss);
        c->cursor = s.resume;
        c->next_ka_us = now + static_cast<uint64_t>(s.o.keepalive_ms) * 1000u;
        sl_proto_cfg_t pc{};
        pc.reasm_buf = c->reasm;
        pc.reasm_size = sizeof c->reasm;
        pc.on_msg = on_command;
        pc.ctx = c.get();
        sl_proto_init(&c->dec, &pc);
        if (s.o.verbose) {
            std::fprintf(stderr, "sl-replay: client %" PRIu64 " %s connected, starting at FFT message %" PRIu64 "\n",
                         c->serial, c->peer.c_str(), c->cursor);
        }
        enqueue_config(*c);
        flush(*c);
        s.clients.push_back(std::move(c));
    }
}

int open_listener(const ServeOptions &o, std::string &bound, std::string &err)
{
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_PASSIVE | AI_NUMERICHOST | AI_NUMERICSERV;
    addrinfo *res = nullptr;
    const std::string port = std::to_string(o.port);
    const int rc = getaddrinfo(o.bind.c_str(), port.c_str(), &hints, &res);
    if (rc != 0 || res == nullptr) {
        err = "bad bind address '" + o.bind + "': " + gai_strerror(rc);
        return -1;
    }
    const int fd = socket(res->ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        err = std::string("socket: ") + std::strerror(errno);
        freeaddrinfo(res);
        return -1;
    }
    const int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (bind(fd, res->ai_addr, res->ai_addrlen) < 0 || listen(fd, 16) < 0) {
        err = "bind/listen " + o.bind + ":" + port + ": " + std::strerror(errno);
        close(fd);
        freeaddrinfo(res);
        return -1;
    }
    freeaddrinfo(res);
    sockaddr_storage ss{};
    socklen_t sl = sizeof ss;
    getsockname(fd, reinterpret_cast<sockaddr *>(&ss), &sl);
    bound = peer_name(ss);
    return fd;
}

} // namespace

int serve(const ServeOptions &o)
{
    Source src;
    std::string err;
    if (!load_source(o, src, err)) {
        std::fprintf(stderr, "sl-replay serve: %s\n", err.c_str());
        return 1;
    }
    std::string bound;
    const int lfd = open_listener(o, bound, err);
    if (lfd < 0) {
        std::fprintf(stderr, "sl-replay serve: %s\n", err.c_str());
        return 1;
    }
    std::fprintf(stderr,
                 "sl-replay: %s: %zu FFT messages, %.3f s per pass, %" PRIu64 " other messages not replayed\n",
                 o.capture.c_str(), src.fft.size(), static_cast<double>(src.cycle_play_us) * 1e-6,
                 src.not_replayed);
    std::printf("sl-replay: listening on %s\n", bound.c_str());
    std::fflush(stdout);

    Server s(o, src);
    const uint64_t t_start = sl_port_now_us();
    const uint64_t t_end = o.timeout_s > 0 ? t_start + static_cast<uint64_t>(o.timeout_s * 1e6) : UINT64_MAX;
    const char *exit_why = "signal";
    std::vector<pollfd> pfds;
    while (!g_stop) {
        uint64_t now = sl_port_now_us();
        if (now >= t_end) {
            exit_why = "--timeout";
            break;
        }
        uint64_t wake = t_end;
        for (auto &c : s.clients) {
            wake = std::min(wake, produce(*c, now));
            flush(*c);
            if (o.trickle_bps > 0 && !c->q.empty()) {
                wake = std::min(wake, c->next_byte_us);
            }
        }
        // Forget closed clients.
        for (size_t i = 0; i < s.clients.size();) {
            if (s.clients[i]->dead) {
                s.clients.erase(s.clients.begin() + static_cast<long>(i));
            } else {
                ++i;
            }
        }
        pfds.clear();
        pfds.push_back({lfd, POLLIN, 0});
        for (auto &c : s.clients) {
            short ev = POLLIN;
            if (!c->q.empty() && o.trickle_bps == 0) {
                ev = static_cast<short>(ev | POLLOUT);
            }
            pfds.push_back({c->fd, ev, 0});
        }
        int timeout = -1;
        if (wake != UINT64_MAX) {
            now = sl_port_now_us();
            timeout = wake <= now ? 0 : static_cast<int>(std::min<uint64_t>((wake - now + 999) / 1000, 60000));
        }
        const int rc = poll(pfds.data(), pfds.size(), timeout);
        if (rc < 0) {
            if (errno == EINTR) {
                continue;
            }
            std::fprintf(stderr, "sl-replay serve: poll: %s\n", std::strerror(errno));
            break;
        }
        if (rc == 0) {
            continue;
        }
        // pfds[1..] correspond to s.clients in order (no client was added since).
        const size_t nclients = s.clients.size();
        for (size_t i = 0; i < nclients; ++i) {
            Client &c = *s.clients[i];
            const short re = pfds[i + 1].revents;
            if (re == 0 || c.dead) {
                continue;
            }
            if (re & (POLLIN | POLLHUP | POLLERR)) {
                read_client(c);
            }
            if (!c.dead && (re & POLLOUT)) {
                flush(c);
            }
        }
        if (pfds[0].revents & POLLIN) {
            accept_all(s, lfd, sl_port_now_us());
        }
    }
    for (auto &c : s.clients) {
        kill_client(*c, "closed at exit");
    }
    close(lfd);
    std::fprintf(stderr,
                 "sl-replay: exit (%s): %" PRIu64 " connections accepted, %" PRIu64 " refused, %" PRIu64
                 " closed by --close-after, %" PRIu64 " stalled, %" PRIu64 " FFT messages sent, %" PRIu64
                 " dropped\n",
                 exit_why, s.accepted, s.refused, s.closed_by_fault, s.stalls, s.total_fft, s.total_dropped);
    return 0;
}

} // namespace sl::replay
