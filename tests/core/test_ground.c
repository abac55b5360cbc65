// SPDX-License-Identifier: MIT
// Unit tests of the ground from the shadow's edge (sl_ground.h) on synthetic rows of the
// paper-sim board: the ground return starts where the ray at the board's theta meets a
// plane (height, pitch, roll) plus terrain; its power is a step from the floor to the
// ground's level through a Gaussian range response (sigma 3.4 bins, the CTS350-X's), on
// the CTS350-X value scale, optionally with single-look speckle (exponential power). Past the
// edge the ground's level falls as (e / r)^3 (flat ground).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <math.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_ground.h"

#define BINS 320U

static const double kPi = 3.14159265358979323846;

static const sl_board_t *board(void)
{
    const sl_board_t *b = sl_board_find("paper-sim");
    assert_non_null(b);
    return b;
}

typedef struct truth {
    double h_m, pitch_deg, roll_deg; // h: the plane's depth below the radar at its foot;
                                     // ISO 8855: pitch nose down > 0, roll right down > 0
    double drop_m;                   // extra depth of the ground in [az_lo, az_hi) deg
    double az_lo, az_hi;
    double drop_x_m;                 // > 0: ground lower from this forward distance on
    double drop_dx_m;                // ... its depth
    bool speckle;
    uint64_t seed;
    double pole_az;                  // a pole in the shadow at this azimuth (deg, < 0: none)
} truth_t;

static double rnd(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return ((double)(*s >> 11) + 0.5) / 9007199254740992.0;
}

// Slant range of the ground's start on azimuth phi (vehicle frame, deg clockwise).
static double edge_m(const truth_t *t, double phi_deg, double theta_deg)
{
    const double th = theta_deg * kPi / 180.0, ph = phi_deg * kPi / 180.0;
    const double a = -tan(t->pitch_deg * kPi / 180.0), b = tan(t->roll_deg * kPi / 180.0);
    const double ux = cos(ph), uy = -sin(ph);
    double extra = 0;
    if (phi_deg >= t->az_lo && phi_deg < t->az_hi) {
        extra = t->drop_m;
    }
    // depth of the plane along the ray: h + rho (a ux + b uy); rho = s cos(theta)
    double s = (t->h_m + extra) / (sin(th) - cos(th) * (a * ux + b * uy));
    if (t->drop_dx_m != 0 && ux > 0 && s * cos(th) * ux > t->drop_x_m) {
        s = (t->h_m + extra + t->drop_dx_m) / (sin(th) - cos(th) * (a * ux + b * uy));
    }
    return s;
}

static double cdf(double x)
{
    return 0.5 * erfc(-x / (3.4 * sqrt(2.0)));
}

// 8-bit row on the CTS350-X scale (6.02 values per octave of power).
static void make_row(uint8_t *row, double e_bins, const truth_t *t, uint64_t *rs, bool pole)
{
    const double floor_p = pow(2.0, 12.0 / 6.02), ground_p = pow(2.0, 70.0 / 6.02);
    for (unsigned k = 0; k < BINS; k++) {
        // flat ground: the level falls as (e / r)^3 past the edge (sl_ground.h, step 3)
        const double x = k + 0.5 > e_bins ? k + 0.5 : e_bins;
        double p = floor_p + ground_p * cdf(k + 0.5 - e_bins) * pow(e_bins / x, 3.0);
        if (pole && k >= 80 && k < 90) {
            p += pow(2.0, 90.0 / 6.02);
        }
        if (t->speckle) {
            p *= -log(rnd(rs));
        }
        double v = 6.02 * log2(p);
        v = v < 0 ? 0 : (v > 255 ? 255 : v);
        row[k] = (uint8_t)lround(v);
    }
}

static void rotation(sl_ground_t *g, const truth_t *t, uint64_t *rs)
{
    const sl_board_t *b = board();
    uint8_t row[BINS];
    for (unsigned az = 0; az < b->azimuths; az++) {
        if (az != sl_ground_want(g)) {
            sl_ground_row(g, (uint16_t)az, NULL, 0U, NULL, 0U); // not read: O(1)
            continue;
        }
        const double phi = az * 360.0 / b->azimuths + b->radar_yaw_cdeg / 100.0;
        const double e = edge_m(t, phi, b->theta_cdeg[az] / 100.0) / (b->bin_size_um * 1e-6);
        const bool pole = t->pole_az >= 0 && fabs(phi - t->pole_az) < 0.5;
        make_row(row, e, t, rs, pole);
        sl_ground_row(g, (uint16_t)az, row, BINS, NULL, 0U);
    }
    sl_ground_end_rotation(g);
}

static void run(sl_ground_t *g, const truth_t *t, int rotations)
{
    uint64_t rs = t->seed != 0 ? t->seed : 0x9E3779B97F4A7C15ULL;
    for (int i = 0; i < rotations; i++) {
        rotation(g, t, &rs);
    }
}

static void init(sl_ground_t *g)
{
    assert_int_equal(sl_ground_init(g, board(), NULL), SL_OK);
}

static int hazards(const sl_ground_t *g, uint8_t kind)
{
    int n = 0;
    for (unsigned k = 0; k < SL_CFG_GROUND_SECTORS; k++) {
        n += g->sec[k].kind == kind;
    }
    return n;
}

static void test_edge_sub_bin(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    const truth_t t = {0};
    uint8_t row[BINS];
    for (int i = 0; i < 16; i++) {
        const double e = 130.0 + i / 16.0;
        make_row(row, e, &t, NULL, false);
        const int32_t q = sl_ground_edge_q8(&g, row, BINS, NULL, 0U, (int32_t)(134.3 * 256), NULL);
        assert_true(q > 0);
        // the 8-bit values' rounding (0.5 dB: +-3 % of a bin's power) is the only error:
        // within 0.25 bin (0.5 cm of depth)
        assert_true(fabs(q / 256.0 - e) < 0.25);
    }
}

static void test_edge_errors(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    const truth_t t = {0};
    uint8_t row[BINS];
    make_row(row, 134.0, &t, NULL, true);
    assert_int_equal(sl_ground_edge_q8(&g, row, BINS, NULL, 0U, 134 * 256, NULL), SL_GROUND_EDGE_OCCUPIED);
    // the same from the thresholded bits (word-wise)
    uint32_t bits[BINS / 32U] = {0};
    for (unsigned k = 0; k < 128U; k++) {
        bits[k / 32U] |= (row[k] >= 40U ? 1U : 0U) << (k % 32U);
    }
    memset(row + 80, 0, 10); // the bytes no longer show it: the bits do
    assert_int_equal(sl_ground_edge_q8(&g, row, BINS, bits, 128U, 134 * 256, NULL), SL_GROUND_EDGE_OCCUPIED);
    memset(row, 5, sizeof row);
    assert_int_equal(sl_ground_edge_q8(&g, row, BINS, NULL, 0U, 134 * 256, NULL), SL_GROUND_EDGE_NO_GROUND);
    make_row(row, 134.0, &t, NULL, false);
    assert_int_equal(sl_ground_edge_q8(&g, row, 150U, NULL, 0U, 134 * 256, NULL), SL_GROUND_EDGE_SHORT);
    sl_ground_cfg_t cfg;
    sl_ground_cfg_default(&cfg, board());
    cfg.margin_bins = 0U;
    assert_int_equal(sl_ground_init(&g, board(), &cfg), SL_ERR_ARG);
    assert_int_equal(sl_ground_init(NULL, board(), NULL), SL_ERR_ARG);
}

static void test_flat_level(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    const truth_t t = {.h_m = 2.58, .pole_az = -1};
    run(&g, &t, 16);
    assert_int_equal(g.plane.quality, SL_GROUND_GOOD);
    assert_int_equal(g.plane.sectors, SL_CFG_GROUND_SECTORS);
    assert_true(abs(g.plane.height_mm - 2580) <= 3);
    assert_true(abs(g.plane.pitch_cdeg) <= 3);
    assert_true(abs(g.plane.roll_cdeg) <= 3);
    assert_int_equal(hazards(&g, SL_GROUND_DROP) + hazards(&g, SL_GROUND_STEP), 0);
    assert_int_equal(sl_ground_worst(&g), -1);
}

// Attitude with speckle: pitch and roll within 0.3 deg, height within 2 cm, sigmas that
// cover the errors.
static void test_attitude_speckle(void **state)
{
    (void)state;
    const double cases[][3] = {{2.58, 2.0, -1.5}, {2.45, -3.0, 0.5}, {2.70, 0.0, 4.0}};
    for (unsigned c = 0; c < 3; c++) {
        sl_ground_t g;
        init(&g);
        const truth_t t = {.h_m = cases[c][0], .pitch_deg = cases[c][1], .roll_deg = cases[c][2],
                           .speckle = true, .seed = 11U + c, .pole_az = -1};
        run(&g, &t, 40);
        // the height above the plane, perpendicular: the depth below the radar at its foot
        // (the truth's h) over sqrt(1 + a^2 + b^2)
        const double ta = tan(cases[c][1] * kPi / 180.0), tb = tan(cases[c][2] * kPi / 180.0);
        const double eh = g.plane.height_mm - cases[c][0] * 1000 / sqrt(1 + ta * ta + tb * tb);
        const double ep = g.plane.pitch_cdeg / 100.0 - cases[c][1];
        const double er = g.plane.roll_cdeg / 100.0 - cases[c][2];
        print_message("attitude %u: h %d mm (err %.1f, sigma %u) pitch %.2f (err %.2f, sigma %.2f) "
                      "roll %.2f (err %.2f, sigma %.2f) q %u\n",
                      c, g.plane.height_mm, eh, g.plane.height_sigma_mm, g.plane.pitch_cdeg / 100.0,
                      ep, g.plane.pitch_sigma_cdeg / 100.0, g.plane.roll_cdeg / 100.0, er,
                      g.plane.roll_sigma_cdeg / 100.0, g.plane.quality);
        assert_true(fabs(eh) <= 20.0);
        assert_true(fabs(ep) <= 0.3);
        assert_true(fabs(er) <= 0.3);
        assert_true(g.plane.quality != SL_GROUND_NONE);
        assert_int_equal(hazards(&g, SL_GROUND_DROP) + hazards(&g, SL_GROUND_STEP), 0);
    }
}

static void test_drop_and_step_sectors(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    // a ditch 0.2 m deep over 30 deg to the right; the plane must not follow it
    truth_t t = {.h_m = 2.58, .drop_m = 0.2, .az_lo = 80, .az_hi = 110, .pole_az = -1};
    run(&g, &t, 16);
    assert_true(hazards(&g, SL_GROUND_DROP) >= 2);
    assert_int_equal(hazards(&g, SL_GROUND_STEP), 0);
    assert_true(abs(g.plane.height_mm - 2580) <= 5);
    assert_true(abs(g.plane.roll_cdeg) <= 5);
    const int w = sl_ground_worst(&g);
    assert_true(w >= 0);
    const int32_t cd = sl_ground_sector_cdeg(&g, (uint32_t)w);
    assert_true(cd >= 8000 && cd < 11000);
    assert_true(abs(g.sec[w].resid_mm - 200) <= 15);
    // a kerb 0.1 m high on the left
    sl_ground_t g2;
    init(&g2);
    truth_t k = {.h_m = 2.58, .drop_m = -0.1, .az_lo = 250, .az_hi = 290, .pole_az = -1};
    run(&g2, &k, 16);
    assert_true(hazards(&g2, SL_GROUND_STEP) >= 2);
    assert_int_equal(hazards(&g2, SL_GROUND_DROP), 0);
    // cleared when the ground is back at the plane (hysteresis: confirm samples)
    t.drop_m = 0;
    run(&g, &t, 8);
    assert_int_equal(hazards(&g, SL_GROUND_DROP), 0);
}

// A 10 cm change in one sample is not a STEP: confirm samples are needed.
static void test_confirmation(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    truth_t t = {.h_m = 2.58, .pole_az = -1};
    run(&g, &t, 12);
    t.drop_m = 0.3;
    t.az_lo = 0;
    t.az_hi = 20;
    run(&g, &t, 1);
    assert_int_equal(hazards(&g, SL_GROUND_DROP), 0);
    run(&g, &t, 12); // parked: the mean over 8 samples, then 3 confirming samples
    assert_true(hazards(&g, SL_GROUND_DROP) >= 1);
}

// A pole standing in the shadow: its azimuth's rows are skipped, the plane is unchanged.
static void test_pole_in_shadow(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    const truth_t t = {.h_m = 2.58, .pole_az = 45.9};
    run(&g, &t, 40);
    assert_true(g.stats.occupied > 0U);
    assert_true(abs(g.plane.height_mm - 2580) <= 3);
    assert_int_equal(hazards(&g, SL_GROUND_DROP) + hazards(&g, SL_GROUND_STEP), 0);
}

// No ground anywhere: no plane, quality NONE, counted.
static void test_no_ground(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    uint8_t row[BINS];
    memset(row, 3, sizeof row);
    for (int r = 0; r < 4; r++) {
        for (unsigned az = 0; az < board()->azimuths; az++) {
            sl_ground_row(&g, (uint16_t)az, row, BINS, NULL, 0U);
        }
        sl_ground_end_rotation(&g);
    }
    assert_int_equal(g.plane.quality, SL_GROUND_NONE);
    assert_int_equal(g.stats.planes, 0U);
    assert_true(g.stats.no_ground >= 4U * SL_CFG_GROUND_SECTORS);
}

// Driving at 1 m/s towards a drop-off 0.2 m deep: warned (DROP ahead, with the distance)
// while the radar is still more than 2.5 m from the edge (the paper-sim body's front is
// 1 m ahead of the radar: 1.5 m to spare), the distance never further than the edge by
// more than half a rotation's travel + 0.1 m, and nearer by at most 1 m (a noisy single
// sample on the plane dates the crossing early: the near side, the safe one).
static void test_drop_ahead_moving(void **state)
{
    (void)state;
    sl_ground_t g;
    init(&g);
    const double edge_x = 9.0; // world x of the drop-off; the radar starts at 0
    uint64_t rs = 7U;
    double first_dist = -1, first_true = -1;
    for (int r = 0; r < 60; r++) {
        const double xr = r * 0.25; // 1 m/s, 4 Hz
        truth_t t = {.h_m = 2.58, .drop_x_m = edge_x - xr, .drop_dx_m = 0.2, .speckle = true,
                     .seed = 1, .pole_az = -1};
        sl_ground_set_motion(&g, true, 1000, 250000U);
        rotation(&g, &t, &rs);
        if (first_dist < 0) {
            for (unsigned k = 0; k < SL_CFG_GROUND_SECTORS; k++) {
                const int32_t cd = sl_ground_sector_cdeg(&g, k);
                if (g.sec[k].kind == SL_GROUND_DROP && (cd < 3000 || cd > 33000)) {
                    first_dist = g.sec[k].hx_um * 1e-6;
                    first_true = edge_x - xr;
                }
            }
        }
    }
    print_message("drop ahead: first warning at %.2f m (true %.2f m)\n", first_dist, first_true);
    assert_true(first_true > 2.5);
    assert_true(first_dist - first_true < 0.225);
    assert_true(first_true - first_dist < 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edge_sub_bin),
        cmocka_unit_test(test_edge_errors),
        cmocka_unit_test(test_flat_level),
        cmocka_unit_test(test_attitude_speckle),
        cmocka_unit_test(test_drop_and_step_sectors),
        cmocka_unit_test(test_confirmation),
        cmocka_unit_test(test_pole_in_shadow),
        cmocka_unit_test(test_no_ground),
        cmocka_unit_test(test_drop_ahead_moving),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
