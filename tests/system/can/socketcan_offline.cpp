// SPDX-License-Identifier: MIT
// socketcan_offline: the SocketCAN sink's paths that need no CAN interface (runs on any
// host, also one whose kernel has no CAN at all): argument checks, an interface that does
// not exist (every frame dropped and counted as "down", SL_ERR_PORT, never blocking,
// reopen attempts on schedule), the generic sink vtable and close() idempotence.
#include <cstdio>
#include <cstring>
#include <iostream>

#include "can_sink.h"
#include "socketcan.h"
#include "check.hpp"

namespace {
using sl_test::failures;
} // namespace

int main()
{
    slp_socketcan_t s;
    CHECK(slp_socketcan_open(nullptr, "vcan0", nullptr) == SL_ERR_ARG);
    CHECK(slp_socketcan_open(&s, nullptr, nullptr) == SL_ERR_ARG);
    CHECK(slp_socketcan_open(&s, "", nullptr) == SL_ERR_ARG);
    CHECK(slp_socketcan_open(&s, "a-name-longer-than-15", nullptr) == SL_ERR_ARG);
    slp_socketcan_cfg_t big = slp_socketcan_default_cfg();
    big.queue_cap = SLP_SOCKETCAN_QUEUE_MAX + 1;
    CHECK(slp_socketcan_open(&s, "vcan0", &big) == SL_ERR_ARG);
    slp_socketcan_close(&s);

    // An interface that does not exist (or no CAN in this kernel: EAFNOSUPPORT).
    slp_socketcan_cfg_t cfg = slp_socketcan_default_cfg();
    CHECK(slp_socketcan_open(&s, "slnone0", &cfg) == SL_ERR_PORT);
    CHECK(s.gone && s.fd < 0 && s.last_errno != 0);
    std::printf("open slnone0: %s (expected: no such device, or no CAN support)\n",
                std::strerror(s.last_errno));
    const slp_can_sink_t k = slp_socketcan_sink(&s);
    CHECK(std::strcmp(k.name, "socketcan") == 0);
    sl_can_frame_t f{};
    f.id = 0x620;
    f.dlc = 8;
    uint64_t t = 5000000;
    for (int i = 0; i < 100; i++) {
        CHECK(k.send(k.ctx, &f, t) == SL_ERR_PORT);
        t += 100000; // 0.1 s: a reopen is attempted every 1 s
    }
    CHECK(s.stats.dropped_down == 100);
    CHECK(s.stats.sent == 0 && s.stats.reopens == 0);
    slp_can_sink_stats_t st{};
    k.get_stats(k.ctx, &st);
    CHECK(st.dropped == 100 && st.sent == 0 && st.queued == 0);
    CHECK(slp_can_sinks_dropped(&k, 1) == 100);
    CHECK(slp_can_sinks_send(&k, 1, &f, t) == SL_ERR_PORT);
    slp_can_sinks_poll(&k, 1, t);
    CHECK(slp_socketcan_send(&s, nullptr, t) == SL_ERR_ARG);
    slp_socketcan_close(&s);
    slp_socketcan_close(&s);
    std::printf("socketcan_offline: %d failures\n", failures);
    return failures == 0 ? 0 : 1;
}
