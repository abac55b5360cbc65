// SPDX-License-Identifier: MIT
// The exit drain of the CAN sinks (firmware/port/linux/can_sink.c): progress-based.
// Fake sinks on a fake clock: every wait advances time by a fixed step, so nothing here
// depends on the machine's speed. A deliberately slow adapter (one frame every few polls,
// seconds of simulated time in total) is drained completely; one that stops is given up
// after the stall bound, and what it held is reported.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "can_sink.h"

typedef struct fake_sink {
    uint32_t queued, sent, dropped;
    uint32_t every;     // confirm one frame every `every` polls (0: never)
    uint32_t stop_after; // stop confirming after this many frames (0: never stops)
    uint32_t polls;
} fake_sink_t;

static sl_err_t fake_send(void *ctx, const sl_can_frame_t *f, uint64_t t_us)
{
    (void)ctx;
    (void)f;
    (void)t_us;
    return SL_OK;
}

static void fake_poll(void *ctx, uint64_t t_us)
{
    (void)t_us;
    fake_sink_t *s = ctx;
    s->polls++;
    const int stopped = s->stop_after != 0 && s->sent >= s->stop_after;
    if (s->every != 0 && !stopped && s->queued != 0 && s->polls % s->every == 0) {
        s->queued--;
        s->sent++;
    }
}

static void fake_stats(void *ctx, slp_can_sink_stats_t *out)
{
    const fake_sink_t *s = ctx;
    out->sent = s->sent;
    out->dropped = s->dropped;
    out->queued = s->queued;
    out->errors = 0;
}

typedef struct fake_clock {
    uint64_t t_us, step_us;
    uint32_t waits;
} fake_clock_t;

static uint64_t clk_now(void *ctx)
{
    return ((fake_clock_t *)ctx)->t_us;
}

static void clk_wait(void *ctx)
{
    fake_clock_t *c = ctx;
    c->t_us += c->step_us;
    c->waits++;
}

static slp_can_sink_t as_sink(fake_sink_t *s)
{
    slp_can_sink_t k = {"fake", s, fake_send, fake_poll, fake_stats};
    return k;
}

// 40 frames, one confirmed every 5 polls, 100 ms per wait: 20 s of (simulated) drain,
// 40x the old 500 ms wall-time bound, yet never 1 s without progress: all drained.
static void slow_adapter_is_drained_completely(void **state)
{
    (void)state;
    fake_sink_t s = {40, 0, 0, 5, 0, 0};
    slp_can_sink_t k = as_sink(&s);
    fake_clock_t c = {1000000, 100000, 0};
    const slp_can_drain_result_t r = slp_can_sinks_drain(&k, 1, 1000000, clk_now, clk_wait, &c);
    assert_int_equal(r.left, 0);
    assert_int_equal(r.moved, 40);
    assert_int_equal(s.queued, 0);
    assert_int_equal(s.sent, 40);
    assert_true(c.t_us - 1000000 >= 19000000); // it really waited that long
}

// An adapter that confirms 7 frames and then nothing: the drain ends one stall bound after
// the last progress, reports the 13 frames left, and polls a bounded number of times.
static void stalled_adapter_ends_after_the_stall_bound(void **state)
{
    (void)state;
    fake_sink_t s = {20, 0, 0, 2, 7, 0};
    slp_can_sink_t k = as_sink(&s);
    fake_clock_t c = {0, 50000, 0};
    const slp_can_drain_result_t r = slp_can_sinks_drain(&k, 1, 1000000, clk_now, clk_wait, &c);
    assert_int_equal(r.left, 13);
    assert_int_equal(r.moved, 7);
    assert_true(r.stall_us >= 1000000);
    // 7 frames x 2 polls, then 1 s / 50 ms of polls without progress (+1 for the edges).
    assert_true(r.polls <= 14 + 21 + 1);
    assert_true(r.polls >= 14 + 20);
}

// Empty sinks end the drain at once (one poll round, no wait); a sink that holds frames
// and never moves them (no poll function at all) is given up after the bound, all reported.
static void empty_sinks_end_at_once_stuck_frames_are_reported(void **state)
{
    (void)state;
    fake_sink_t a = {0, 5, 0, 0, 0, 0};
    slp_can_sink_t k1 = as_sink(&a);
    fake_clock_t c = {0, 100000, 0};
    slp_can_drain_result_t r = slp_can_sinks_drain(&k1, 1, 1000000, clk_now, clk_wait, &c);
    assert_int_equal(r.left, 0);
    assert_int_equal(r.polls, 1);
    assert_int_equal(c.waits, 0);

    fake_sink_t b = {6, 0, 0, 0, 0, 0};
    slp_can_sink_t ks[2] = {as_sink(&a), as_sink(&b)};
    ks[1].poll = NULL;
    c.waits = 0;
    r = slp_can_sinks_drain(ks, 2, 1000000, clk_now, clk_wait, &c);
    assert_int_equal(r.left, 6);
    assert_int_equal(r.moved, 0);
    assert_int_equal(c.waits, 10); // 10 x 100 ms reaches the 1 s bound
}

// Drops count as progress (a gs_usb sink drops stale queued frames and timed-out echoes).
static void dropper_poll(void *ctx, uint64_t t_us)
{
    (void)t_us;
    fake_sink_t *s = ctx;
    s->polls++;
    if (s->queued != 0 && s->polls % 9 == 0) {
        s->queued--;
        s->dropped++;
    }
}

static void dropping_sink_is_drained(void **state)
{
    (void)state;
    fake_sink_t b = {6, 0, 0, 0, 0, 0};
    slp_can_sink_t k = as_sink(&b);
    k.poll = dropper_poll;
    fake_clock_t c = {0, 100000, 0};
    const slp_can_drain_result_t r = slp_can_sinks_drain(&k, 1, 1000000, clk_now, clk_wait, &c);
    assert_int_equal(r.left, 0);
    assert_int_equal(r.moved, 6);
    assert_int_equal(b.dropped, 6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(slow_adapter_is_drained_completely),
        cmocka_unit_test(stalled_adapter_ends_after_the_stall_bound),
        cmocka_unit_test(empty_sinks_end_at_once_stuck_frames_are_reported),
        cmocka_unit_test(dropping_sink_is_drained),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
