// SPDX-License-Identifier: MIT
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

static uint32_t az_dist_test(uint32_t a, uint32_t b)
{
    const uint32_t d = (a > b ? a - b : b - a) % 400U;
    return d > 200U ? 400U - d : d;
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
    // Slack at r1 = 2.8 m for 0.75 m: 0.268 rad = 17.1 azimuths -> gate 3 + 18 = 21, centred
    // on where a static object at azimuth 100 (abeam), 2.8 m, is expected after 0.75 m.
    uint16_t paz;
    uint32_t pr;
    sl_track_predict_static(&board, 100, 2800000U, 750000U, &paz, &pr);
    for (int off = 21; off <= 22; off++) {
        assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
        sl_track_set_motion(&trk, 750000U, 0U);
        sl_target_t t = tgt(100, 2800000U, 500, 80, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, 1000000);
        t = tgt((uint16_t)(paz + off), pr, 500, 80, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, 1250000);
        assert_int_equal(trk.stats.associated, off == 21 ? 1U : 0U);
        assert_int_equal(trk.stats.created, off == 21 ? 1U : 2U);
    }
    // Yaw only: 9 deg per update = 10 azimuths (rounded up) on top of the gate of 3.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 0U, (uint32_t)(9.0 / 360.0 * 4294967296.0));
    sl_target_t t = tgt(200, 2800000U, 500, 80, SL_INCLINE_VALID);
    sl_track_update(&trk, &t, 1, 1000000);
    t = tgt(187, 2800000U, 500, 80, SL_INCLINE_VALID);
    sl_track_update(&trk, &t, 1, 1250000);
    assert_int_equal(trk.stats.associated, 1U);
    t = tgt(173, 2800000U, 500, 80, SL_INCLINE_VALID); // 14 steps: outside
    sl_track_update(&trk, &t, 1, 1500000);
    assert_int_equal(trk.stats.associated, 1U);
}

// A static object under ego motion: the prediction against the exact geometry (double).
static void test_track_predicts_a_static_object_under_ego_motion(void **state)
{
    (void)state;
    const double kPi = 3.14159265358979323846;
    for (int yaw = 0; yaw < 2; yaw++) {
        board.radar_yaw_cdeg = yaw ? 9000 : 0; // encoder zero 90 deg right of forward
        for (uint16_t az = 0; az < 400; az += 7) {
            for (uint32_t d = 0; d <= 600000U; d += 150000U) {
                const uint32_t r = 3100000U;
                uint16_t paz;
                uint32_t pr;
                sl_track_predict_static(&board, az, r, d, &paz, &pr);
                const double b = (az * 0.9 + (yaw ? 90.0 : 0.0)) * kPi / 180.0;
                const double x = r * cos(b) - d, y = r * sin(b);
                const double re = hypot(x, y);
                double be = atan2(y, x) * 180.0 / kPi - (yaw ? 90.0 : 0.0);
                be = fmod(be + 720.0, 360.0) / 0.9;
                double da = fabs(be - paz);
                da = da > 200.0 ? 400.0 - da : da;
                assert_true(fabs(re - pr) < 0.002 * r + 2.0);
                assert_true(da <= 0.5 + 0.15);
            }
        }
    }
    board.radar_yaw_cdeg = 0;
}

// Confirmation: a static pole passed at 1 m/s (range and bearing follow the ego motion)
// confirms at its third rotation and stays confirmed through one missed rotation; clutter
// that appears somewhere in a band every rotation (inside the gates, off the prediction)
// never confirms, however often it associates.
static void test_track_confirms_static_objects_not_scattered_clutter(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 250000U, 0U);
    uint16_t az = 60;
    uint32_t r = 4000000U;
    uint64_t now = 1000000;
    for (int k = 0; k < 8; k++) {
        if (k != 5) { // rotation 5: the pole is missed
            sl_target_t t = tgt(az, r, 500, 80, SL_INCLINE_VALID);
            sl_track_update(&trk, &t, 1, now);
        } else {
            sl_track_update(&trk, NULL, 0, now);
        }
        const sl_track_t *tt = &trk.tracks[0];
        assert_int_equal(trk.live, 1);
        assert_int_equal(tt->confirmed, k >= 2 ? 1 : 0);
        sl_track_predict_static(&board, az, r, 250000U, &az, &r);
        now += 250000;
    }
    assert_int_equal(trk.stats.created, 1);
    assert_int_equal(trk.stats.inconsistent, 0);
    // Clutter: one return per rotation in a band at 5.1 .. 5.8 m within 6 azimuths of the
    // last one, but never where a static object would be.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 250000U, 0U);
    uint32_t seed = 12345U;
    az = 100;
    for (int k = 0; k < 200; k++) {
        seed = seed * 1103515245U + 12345U;
        const uint32_t rr = 5100000U + (seed >> 8) % 700000U;
        seed = seed * 1103515245U + 12345U;
        uint16_t paz;
        uint32_t pr;
        sl_track_predict_static(&board, az, rr, 250000U, &paz, &pr);
        az = (uint16_t)((az + 4U + (seed >> 12) % 3U) % 400U); // always >= 4 off the track
        if (az_dist_test(az, paz) <= 3U) {
            az = (uint16_t)((paz + 5U) % 400U);
        }
        sl_target_t t = tgt(az, rr, 300, 80, SL_INCLINE_VALID);
        sl_track_update(&trk, &t, 1, now);
        now += 250000;
        for (int i = 0; i < SL_CFG_MAX_TARGETS; i++) {
            assert_int_equal(trk.tracks[i].confirmed, 0);
        }
    }
    assert_int_equal(trk.stats.confirmations, 0);
}

// A pole leaning across the line of sight is a group of 12 azimuths whose representative
// (its lowest visible point, SLANT) moves 4-10 azimuths off the static prediction from one
// rotation to the next; the prediction stays inside the group: consistent, the track
// confirms. A group whose extent ends 4 azimuths short of the prediction is not.
static void test_track_checks_consistency_against_the_group_extent(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 250000U, 0U);
    uint16_t az = 60;
    uint32_t r = 4000000U;
    uint64_t now = 1000000;
    const int16_t jump[6] = {0, 5, 0, 6, 1, 6}; // what sl-eval driveby --psi 20 shows
    for (int k = 0; k < 6; k++) {
        sl_target_t t = tgt((uint16_t)((az + 400 + jump[k]) % 400), r, 500, 80, SL_INCLINE_VALID);
        t.az_first = (uint16_t)((az + 400 - 2) % 400); // the prediction 2 azimuths inside
        t.az_count = 12U;
        t.flags = SL_TARGET_SLANT;
        sl_track_update(&trk, &t, 1, now);
        assert_int_equal(trk.tracks[0].confirmed, k >= 2 ? 1 : 0);
        // the tracker carries the representative's azimuth; the test predicts from the truth
        sl_track_predict_static(&board, az, r, 250000U, &az, &r);
        now += 250000;
    }
    assert_int_equal(trk.stats.inconsistent, 0);
    assert_int_equal(trk.stats.created, 1);
    // The group's far edge 4 azimuths short of the prediction: inconsistent every time.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 250000U, 0U);
    az = 60;
    r = 4000000U;
    for (int k = 0; k < 6; k++) {
        uint16_t paz;
        uint32_t pr;
        sl_track_predict_static(&board, az, r, 250000U, &paz, &pr);
        sl_target_t t = tgt(az, r, 500, 80, SL_INCLINE_VALID);
        t.az_first = (uint16_t)((az + 400 - 11) % 400);
        t.az_count = 12U; // [az - 11, az]
        sl_track_update(&trk, &t, 1, now);
        // next rotation: the representative at the group's end, the prediction 4 beyond it
        az = (uint16_t)((paz + 400 - 4) % 400);
        r = pr;
        now += 250000;
    }
    assert_int_equal(trk.stats.confirmations, 0);
    assert_true(trk.stats.inconsistent >= 4U);
}

// Association measures the bearing to the target's group as well (sl-eval driveby
// --realistic --power-scale, psi 20 leaning away, 3 m left of the path, 1 m/s: a SLANT
// representative 11 azimuths from the prediction, which lies at the end of its 12-azimuth
// group; beyond the 8-azimuth gate the track was lost and restarted, and the pass kept 10 of
// its 25 observations). Here the group's target, not a return nearer the prediction but
// outside the group, continues the track.
static void test_track_associates_a_group_holding_the_prediction(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 250000U, 0U);
    uint16_t az = 320;
    uint32_t r = 3700000U;
    uint64_t now = 1000000;
    sl_target_t t0 = tgt(az, r, -1000, 80, SL_INCLINE_VALID);
    sl_track_update(&trk, &t0, 1, now);
    const uint16_t id = trk.tracks[0].id;
    uint16_t paz;
    uint32_t pr;
    sl_track_predict_static(&board, az, r, 250000U, &paz, &pr);
    assert_true(sl_track_gate_az(&trk, &trk.tracks[0]) < 11U);
    sl_target_t ts[2];
    ts[0] = tgt((uint16_t)((paz + 6U) % 400U), pr, 0, 80, SL_INCLINE_VALID); // nearer, alone
    ts[1] = tgt((uint16_t)((paz + 400U - 11U) % 400U), pr + 10000U, -1000, 80, SL_INCLINE_VALID);
    ts[1].az_first = ts[1].az;
    ts[1].az_count = 12U; // [paz - 11, paz]
    ts[1].flags = SL_TARGET_SLANT;
    sl_track_update(&trk, ts, 2, now + 250000);
    const sl_track_t *t = sl_track_find(&trk, id);
    assert_non_null(t);
    assert_int_equal(t->az, ts[1].az);
    assert_int_equal(t->evidence, 2);
    assert_int_equal(trk.stats.associated, 1);
    assert_int_equal(trk.stats.created, 2); // the lone return opens its own track
    // Alone, the group's target continues the track too (before: a new track).
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 250000U, 0U);
    sl_track_update(&trk, &t0, 1, now);
    sl_track_update(&trk, &ts[1], 1, now + 250000);
    assert_int_equal(trk.stats.created, 1);
    assert_int_equal(trk.stats.associated, 1);
    assert_int_equal(trk.stats.inconsistent, 0);
}

// Six rotations of a static pole at 3 m/s read alternately SLANT (r1 = the union's inner
// bound) and as a wide group (r1 = the representative run's first bin, 7 bins further, with
// `ext_grow` 7 bins before it, or 0 when the union is not reported); `confirmed` after each.
static void drive_alternating_readings(uint8_t ext_grow, uint8_t confirmed[6])
{
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 750000U, 0U);
    uint16_t az = 320;
    uint32_t r = 3800000U;
    uint64_t now = 1000000;
    for (int k = 0; k < 6; k++) {
        sl_target_t t = tgt(az, r, 1900, 80, SL_INCLINE_VALID);
        t.az_first = (uint16_t)((az + 400 - 3) % 400);
        t.az_count = 8U;
        t.r2_um = r + 700000U;
        if (k % 2 == 0) {
            t.flags = SL_TARGET_SLANT; // r1: the union's inner bound
        } else {
            t.r1_um = r + 7U * 43800U; // the representative run's first bin
            t.ext_grow = ext_grow;
        }
        sl_track_update(&trk, &t, 1, now);
        confirmed[k] = trk.tracks[0].confirmed;
        sl_track_predict_static(&board, az, r, 750000U, &az, &r);
        now += 250000;
    }
}

// The same pole's nearest point seen two ways (sl-eval driveby, psi 20 deg leaning towards
// the path, 4 m off it, 3 m/s): as a SLANT target its r1 is the group's union inner bound; as
// a wide upright-looking group its r1 is the representative run's first bin, 0.3 m further,
// with the union's 7 bins before it in ext_grow. The prediction (from either) stays within
// the target's range extent [union inner bound, r2]: consistent, the track confirms. A
// return at the predicted azimuth whose extent ends 0.25-0.4 m short of or starts that far
// beyond the prediction is not (an extent is no licence for any range).
static void test_track_checks_consistency_against_the_range_extent(void **state)
{
    (void)state;
    uint8_t confirmed[6];
    drive_alternating_readings(7U, confirmed);
    for (int k = 0; k < 6; k++) {
        assert_int_equal(confirmed[k], k >= 2 ? 1 : 0);
    }
    assert_int_equal(trk.stats.inconsistent, 0);
    assert_int_equal(trk.stats.created, 1);
    // Without the union's bins in ext_grow the representative's r1 is 0.31 m off: inconsistent.
    drive_alternating_readings(0U, confirmed);
    assert_int_equal(trk.stats.inconsistent, 3);
    // Returns at the predicted azimuth, two bins long, 0.25-0.4 m before or beyond it: all
    // associate (one track), none is consistent.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    sl_track_set_motion(&trk, 250000U, 0U);
    uint32_t seed = 777U;
    uint16_t az = 100;
    uint32_t r = 5000000U;
    uint64_t now = 1000000;
    for (int k = 0; k < 100; k++) {
        seed = seed * 1103515245U + 12345U;
        const uint32_t off = 250000U + (seed >> 8) % 150000U; // inside the range gate
        uint16_t paz;
        uint32_t pr;
        sl_track_predict_static(&board, az, r, 250000U, &paz, &pr);
        if (k == 0) {
            paz = az;
            pr = r;
        }
        const bool before = ((seed >> 4) & 1U) != 0U;
        const uint32_t r1 = before ? pr - off - 2U * 43800U : pr + off;
        sl_target_t t = tgt(paz, r1, 300, 80, SL_INCLINE_VALID);
        t.r2_um = r1 + 2U * 43800U;
        sl_track_update(&trk, &t, 1, now);
        az = paz;
        r = r1;
        now += 250000;
        for (int i = 0; i < SL_CFG_MAX_TARGETS; i++) {
            assert_int_equal(trk.tracks[i].confirmed, 0);
        }
    }
    assert_int_equal(trk.stats.confirmations, 0);
    assert_int_equal(trk.stats.created, 1);
    assert_int_equal(trk.stats.inconsistent, 99);
}

// Reversing: a static pole ahead-right (bearing 45 deg, 3.5 m) seen while the vehicle backs
// away at 1 m/s confirms only when the tracker knows the direction (sl_track_set_reverse).
static void test_track_prediction_follows_a_reversing_vehicle(void **state)
{
    (void)state;
    const double kPi = 3.14159265358979323846;
    for (int told = 0; told < 2; told++) {
        assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
        sl_track_set_motion(&trk, 250000U, 0U);
        sl_track_set_reverse(&trk, told != 0);
        double x = 3.5 * cos(45.0 * kPi / 180.0), y = 3.5 * sin(45.0 * kPi / 180.0);
        uint64_t now = 1000000;
        for (int k = 0; k < 5; k++) {
            const double b = fmod(atan2(y, x) * 180.0 / kPi + 360.0, 360.0);
            sl_target_t t = tgt((uint16_t)lround(b / 0.9) % 400U, (uint32_t)lround(hypot(x, y) * 1e6),
                                500, 80, SL_INCLINE_VALID);
            sl_track_update(&trk, &t, 1, now);
            now += 250000;
            x += 0.25; // the vehicle backs off: the pole moves forward in its frame
        }
        assert_int_equal(trk.live, 1);
        assert_int_equal(trk.tracks[0].confirmed, told ? 1 : 0);
        assert_int_equal(trk.stats.inconsistent, told ? 0U : 4U);
    }
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
    // Moving bounds flagged coarse (a walk's end under a smear tail, one rotation's edges:
    // sl_profile.h, "Uncertainty of the bounds"): their error repeats, so the same floor.
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    for (int i = 0; i < 20; i++) {
        sl_target_t t = tgt(50, 2500000U + (uint32_t)(i % 2) * 1000U, 300, 120, SL_INCLINE_VALID);
        t.flags = SL_TARGET_PROFILE | SL_TARGET_COARSE;
        sl_track_update(&trk, &t, 1, now);
        now += 250000;
    }
    assert_int_equal(trk.tracks[0].alpha_cdeg, 300);
    assert_true(trk.tracks[0].sigma_cdeg >= 120);
}

// Mask bounds first (whole bins, the same error every static rotation), then the target's
// range profile (sl_profile.h): the first profile measurement restarts the filter, so the
// mask's bias does not linger in what PoleLean reports; later mask-only measurements are
// fused as usual.
static void test_track_restarts_on_the_first_profile_measurement(void **state)
{
    (void)state;
    assert_int_equal(sl_track_init(&trk, &board, NULL), SL_OK);
    uint64_t now = 0;
    for (int i = 0; i < 3; i++) {
        sl_target_t t = tgt(50, 2500000U, 1200, 60, SL_INCLINE_VALID); // mask: +12.00
        sl_track_update(&trk, &t, 1, now);
        now += 250000;
    }
    assert_int_equal(trk.tracks[0].alpha_cdeg, 1200);
    sl_target_t p = tgt(50, 2510000U, 1040, 60, SL_INCLINE_VALID); // profile: +10.40
    p.flags = SL_TARGET_PROFILE;
    sl_track_update(&trk, &p, 1, now);
    now += 250000;
    assert_int_equal(trk.tracks[0].alpha_cdeg, 1040);
    assert_int_equal(trk.tracks[0].sigma_cdeg, 60);
    assert_int_equal(trk.tracks[0].valid_hits, 4);
    assert_int_equal(trk.tracks[0].profiled, 1);
    // a later mask-only measurement is fused, not restarted from
    sl_target_t m = tgt(50, 2500000U, 1200, 60, SL_INCLINE_VALID);
    sl_track_update(&trk, &m, 1, now);
    assert_true(trk.tracks[0].alpha_cdeg > 1040 && trk.tracks[0].alpha_cdeg < 1200);
    // and a second profile measurement does not restart either
    const int32_t before = trk.tracks[0].alpha_cdeg;
    p.r1_um = 2520000U;
    p.alpha_cdeg = 900;
    sl_track_update(&trk, &p, 1, now + 250000U);
    assert_true(trk.tracks[0].alpha_cdeg > 900 && trk.tracks[0].alpha_cdeg < before);
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
        cmocka_unit_test_setup(test_track_predicts_a_static_object_under_ego_motion, setup),
        cmocka_unit_test_setup(test_track_confirms_static_objects_not_scattered_clutter, setup),
        cmocka_unit_test_setup(test_track_prediction_follows_a_reversing_vehicle, setup),
        cmocka_unit_test_setup(test_track_restarts_on_the_first_profile_measurement, setup),
        cmocka_unit_test_setup(test_track_checks_consistency_against_the_group_extent, setup),
        cmocka_unit_test_setup(test_track_checks_consistency_against_the_range_extent, setup),
        cmocka_unit_test_setup(test_track_associates_a_group_holding_the_prediction, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
