// SPDX-License-Identifier: MIT
// Unit tests for sl_detect.h: pole extraction on hand-made stable-occupied rows, the
// rejections, the corrections of MATH.md s.4 and alpha. The board is built here (theta =
// 26 deg, beta = 0, the paper-sim geometry) with its geometry entry computed with libm.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <math.h>

#include "shadowlean/sl_detect.h"
#include "shadowlean/sl_mask.h"
#include "shadowlean/sl_thresh.h"

#define NAZ 400
#define NW (SL_ROI_WORDS)
#define BIN_UM 43800U
#define H_UM 2580000U
#define THETA_DEG 26.0

static const double kPi = 3.14159265358979323846;

static sl_incline_geom_t geom[NAZ];
static uint32_t shadow_um[NAZ];
static uint16_t shadow_bins[NAZ];
static int16_t theta_cdeg[NAZ];
static sl_board_t board;
static sl_detect_t det;
static uint32_t rows[NAZ][NW];

static int32_t q30(double v)
{
    return (int32_t)llround(v * 1073741824.0);
}

static uint32_t q28(double v)
{
    return (uint32_t)llround(v * 268435456.0);
}

static void make_board(void)
{
    const double t = THETA_DEG * kPi / 180.0, b = 0.0;
    sl_incline_geom_t g;
    g.cos_theta_q30 = q30(cos(t));
    g.sin_theta_q30 = q30(sin(t));
    g.cos_beta_q30 = q30(cos(b));
    g.sin_beta_q30 = q30(sin(b));
    g.cos_tb_q30 = q30(cos(t + b));
    g.sin_tb_q30 = q30(sin(t + b));
    g.rho_amb_q28 = q28(1.0 / cos((t + b) / 2.0));
    g.rho_seam_q28 = q28(1.0 / cos(t + b));
    g.theta_bam32 = (uint32_t)llround(THETA_DEG / 360.0 * 4294967296.0);
    g.beta_bam32 = 0U;
    const double rs_m = 2.58 / tan(t);
    for (int i = 0; i < NAZ; i++) {
        geom[i] = g;
        shadow_um[i] = (uint32_t)llround(rs_m * 1e6);
        shadow_bins[i] = (uint16_t)(floor(rs_m / 0.0438) - 1.0);
        theta_cdeg[i] = 2600;
    }
    memset(&board, 0, sizeof board);
    board.name = "test-26";
    board.radar_height_um = H_UM;
    board.azimuths = NAZ;
    board.encoder_size = 5600;
    board.bin_size_um = BIN_UM;
    board.range_bins = 3768;
    board.roi_bins = 512;
    board.near_exclusion_bins = 39; // 1.7 m
    board.threshold = 40;
    board.mask_frames = 16;
    board.max_targets = 16;
    board.range_sigma_um = 12640;
    board.theta_sigma_cdeg = 10;
    board.caution_lean_cdeg = 500;
    board.danger_lean_cdeg = 1000;
    board.track_timeout_us = 2000000;
    board.geom = geom;
    board.theta_cdeg = theta_cdeg;
    board.shadow_um = shadow_um;
    board.shadow_bins = shadow_bins;
}

static int setup(void **state)
{
    (void)state;
    make_board();
    memset(rows, 0, sizeof rows);
    return 0;
}

static void set_run(int az, uint32_t first, uint32_t last)
{
    for (uint32_t k = first; k <= last; k++) {
        sl_bits_put(rows[az], k, true);
    }
}

static void set_band(uint32_t last_bin)
{
    for (int a = 0; a < NAZ; a++) {
        set_run(a, 0, last_bin);
    }
}

static int run_rotation(void)
{
    sl_detect_begin(&det);
    for (int a = 0; a < NAZ; a++) {
        assert_int_equal(sl_detect_row(&det, (uint16_t)a, rows[a], NW), SL_OK);
    }
    return (int)sl_detect_end(&det);
}

static uint32_t half_bin_um(uint32_t bin)
{
    return (uint32_t)(((2ULL * bin + 1U) * BIN_UM + 1U) / 2U);
}

// Double-precision alpha (beta = 0) from corrected bounds, MATH.md s.2.
static double alpha_ref_deg(double r1, double r2)
{
    const double t = THETA_DEG * kPi / 180.0, rho = r2 / r1;
    if (rho >= 1.0 / cos(t)) {
        return atan((rho * cos(t) - 1.0) / (rho * sin(t))) * 180.0 / kPi;
    }
    return (acos(1.0 / rho) - t) * 180.0 / kPi;
}

// A pole leaning alpha_deg towards the radar, crossing radar height at horizontal x0_m:
// r1 on the horizontal ray (alpha >= 0), r2 on the -theta ray. Returns the bins.
static void pole_bins(double x0_m, double alpha_deg, uint32_t *first, uint32_t *last,
                      double *r1_m, double *r2_m)
{
    const double t = THETA_DEG * kPi / 180.0, a = alpha_deg * kPi / 180.0;
    const double s = -x0_m * tan(t) / (cos(a) - sin(a) * tan(t));
    const double x = x0_m - s * sin(a);
    *r1_m = x0_m;
    *r2_m = x / cos(t);
    *first = (uint32_t)floor(*r1_m / 0.0438);
    *last = (uint32_t)floor(*r2_m / 0.0438);
}

static void test_detect_finds_a_slanted_pole_with_corrected_bounds(void **state)
{
    (void)state;
    sl_detect_cfg_t cfg;
    sl_detect_cfg_default(&cfg);
    cfg.radius_from_width = false;
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    uint32_t f, l;
    double r1m, r2m;
    pole_bins(3.0, 10.0, &f, &l, &r1m, &r2m);
    assert_int_equal(f, 68);
    assert_int_equal(l, 83);
    // Beam-edge azimuths see a shorter run; the strongest is the representative.
    set_run(100, f + 1, l - 1);
    set_run(101, f, l);
    set_run(102, f, l);
    set_run(103, f + 1, l - 2);
    assert_int_equal(run_rotation(), 1);
    const sl_target_t *t = &det.targets[0];
    assert_int_equal(t->az, 101); // tie 101/102, both as central: lower index
    assert_int_equal(t->az_first, 100);
    assert_int_equal(t->az_count, 4);
    assert_int_equal(t->bin_first, f);
    assert_int_equal(t->bin_last, l);
    assert_int_equal(t->r1_raw_um, f * BIN_UM);
    assert_int_equal(t->r2_raw_um, (l + 1U) * BIN_UM);
    assert_int_equal(t->r1_um, half_bin_um(f));
    assert_int_equal(t->r2_um, half_bin_um(l));
    assert_int_equal(t->radius_um, 0);
    assert_int_equal(t->incline_flag, SL_INCLINE_VALID);
    assert_int_equal(t->incline_branch, SL_INCLINE_BRANCH_1);
    const double want = alpha_ref_deg(t->r1_um, t->r2_um);
    assert_true(fabs(t->alpha_cdeg / 100.0 - want) < 0.02);
    assert_true(fabs(t->alpha_cdeg / 100.0 - 10.0) < 1.2); // bin quantisation only
    assert_true(t->sigma_cdeg > 0);
    assert_int_equal(det.stats.targets, 1);
    for (int r = 0; r < SL_DETECT_REJ_COUNT; r++) {
        assert_int_equal(det.stats.rejected[r], 0);
    }
}

static void test_detect_estimates_a_leaning_away_pole_on_branch_two(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    // alpha = -5 deg: r1 = foot of the perpendicular, r2 on the -theta ray.
    const double t = THETA_DEG * kPi / 180.0, a = -5.0 * kPi / 180.0, p = 3.2;
    const double r1 = p, r2 = p / cos(a + t);
    const uint32_t f = (uint32_t)floor(r1 / 0.0438), l = (uint32_t)floor(r2 / 0.0438);
    set_run(200, f, l);
    set_run(201, f, l);
    assert_int_equal(run_rotation(), 1);
    const sl_target_t *tg = &det.targets[0];
    assert_int_equal(tg->incline_flag, SL_INCLINE_VALID);
    assert_int_equal(tg->incline_branch, SL_INCLINE_BRANCH_2);
    assert_int_equal(tg->radius_um, 0); // 2 azimuths: nothing beyond the beam
    assert_true((tg->flags & SL_TARGET_RADIUS_WIDTH) != 0U);
    assert_int_equal(tg->flags & SL_TARGET_COARSE, 0); // no radius: the board's sigma
    assert_true(fabs(tg->alpha_cdeg / 100.0 - alpha_ref_deg(tg->r1_um, tg->r2_um)) < 0.02);
    assert_true(fabs(tg->alpha_cdeg / 100.0 + 5.0) < 1.5);
}

static void test_detect_never_reports_the_near_field_band(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    set_band(38); // bright band in bins 0..38, all azimuths: ends right below the exclusion
    set_run(50, 70, 85);
    set_run(51, 70, 85);
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.targets[0].az, 50);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_NEAR], 0);
    // The band leaks past the exclusion on azimuths 10..12: that group is rejected NEAR.
    set_run(10, 39, 44);
    set_run(11, 39, 46);
    set_run(12, 39, 44);
    // A pole whose run starts right at the exclusion, continuing the band: NEAR too.
    set_run(300, 39, 60);
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.targets[0].az, 50);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_NEAR], 2);
    // A run just past the exclusion with a free bin before it is fine.
    set_run(150, 40, 60);
    set_run(151, 40, 60);
    assert_int_equal(run_rotation(), 2);
}

static void test_detect_never_reports_ground_outside_the_shadow(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    // Slant range of the shadow edge: sqrt(R^2 + H^2) with R = H / tan(26 deg).
    const double s_m = 2.58 / sin(THETA_DEG * kPi / 180.0);
    const uint32_t s_bin = (uint32_t)floor(s_m / 0.0438); // 134
    assert_int_equal(det.win_bins[0], (uint16_t)ceil(s_m / 0.0438));
    assert_int_equal(det.edge_bins[0], s_bin);
    assert_int_equal(sl_detect_bins_needed(&det), s_bin + 1U);
    // Ground clutter from the edge outwards on every azimuth.
    for (int a = 0; a < NAZ; a++) {
        set_run(a, s_bin, 300);
    }
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHADOW], 1); // one group, all around
    // A pole whose base is outside the shadow: its run joins the ground.
    set_run(80, 110, 133);
    set_run(81, 110, 133);
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHADOW], 2);
    // Ground clutter that starts beyond the window is not even a run.
    memset(rows, 0, sizeof rows);
    for (int a = 0; a < NAZ; a++) {
        set_run(a, s_bin + 1U, 300);
    }
    const uint32_t runs0 = det.stats.runs;
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.runs, runs0);
    // A pole ending one bin before the edge bin is inside (ground further than gap_bins).
    memset(rows, 0, sizeof rows);
    for (int a = 0; a < NAZ; a++) {
        set_run(a, s_bin + 3U, 300);
    }
    set_run(90, 110, s_bin - 1U);
    set_run(91, 110, s_bin - 1U);
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.targets[0].bin_last, s_bin - 1U);
    assert_true(det.targets[0].r2_um < det.targets[0].shadow_slant_um);
}

static void test_detect_rejects_wide_and_broken_returns(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    // A car-sized object at 3 m: 20 azimuths (18 deg, ~1 m). Allowed at 3 m for 0.3 m:
    // floor((0.1 rad + 1.8 deg) / 0.9 deg) + 2 = 10.
    for (int a = 20; a < 40; a++) {
        set_run(a, 68, 75);
    }
    // Wider than the group storage (SL_CFG_DETECT_MAX_SPAN): WIDE as well.
    for (int a = 100; a < 100 + SL_CFG_DETECT_MAX_SPAN + 5; a++) {
        set_run(a, 60, 64);
    }
    // A broken run: one free bin inside the run on the representative azimuth.
    set_run(250, 70, 90);
    sl_bits_put(rows[250], 80, false);
    set_run(251, 72, 88);
    // Gaps wider than gap_bins split runs: two targets on the same azimuths.
    set_run(320, 60, 66);
    set_run(320, 70, 80);
    set_run(321, 60, 66);
    set_run(321, 70, 80);
    assert_int_equal(run_rotation(), 2);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 2);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_BROKEN], 1);
    assert_int_equal(det.stats.span_overflow, 1);
    assert_int_equal(det.targets[0].az, 320);
    assert_int_equal(det.targets[1].az, 320);
    // Ten azimuths at 3 m is still a pole (allowed 10); its width radius is clamped.
    memset(rows, 0, sizeof rows);
    for (int a = 20; a < 30; a++) {
        set_run(a, 68, 75);
    }
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.targets[0].az_count, 10);
    assert_int_equal(det.targets[0].radius_um, 150000);
    assert_true((det.targets[0].flags & SL_TARGET_RADIUS_CLAMPED) != 0U);
    // Eight azimuths: R = r1 * tan(w/2), w = 7 * 0.9 - 1.8 = 4.5 deg.
    memset(rows, 0, sizeof rows);
    for (int a = 20; a < 28; a++) {
        set_run(a, 68, 75);
    }
    assert_int_equal(run_rotation(), 1);
    assert_true((det.targets[0].flags & SL_TARGET_RADIUS_WIDTH) != 0U);
    assert_true((det.targets[0].flags & SL_TARGET_RADIUS_CLAMPED) == 0U);
    const double r1 = half_bin_um(68) * 1e-6;
    const double rexp = r1 * tan(4.5 / 2.0 * kPi / 180.0) * 1e6;
    assert_true(fabs((double)det.targets[0].radius_um - rexp) < rexp * 0.002 + 2.0);
    assert_int_equal(det.targets[0].r1_um, half_bin_um(68) + det.targets[0].radius_um);
    // The radius from width is uncertain by its own size (stage 6): r1's sigma is
    // sqrt(s^2 + R^2 / 3), combined with r2's, and the target is flagged coarse.
    const sl_target_t *t = &det.targets[0];
    const uint32_t s1 = sl_detect_r1_sigma_um(t, board.range_sigma_um);
    const double s1exp = sqrt((double)board.range_sigma_um * board.range_sigma_um +
                              (double)t->radius_um * t->radius_um / 3.0);
    assert_true(fabs(s1 - s1exp) <= 1.0);
    assert_true((t->flags & SL_TARGET_COARSE) != 0U);
    const sl_incline_result_t res = sl_incline_estimate(
        t->r1_um, t->r2_um, &board.geom[t->az],
        sl_incline_bounds_sigma_um(t->r1_um, t->r2_um, s1, board.range_sigma_um),
        board.theta_sigma_cdeg);
    assert_int_equal(t->incline_flag, res.flag);
    assert_int_equal(t->sigma_cdeg, res.sigma_cdeg);
    // without a radius (or with the board's): the edge's own sigma
    sl_target_t u = *t;
    u.radius_um = 0U;
    assert_int_equal(sl_detect_r1_sigma_um(&u, 12640U), 12640U);
    u.radius_um = 30000U;
    u.flags = SL_TARGET_RADIUS_BOARD;
    assert_int_equal(sl_detect_r1_sigma_um(&u, 12640U), 12640U);
}

// A 20 deg pole leaning across the line of sight at ~3.3 m, as sl-sim renders it for a
// vehicle passing at 1 m/s (rotation 30 of `sl-eval driveby --psi 20 --phi 0 --offset 3`):
// every azimuth holds a short piece, the pieces step through range over 13 azimuths where a
// vertical pole may span 9.
static const uint16_t k_leaning_pole[13][2] = {{87, 89}, {85, 89}, {83, 89}, {81, 87},
                                                {80, 85}, {78, 82}, {77, 81}, {76, 79},
                                                {75, 77}, {74, 76}, {74, 75}, {74, 74},
                                                {73, 74}};

static void set_leaning_pole(int az0)
{
    for (int i = 0; i < 13; i++) {
        set_run(az0 + i, k_leaning_pole[i][0], k_leaning_pole[i][1]);
    }
}

static void test_detect_keeps_a_pole_leaning_across_the_beam_while_moving(void **state)
{
    (void)state;
    sl_detect_cfg_t cfg;
    sl_detect_cfg_default(&cfg);
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    set_leaning_pole(100);
    for (int a = 20; a < 40; a++) { // a car side at 3 m: fills its 20 azimuths
        set_run(a, 68, 75);
    }
    // Parked: both WIDE.
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 2);
    // Moving (no track needed: a SLANT group may start one): the leaning pole is kept as
    // SLANT with the group's union extent as bounds; the car side is not thin (160 occupied
    // bins > 8 bins x 10 azimuths) and stays WIDE, with or without a track expected there.
    det.union_ext = true;
    det.slant = true;
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 3);
    sl_detect_hint(&det, 30, 2);
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 4);
    const sl_target_t *t = &det.targets[0];
    assert_true((t->flags & SL_TARGET_SLANT) != 0U);
    assert_int_equal(t->az_first, 100);
    assert_int_equal(t->az_count, 13);
    // representative: the middle of the azimuths whose run ends on the union's last bin
    // (100-102: the pole's lowest visible point), with its run's occupied bins (85-89)
    assert_int_equal(t->az, 101);
    assert_int_equal(t->occupied, 5);
    assert_int_equal(t->bin_first, 73);
    assert_int_equal(t->bin_last, 89);
    assert_int_equal(t->ext_grow, 0);
    assert_int_equal(t->radius_um, 0); // not the lean's spread in bearing
    assert_int_equal(t->r1_um, half_bin_um(73));
    assert_int_equal(t->r2_um, half_bin_um(89));
    assert_int_equal(t->incline_flag, SL_INCLINE_VALID);
    const double a_ref = alpha_ref_deg(half_bin_um(73) * 1e-6, half_bin_um(89) * 1e-6);
    assert_true(fabs(t->alpha_cdeg / 100.0 - a_ref) < 0.01);
    // The lean bound: the pole's visible height (r(89) sin 26 = 1.71 m) turned by at most
    // 5 deg reaches 3 azimuths at r(73) = 3.2 m: 9 + 3 < 13, WIDE; by 10 deg, 6: kept.
    cfg.max_lean_tan_q16 = (uint16_t)lround(tan(5.0 * kPi / 180.0) * 65536.0);
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    det.union_ext = det.slant = true;
    assert_int_equal(run_rotation(), 0);
    cfg.max_lean_tan_q16 = (uint16_t)lround(tan(10.0 * kPi / 180.0) * 65536.0);
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    det.union_ext = det.slant = true;
    assert_int_equal(run_rotation(), 1);
    // One line, not clutter: a run with a gap, or a run stepping back by two bins, breaks it.
    sl_bits_put(rows[106], 78, false); // 77-81 -> 77, 79-81: bridged, broken
    assert_int_equal(run_rotation(), 0);
    sl_bits_put(rows[106], 78, true);
    memset(rows[107], 0, sizeof rows[107]);
    set_run(107, 78, 81); // after 77-81: first bin one against the direction (speckle)
    assert_int_equal(run_rotation(), 1);
    memset(rows[107], 0, sizeof rows[107]);
    set_run(107, 76, 83); // last bin two against it (83 after 81): not one line
    assert_int_equal(run_rotation(), 0);
    memset(rows[107], 0, sizeof rows[107]);
    set_run(107, 76, 79);
    assert_int_equal(run_rotation(), 1);
    // 0 keeps every wider group WIDE.
    cfg.max_lean_tan_q16 = 0U;
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    det.union_ext = det.slant = true;
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 2);
}

static void test_detect_groups_across_the_azimuth_wrap(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    set_run(398, 70, 80);
    set_run(399, 69, 82);
    set_run(0, 69, 82);
    set_run(1, 71, 80);
    set_run(200, 60, 70);
    assert_int_equal(run_rotation(), 2);
    const sl_target_t *w = det.targets[0].az_count == 4 ? &det.targets[0] : &det.targets[1];
    assert_int_equal(w->az_count, 4);
    assert_int_equal(w->az_first, 398);
    assert_int_equal(w->az, 399);
    assert_true((w->flags & SL_TARGET_WRAPS) != 0U);
    assert_int_equal(w->bin_first, 69);
    assert_int_equal(w->bin_last, 82);
}

static void test_detect_merges_groups_joined_by_a_later_azimuth(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    // Two runs on azimuth 60 that a long run on 61 joins (a V shape): one group.
    set_run(60, 60, 65);
    set_run(60, 75, 80);
    set_run(61, 60, 80);
    set_run(62, 62, 78);
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.targets[0].az, 61);
    assert_int_equal(det.targets[0].az_first, 60);
    assert_int_equal(det.targets[0].az_count, 3);
    assert_int_equal(det.stats.groups, 1);
}

static void test_detect_rejects_clutter_before_it_takes_a_slot(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    set_run(40, 118, 118);  // a speck: one bin -> SHORT
    set_run(80, 118, 119);  // two bins at 5.2 m: rho 1.008, far below rho_amb 1.026 -> RHO
    set_run(120, 116, 118); // three bins at 5.1 m: rho 1.017 < 1.026 - b/r1 (1.018) -> RHO
    set_run(160, 68, 70);   // three bins at 3 m: rho 1.029, a pole near the fold: kept
    for (int a = 200; a < 204; a++) {
        set_run(a, 69, 82); // a slanted pole: kept
    }
    assert_int_equal(run_rotation(), 2);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHORT], 1);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_RHO], 2);
    assert_int_equal(det.targets[0].az, 160);
    assert_int_equal(det.targets[1].az_first, 200);
    // The rule alone: AMBIGUOUS within one bin of the fold passes, further below does not.
    sl_target_t t;
    memset(&t, 0, sizeof t);
    t.az = 3;
    t.bin_first = 68;
    t.bin_last = 70;
    t.r1_um = 3000000U;
    t.incline_flag = SL_INCLINE_AMBIGUOUS;
    const uint32_t amb = geom[3].rho_amb_q28;
    const uint32_t tol = (uint32_t)(((uint64_t)BIN_UM << 28) / 3000000U);
    assert_int_equal(sl_detect_clutter_reason(&board, &t, amb - tol), -1);
    assert_int_equal(sl_detect_clutter_reason(&board, &t, amb - tol - 1U), SL_DETECT_REJ_RHO);
    t.incline_flag = SL_INCLINE_INVALID;
    assert_int_equal(sl_detect_clutter_reason(&board, &t, 0), SL_DETECT_REJ_RHO);
    // The rule reads the run as measured, before the elongation model d(r2): a pole leaning
    // away whose corrected r2 the model pulled to the fold, or to r1, is not clutter when
    // its measured extent (r2 + d) reaches the fold within one bin.
    t.r2_um = 3001000U;
    const uint32_t rho_c = (uint32_t)(((uint64_t)t.r2_um << 28) / t.r1_um);
    t.incline_flag = SL_INCLINE_AMBIGUOUS;
    t.elong_um = 0;
    assert_int_equal(sl_detect_clutter_reason(&board, &t, rho_c), SL_DETECT_REJ_RHO);
    t.elong_um = 700000;
    assert_int_equal(sl_detect_clutter_reason(&board, &t, rho_c), -1);
    t.elong_um = 2000; // measured rho 1.001: still far below the fold
    assert_int_equal(sl_detect_clutter_reason(&board, &t, rho_c), SL_DETECT_REJ_RHO);
    t.incline_flag = SL_INCLINE_INVALID;
    t.r2_um = 2900000U;
    t.elong_um = 700000;
    assert_int_equal(sl_detect_clutter_reason(&board, &t, 0), -1);
    t.elong_um = 100000; // r2 + d = r1: r1 >= r2 as measured
    assert_int_equal(sl_detect_clutter_reason(&board, &t, 0), SL_DETECT_REJ_RHO);
    t.elong_um = 0;
    t.incline_flag = SL_INCLINE_VALID;
    assert_int_equal(sl_detect_clutter_reason(&board, &t, amb + 1000U), -1);
    t.bin_last = 68;
    assert_int_equal(sl_detect_clutter_reason(&board, &t, amb + 1000U), SL_DETECT_REJ_SHORT);
}

// WEAK: with amplitude rows, a group none of whose runs is clearly above its local floor
// (peak < threshold + 6 and < floor + 20) is rejected; the same bins over a quiet floor, or
// 6 counts over the threshold, are kept. Rows without amplitude are not tested.
static uint8_t amp[NAZ][512];
static void test_detect_rejects_returns_never_clearly_above_the_floor(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    memset(amp, 0, sizeof amp);
    const uint16_t azs[4] = {50, 100, 150, 200};
    for (int i = 0; i < 4; i++) {
        for (int a = azs[i]; a < azs[i] + 4; a++) {
            set_run(a, 69, 82); // a slanted pole's bins
            for (uint32_t k = 60; k < 95; k++) {
                // 50: clutter band (floor 30, peak 45); 100: quiet floor (5), peak 45;
                // 150: floor 35, peak 46 (threshold 40 + 6); 200: like 50, no amplitude.
                const bool in = k >= 69 && k <= 82;
                amp[a][k] = (uint8_t)(i == 1 ? (in ? 45 : 5) : i == 2 ? (in ? 46 : 35) : (in ? 45 : 30));
            }
        }
    }
    sl_detect_begin(&det);
    for (int a = 0; a < NAZ; a++) {
        if (a < 200 || a >= 204) {
            sl_detect_set_amplitude(&det, amp[a], 512, 40);
        }
        assert_int_equal(sl_detect_row(&det, (uint16_t)a, rows[a], NW), SL_OK);
        assert_null(det.amp); // used by one row only
    }
    assert_int_equal(sl_detect_end(&det), 3);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WEAK], 1);
    for (int i = 0; i < 3; i++) {
        assert_true(det.targets[i].az_first != 50);
    }
}

// Grouping with amplitude rows (sl_detect.h stage 2): weak clutter beside a pole, overlapping
// its ranges on the neighbouring azimuths, neither widens its group nor bridges it to the
// ground beyond the shadow edge; it forms groups of its own, rejected WEAK. Without
// amplitude rows the same bits are one group, WIDE.
// run_rotation() with every row's amplitude (amp[], threshold 40).
static int amp_rotation(void)
{
    sl_detect_begin(&det);
    for (int a = 0; a < NAZ; a++) {
        sl_detect_set_amplitude(&det, amp[a], 512, 40);
        assert_int_equal(sl_detect_row(&det, (uint16_t)a, rows[a], NW), SL_OK);
    }
    return (int)sl_detect_end(&det);
}

static void test_detect_weak_clutter_never_joins_a_pole(void **state)
{
    (void)state;
    memset(amp, 0, sizeof amp);
    for (int a = 92; a < 112; a++) {
        for (uint32_t k = 60; k < 100; k++) {
            amp[a][k] = 30; // the clutter band's floor, below the threshold
        }
    }
    for (int a = 100; a < 104; a++) { // the pole: 4 azimuths, far above the floor
        set_run(a, 69, 78);
        for (uint32_t k = 69; k <= 78; k++) {
            amp[a][k] = 90;
        }
    }
    for (int a = 93; a < 111; a++) { // clutter on both sides, just above the threshold
        if (a >= 100 && a < 104) {
            continue;
        }
        const uint32_t f = 70U + (uint32_t)(a % 3);
        set_run(a, f, f + 4U);
        for (uint32_t k = f; k <= f + 4U; k++) {
            amp[a][k] = 42;
        }
    }
    // Without amplitude: one group of 17 azimuths, WIDE.
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 1);
    // With amplitude: the pole alone, and the clutter on each side rejected WEAK.
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(amp_rotation(), 1);
    assert_int_equal(det.targets[0].az_first, 100);
    assert_int_equal(det.targets[0].az_count, 4);
    assert_int_equal(det.targets[0].bin_first, 69);
    assert_int_equal(det.targets[0].bin_last, 78);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WEAK], 2);
    // Clutter reaching the shadow edge (a run into the ground beyond it on azimuth 105)
    // next to the pole: before grading, the pole's group ran into the ground and was
    // rejected SHADOW with it; now the ground's run takes the clutter only.
    const uint32_t edge = det.edge_bins[105];
    memset(rows[105], 0, sizeof rows[105]);
    set_run(105, 72, edge + 20U);
    for (uint32_t k = 72; k <= edge + 20U && k < 512U; k++) {
        amp[105][k] = k < 77U ? 42 : 120;
    }
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(run_rotation(), 0); // without amplitude: all SHADOW
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHADOW], 1);
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(amp_rotation(), 1);
    assert_int_equal(det.targets[0].az_first, 100);
    assert_int_equal(det.targets[0].az_count, 4);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHADOW], 1); // clutter + ground, right
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WEAK], 1);   // clutter, left
}

// Without the gate of a confirmed track, what stops weak clutter from starting a track as a
// pole leaning across the beam: the same one-line group of the SLANT test, but no bin
// clearly above the threshold or its floor, is rejected WEAK; strong, it is SLANT.
static void test_detect_a_weak_line_is_never_slant(void **state)
{
    (void)state;
    sl_detect_cfg_t cfg;
    sl_detect_cfg_default(&cfg);
    memset(amp, 0, sizeof amp);
    set_leaning_pole(100);
    for (int a = 100; a < 113; a++) {
        for (uint32_t k = 60; k < 100; k++) {
            amp[a][k] = sl_bits_get(rows[a], k) ? 42 : 30;
        }
    }
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    det.union_ext = det.slant = true;
    assert_int_equal(amp_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WEAK], 1);
    for (int a = 100; a < 113; a++) {
        for (uint32_t k = 60; k < 100; k++) {
            amp[a][k] = sl_bits_get(rows[a], k) ? 90 : 30;
        }
    }
    assert_int_equal(amp_rotation(), 1);
    assert_true((det.targets[0].flags & SL_TARGET_SLANT) != 0U);
}

// The same pole (k_leaning_pole) on a smearing sensor (sl-eval driveby --realistic): every azimuth's piece
// (level L) is followed by a tail falling 3 values per bin to the threshold 40, (L - 40) / 3
// bins, and the beam's edge azimuths are weaker, so shorter. In bits the runs are ~20 bins
// over nearly the same ranges, the group fills its extent like a wall and the tails' ends
// step against the line: WIDE. With the stream's tail slope known (3 values per bin), each
// entry's own extent is its last bin less the tail its peak leaves: one line, thin, SLANT,
// its representative the pole's lowest point. A smeared car side stays WIDE: its own runs
// fill its extent whatever the slope.
static void smear_piece(int a, uint32_t first, uint32_t own_last, int level)
{
    const uint32_t tail = (uint32_t)(level - 40) / 3U;
    set_run(a, first, own_last + tail);
    for (uint32_t k = first; k <= own_last; k++) {
        amp[a][k] = (uint8_t)level;
    }
    for (uint32_t j = 1; j <= tail; j++) {
        amp[a][own_last + j] = (uint8_t)(level - 3 * (int)j);
    }
}

static void test_detect_a_smeared_pole_leaning_across_the_beam_with_the_tail_slope(void **state)
{
    (void)state;
    static const int level[13] = {79, 91, 100, 100, 100, 100, 100, 100, 100, 100, 100, 91, 79};
    sl_detect_cfg_t cfg;
    sl_detect_cfg_default(&cfg);
    memset(rows, 0, sizeof rows);
    memset(amp, 0, sizeof amp);
    for (int i = 0; i < 13; i++) {
        smear_piece(100 + i, k_leaning_pole[i][0], k_leaning_pole[i][1], level[i]);
    }
    for (int a = 20; a < 40; a++) { // a car side at 3 m, smeared the same way
        smear_piece(a, 68, 75, 100);
    }
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    det.union_ext = det.slant = true;
    assert_int_equal(amp_rotation(), 0); // no slope yet: both WIDE
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 2);
    sl_detect_set_tail_slope(&det, 3U * 256U);
    assert_int_equal(amp_rotation(), 1);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 3);
    const sl_target_t *t = &det.targets[0];
    assert_true((t->flags & SL_TARGET_SLANT) != 0U);
    assert_int_equal(t->az_first, 100);
    assert_int_equal(t->az_count, 13);
    assert_int_equal(t->az, 101); // own extents ending on 89: azimuths 100-102
    assert_int_equal(t->bin_first, 73);
    assert_int_equal(t->bin_last, 89 + 20); // the union's far end, tail included (the
                                            // range profile or d(r) corrects it)
    // A slope three times too steep leaves two thirds of every tail in the own extents: WIDE
    // again. (Twice too steep is within the two bins an own extent may step against the line
    // on a noisy tail here: the weak edge azimuths keep 2 bins more than the strong ones. The
    // calibration's gate keeps a self-fitted slope within +-30 % of its running value.)
    sl_detect_set_tail_slope(&det, 9U * 256U);
    assert_int_equal(amp_rotation(), 0);
    // Not while parked, whatever the slope.
    sl_detect_set_tail_slope(&det, 3U * 256U);
    det.slant = false;
    assert_int_equal(amp_rotation(), 0);
}

// The same smeared pole on the sensor's value scale (0.5 dB per value: the tail near the
// threshold carries a value or two of noise): a tail bin dips below the threshold (a gap the
// run bridges) and a tail's end reads 3 bins long, so that entry's own extent (its last bin
// less the tail its peak leaves) ends 2 bins against the line. Both are within what the
// tail's noise does: SLANT (before: WIDE, no track, on `sl-eval driveby --realistic
// --power-scale` for poles of 20 deg leaning along the path). An own extent 3 bins against
// the line is not one line: WIDE. (A run records how many bins it missed, not where: up to
// the tail's length are allowed anywhere in it; a weak run, whose peak leaves no tail, must
// be whole.)
static int noisy_slanted_pole(uint32_t longer, uint32_t gap_at)
{
    static const int level[13] = {79, 91, 100, 100, 100, 100, 100, 100, 100, 100, 100, 91, 79};
    memset(rows, 0, sizeof rows);
    memset(amp, 0, sizeof amp);
    for (int i = 0; i < 13; i++) {
        smear_piece(100 + i, k_leaning_pole[i][0], k_leaning_pole[i][1], level[i]);
    }
    // azimuth 106 (own bins 77..81, after 78..82): its tail's end `longer` bins further out
    const uint32_t end = 81U + 20U;
    for (uint32_t j = 1; j <= longer; j++) {
        sl_bits_put(rows[106], end + j, true);
        amp[106][end + j] = 41;
    }
    // azimuth 102 (own bins 83..89, tail to 109): tail bin `gap_at` below the threshold
    if (gap_at != 0U) {
        sl_bits_put(rows[102], gap_at, false);
        amp[102][gap_at] = 39;
    }
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    det.union_ext = det.slant = true;
    sl_detect_set_tail_slope(&det, 3U * 256U);
    return amp_rotation();
}

static void test_detect_a_noisy_tail_keeps_a_slanted_pole_one_line(void **state)
{
    (void)state;
    assert_int_equal(noisy_slanted_pole(0U, 0U), 1);
    assert_true((det.targets[0].flags & SL_TARGET_SLANT) != 0U);
    assert_int_equal(noisy_slanted_pole(3U, 105U), 1); // 2 bins against, one gap
    assert_true((det.targets[0].flags & SL_TARGET_SLANT) != 0U);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 0);
    assert_int_equal(noisy_slanted_pole(4U, 0U), 0); // 3 bins against
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_WIDE], 1);
}

// BROKEN on a noisy sensor: a vertical pole's run (own bins 70..73 at 100, a tail falling 3
// values per bin to the threshold: 20 bins) whose tail dips below the threshold at bin 85 is
// a pole while moving once the stream's tail slope is known (the runs' peaks are measured
// then, stage 4: the gap is within the tail's bins); without the slope, parked, or for a
// weak run (a 1-bin tail) with a 2-bin gap, BROKEN.
static int gapped_run(int level)
{
    memset(rows, 0, sizeof rows);
    memset(amp, 0, sizeof amp);
    for (int a = 200; a < 203; a++) {
        smear_piece(a, 70U, 73U, a == 201 ? level : level - 10);
        sl_bits_put(rows[a], 85, false);
        amp[a][85] = 39;
    }
    return amp_rotation();
}

static void test_detect_a_gap_in_a_smear_tail_is_not_a_broken_run(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(gapped_run(100), 0); // no slope yet: BROKEN
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_BROKEN], 1);
    sl_detect_set_tail_slope(&det, 3U * 256U);
    assert_int_equal(gapped_run(100), 0); // parked: no peaks measured, BROKEN
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_BROKEN], 2);
    det.slant = true; // moving (the pipeline sets it with a motion input)
    assert_int_equal(gapped_run(100), 1);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_BROKEN], 2);
    assert_int_equal(det.targets[0].bin_first, 70);
    // weak: peak 44, a 1-bin tail: 2 bins missing are not the tail's
    memset(rows, 0, sizeof rows);
    memset(amp, 0, sizeof amp);
    for (int a = 200; a < 203; a++) {
        set_run(a, 70, 78);
        sl_bits_put(rows[a], 75, false);
        sl_bits_put(rows[a], 76, false);
        for (uint32_t k = 70; k <= 78; k++) {
            amp[a][k] = k == 75 || k == 76 ? 39 : 44;
        }
    }
    assert_int_equal(amp_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_BROKEN] +
                         det.stats.rejected[SL_DETECT_REJ_WEAK], 3);
}

// Stage 1 at the shadow edge with amplitude rows (d(S) a prior, not the truth): a pole
// inside the shadow whose smear tail crosses the edge is kept and flagged TAIL_EDGE; ground
// beyond the edge joined to it (flat, not decaying), a brighter return beyond the edge (a
// base outside the shadow) and, once the stream's tail slope is known, an overshoot longer
// than the inside peak's longest tail are SHADOW; without amplitude the d(S) rule stays.
static int edge_rotation(const uint16_t *azs, int n, bool with_amp)
{
    sl_detect_begin(&det);
    for (int a = 0; a < NAZ; a++) {
        bool ours = false;
        for (int i = 0; i < n; i++) {
            ours = ours || (a >= azs[i] && a < azs[i] + 3);
        }
        if (with_amp && ours) {
            sl_detect_set_amplitude(&det, amp[a], 512, 40);
        }
        assert_int_equal(sl_detect_row(&det, (uint16_t)a, rows[a], NW), SL_OK);
    }
    return (int)sl_detect_end(&det);
}

static void edge_case(int az0, uint32_t end, int (*level)(uint32_t k))
{
    for (int a = az0; a < az0 + 3; a++) {
        set_run(a, 110, end);
        for (uint32_t k = 100; k < 512; k++) {
            const int v = level(k);
            amp[a][k] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
        }
    }
}

// own bins 110..120 at 110, then a tail falling 3 values per bin (to 40 at bin 144)
static int lvl_tail(uint32_t k)
{
    return k < 110 ? 5 : k <= 120 ? 110 : 110 - 3 * (int)(k - 120);
}
// the same pole joined to flat ground at 60 from the edge on
static int lvl_ground(uint32_t k)
{
    return k < 128 ? lvl_tail(k) : 60;
}
// a brighter return beyond the edge
static int lvl_bright(uint32_t k)
{
    return k < 110 ? 5 : k < 136 ? 80 : 120 - (int)(k - 136);
}
// a slow decay: 1 value per bin from 100 at bin 120 (reaches 40 at bin 180)
static int lvl_slow(uint32_t k)
{
    return k < 110 ? 5 : k <= 120 ? 100 : 100 - (int)(k - 120);
}

static void test_detect_shadow_edge_tail_is_not_the_ground(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    memset(amp, 0, sizeof amp);
    const uint32_t s_bin = det.edge_bins[0]; // no elongation table: the edge bin itself
    assert_int_equal(s_bin, 134U);
    const uint16_t azs[4] = {50, 100, 150, 200};
    edge_case(50, 143, lvl_tail);     // tail to bin 143: 9 bins past the edge
    edge_case(100, 300, lvl_ground);  // joined to the ground
    edge_case(150, 140, lvl_bright);  // brighter beyond the edge
    edge_case(200, 179, lvl_slow);    // slow tail, 45 bins past the edge
    // The d(S) rule without amplitude rows: all four SHADOW.
    assert_int_equal(edge_rotation(azs, 4, false), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHADOW], 4);
    // With amplitude, no tail slope known yet: the tail and the slow tail pass, flagged.
    assert_int_equal(edge_rotation(azs, 4, true), 2);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHADOW], 6);
    assert_int_equal(det.targets[0].az_first, 50);
    assert_int_equal(det.targets[1].az_first, 200);
    for (int i = 0; i < 2; i++) {
        assert_true((det.targets[i].flags & SL_TARGET_TAIL_EDGE) != 0U);
        assert_int_equal(det.targets[i].bin_first, 110);
    }
    // The stream's tail is 3 values per bin: the inside peak (110 and 100) leaves at most
    // ceil(70 / 3) = 24 and 20 bins past the window end (135): the 9-bin tail stays,
    // the 45-bin slow one is the ground.
    sl_detect_set_tail_slope(&det, 3U * 256U);
    assert_int_equal(edge_rotation(azs, 4, true), 1);
    assert_int_equal(det.targets[0].az_first, 50);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHADOW], 9);
    // A tail slope of 1 value per bin allows the slow one again.
    sl_detect_set_tail_slope(&det, 256U);
    assert_int_equal(edge_rotation(azs, 4, true), 2);
    // Inside the window nothing changes: a run ending before the edge is not flagged.
    memset(rows, 0, sizeof rows);
    edge_case(50, 130, lvl_tail);
    assert_int_equal(edge_rotation(azs, 1, true), 1);
    assert_int_equal(det.targets[0].flags & SL_TARGET_TAIL_EDGE, 0);
}

static void test_detect_slots_go_to_the_strongest_not_the_lowest_azimuths(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    // 20 clutter returns that pass every test (6 bins, one azimuth each, valid rho) at the
    // lowest azimuths, then two poles at higher azimuths: 22 candidates for 16 slots.
    for (int k = 0; k < 20; k++) {
        set_run(10 + 4 * k, 110, 115);
    }
    for (int a = 300; a < 305; a++) {
        set_run(a, 69, 82);
    }
    for (int a = 350; a < 354; a++) {
        set_run(a, 70, 76);
    }
    assert_int_equal(run_rotation(), 16);
    assert_int_equal(det.stats.target_overflow, 6);
    int poles = 0, clutter = 0;
    for (int i = 0; i < 16; i++) {
        const sl_target_t *t = &det.targets[i];
        if (t->az_first == 300 || t->az_first == 350) {
            poles++;
            assert_true(t->evidence > sl_detect_evidence(6, 1, 6));
        } else {
            clutter++;
            assert_int_equal(t->evidence, sl_detect_evidence(6, 1, 6));
        }
    }
    assert_int_equal(poles, 2);
    assert_int_equal(clutter, 14);
    assert_int_equal(sl_detect_evidence(6, 1, 6), 4 * 6 + 16 + 8 * 6);
    assert_int_equal(sl_detect_evidence(100000, 0, 0), 0xFFFF);
    // A hint (a confirmed track expected there) keeps a weak return's slot: the clutter
    // return at azimuth 90 is hinted and survives 21 stronger candidates (20 copies of the
    // second pole's shape at azimuths 110..300 and the pole at 350).
    memset(rows, 0, sizeof rows);
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    sl_detect_hint(&det, 91, 1); // 90..92
    set_run(90, 110, 115);
    for (int k = 0; k < 20; k++) {
        for (int a = 110 + 10 * k; a < 114 + 10 * k; a++) {
            set_run(a, 70, 76);
        }
    }
    for (int a = 350; a < 354; a++) {
        set_run(a, 70, 76);
    }
    assert_int_equal(run_rotation(), 16);
    int hinted = 0;
    for (int i = 0; i < 16; i++) {
        if (det.targets[i].az == 90) {
            hinted++;
            assert_int_equal(det.targets[i].evidence,
                             sl_detect_evidence(6, 1, 6) + SL_DETECT_EVIDENCE_TRACK);
        }
    }
    assert_int_equal(hinted, 1);
    assert_int_equal(det.stats.target_overflow, 6);
    // Hints wrap around azimuth 0 and are cleared explicitly.
    sl_detect_hints_clear(&det);
    sl_detect_hint(&det, 1, 2); // 399, 0, 1, 2, 3
    assert_int_equal(det.hint_bits[0], 0xFU);
    assert_int_equal(det.hint_bits[(NAZ - 1) / 32] >> ((NAZ - 2) % 32), 0x2U);
    sl_detect_hint(&det, NAZ, 2); // out of range: ignored
    sl_detect_hints_clear(&det);
    for (unsigned w = 0; w < (NAZ + 31) / 32; w++) {
        assert_int_equal(det.hint_bits[w], 0);
    }
}

static void test_detect_handles_empty_saturated_and_misordered_input(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(run_rotation(), 0); // empty
    memset(rows, 0xFF, sizeof rows);     // saturated: one band-connected group, NEAR
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_NEAR], 1);
    memset(rows, 0, sizeof rows);
    sl_detect_begin(&det);
    assert_int_equal(sl_detect_row(&det, 5, rows[5], NW), SL_OK);
    assert_int_equal(sl_detect_row(&det, 5, rows[5], NW), SL_ERR_RANGE);
    assert_int_equal(sl_detect_row(&det, 4, rows[4], NW), SL_ERR_RANGE);
    assert_int_equal(sl_detect_row(&det, NAZ, rows[4], NW), SL_ERR_RANGE);
    assert_int_equal(det.stats.order_errors, 3);
    assert_int_equal(sl_detect_end(&det), 0);
    assert_int_equal(sl_detect_row(&det, 6, rows[6], NW), SL_ERR_RANGE); // after end
    // Too many separate runs on one azimuth (no gap bridging): groups and targets overflow.
    sl_detect_cfg_t cfg;
    sl_detect_cfg_default(&cfg);
    cfg.gap_bins = 0;
    assert_int_equal(sl_detect_init(&det, &board, &cfg), SL_OK);
    for (uint32_t k = 40; k <= 132U; k += 2U) {
        set_run(7, k, k); // 47 one-bin runs
    }
    // Every group that got a slot is a single bin: rejected SHORT before taking a target slot.
    assert_int_equal(run_rotation(), 0);
    assert_int_equal(det.stats.runs, 47);
    assert_int_equal(det.stats.cand_overflow, 47 - SL_CFG_DETECT_MAX_CANDIDATES);
    assert_int_equal(det.stats.rejected[SL_DETECT_REJ_SHORT], SL_CFG_DETECT_MAX_CANDIDATES);
    assert_int_equal(det.stats.target_overflow, 0);
    // Init rejects boards it cannot use.
    sl_board_t bad = board;
    bad.shadow_um = NULL;
    bad.shadow_bins = NULL;
    assert_int_equal(sl_detect_init(&det, &bad, NULL), SL_ERR_ARG);
    bad = board;
    bad.bin_size_um = 0;
    assert_int_equal(sl_detect_init(&det, &bad, NULL), SL_ERR_ARG);
    assert_int_equal(sl_detect_init(NULL, &board, NULL), SL_ERR_ARG);
}

static void test_detect_correct_half_bin_elongation_and_radius(void **state)
{
    (void)state;
    sl_target_t t;
    memset(&t, 0, sizeof t);
    // A point target in one bin: r1 = r2 = the bin centre.
    sl_detect_correct(&board, NULL, 0, 70, 70, 2, &t);
    assert_int_equal(t.r1_raw_um, 70U * BIN_UM);
    assert_int_equal(t.r2_raw_um, 71U * BIN_UM);
    assert_int_equal(t.r1_um, 70U * BIN_UM + BIN_UM / 2U);
    assert_int_equal(t.r2_um, t.r1_um);
    assert_int_equal(t.flags & SL_TARGET_ELONG, 0);
    // Elongation table of the paper's bench: 1.75:0.806, 2.30:0.806, 2.38:0.741 (m).
    sl_board_t b = board;
    b.elong_points = 3;
    b.elong_range_um[0] = 1750000;
    b.elong_d_um[0] = 806000;
    b.elong_range_um[1] = 2300000;
    b.elong_d_um[1] = 806000;
    b.elong_range_um[2] = 2380000;
    b.elong_d_um[2] = 741000;
    assert_int_equal(sl_detect_elong_um(&b, 1000000), 806000);
    assert_int_equal(sl_detect_elong_um(&b, 2000000), 806000);
    assert_int_equal(sl_detect_elong_um(&b, 2340000), 773500);
    assert_int_equal(sl_detect_elong_um(&b, 2380000), 741000);
    assert_int_equal(sl_detect_elong_um(&b, 9000000), 741000);
    assert_int_equal(sl_detect_elong_um(&board, 2000000), 0);
    sl_detect_correct(&b, NULL, 0, 50, 80, 2, &t); // r2 centre 3.5259 m: d = 0.741 m
    assert_int_equal(t.elong_um, 741000);
    assert_int_equal(t.r2_um, half_bin_um(80) - 741000U);
    assert_int_equal(t.r1_um, half_bin_um(50));
    assert_true((t.flags & SL_TARGET_ELONG) != 0U);
    // Board radius 0.1 m: r1 += R; r2 += sqrt(R^2 - L^2), L = r1 tan(0.9 deg).
    b = board;
    b.pole_radius_um = 100000;
    sl_detect_correct(&b, NULL, 0, 60, 80, 3, &t);
    const double r1 = half_bin_um(60) * 1e-6, L = r1 * tan(0.9 * kPi / 180.0);
    const double add2 = sqrt(0.1 * 0.1 - L * L);
    assert_int_equal(t.radius_um, 100000);
    assert_true((t.flags & SL_TARGET_RADIUS_BOARD) != 0U);
    assert_int_equal(t.r1_um, half_bin_um(60) + 100000U);
    assert_true(fabs((double)t.r2_um - (half_bin_um(80) + add2 * 1e6)) < 30.0);
    // Width estimate clamped.
    sl_detect_cfg_t cfg;
    sl_detect_cfg_default(&cfg);
    cfg.max_radius_um = 20000;
    sl_detect_correct(&board, &cfg, 0, 60, 80, 12, &t);
    assert_int_equal(t.radius_um, 20000);
    assert_true((t.flags & SL_TARGET_RADIUS_CLAMPED) != 0U);
}

// End to end over threshold + mask + detect: a static scene with a near-field band, a
// pole, ground beyond the shadow and flickering clutter; the pole appears after n rotations.
static sl_mask_t mask;
static void test_detect_from_mask_reports_the_pole_after_n_stable_rotations(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(sl_mask_init(&mask, NAZ, 512, 16, 2), SL_OK);
    static uint8_t power[512];
    uint32_t bits[NW];
    uint64_t rng = 12345;
    uint32_t f, l;
    double r1m, r2m;
    pole_bins(3.0, 5.0, &f, &l, &r1m, &r2m);
    for (int rot = 1; rot <= 20; rot++) {
        for (int a = 0; a < NAZ; a++) {
            for (int k = 0; k < 512; k++) {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                uint8_t v = (uint8_t)(rng & 31U); // floor below threshold
                if (k < 36) {
                    v = 80; // near-field band
                }
                if (k >= 134 && (rng >> 20) % 3U == 0U) {
                    v = 60; // flickering ground clutter beyond the shadow
                }
                if (k >= 160 && k < 170) {
                    v = 90; // a stable wall outside the shadow
                }
                if ((a == 120 || a == 121 || a == 122) && k >= (int)f && k <= (int)l) {
                    v = 100; // the pole
                }
                if (a == 300 && k >= 90 && k < 95 && (rng >> 30) % 2U == 0U) {
                    v = 100; // a flickering object inside the shadow: never stable
                }
                power[k] = v;
            }
            sl_thresh_u8(power, 512, board.threshold, bits);
            assert_int_equal(sl_mask_update(&mask, (uint16_t)a, bits, NULL, NULL), SL_OK);
        }
        sl_mask_end_rotation(&mask);
        const sl_ssize_t n = sl_detect_rotation_from_mask(&det, &mask);
        if (rot < 16) {
            assert_int_equal(n, 0);
        } else {
            assert_int_equal(n, 1);
            assert_int_equal(det.targets[0].az, 121);
            assert_int_equal(det.targets[0].bin_first, f);
            assert_int_equal(det.targets[0].bin_last, l);
            assert_int_equal(det.targets[0].incline_flag, SL_INCLINE_VALID);
            assert_true(fabs(det.targets[0].alpha_cdeg / 100.0 - 5.0) < 1.5);
        }
    }
}

// The generated paper-sim board (when linked) gives the same geometry as the one built here.
static void test_detect_agrees_with_the_generated_paper_sim_board(void **state)
{
    (void)state;
    const sl_board_t *ps = sl_board_find("paper-sim");
    if (ps == NULL) {
        skip();
    }
    assert_int_equal(sl_detect_init(&det, ps, NULL), SL_OK);
    const double s_m = sqrt(pow(ps->shadow_um[0] * 1e-6, 2) + pow(ps->radar_height_um * 1e-6, 2));
    assert_int_equal(det.win_bins[0], (uint16_t)ceil(s_m / (ps->bin_size_um * 1e-6)));
    assert_int_equal(det.near_bins, ps->near_exclusion_bins);
    uint32_t f, l;
    double r1m, r2m;
    pole_bins(3.0, 10.0, &f, &l, &r1m, &r2m);
    set_run(10, f, l);
    set_run(11, f, l);
    set_run(12, f, l);
    assert_int_equal(run_rotation(), 1);
    const sl_target_t got = det.targets[0];
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(got.r1_um, det.targets[0].r1_um);
    assert_int_equal(got.r2_um, det.targets[0].r2_um);
    assert_int_equal(got.incline_flag, SL_INCLINE_VALID);
    assert_true(abs(got.alpha_cdeg - det.targets[0].alpha_cdeg) <= 1);
}

// A leaning pole spreads in bearing along its length: the group is wide, but the column at
// its inner edge is narrow. The radius comes from that column (docs/DESIGN.md, "Detection"), not from
// the group (which would give the clamp).
static void test_detect_radius_from_the_column_at_the_inner_edge(void **state)
{
    (void)state;
    assert_int_equal(sl_detect_init(&det, &board, NULL), SL_OK);
    // 9 azimuths; the inner slab (bins 64..66) is reached only on azimuths 40..42 (the
    // strongest columns), the others slide outward by 3 bins per azimuth (3 columns: w = 2 x 0.9 - 1.8
    // = 0 deg, R = 0; the whole group would give 8 x 0.9 - 1.8 = 5.4 deg).
    for (int a = 40; a < 49; a++) {
        if (a <= 42) {
            set_run(a, 64, 76);
        } else {
            set_run(a, (uint32_t)(64 + 3 * (a - 42)), (uint32_t)(64 + 3 * (a - 42) + 8));
        }
    }
    assert_int_equal(run_rotation(), 1);
    assert_int_equal(det.targets[0].az_count, 9);
    assert_int_equal(det.targets[0].bin_first, 64);
    assert_true((det.targets[0].flags & SL_TARGET_RADIUS_CLAMPED) == 0U);
    assert_true((det.targets[0].flags & SL_TARGET_RADIUS_WIDTH) != 0U);
    assert_int_equal(det.targets[0].radius_um, 0);
    // Six columns cover the inner bin: w = 5 x 0.9 - 1.8 = 2.7 deg.
    memset(rows, 0, sizeof rows);
    for (int a = 40; a < 49; a++) {
        if (a <= 45) {
            set_run(a, 64, 76);
        } else {
            set_run(a, (uint32_t)(64 + 3 * (a - 45)), (uint32_t)(64 + 3 * (a - 45) + 8));
        }
    }
    assert_int_equal(run_rotation(), 1);
    const sl_target_t *t = &det.targets[0];
    assert_int_equal(t->bin_first, 64);
    const double r1 = half_bin_um((uint16_t)t->bin_first) * 1e-6;
    const double rexp = r1 * tan(2.7 / 2.0 * kPi / 180.0) * 1e6;
    assert_true(fabs((double)t->radius_um - rexp) < rexp * 0.01 + 2.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_detect_finds_a_slanted_pole_with_corrected_bounds, setup),
        cmocka_unit_test_setup(test_detect_estimates_a_leaning_away_pole_on_branch_two, setup),
        cmocka_unit_test_setup(test_detect_never_reports_the_near_field_band, setup),
        cmocka_unit_test_setup(test_detect_never_reports_ground_outside_the_shadow, setup),
        cmocka_unit_test_setup(test_detect_rejects_wide_and_broken_returns, setup),
        cmocka_unit_test_setup(test_detect_keeps_a_pole_leaning_across_the_beam_while_moving,
                               setup),
        cmocka_unit_test_setup(test_detect_groups_across_the_azimuth_wrap, setup),
        cmocka_unit_test_setup(test_detect_merges_groups_joined_by_a_later_azimuth, setup),
        cmocka_unit_test_setup(test_detect_handles_empty_saturated_and_misordered_input, setup),
        cmocka_unit_test_setup(test_detect_rejects_clutter_before_it_takes_a_slot, setup),
        cmocka_unit_test_setup(test_detect_rejects_returns_never_clearly_above_the_floor, setup),
        cmocka_unit_test_setup(test_detect_weak_clutter_never_joins_a_pole, setup),
        cmocka_unit_test_setup(test_detect_a_weak_line_is_never_slant, setup),
        cmocka_unit_test_setup(test_detect_a_noisy_tail_keeps_a_slanted_pole_one_line, setup),
        cmocka_unit_test_setup(test_detect_a_gap_in_a_smear_tail_is_not_a_broken_run, setup),
        cmocka_unit_test_setup(test_detect_a_smeared_pole_leaning_across_the_beam_with_the_tail_slope,
                               setup),
        cmocka_unit_test_setup(test_detect_shadow_edge_tail_is_not_the_ground, setup),
        cmocka_unit_test_setup(test_detect_slots_go_to_the_strongest_not_the_lowest_azimuths, setup),
        cmocka_unit_test_setup(test_detect_correct_half_bin_elongation_and_radius, setup),
        cmocka_unit_test_setup(test_detect_radius_from_the_column_at_the_inner_edge, setup),
        cmocka_unit_test_setup(test_detect_from_mask_reports_the_pole_after_n_stable_rotations,
                               setup),
        cmocka_unit_test_setup(test_detect_agrees_with_the_generated_paper_sim_board, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
