// SPDX-License-Identifier: MIT
// vcan_sink_check: the SocketCAN sink on a real kernel CAN stack (run inside user-mode
// Linux by uml_sink_guest.sh, as root, with vcan0 up, sch_plug loaded and `candump -L any`
// recording).
//
//   vcan_sink_check --out DIR [--iface vcan0] [--n 500] [--board paper-sim]
//
// Writes DIR/produced_a.log (phase A: every frame handed to the sinks, through the candump
// log sink) and DIR/sent.log (every frame the SocketCAN sink reports as written, all
// phases, through its on_sent hook). The host then checks that candump's recording equals
// sent.log, and that its first N frames equal produced_a.log (uml_sink_compare.py).
//
// Phases (a synthetic clock drives the sink; only the sink's own logic uses it):
//  A  N core-encoded frames (+ 29-bit, empty and RTR frames) to both sinks: all sent.
//  B  interface down mid-stream: drops counted (ENETDOWN), recovery when it is up again.
//  C  full interface queue (sch_plug, limit 10 frames): ENOBUFS -> bounded retry queue,
//     tail drops when it is full, the queue drains in order after the release.
//  E  queued frames older than max_age_us are dropped, not sent.
//  D  full socket send buffer (SO_SNDBUF minimum + plugged qdisc): EAGAIN -> retry queue.
//  F  error frames injected on vcan0: bus-off drops, restart, hold timeout, error passive.
//  G  interface deleted and re-created: ENODEV/ENXIO -> reopen after reopen_interval_us.
// Exit status 0 when every CHECK holds.
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <string>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include "can_sink.h"
#include "socketcan.h"
#include "candump_log.h"
#include "sl_board_spec.h"
#include "sl_dbc.h"
#include "shadowlean/sl_can.h"
#include "check.hpp"

namespace {

using sl_test::failures;

uint64_t now_us = 1000000000000ULL; // synthetic clock
uint64_t tick(uint64_t dt = 1000)
{
    now_us += dt;
    return now_us;
}

void sh(const std::string &cmd)
{
    const int rc = std::system(cmd.c_str());
    if (rc != 0) {
        std::cerr << "command failed (" << rc << "): " << cmd << "\n";
        failures++;
    }
}

void on_sent(void *user, const sl_can_frame_t *f, uint64_t t_us)
{
    static_cast<sl::CandumpWriter *>(user)->write(*f, t_us);
}

void print_stats(const char *phase, const slp_socketcan_t &s)
{
    const slp_socketcan_stats_t &st = s.stats;
    std::printf("[%s] sent %u retries %u (eagain %u enobufs %u) dropped: full %u stale %u down %u "
                "bus_off %u error %u | link down %u up %u reopens %u | error frames %u bus_off %u "
                "timeouts %u restarts %u passive %u | queued %u\n",
                phase, st.sent, st.retries, st.eagain, st.enobufs, st.dropped_full,
                st.dropped_stale, st.dropped_down, st.dropped_bus_off, st.dropped_error,
                st.link_down, st.link_up, st.reopens, st.error_frames, st.bus_off,
                st.bus_off_timeouts, st.restarts, st.error_passive, unsigned(s.q_len));
}

// Frames for phase A: the core's encoders with random contents, plus other shapes.
struct Gen {
    sl_can_tx_t tx;
    std::mt19937_64 rng{42};
    int64_t uni(int64_t lo, int64_t hi) { return std::uniform_int_distribution<int64_t>(lo, hi)(rng); }
    sl_can_frame_t next(long i)
    {
        sl_can_frame_t f{};
        switch (i % 10) {
        case 0: {
            sl_can_status_t s{};
            s.link_state = static_cast<uint8_t>(uni(0, 4));
            s.rotations = static_cast<uint32_t>(i);
            sl_can_encode_status(&tx, &s, &f);
            break;
        }
        case 1: {
            sl_can_lean_warning_t w{};
            w.level = static_cast<uint8_t>(uni(0, 2));
            w.has_target = true;
            w.lean_cdeg = static_cast<int32_t>(uni(-3000, 3000));
            w.range_um = static_cast<uint32_t>(uni(1000000, 6000000));
            sl_can_encode_lean_warning(&tx, &w, &f);
            break;
        }
        case 2: // 29-bit, DLC 0..8
            f.id = 0x18FF0000U | static_cast<uint32_t>(i & 0xFFFF);
            f.flags = SL_CAN_FLAG_EFF;
            f.dlc = static_cast<uint8_t>(i % 9);
            for (unsigned k = 0; k < f.dlc; k++) {
                f.data[k] = static_cast<uint8_t>(uni(0, 255));
            }
            break;
        case 3: // RTR
            f.id = 0x123;
            f.flags = SL_CAN_FLAG_RTR;
            f.dlc = static_cast<uint8_t>(i % 9);
            break;
        default: {
            sl_can_pole_lean_t p{};
            p.target_id = static_cast<uint8_t>(uni(0, 15));
            p.quality = static_cast<uint8_t>(uni(0, 4));
            p.azimuth_cdeg = static_cast<int32_t>(uni(0, 35999));
            p.lean_cdeg = static_cast<int32_t>(uni(-4000, 4000));
            p.lean_sigma_cdeg = static_cast<uint32_t>(uni(0, 600));
            p.range_inner_um = static_cast<uint32_t>(uni(1500000, 6000000));
            p.range_outer_um = p.range_inner_um + static_cast<uint32_t>(uni(100000, 3000000));
            sl_can_encode_pole_lean(&tx, &p, &f);
            break;
        }
        }
        return f;
    }
};

// A plain raw socket that injects error frames on the interface (what a CAN driver would
// report), so the sink's error-frame handling runs against the real kernel path.
struct Injector {
    int fd = -1;
    bool open(const char *ifname)
    {
        fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
        if (fd < 0) {
            return false;
        }
        struct sockaddr_can a{};
        a.can_family = AF_CAN;
        a.can_ifindex = static_cast<int>(if_nametoindex(ifname));
        return bind(fd, reinterpret_cast<struct sockaddr *>(&a), sizeof a) == 0;
    }
    bool error_frame(canid_t cls, uint8_t d1 = 0)
    {
        struct can_frame cf{};
        cf.can_id = CAN_ERR_FLAG | cls;
        cf.len = CAN_ERR_DLC;
        cf.data[1] = d1;
        const ssize_t n = write(fd, &cf, sizeof cf);
        if (n != static_cast<ssize_t>(sizeof cf)) {
            std::cerr << "error frame injection failed: " << std::strerror(errno) << "\n";
            return false;
        }
        return true;
    }
    ~Injector()
    {
        if (fd >= 0) {
            close(fd);
        }
    }
};

// Poll until `done()` or about a second passed (softirq delivery is asynchronous).
template <class F> bool poll_until(slp_socketcan_t *s, F done)
{
    for (int i = 0; i < 1000; i++) {
        slp_socketcan_poll(s, tick(1));
        if (done()) {
            return true;
        }
        usleep(1000);
    }
    return false;
}

} // namespace

int main(int argc, char **argv)
{
    std::string out, iface = "vcan0", board = "paper-sim";
    long n = 500;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--out") {
            out = argv[i + 1];
        } else if (a == "--iface") {
            iface = argv[i + 1];
        } else if (a == "--n") {
            n = std::stol(argv[i + 1]);
        } else if (a == "--board") {
            board = argv[i + 1];
        }
    }
    if (out.empty()) {
        std::cerr << "usage: vcan_sink_check --out DIR [--iface vcan0] [--n 500] [--board B]\n";
        return 2;
    }
    const char *ifn = iface.c_str();
    Gen gen;
    const sl::BoardSpec b = sl::load_board(board);
    const sl_can_ids_t ids = sl::can_ids(b);
    CHECK(sl_can_tx_init(&gen.tx, &ids) == SL_OK);

    sl::CandumpWriter produced, sent_log;
    produced.open(out + "/produced_a.log", iface);
    sent_log.open(out + "/sent.log", iface);

    slp_socketcan_cfg_t cfg = slp_socketcan_default_cfg();
    cfg.queue_cap = 8;
    cfg.max_age_us = 0;
    cfg.on_sent = on_sent;
    cfg.on_sent_user = &sent_log;
    slp_socketcan_t s;
    const sl_err_t oe = slp_socketcan_open(&s, ifn, &cfg);
    if (oe != SL_OK) {
        std::cerr << "open " << iface << ": " << std::strerror(s.last_errno) << "\n";
        return 1;
    }
    const slp_can_sink_t sinks[2] = {slp_socketcan_sink(&s), produced.sink()};

    // --- A: plain stream to both sinks
    for (long i = 0; i < n; i++) {
        const sl_can_frame_t f = gen.next(i);
        CHECK(slp_can_sinks_send(sinks, 2, &f, tick()) == SL_OK);
        usleep(200); // let candump keep up (its receive queue is finite)
    }
    slp_can_sinks_poll(sinks, 2, tick());
    CHECK(s.stats.sent == static_cast<uint32_t>(n));
    CHECK(slp_can_sinks_dropped(sinks, 2) == 0);
    produced.close();
    print_stats("A plain", s);

    // --- B: interface down mid-stream, then up again
    uint32_t sent0 = s.stats.sent;
    for (int i = 0; i < 20; i++) {
        const sl_can_frame_t f = gen.next(4);
        CHECK(slp_socketcan_send(&s, &f, tick()) == SL_OK);
    }
    sh("ip link set " + iface + " down");
    for (int i = 0; i < 10; i++) {
        const sl_can_frame_t f = gen.next(4);
        CHECK(slp_socketcan_send(&s, &f, tick()) == SL_ERR_PORT);
    }
    CHECK(s.stats.dropped_down == 10);
    CHECK(s.stats.link_down == 1);
    CHECK(s.link_down);
    sh("ip link set " + iface + " up");
    for (int i = 0; i < 20; i++) {
        const sl_can_frame_t f = gen.next(4);
        CHECK(slp_socketcan_send(&s, &f, tick()) == SL_OK);
    }
    CHECK(s.stats.sent - sent0 == 40);
    CHECK(s.stats.link_up == 1 && !s.link_down);
    print_stats("B down/up", s);

    // --- C: interface queue full (ENOBUFS), bounded retry queue, in-order drain
    sent0 = s.stats.sent;
    sh("tc qdisc add dev " + iface + " root plug limit 160"); // 10 frames of 16 bytes
    for (int i = 0; i < 10; i++) {
        const sl_can_frame_t f = gen.next(4);
        CHECK(slp_socketcan_send(&s, &f, tick()) == SL_OK); // held by the qdisc
    }
    int ok = 0, busy = 0;
    for (int i = 0; i < 12; i++) {
        const sl_can_frame_t f = gen.next(4);
        const sl_err_t e = slp_socketcan_send(&s, &f, tick());
        ok += e == SL_OK;
        busy += e == SL_ERR_BUSY;
    }
    CHECK(ok == 8 && busy == 4);
    CHECK(s.stats.enobufs >= 1);
    CHECK(s.q_len == 8);
    CHECK(s.stats.dropped_full == 4);
    sh("tc qdisc change dev " + iface + " root plug release_indefinite");
    CHECK(poll_until(&s, [&] { return s.q_len == 0; }));
    CHECK(s.stats.sent - sent0 == 18);
    print_stats("C enobufs", s);

    // --- E: stale queued frames are dropped (max_age_us 50 ms), on a second sink
    sh("tc qdisc del dev " + iface + " root");
    sh("tc qdisc add dev " + iface + " root plug limit 160");
    {
        slp_socketcan_cfg_t c2 = cfg;
        c2.max_age_us = 50000;
        slp_socketcan_t s2;
        CHECK(slp_socketcan_open(&s2, ifn, &c2) == SL_OK);
        for (int i = 0; i < 13; i++) {
            const sl_can_frame_t f = gen.next(4);
            CHECK(slp_socketcan_send(&s2, &f, tick()) == SL_OK);
        }
        CHECK(s2.stats.sent == 10 && s2.q_len == 3);
        sh("tc qdisc change dev " + iface + " root plug release_indefinite");
        slp_socketcan_poll(&s2, tick(100000)); // 100 ms later: too old
        CHECK(s2.q_len == 0 && s2.stats.dropped_stale == 3 && s2.stats.sent == 10);
        print_stats("E stale", s2);
        slp_socketcan_close(&s2);
    }

    // --- D: socket send buffer full (EAGAIN), frames held by a plugged qdisc
    sh("tc qdisc del dev " + iface + " root");
    sh("tc qdisc add dev " + iface + " root plug limit 1000000");
    {
        slp_socketcan_cfg_t c3 = cfg;
        c3.sndbuf_bytes = 1; // the kernel rounds up to its minimum (a few frames)
        slp_socketcan_t s3;
        CHECK(slp_socketcan_open(&s3, ifn, &c3) == SL_OK);
        int d_ok = 0, d_busy = 0;
        for (int i = 0; i < 40; i++) {
            const sl_can_frame_t f = gen.next(4);
            const sl_err_t e = slp_socketcan_send(&s3, &f, tick());
            d_ok += e == SL_OK;
            d_busy += e == SL_ERR_BUSY;
        }
        CHECK(s3.stats.eagain >= 1);
        CHECK(s3.q_len == 8);
        CHECK(d_ok + d_busy == 40 && static_cast<uint32_t>(d_busy) == s3.stats.dropped_full);
        CHECK(s3.stats.sent + 8 + s3.stats.dropped_full == 40);
        sh("tc qdisc change dev " + iface + " root plug release_indefinite");
        CHECK(poll_until(&s3, [&] { return s3.q_len == 0; }));
        CHECK(s3.stats.sent + s3.stats.dropped_full == 40);
        print_stats("D eagain", s3);
        slp_socketcan_close(&s3);
    }
    sh("tc qdisc del dev " + iface + " root");

    // --- F: error frames: bus-off, restart, hold timeout, error passive
    {
        Injector inj;
        CHECK(inj.open(ifn));
        sent0 = s.stats.sent;
        CHECK(inj.error_frame(CAN_ERR_BUSOFF));
        CHECK(poll_until(&s, [&] { return s.stats.bus_off == 1; }));
        CHECK(s.bus_off);
        for (int i = 0; i < 5; i++) {
            const sl_can_frame_t f = gen.next(4);
            CHECK(slp_socketcan_send(&s, &f, tick()) == SL_ERR_BUSY);
        }
        CHECK(s.stats.dropped_bus_off == 5);
        CHECK(inj.error_frame(CAN_ERR_RESTARTED));
        CHECK(poll_until(&s, [&] { return s.stats.restarts == 1; }));
        CHECK(!s.bus_off);
        for (int i = 0; i < 5; i++) {
            const sl_can_frame_t f = gen.next(4);
            CHECK(slp_socketcan_send(&s, &f, tick()) == SL_OK);
        }
        // Bus-off without a restart report: the hold time ends it.
        CHECK(inj.error_frame(CAN_ERR_BUSOFF));
        CHECK(poll_until(&s, [&] { return s.stats.bus_off == 2; }));
        const sl_can_frame_t f = gen.next(4);
        CHECK(slp_socketcan_send(&s, &f, tick()) == SL_ERR_BUSY);
        CHECK(slp_socketcan_send(&s, &f, tick(s.cfg.bus_off_hold_us + 1)) == SL_OK);
        CHECK(s.stats.bus_off_timeouts == 1);
        CHECK(inj.error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE));
        CHECK(poll_until(&s, [&] { return s.stats.error_passive == 1; }));
        CHECK(s.stats.error_frames == 4);
        CHECK(s.stats.sent - sent0 == 6);
        CHECK(s.stats.dropped_bus_off == 6);
        print_stats("F error frames", s);
    }

    // --- G: the interface disappears and comes back
    {
        sh("ip link del dev " + iface);
        const sl_can_frame_t f = gen.next(4);
        const uint32_t down0 = s.stats.dropped_down;
        CHECK(slp_socketcan_send(&s, &f, tick()) == SL_ERR_PORT);
        CHECK(s.gone && s.fd < 0);
        sh("ip link add dev " + iface + " type vcan && ip link set up " + iface);
        CHECK(slp_socketcan_send(&s, &f, tick()) == SL_ERR_PORT); // before reopen_interval
        CHECK(s.stats.dropped_down - down0 == 2);
        sent0 = s.stats.sent;
        CHECK(slp_socketcan_send(&s, &f, tick(s.cfg.reopen_interval_us)) == SL_OK);
        CHECK(s.stats.reopens == 1 && !s.gone);
        for (int i = 0; i < 9; i++) {
            const sl_can_frame_t g = gen.next(4);
            CHECK(slp_socketcan_send(&s, &g, tick()) == SL_OK);
        }
        CHECK(s.stats.sent - sent0 == 10);
        print_stats("G gone/back", s);
    }

    slp_socketcan_close(&s);
    sent_log.close();
    std::printf("vcan_sink_check: %d failures\n", failures);
    return failures == 0 ? 0 : 1;
}
