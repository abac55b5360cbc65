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
//
// The capture is streamed, never loaded (capture.h MessageReader): each connection reads its
// own pass over a regular file (--loop reopens it; --close-after etc. resume by skipping),
// so memory is bounded whatever the capture's size. A pipe, FIFO or "-" can be read once:
// one connection at a time plays it, the next continues where the last one stopped, and
// --loop is refused.
#include "replay.h"

#include "capture.h"

#include "shadowlean/sl_proto.h"

#include "port_clock.h"

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
#include <csignal>
#include <ctime>
#include <sys/ioctl.h>
#include <linux/sockios.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace sl::replay {

namespace {

struct FftEntry {
    std::vector<uint8_t> msg; // the whole message (header + payload), as captured
    int64_t ts_ns = 0;   // capture timestamp
    uint16_t sweep = 0;
    int64_t play_us = 0; // playback time since the pass's first FFT message (gaps clamped)
    uint64_t pass = 0;   // --loop: which pass over the capture
};

void put_le32(uint8_t *p, uint32_t v)
{
    p[0] = static_cast<uint8_t>(v);
    p[1] = static_cast<uint8_t>(v >> 8);
    p[2] = static_cast<uint8_t>(v >> 16);
    p[3] = static_cast<uint8_t>(v >> 24);
}

// One pass over the capture, message by message (capture.h MessageReader: bounded memory).
using Pass = sl::MessageReader;

// What every connection shares: the Configuration served, the pacing step.
struct Source {
    std::string path;
    bool regular = true;       // a regular file: each connection reads its own pass
    std::vector<uint8_t> config;
    int64_t dt_us = 625;       // one FFT message at the Configuration's packet rate
};

// The FFT messages one connection plays: passes over the capture (--loop: again and again,
// timestamps and sweep counters shifted per pass), paced by their timestamps, permuted in
// blocks by --shuffle. Holds one block (or one message) ahead of what was sent.
struct Player {
    const ServeOptions *o = nullptr;
    const Source *src = nullptr;
    std::unique_ptr<Pass> pass;
    uint64_t pass_no = 0;
    std::deque<FftEntry> ahead;
    bool pass_started = false;
    int64_t prev_ts_ns = 0, prev_play_us = 0;
    // The first pass measured (for --loop): its length, timestamp span, sweep span.
    bool cycle_known = false;
    int64_t cycle_play_us = 0, cycle_ts_ns = 0;
    uint16_t cycle_sweep = 0;
    FftEntry first, last;      // of the current pass (as sent: after --shuffle)
    uint64_t pass_fft = 0, not_replayed = 0, passes_done = 0;
    bool ended = false;        // no more messages (end without --loop, or an error)
    std::string err;

    bool open_pass(std::string &e)
    {
        pass = std::make_unique<Pass>();
        pass_started = false;
        pass_fft = 0;
        return pass->open(src->path, e);
    }

    // Reads the next FFT message of the pass (others counted); false at the end of the pass.
    bool read_fft(FftEntry &e)
    {
        uint8_t id = 0;
        std::vector<uint8_t> m;
        while (pass->next(id, m)) {
            if (id == SL_PROTO_ID_CONFIGURATION) {
                continue;
            }
            if (id != SL_PROTO_ID_FFT_DATA && id != SL_PROTO_ID_FFT_DATA_16) {
                ++not_replayed;
                continue;
            }
            sl_proto_msg_t pm{};
            pm.id = id;
            pm.payload.data = m.data() + SL_PROTO_HEADER_BYTES;
            pm.payload.size = m.size() - SL_PROTO_HEADER_BYTES;
            sl_proto_fft_t f{};
            if (sl_proto_parse_fft(&pm, &f) != SL_OK) {
                ++not_replayed;
                continue;
            }
            e.ts_ns = static_cast<int64_t>(f.seconds) * 1000000000 + f.split_ns;
            e.sweep = f.sweep_counter;
            e.play_us = 0;
            if (pass_started) {
                int64_t d_us = (e.ts_ns - prev_ts_ns) / 1000;
                d_us = std::max<int64_t>(0, std::min<int64_t>(d_us, static_cast<int64_t>(o->max_gap_ms) * 1000));
                e.play_us = prev_play_us + d_us;
            }
            pass_started = true;
            prev_ts_ns = e.ts_ns;
            prev_play_us = e.play_us;
            e.pass = pass_no;
            e.msg = std::move(m);
            return true;
        }
        if (!pass->error().empty()) {
            err = pass->error();
        }
        return false;
    }

    // Fills `ahead` with the next block; handles the end of a pass.
    void refill()
    {
        while (ahead.empty() && !ended) {
            const size_t block = o->shuffle > 1 ? o->shuffle : 1;
            std::vector<FftEntry> b;
            FftEntry e;
            while (b.size() < block && read_fft(e)) {
                b.push_back(std::move(e));
                e = FftEntry{};
            }
            if (o->shuffle > 1 && b.size() > 1) {
                // Fault injection: the transport reorders messages within blocks of
                // `shuffle` (each keeps its own azimuth, sweep counter and timestamp; pacing
                // by position). Fixed seed per pass: every pass is permuted alike.
                for (size_t i = b.size() - 1; i > 0; --i) {
                    shuffle_x ^= shuffle_x << 13;
                    shuffle_x ^= shuffle_x >> 7;
                    shuffle_x ^= shuffle_x << 17;
                    const size_t j = static_cast<size_t>(shuffle_x % (i + 1));
                    std::swap(b[i].msg, b[j].msg);
                    std::swap(b[i].ts_ns, b[j].ts_ns);
                    std::swap(b[i].sweep, b[j].sweep);
                }
            }
            for (auto &x : b) {
                if (pass_fft == 0) {
                    first = x;
                    first.msg.clear();
                }
                last = x;
                last.msg.clear();
                ++pass_fft;
                ahead.push_back(std::move(x));
            }
            if (b.size() == block) {
                continue;
            }
            // The end of the pass.
            if (!err.empty() || pass_fft == 0) {
                if (pass_fft == 0 && err.empty() && passes_done == 0) {
                    err = src->path + ": no FFT data message in the capture";
                }
                ended = ahead.empty();
                if (!ahead.empty()) {
                    return; // send what was read first
                }
                break;
            }
            if (!cycle_known) {
                cycle_known = true;
                cycle_play_us = last.play_us + src->dt_us;
                cycle_ts_ns = std::max<int64_t>(last.ts_ns - first.ts_ns, 0) + src->dt_us * 1000;
                cycle_sweep = static_cast<uint16_t>(last.sweep - first.sweep + 1u);
            }
            ++passes_done;
            if (o->verbose || passes_done == 1) {
                std::fprintf(stderr,
                             "sl-replay: %s: pass %" PRIu64 ": %" PRIu64 " FFT messages, %.3f s, %" PRIu64
                             " other messages not replayed\n",
                             src->path.c_str(), pass_no, pass_fft, static_cast<double>(cycle_play_us) * 1e-6,
                             not_replayed);
            }
            if (!o->loop || !src->regular) {
                if (ahead.empty()) {
                    ended = true;
                }
                return;
            }
            ++pass_no;
            shuffle_x = kShuffleSeed;
            std::string e2;
            if (!open_pass(e2)) {
                err = e2;
                ended = ahead.empty();
                return;
            }
            if (!ahead.empty()) {
                return;
            }
        }
    }

    const FftEntry *peek()
    {
        refill();
        return ahead.empty() ? nullptr : &ahead.front();
    }

    void pop()
    {
        if (!ahead.empty()) {
            ahead.pop_front();
            ++popped;
        }
    }

    uint64_t popped = 0; // FFT messages taken, over all passes

    static constexpr uint64_t kShuffleSeed = 0x9E3779B97F4A7C15ULL;
    uint64_t shuffle_x = kShuffleSeed;
};

// Opens a connection's player at FFT message `skip` (a previous connection's fault position).
bool open_player(const ServeOptions &o, const Source &src, Player &pl, uint64_t skip, std::string &err)
{
    pl.o = &o;
    pl.src = &src;
    if (!pl.open_pass(err)) {
        return false;
    }
    for (uint64_t i = 0; i < skip && pl.peek() != nullptr; ++i) {
        pl.pop();
    }
    return true;
}

// Finds the first Configuration (rewritten by the --config-* faults) and checks that the
// capture holds FFT data, streaming only as far as needed. A pipe or FIFO can be read once:
// its pass is kept in `shared` for the first connection (and those that resume after it).
bool load_source(const ServeOptions &o, Source &src, std::unique_ptr<Player> &shared, std::string &err)
{
    src.path = o.capture;
    struct stat st {};
    src.regular = o.capture != "-" && ::stat(o.capture.c_str(), &st) == 0 && S_ISREG(st.st_mode);
    if (!src.regular && o.loop) {
        err = o.capture + ": --loop needs a regular file (a pipe or FIFO can be read only once)";
        return false;
    }
    uint32_t packet_rate = 0;
    {
        // Up to the first valid Configuration; for a pipe the pass continues in `shared`.
        auto probe = std::make_unique<Pass>();
        if (!probe->open(o.capture, err)) {
            return false;
        }
        uint8_t id = 0;
        std::vector<uint8_t> m;
        uint64_t seen = 0;
        while (src.config.empty() && probe->next(id, m)) {
            if (id == SL_PROTO_ID_CONFIGURATION) {
                sl_proto_msg_t pm{};
                pm.id = id;
                pm.payload.data = m.data() + SL_PROTO_HEADER_BYTES;
                pm.payload.size = m.size() - SL_PROTO_HEADER_BYTES;
                sl_proto_config_t c{};
                if (sl_proto_parse_config(&pm, &c) == SL_OK) {
                    src.config = m;
                    packet_rate = c.packet_rate;
                }
            } else if (!src.regular && ++seen > 4096) {
                err = o.capture + ": no valid Configuration message (id 10) in the first 4096 messages of the stream";
                return false;
            }
        }
        if (src.config.empty()) {
            err = probe->error().empty() ? o.capture + ": no valid Configuration message (id 10) in the capture"
                                         : probe->error();
            return false;
        }
        if (!src.regular) {
            // FFT messages before the Configuration of a pipe are not replayed (a radar
            // sends its Configuration first).
            shared = std::make_unique<Player>();
            shared->o = &o;
            shared->src = &src;
            shared->pass = std::move(probe);
        }
    }
    src.dt_us = packet_rate > 0 ? 1000000 / packet_rate : 625;
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
    // FFT data must follow: a regular file is checked now (one message read).
    if (src.regular) {
        Player check;
        if (!open_player(o, src, check, 0, err)) {
            return false;
        }
        if (check.peek() == nullptr) {
            err = check.err.empty() ? o.capture + ": no FFT data message in the capture" : check.err;
            return false;
        }
    } else if (shared->peek() == nullptr) {
        err = shared->err.empty() ? o.capture + ": no FFT data message in the capture" : shared->err;
        return false;
    }
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
    uint64_t rst_deadline_us = 0; // --rst-after: RST at the latest then, acknowledged or not
    uint64_t next_byte_us = 0; // --trickle-bps: when the next byte may go
    const char *why = "";
    Player *pl = nullptr;            // the messages this connection plays (nullptr: none)
    std::unique_ptr<Player> own;     // a regular file: its own pass over the capture
    uint64_t cursor = 0; // FFT messages played or dropped, over all passes
    uint64_t anchor_wall_us = 0;
    int64_t anchor_play_us = 0;
    uint64_t next_ka_us = 0;
    uint64_t fft_sent = 0, fft_dropped = 0, ka_sent = 0, ka_skipped = 0, junk_runs = 0, junk_bytes = 0;
    uint64_t bytes_out = 0, starts = 0, stops = 0, config_requests = 0, other_cmds = 0;
};

struct Server {
    const ServeOptions &o;
    Source &src;
    std::unique_ptr<Player> shared; // a pipe or FIFO: its one pass, played by one connection at a time
    const Client *shared_owner = nullptr;
    uint64_t resume = 0; // where the next connection starts (set by injected faults)
    uint64_t accepted = 0, refused = 0, closed_by_fault = 0, stalls = 0;
    uint64_t total_fft = 0, total_dropped = 0;
    std::vector<std::unique_ptr<Client>> clients;
    Server(const ServeOptions &opt, Source &s) : o(opt), src(s) {}
};

bool has_more(const Client &c) { return c.pl != nullptr && c.pl->peek() != nullptr; }

// Playback time of the next FFT message (has_more must hold).
int64_t play_of_next(const Client &c)
{
    const FftEntry *e = c.pl->peek();
    return static_cast<int64_t>(e->pass) * c.pl->cycle_play_us + e->play_us;
}

uint64_t due_of_next(const Client &c)
{
    const int64_t d = play_of_next(c) - c.anchor_play_us;
    return c.anchor_wall_us + static_cast<uint64_t>(std::max<int64_t>(d, 0));
}

// The next FFT message is done with (sent or dropped).
void advance(Client &c)
{
    c.pl->pop();
    ++c.cursor;
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
    const Player &pr = *c.pl;
    const FftEntry &e = *c.pl->peek();
    const uint64_t pass = e.pass;
    if (pass == 0) {
        enqueue_message(c, e.msg.data(), e.msg.size(), c.fft_sent);
    } else {
        // --loop: shift the timestamp (little-endian seconds + ns) and the sweep counter.
        std::vector<uint8_t> m = e.msg;
        const int64_t ts = e.ts_ns + static_cast<int64_t>(pass) * pr.cycle_ts_ns;
        uint8_t *pl = m.data() + SL_PROTO_HEADER_BYTES;
        put_le32(pl + 6, static_cast<uint32_t>(ts / 1000000000));
        put_le32(pl + 10, static_cast<uint32_t>(ts % 1000000000));
        const uint16_t sw = static_cast<uint16_t>(e.sweep + pass * pr.cycle_sweep);
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
    if (c.srv->shared_owner == &c) {
        c.srv->shared_owner = nullptr; // the next connection continues the pipe's pass
    }
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
        const FftEntry &e = *c.pl->peek();
        enqueue(c, std::vector<uint8_t>(e.msg.begin(), e.msg.begin() + static_cast<long>(e.msg.size() / 2)));
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
        while (has_more(c) && due_of_next(c) <= now) {
            const FftEntry &e = *c.pl->peek();
            if (c.q_bytes + e.msg.size() > o.queue_bytes) {
                ++c.fft_dropped;
                ++c.srv->total_dropped;
                advance(c);
                continue;
            }
            enqueue_fft(c);
            advance(c);
            if (check_faults(c)) {
                return c.stalled ? UINT64_MAX : wake;
            }
        }
        if (has_more(c)) {
            wake = std::min(wake, due_of_next(c));
        }
    } else {
        int budget = 64; // then let poll() serve the others
        while (has_more(c) && c.q_bytes < o.queue_bytes && budget-- > 0) {
            enqueue_fft(c);
            advance(c);
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

// --rst-after: a RST makes the sending kernel discard what it has not yet sent, so a
// receiver slower than the sender (a loaded machine) would lose the messages before the cut
// one, which the next connection does not resend. The RST therefore waits until the peer's
// kernel has acknowledged every byte (SIOCOUTQ 0): what the radar sent before the reset is
// readable by the client, as the fault means. A peer that never reads gets its RST after
// RST_WAIT_US all the same.
constexpr uint64_t RST_POLL_US = 5000;
constexpr uint64_t RST_WAIT_US = 10000000;

bool peer_has_all(Client &c)
{
    const uint64_t now = slp_now_us();
    if (c.rst_deadline_us == 0) {
        c.rst_deadline_us = now + RST_WAIT_US;
    }
    int unacked = 0;
    if (ioctl(c.fd, SIOCOUTQ, &unacked) != 0) {
        return true; // not a TCP socket we can ask: reset now
    }
    if (unacked > 0 && now < c.rst_deadline_us) {
        return false;
    }
    if (unacked > 0) {
        std::fprintf(stderr, "sl-replay: client %" PRIu64 " did not read its last %d bytes in %u s: reset anyway\n",
                     c.serial, unacked, static_cast<unsigned>(RST_WAIT_US / 1000000u));
    }
    return true;
}

void flush(Client &c)
{
    const uint32_t bps = c.srv->o.trickle_bps;
    while (!c.dead && !c.q.empty()) {
        const auto &front = c.q.front();
        size_t len = front.size() - c.q_off;
        if (bps > 0) {
            // --trickle-bps: one byte at a time, at most bps per second.
            const uint64_t now = slp_now_us();
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
        if (c.rst_on_close && !peer_has_all(c)) {
            return; // the main loop looks again in RST_POLL_US
        }
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
    const uint64_t now = slp_now_us();
    switch (m->id) {
    case SL_PROTO_ID_START_FFT:
    case SL_PROTO_ID_START_NONCONTOUR_FFT:
        ++c.starts;
        if (!c.streaming) {
            c.streaming = true;
            c.anchor_wall_us = now;
            c.anchor_play_us = has_more(c) ? play_of_next(c) : 0;
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
        if (s.src.regular) {
            std::string err;
            c->own = std::make_unique<Player>();
            if (open_player(s.o, s.src, *c->own, s.resume, err)) {
                c->pl = c->own.get();
            } else {
                std::fprintf(stderr, "sl-replay: client %" PRIu64 ": %s (no FFT data for it)\n", c->serial, err.c_str());
            }
        } else if (s.shared_owner == nullptr) {
            c->pl = s.shared.get();
            s.shared_owner = c.get();
            c->cursor = s.shared->popped;
        } else {
            std::fprintf(stderr, "sl-replay: client %" PRIu64 ": the input is a pipe, played by client %" PRIu64
                         " already: this connection gets the Configuration and keep-alives only\n",
                         c->serial, s.shared_owner->serial);
        }
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
    std::unique_ptr<Player> shared;
    if (!load_source(o, src, shared, err)) {
        std::fprintf(stderr, "sl-replay serve: %s\n", err.c_str());
        return 1;
    }
    std::string bound;
    const int lfd = open_listener(o, bound, err);
    if (lfd < 0) {
        std::fprintf(stderr, "sl-replay serve: %s\n", err.c_str());
        return 1;
    }
    std::fprintf(stderr, "sl-replay: %s: streamed (%s), Configuration found, FFT data follows\n",
                 o.capture.c_str(), src.regular ? "each connection reads its own pass" : "a pipe: read once");
    std::printf("sl-replay: listening on %s\n", bound.c_str());
    std::fflush(stdout);

    Server s(o, src);
    s.shared = std::move(shared);
    const uint64_t t_start = slp_now_us();
    const uint64_t t_end = o.timeout_s > 0 ? t_start + static_cast<uint64_t>(o.timeout_s * 1e6) : UINT64_MAX;
    const char *exit_why = "signal";
    std::vector<pollfd> pfds;
    // SIGINT / SIGTERM are blocked except inside ppoll(): a signal that arrives between the
    // g_stop test and the wait is delivered when the wait starts (EINTR) instead of being
    // lost until the next wake-up (none without clients or --timeout: the server hung).
    sigset_t stop_sigs, wait_mask;
    sigemptyset(&stop_sigs);
    sigaddset(&stop_sigs, SIGINT);
    sigaddset(&stop_sigs, SIGTERM);
    sigprocmask(SIG_BLOCK, &stop_sigs, &wait_mask);
    sigdelset(&wait_mask, SIGINT);
    sigdelset(&wait_mask, SIGTERM);
    while (!g_stop) {
        uint64_t now = slp_now_us();
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
            if (!c->dead && c->rst_on_close && c->close_when_drained && c->q.empty()) {
                wake = std::min(wake, now + RST_POLL_US); // waiting for the peer's acknowledgement
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
            now = slp_now_us();
            timeout = wake <= now ? 0 : static_cast<int>(std::min<uint64_t>((wake - now + 999) / 1000, 60000));
        }
        timespec ts{};
        ts.tv_sec = timeout / 1000;
        ts.tv_nsec = static_cast<long>(timeout % 1000) * 1000000L;
        const int rc = ppoll(pfds.data(), pfds.size(), timeout < 0 ? nullptr : &ts, &wait_mask);
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
            accept_all(s, lfd, slp_now_us());
        }
    }
    sigprocmask(SIG_UNBLOCK, &stop_sigs, nullptr);
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
