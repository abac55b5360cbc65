// Unit tests for sl_track.h: association gates, the fixed-point Kalman filter against a
// double-precision one, warning levels with confirmations and hysteresis, timeouts.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>
#include <math.h>

#include "shadowlean/sl_track.h"

static sl_board_t board;
static sl_tracker_t trk;

static int setup(void **state)
{
    (void)state;
    memset(&board, 0, sizeof board);
    board.name = "track-test";
    board.azimuths = 400;
    board.bin_size_um = 43800;
    board.caution_lean_cdeg = 500;
    board.danger_lean_cdeg = 1000;
    board.track_timeout_us = 2000000;
    return 0;
}

static sl_target_t tgt(uint16_t az, uint32_t r1_um, int32_t alpha_cdeg, uint16_t sigma_cdeg,
                       uint8_t flag)
{
    sl_target_t t;
    memset(&t, 0, sizeof t);
    t.az = az;
    t.r1_um = r1_um;
    t.r2_um = r1_um + 600000U;
    t.alpha_cdeg = alpha_cdeg;
    t.sigma_cdeg = sigma_cdeg;
    t.incline_flag = flag;
    return t;
}

static void test_track_filters_alpha_like_a_double_precision_kalman(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    double x = 0, p = 0;
    const double q = 20.0;
    uint64_t now = 1000000;
    for (int k = 0; k < 40; k++) {
        const int32_t z = 800 + ((k * 37) % 200) - 100; // deterministic "noise" +-100 cdeg
        const uint16_t s = (uint16_t)(60 + (k % 5) * 30);
        sl_target_t t = tgt((uint16_t)(100 + (k % 3) - 1), 3000000U + (uint32_t)(k % 4) * 10000U,
                            z, s, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, now);
        now += 250000;
        const double r = (double)s * s;
        if (k == 0) {
            x = z;
            p = r;
        } else {
            p += q * q;
            const double kk = p / (p + r);
            x += kk * (z - x);
            p *= 1.0 - kk;
        }
        assert_int_equal(trk.live, 1);
        const sl_track_t *tr = &trk.tracks[0];
        assert_true(fabs(tr->alpha_cdeg - x) <= 1.0);
        assert_true(fabs(tr->sigma_cdeg - sqrt(p)) <= 1.0);
    }
    assert_int_equal(trk.tracks[0].hits, 40);
    assert_int_equal(trk.tracks[0].valid_hits, 40);
    assert_int_equal(trk.stats.created, 1);
    assert_int_equal(trk.stats.associated, 39);
    assert_true(trk.tracks[0].sigma_cdeg < 60);
}

// The filter follows the measurement almost at once with a large q: levels see z itself.
static void feed(int32_t z, uint8_t flag, uint64_t *now)
{
    sl_target_t t = tgt(50, 2500000U, z, 50, flag);
    sl_track_update(&trk, &t, 1, *now);
    *now += 250000;
}

static void test_track_raises_after_confirmations_and_lowers_with_hysteresis(void **state)
{
    (void)state;
    sl_track_cfg_t cfg;
    sl_track_cfg_default(&cfg);
    cfg.q_cdeg = 5000; // K ~ 1
    assert_int_equal(sl_track_init(&trk, &board, &cfg), SL_OK);
    uint64_t now = 0;
    const sl_track_t *t = &trk.tracks[0];
    feed(0, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_NONE);
    feed(600, SL_INCLINE_VALID, &now);
    feed(600, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_NONE); // two confirmations
    feed(600, SL_INCLINE_AMBIGUOUS, &now);    // no number: neither counts nor breaks
    assert_int_equal(t->level, SL_WARN_NONE);
    feed(600, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_CAUTION); // third
    feed(450, SL_INCLINE_VALID, &now);           // below 5 deg, inside the 1 deg band
    assert_int_equal(t->level, SL_WARN_CAUTION);
    feed(410, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_CAUTION);
    feed(390, SL_INCLINE_VALID, &now); // below 4 deg: lowered at once
    assert_int_equal(t->level, SL_WARN_NONE);
    feed(1100, SL_INCLINE_VALID, &now);
    feed(1100, SL_INCLINE_VALID, &now);
    feed(450, SL_INCLINE_VALID, &now); // breaks the streak
    feed(1100, SL_INCLINE_VALID, &now);
    feed(1100, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_NONE);
    feed(1100, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_DANGER); // straight from NONE to DANGER
    feed(950, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_DANGER); // within the band below 10 deg
    feed(850, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_CAUTION); // to the level that still holds
    feed(-700, SL_INCLINE_VALID, &now);          // leaning away 7 deg: |lean| holds CAUTION
    assert_int_equal(t->level, SL_WARN_CAUTION);
    feed(-300, SL_INCLINE_VALID, &now);
    assert_int_equal(t->level, SL_WARN_NONE);
    assert_int_equal(sl_track_max_level(&trk), SL_WARN_NONE);
    assert_int_equal(trk.stats.level_changes, 5);
    // Towards-only CAUTION.
    cfg.caution_abs = false;
    assert_int_equal(sl_track_init(&trk, &board, &cfg), SL_OK);
    for (int i = 0; i < 5; i++) {
        feed(-800, SL_INCLINE_VALID, &now);
    }
    assert_int_equal(trk.tracks[0].level, SL_WARN_NONE);
    for (int i = 0; i < 3; i++) {
        feed(700, SL_INCLINE_VALID, &now);
    }
    assert_int_equal(trk.tracks[0].level, SL_WARN_CAUTION);
    assert_int_equal(sl_track_max_level(&trk), SL_WARN_CAUTION);
}

static void test_track_needs_a_small_sigma_to_raise(void **state)
{
    (void)state;
    sl_track_cfg_t cfg;
    sl_track_cfg_default(&cfg);
    cfg.q_cdeg = 5000;
    assert_int_equal(sl_track_init(&trk, &board, &cfg), SL_OK);
    uint64_t now = 0;
    for (int i = 0; i < 10; i++) {
        sl_target_t t = tgt(50, 2500000U, 1500, 2000, SL_INCLINE_VALID); // sigma 20 deg
        sl_track_update(&trk, &t, 1, now);
        now += 250000;
    }
    assert_int_equal(trk.tracks[0].level, SL_WARN_NONE);
}

static void test_track_drops_a_vanished_target_after_the_timeout(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_target_t t = tgt(10, 3000000U, 100, 100, SL_INCLINE_VALID);
    sl_track_update(&trk, &t, 1, 5000000);
    const uint16_t id = trk.tracks[0].id;
    assert_true(id != 0U);
    sl_track_update(&trk, NULL, 0, 6000000);
    sl_track_update(&trk, NULL, 0, 7000000); // exactly the timeout: kept
    assert_non_null(sl_track_find(&trk, id));
    sl_track_update(&trk, NULL, 0, 7000001);
    assert_null(sl_track_find(&trk, id));
    assert_int_equal(trk.live, 0);
    assert_int_equal(trk.stats.dropped, 1);
    // It comes back: a new track with a new id.
    sl_track_update(&trk, &t, 1, 8000000);
    assert_int_equal(trk.live, 1);
    assert_true(trk.tracks[0].id != id);
    // Time going backwards is counted, not fatal.
    sl_track_update(&trk, NULL, 0, 100);
    assert_int_equal(trk.stats.time_backwards, 1);
    assert_int_equal(trk.live, 1);
}

static void test_track_keeps_poles_apart_by_azimuth_and_range_gates(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_target_t ts[3] = {tgt(10, 3000000U, 0, 100, SL_INCLINE_VALID),
                         tgt(20, 3000000U, 0, 100, SL_INCLINE_VALID),
                         tgt(399, 2600000U, 0, 100, SL_INCLINE_INVALID)};
    sl_track_update(&trk, ts, 3, 0);
    assert_int_equal(trk.live, 3);
    const uint16_t id10 = trk.tracks[0].id, id20 = trk.tracks[1].id, id399 = trk.tracks[2].id;
    assert_true(id10 != id20 && id20 != id399 && id10 != id399);
    // Next rotation: listed in another order, moved within the gates, 399 -> 1 (wrap).
    sl_target_t us[4] = {tgt(1, 2650000U, 0, 100, SL_INCLINE_VALID),
                         tgt(22, 3100000U, 0, 100, SL_INCLINE_VALID),
                         tgt(12, 2950000U, 0, 100, SL_INCLINE_VALID),
                         tgt(11, 3500000U, 0, 100, SL_INCLINE_VALID)}; // 0.5 m off: new
    sl_track_update(&trk, us, 4, 250000);
    assert_int_equal(trk.live, 4);
    assert_int_equal(sl_track_find(&trk, id10)->az, 12);
    assert_int_equal(sl_track_find(&trk, id20)->az, 22);
    assert_int_equal(sl_track_find(&trk, id399)->az, 1);
    assert_int_equal(sl_track_find(&trk, id399)->valid_hits, 1); // first one was INVALID
    assert_int_equal(trk.stats.created, 4);
    assert_int_equal(trk.stats.associated, 3);
    // Competing targets: the nearer one wins, the other opens a track.
    sl_target_t vs[2] = {tgt(14, 2950000U, 0, 100, SL_INCLINE_VALID),
                         tgt(12, 2960000U, 0, 100, SL_INCLINE_VALID)};
    sl_track_update(&trk, vs, 2, 500000);
    assert_int_equal(sl_track_find(&trk, id10)->az, 12);
    assert_int_equal(trk.stats.created, 5);
}

// Ego motion widens the gates: a pole 2.8 m away that moves 7 azimuths and 0.4 m between
// rotations (3 m/s) opens a new track without it, continues its track with it; the azimuth
// slack follows 1 / r1 (a far pole gets less) and the yaw adds its own steps.
static void test_track_motion_widens_the_gates(void **state)
{
    (void)state;
    for (int moving = 0; moving < 2; moving++) {
        assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
        if (moving) {
            sl_track_set_motion(&trk, 750000U, 0U); // 3 m/s x 0.25 s
        }
        sl_target_t t = tgt(100, 2800000U, 500, 80, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, 1000000);
        t = tgt(107, 3200000U, 520, 80, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, 1250000);
        assert_int_equal(trk.stats.created, moving ? 1U : 2U);
        assert_int_equal(trk.stats.associated, moving ? 1U : 0U);
    }
    // Slack at r1 = 2.8 m for 0.75 m: 0.268 rad = 17.1 azimuths -> gate 3 + 18 = 21.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 750000U, 0U);
    sl_target_t t = tgt(100, 2800000U, 500, 80, SL_INCLINE_VALID);
    sl_track_update(&trk, &t, 1, 1000000);
    t = tgt(121, 2800000U, 500, 80, SL_INCLINE_VALID);
    sl_track_update(&trk, &t, 1, 1250000);
    assert_int_equal(trk.stats.associated, 1U);
    t = tgt(143, 2800000U, 500, 80, SL_INCLINE_VALID); // 22 steps: outside
    sl_track_update(&trk, &t, 1, 1500000);
    assert_int_equal(trk.stats.associated, 1U);
    assert_int_equal(trk.stats.created, 2U);
    // Yaw only: 9 deg per update = 10 azimuths (rounded up) on top of the gate of 3.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 0U, (uint32_t)(9.0 / 360.0 * 4294967296.0));
    t = tgt(200, 2800000U, 500, 80, SL_INCLINE_VALID);
    sl_track_update(&trk, &t, 1, 1000000);
    t = tgt(187, 2800000U, 500, 80, SL_INCLINE_VALID);
    sl_track_update(&trk, &t, 1, 1250000);
    assert_int_equal(trk.stats.associated, 1U);
    t = tgt(173, 2800000U, 500, 80, SL_INCLINE_VALID); // 14 steps: outside
    sl_track_update(&trk, &t, 1, 1500000);
    assert_int_equal(trk.stats.associated, 1U);
}

static void test_track_counts_targets_beyond_its_capacity(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    static sl_target_t many[SL_CFG_MAX_TARGETS + 8];
    for (int i = 0; i < SL_CFG_MAX_TARGETS + 8; i++) {
        many[i] = tgt((uint16_t)(i * 10), 3000000U, 0, 100, SL_INCLINE_VALID);
    }
    sl_track_update(&trk, many, SL_CFG_MAX_TARGETS + 8, 0);
    assert_int_equal(trk.live, SL_CFG_MAX_TARGETS);
    assert_int_equal(trk.stats.full, 8);
    sl_track_cfg_t cfg;
    sl_track_cfg_default(&cfg);
    cfg.az_gate = 0;
    assert_int_equal(sl_track_init(&trk, &board, &cfg), SL_ERR_ARG);
    assert_int_equal(sl_track_init(NULL, &board, NULL), SL_ERR_ARG);
    assert_int_equal(sl_track_init(&trk, NULL, NULL), SL_ERR_ARG);
}

// A static scene quantised the same way every rotation: identical bounds are one
// measurement, so the filtered sigma stays at the measurement's own (variance floor while
// the bins repeat); bounds that change are independent and shrink it as before.
static void test_track_does_not_trust_repeated_identical_bounds(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    uint64_t now = 0;
    for (int i = 0; i < 20; i++) {
        sl_target_t t = tgt(50, 2500000U, 300, 120, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, now);
        now += 250000;
    }
    assert_int_equal(trk.tracks[0].alpha_cdeg, 300);
    assert_true(trk.tracks[0].sigma_cdeg >= 120);
    // The same measurement noise with bounds that move: independent, sigma shrinks.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    for (int i = 0; i < 20; i++) {
        sl_target_t t = tgt(50, 2500000U + (uint32_t)(i % 2) * 1000U, 300, 120, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, now);
        now += 250000;
    }
    assert_true(trk.tracks[0].sigma_cdeg < 60);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_track_filters_alpha_like_a_double_precision_kalman, setup),
        cmocka_unit_test_setup(test_track_raises_after_confirmations_and_lowers_with_hysteresis,
                               setup),
        cmocka_unit_test_setup(test_track_needs_a_small_sigma_to_raise, setup),
        cmocka_unit_test_setup(test_track_drops_a_vanished_target_after_the_timeout, setup),
        cmocka_unit_test_setup(test_track_keeps_poles_apart_by_azimuth_and_range_gates, setup),
        cmocka_unit_test_setup(test_track_motion_widens_the_gates, setup),
        cmocka_unit_test_setup(test_track_counts_targets_beyond_its_capacity, setup),
        cmocka_unit_test_setup(test_track_does_not_trust_repeated_identical_bounds, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
