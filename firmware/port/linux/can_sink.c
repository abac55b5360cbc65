// SPDX-License-Identifier: MIT
// The exit drain of the CAN sinks (can_sink.h): progress-based, never bounded by elapsed time.
#include "can_sink.h"

// Totals over the sinks: frames held now, and frames that ever left (sent or dropped).
static void totals(const slp_can_sink_t *sinks, size_t n, uint32_t *queued, uint32_t *moved)
{
    uint32_t q = 0;
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++) {
        slp_can_sink_stats_t st = {0, 0, 0, 0};
        sinks[i].get_stats(sinks[i].ctx, &st);
        q += st.queued;
        m += st.sent + st.dropped; // wraps like the counters; only compared for change
    }
    *queued = q;
    *moved = m;
}

slp_can_drain_result_t slp_can_sinks_drain(const slp_can_sink_t *sinks, size_t n, uint64_t stall_us,
                                           uint64_t (*now_us)(void *ctx), void (*wait)(void *ctx),
                                           void *ctx)
{
    slp_can_drain_result_t r = {0, 0, 0, 0};
    uint32_t queued = 0;
    uint32_t moved0 = 0;
    totals(sinks, n, &queued, &moved0);
    uint32_t last_moved = moved0;
    uint64_t last_progress = now_us(ctx);
    for (;;) {
        const uint64_t t = now_us(ctx);
        slp_can_sinks_poll(sinks, n, t);
        r.polls++;
        uint32_t moved = 0;
        totals(sinks, n, &queued, &moved);
        if (moved != last_moved) {
            last_moved = moved;
            last_progress = t;
        }
        r.stall_us = t >= last_progress ? t - last_progress : 0;
        if (queued == 0 || r.stall_us >= stall_us) {
            break;
        }
        wait(ctx);
    }
    r.left = queued;
    r.moved = last_moved - moved0;
    return r;
}
