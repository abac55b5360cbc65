// SPDX-License-Identifier: MIT
// Unit tests for sl_incline.h: the fixed-point inclination estimator against a plain libm
// double oracle written here (MATH.md s.2-3). The geometry entries are built here with
// libm too, with the same rounding rule as sl::make_geom (llround of each exact value), so
// this test runs on the cross targets (aarch64, s390x under qemu-user) without host tools.
//
// Sweep (test_incline_alpha_and_sigma_match_double_oracle_over_sweep): theta 5..34 deg in
// 0.5 deg steps (59) x beta 0..5 deg in 1 deg steps (6) = 354 geometries; for each, rho on
// SWEEP_LOG points spread geometrically from the ambiguity bound to 10, SWEEP_B2 points
// across branch 2, the seam +-SEAM_LSB LSB and the ambiguity bound +0..+AMB_LSB LSB.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_incline.h"

#define SWEEP_LOG 400
#define SWEEP_B2 150
#define SEAM_LSB 8
#define AMB_LSB 4

// Bounds asserted (sl_incline.h states them).
#define MAX_ERR_BAM_DEG 1.0e-4
#define MAX_ERR_CDEG_DEG 0.01
#define SIGMA_ABS_CDEG 0.5
#define SIGMA_REL 1.0e-4

static const double PI = 3.14159265358979323846;

static double rad(double deg)
{
    return deg * PI / 180.0;
}

static double deg(double r)
{
    return r * 180.0 / PI;
}

static int32_t q30(double v)
{
    return (int32_t)llround(v * 1073741824.0);
}

static uint32_t uq28(double v)
{
    const double s = v * 268435456.0;
    return (s >= 4294967295.0) ? UINT32_MAX : (uint32_t)llround(s);
}

static uint32_t bam(double d)
{
    // Modular conversion int64 -> uint32 is well defined (two's complement for negatives).
    return (uint32_t)(uint64_t)llround(d / 360.0 * 4294967296.0);
}

static double bam_deg(uint32_t a)
{
    const double d = (double)a / 4294967296.0 * 360.0;
    return d >= 180.0 ? d - 360.0 : d;
}

// Same rule as sl::make_geom: each field is the exact value rounded once to nearest.
static sl_incline_geom_t geom_deg(double theta_deg, double beta_deg)
{
    const double t = rad(theta_deg);
    const double b = rad(beta_deg);
    sl_incline_geom_t g;
    g.cos_theta_q30 = q30(cos(t));
    g.sin_theta_q30 = q30(sin(t));
    g.cos_beta_q30 = q30(cos(b));
    g.sin_beta_q30 = q30(sin(b));
    g.cos_tb_q30 = q30(cos(t + b));
    g.sin_tb_q30 = q30(sin(t + b));
    g.rho_amb_q28 = uq28(1.0 / cos((t + b) / 2.0));
    g.rho_seam_q28 = uq28(1.0 / cos(t + b));
    g.theta_bam32 = bam(theta_deg);
    g.beta_bam32 = bam(beta_deg);
    return g;
}

// ---- the double oracle (MATH.md s.2, s.3) ----------------------------------------------

typedef struct {
    int flag;      // sl_incline_flag_t
    int branch;    // 1 or 2 when valid
    double alpha;  // deg
    double sigma;  // deg
} oracle_t;

static oracle_t oracle(double rho, double theta_deg, double beta_deg, double sr_over_r1,
                       double sigma_theta_deg)
{
    oracle_t o = {SL_INCLINE_VALID, 0, 0.0, 0.0};
    const double t = rad(theta_deg);
    const double b = rad(beta_deg);
    if (rho <= 1.0) {
        o.flag = SL_INCLINE_INVALID;
        return o;
    }
    if (rho > 10.0) {
        o.flag = SL_INCLINE_OUT_OF_DOMAIN;
        return o;
    }
    if (rho < 1.0 / cos((t + b) / 2.0)) {
        o.flag = SL_INCLINE_AMBIGUOUS;
        return o;
    }
    double da_drho;
    double da_dtheta;
    if (rho >= 1.0 / cos(t + b)) {
        const double n = rho * cos(t) - cos(b);
        const double d = rho * sin(t) + sin(b);
        o.branch = 1;
        o.alpha = deg(atan(n / d));
        da_drho = sin(t + b) / (n * n + d * d);
        da_dtheta = -rho * (rho - cos(t + b)) / (n * n + d * d);
    } else {
        o.branch = 2;
        o.alpha = deg(acos(1.0 / rho) - t);
        da_drho = 1.0 / (rho * sqrt(rho * rho - 1.0));
        da_dtheta = -1.0;
    }
    const double s_rho = sr_over_r1 * sqrt(1.0 + rho * rho);
    const double a = da_drho * s_rho;
    const double c = da_dtheta * rad(sigma_theta_deg);
    o.sigma = deg(sqrt(a * a + c * c));
    return o;
}

// ---- atan2 --------------------------------------------------------------------------------

static void test_incline_atan_table_matches_libm_at_every_node(void **state)
{
    (void)state;
    for (int32_t i = 0; i <= 256; i++) {
        // y/x = i/256 exactly: the interpolation fraction is 0 and the table entry shows.
        const uint32_t got = sl_incline_atan2_bam32(i << 20, 1 << 28);
        const uint32_t want = (uint32_t)llround(atan(i / 256.0) / (2.0 * PI) * 4294967296.0);
        assert_int_equal(got, want);
    }
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

static uint64_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

static double urand(double lo, double hi)
{
    return lo + (hi - lo) * ((double)(rng() >> 11) / 9007199254740992.0);
}

static double atan2_err_rad(int32_t y, int32_t x)
{
    const double want = atan2((double)y, (double)x);
    double got = rad(bam_deg(sl_incline_atan2_bam32(y, x)));
    double e = got - want;
    // atan2 of (0, negative) is +pi; the bam result -pi is the same angle.
    if (e > PI) {
        e -= 2.0 * PI;
    }
    if (e < -PI) {
        e += 2.0 * PI;
    }
    return fabs(e);
}

static void test_incline_atan2_is_accurate_in_all_octants(void **state)
{
    (void)state;
    static const int32_t special[] = {0, 1, -1, 2, -2, 1000, -1000, INT32_MAX, INT32_MIN,
                                      INT32_MIN + 1, 1 << 30, -(1 << 30)};
    const size_t ns = sizeof special / sizeof special[0];
    double worst = 0.0;
    for (size_t i = 0; i < ns; i++) {
        for (size_t j = 0; j < ns; j++) {
            if (special[i] == 0 && special[j] == 0) {
                assert_int_equal(sl_incline_atan2_bam32(0, 0), 0);
                continue;
            }
            worst = fmax(worst, atan2_err_rad(special[i], special[j]));
        }
    }
    // Axes and diagonals land on exact angles.
    assert_int_equal(sl_incline_atan2_bam32(0, 5), 0u);
    assert_int_equal(sl_incline_atan2_bam32(5, 0), 1u << 30);
    assert_int_equal(sl_incline_atan2_bam32(0, -5), 1u << 31);
    assert_int_equal(sl_incline_atan2_bam32(-5, 0), 3u << 30);
    assert_int_equal(sl_incline_atan2_bam32(7, 7), 1u << 29);
    assert_int_equal(sl_incline_atan2_bam32(-7, -7), 5u << 29);
    for (int k = 0; k < 20000; k++) {
        const int32_t y = (int32_t)(uint32_t)rng();
        // Mix full-scale and small magnitudes.
        const int32_t x = (k & 1) ? (int32_t)(uint32_t)rng() : (int32_t)(rng() % 2001) - 1000;
        if (x == 0 && y == 0) {
            continue;
        }
        worst = fmax(worst, atan2_err_rad(y, x));
    }
    print_message("atan2: max error %.3g rad (%.3g deg)\n", worst, deg(worst));
    assert_true(worst <= 1.3e-6);
}

static void test_incline_bam32_to_cdeg_rounds_half_up(void **state)
{
    (void)state;
    // 2^26 bam = 562.5 cdeg exactly: half up gives 563 and -562.
    assert_int_equal(sl_incline_bam32_to_cdeg(1u << 26), 563);
    assert_int_equal(sl_incline_bam32_to_cdeg((uint32_t)0 - (1u << 26)), -562);
    assert_int_equal(sl_incline_bam32_to_cdeg(0), 0);
    assert_int_equal(sl_incline_bam32_to_cdeg(1u << 31), -18000);
    assert_int_equal(sl_incline_bam32_to_cdeg(0x7FFFFFFFu), 18000);
    assert_int_equal(sl_incline_bam32_to_cdeg(1u << 30), 9000);
    assert_int_equal(sl_incline_bam32_to_cdeg(3u << 30), -9000);
}

// ---- the estimator -----------------------------------------------------------------------

typedef struct {
    long points;
    double max_bam;   // deg, before rounding
    double max_cdeg;  // deg, after rounding to 0.01 deg
    double max_sigma_excess; // cdeg beyond SIGMA_ABS + SIGMA_REL * sigma (<= 0 passes)
    double max_sigma_abs;    // cdeg
    long branch_checked;
} sweep_stats_t;

// One estimate through r1 = 2^28 (rho exactly rho_q28 / 2^28) against the oracle.
static void check_point(sweep_stats_t *st, const sl_incline_geom_t *g, double theta_deg,
                        double beta_deg, uint32_t rho_q28, uint32_t sigma_r, uint16_t st_cdeg)
{
    const uint32_t r1 = 1u << 28;
    const sl_incline_result_t r = sl_incline_estimate(r1, rho_q28, g, sigma_r, st_cdeg);
    const double rho = (double)rho_q28 / 268435456.0;
    const oracle_t o = oracle(rho, theta_deg, beta_deg, (double)sigma_r / r1, st_cdeg / 100.0);
    assert_int_equal(r.rho_q28, rho_q28);
    if (o.flag != SL_INCLINE_VALID) {
        // Only possible within one LSB of the ambiguity bound (rho_amb is rounded).
        const double amb = 268435456.0 / cos(rad(theta_deg + beta_deg) / 2.0);
        assert_true(fabs((double)rho_q28 - amb) <= 1.0);
        return;
    }
    if (r.flag != SL_INCLINE_VALID) {
        const double amb = 268435456.0 / cos(rad(theta_deg + beta_deg) / 2.0);
        if (fabs((double)rho_q28 - amb) > 1.0) {
            print_message("theta %.2f beta %.1f rho_q28 %u: flag %d\n", theta_deg, beta_deg,
                          rho_q28, r.flag);
        }
        assert_true(fabs((double)rho_q28 - amb) <= 1.0);
        return;
    }
    const double seam = 268435456.0 / cos(rad(theta_deg + beta_deg));
    if (fabs((double)rho_q28 - seam) > 1.0) {
        assert_int_equal(r.branch, o.branch);
        st->branch_checked++;
    }
    const double e_bam = fabs(bam_deg(r.alpha_bam32) - o.alpha);
    const double e_cdeg = fabs(r.alpha_cdeg / 100.0 - o.alpha);
    if (e_cdeg > MAX_ERR_CDEG_DEG || e_bam > MAX_ERR_BAM_DEG) {
        print_message("theta %.2f beta %.1f rho %.9f: alpha %d cdeg (%.6f) want %.6f\n",
                      theta_deg, beta_deg, rho, r.alpha_cdeg, bam_deg(r.alpha_bam32), o.alpha);
    }
    st->max_bam = fmax(st->max_bam, e_bam);
    st->max_cdeg = fmax(st->max_cdeg, e_cdeg);
    const double s_want = o.sigma * 100.0;
    const double s_err = fabs((double)r.sigma_cdeg - s_want);
    st->max_sigma_abs = fmax(st->max_sigma_abs, s_err);
    const double excess = s_err - (SIGMA_ABS_CDEG + SIGMA_REL * s_want);
    if (excess > 0.0) {
        print_message("theta %.2f beta %.1f rho %.9f: sigma %u cdeg want %.4f\n", theta_deg,
                      beta_deg, rho, r.sigma_cdeg, s_want);
    }
    st->max_sigma_excess = fmax(st->max_sigma_excess, excess);
    st->points++;
}

static void test_incline_alpha_and_sigma_match_double_oracle_over_sweep(void **state)
{
    (void)state;
    sweep_stats_t st = {0, 0.0, 0.0, -1e9, 0.0, 0};
    const uint32_t rho_max = SL_INCLINE_RHO_MAX_Q28;
    int geoms = 0;
    for (int ti = 0; ti <= 58; ti++) {
        const double theta = 5.0 + 0.5 * ti;
        for (int bi = 0; bi <= 5; bi++) {
            const double beta = (double)bi;
            const sl_incline_geom_t g = geom_deg(theta, beta);
            geoms++;
            // Alternate the sigma inputs so both terms get exercised: the pipeline's
            // numbers (12.6 mm at 2 m, 0.2 deg), pure range term, pure theta term.
            const uint32_t srs[3] = {(uint32_t)(268435456.0 * 0.0063), 1u << 22, 0u};
            const uint16_t sts[3] = {20u, 0u, 35u};
            int k = 0;
            const double lo = (double)g.rho_amb_q28;
            const double hi = (double)rho_max;
            for (int i = 0; i < SWEEP_LOG; i++, k++) {
                const double v = lo * pow(hi / lo, (double)i / (SWEEP_LOG - 1));
                check_point(&st, &g, theta, beta, (uint32_t)llround(v), srs[k % 3], sts[k % 3]);
            }
            for (int i = 0; i < SWEEP_B2; i++, k++) {
                const double v = lo + ((double)g.rho_seam_q28 - lo) * i / SWEEP_B2;
                check_point(&st, &g, theta, beta, (uint32_t)llround(v), srs[k % 3], sts[k % 3]);
            }
            for (int d = -SEAM_LSB; d <= SEAM_LSB; d++, k++) {
                check_point(&st, &g, theta, beta, (uint32_t)((int64_t)g.rho_seam_q28 + d),
                            srs[k % 3], sts[k % 3]);
            }
            for (int d = 0; d <= AMB_LSB; d++, k++) {
                check_point(&st, &g, theta, beta, g.rho_amb_q28 + (uint32_t)d, srs[k % 3],
                            sts[k % 3]);
            }
        }
    }
    print_message("sweep: %d geometries, %ld points (%ld with branch checked)\n", geoms,
                  st.points, st.branch_checked);
    print_message("sweep: max |alpha error| %.3g deg (bam32), %.5f deg (cdeg, rounded)\n",
                  st.max_bam, st.max_cdeg);
    print_message("sweep: max |sigma error| %.4f cdeg (max excess over 0.5 cdeg + 1e-4 x "
                  "sigma: %.4f cdeg)\n", st.max_sigma_abs, st.max_sigma_excess);
    assert_true(st.points > 150000);
    assert_true(st.max_bam <= MAX_ERR_BAM_DEG);
    assert_true(st.max_cdeg <= MAX_ERR_CDEG_DEG);
    assert_true(st.max_sigma_excess <= 0.0);
}

static void test_incline_micrometre_bounds_match_oracle_over_whole_domain(void **state)
{
    (void)state;
    // Realistic integer bounds: r1 in 0.5..60 m (micrometres), theta 1..60, beta -10..15,
    // rho from just below the ambiguity bound to just above 10. rho is floor(r2 2^28 / r1);
    // the oracle sees r2 / r1 in double.
    sweep_stats_t st = {0, 0.0, 0.0, -1e9, 0.0, 0};
    long amb = 0;
    long ood = 0;
    for (int k = 0; k < 20000; k++) {
        double theta = urand(1.0, 60.0);
        double beta = urand(-10.0, 15.0);
        if (theta + beta < 1.0) {
            continue;
        }
        const sl_incline_geom_t g = geom_deg(theta, beta);
        const double rho_amb = 1.0 / cos(rad(theta + beta) / 2.0);
        // Mostly log-uniform over the domain; 10 % near the ambiguity bound, 5 % near 10.
        const uint64_t pick = rng() % 20u;
        const double rho_t = (pick < 2u)    ? rho_amb * urand(0.99, 1.01)
                             : (pick == 2u) ? urand(9.95, 10.05)
                                            : exp(urand(log(rho_amb), log(10.0)));
        const uint32_t r1 = (uint32_t)urand(5e5, 6e7);
        const double r2d = floor(r1 * rho_t + 0.5);
        const uint32_t r2 = (uint32_t)r2d;
        const double rho = r2d / r1;
        const uint32_t sigma_r = 12600u;
        const sl_incline_result_t r = sl_incline_estimate(r1, r2, &g, sigma_r, 20u);
        const oracle_t o = oracle(rho, theta, beta, (double)sigma_r / r1, 0.2);
        const double amb_rel = fabs(rho / rho_amb - 1.0);
        const double max_rel = fabs(rho / 10.0 - 1.0);
        if (amb_rel < 1e-6 || max_rel < 1e-6) {
            continue; // either answer is right at a bound
        }
        assert_int_equal(r.flag, o.flag);
        if (o.flag == SL_INCLINE_AMBIGUOUS) {
            amb++;
            continue;
        }
        if (o.flag == SL_INCLINE_OUT_OF_DOMAIN) {
            ood++;
            continue;
        }
        const double e_bam = fabs(bam_deg(r.alpha_bam32) - o.alpha);
        const double e_cdeg = fabs(r.alpha_cdeg / 100.0 - o.alpha);
        st.max_bam = fmax(st.max_bam, e_bam);
        st.max_cdeg = fmax(st.max_cdeg, e_cdeg);
        const double s_want = o.sigma * 100.0;
        const double s_err = fabs((double)r.sigma_cdeg - s_want);
        st.max_sigma_abs = fmax(st.max_sigma_abs, s_err);
        st.max_sigma_excess =
            fmax(st.max_sigma_excess, s_err - (SIGMA_ABS_CDEG + SIGMA_REL * s_want));
        st.points++;
    }
    print_message("random: %ld valid points (+%ld ambiguous, %ld above rho 10)\n", st.points,
                  amb, ood);
    print_message("random: max |alpha error| %.3g deg (bam32), %.5f deg (cdeg); sigma %.3f cdeg\n",
                  st.max_bam, st.max_cdeg, st.max_sigma_abs);
    assert_true(st.points > 10000 && amb > 100 && ood > 10);
    assert_true(st.max_bam <= MAX_ERR_BAM_DEG);
    assert_true(st.max_cdeg <= MAX_ERR_CDEG_DEG);
    assert_true(st.max_sigma_excess <= 0.0);
}

static void test_incline_ambiguity_bound_is_exact_to_one_lsb(void **state)
{
    (void)state;
    for (int ti = 0; ti <= 59; ti++) {
        for (int bi = -10; bi <= 15; bi += 5) {
            const double theta = 1.0 + ti;
            const double beta = (double)bi;
            if (theta + beta < 1.0) {
                continue;
            }
            const sl_incline_geom_t g = geom_deg(theta, beta);
            const double exact = 268435456.0 / cos(rad(theta + beta) / 2.0);
            assert_true(fabs((double)g.rho_amb_q28 - exact) <= 0.5);
            const uint32_t r1 = 1u << 28;
            sl_incline_result_t r = sl_incline_estimate(r1, g.rho_amb_q28, &g, 0u, 0u);
            assert_int_equal(r.flag, SL_INCLINE_VALID);
            assert_int_equal(r.branch, SL_INCLINE_BRANCH_2);
            // At the bound alpha = (beta - theta) / 2: the most-away lean the model resolves.
            assert_true(fabs(r.alpha_cdeg / 100.0 - (beta - theta) / 2.0) <= 0.01);
            r = sl_incline_estimate(r1, g.rho_amb_q28 - 1u, &g, 0u, 0u);
            assert_int_equal(r.flag, SL_INCLINE_AMBIGUOUS);
            assert_int_equal(r.branch, SL_INCLINE_BRANCH_NONE);
            assert_int_equal(r.alpha_cdeg, 0);
            assert_int_equal(r.sigma_cdeg, 0);
            assert_int_equal(r.rho_q28, g.rho_amb_q28 - 1u);
            // Same with micrometre bounds: the smallest r2 whose floor(r2 2^28 / r1) reaches
            // the bound is valid, one micrometre less is ambiguous.
            const uint32_t r1um = 2345678u;
            const uint64_t r2min = ((uint64_t)g.rho_amb_q28 * r1um + (1u << 28) - 1u) >> 28;
            r = sl_incline_estimate(r1um, (uint32_t)r2min, &g, 0u, 0u);
            assert_int_equal(r.flag, SL_INCLINE_VALID);
            r = sl_incline_estimate(r1um, (uint32_t)r2min - 1u, &g, 0u, 0u);
            assert_int_equal(r.flag, SL_INCLINE_AMBIGUOUS);
        }
    }
}

static void test_incline_rejects_invalid_bounds(void **state)
{
    (void)state;
    const sl_incline_geom_t g = geom_deg(26.0, 3.0);
    const uint32_t bad[][2] = {{0u, 1000u}, {0u, 0u}, {1000u, 1000u}, {2000u, 1000u},
                               {UINT32_MAX, 5u}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const sl_incline_result_t r = sl_incline_estimate(bad[i][0], bad[i][1], &g, 10u, 20u);
        assert_int_equal(r.flag, SL_INCLINE_INVALID);
        assert_int_equal(r.branch, SL_INCLINE_BRANCH_NONE);
        assert_int_equal(r.alpha_cdeg, 0);
        assert_int_equal(r.alpha_bam32, 0);
        assert_int_equal(r.sigma_cdeg, 0);
        assert_int_equal(r.rho_q28, 0);
    }
}

static void test_incline_flags_rho_above_ten_as_out_of_domain(void **state)
{
    (void)state;
    const sl_incline_geom_t g = geom_deg(26.0, 3.0);
    sl_incline_result_t r = sl_incline_estimate(1000000u, 10000000u, &g, 0u, 0u);
    assert_int_equal(r.flag, SL_INCLINE_VALID); // exactly 10
    assert_int_equal(r.branch, SL_INCLINE_BRANCH_1);
    r = sl_incline_estimate(1000000u, 10000001u, &g, 0u, 0u);
    assert_int_equal(r.flag, SL_INCLINE_OUT_OF_DOMAIN);
    assert_int_equal(r.alpha_cdeg, 0);
    r = sl_incline_estimate(1u, UINT32_MAX, &g, 0u, 0u);
    assert_int_equal(r.flag, SL_INCLINE_OUT_OF_DOMAIN);
    assert_int_equal(r.rho_q28, UINT32_MAX);
}

static void test_incline_rejects_geometry_outside_domain(void **state)
{
    (void)state;
    static const double bad[][2] = {{0.9, 0.0}, {60.01, 0.0}, {20.0, -10.01}, {20.0, 15.01},
                                    {5.0, -4.5}, {0.0, 0.0}, {-5.0, 3.0}, {90.0, 0.0}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const sl_incline_geom_t g = geom_deg(bad[i][0], bad[i][1]);
        assert_false(sl_incline_geom_ok(&g));
        const sl_incline_result_t r = sl_incline_estimate(1000000u, 1500000u, &g, 0u, 0u);
        assert_int_equal(r.flag, SL_INCLINE_OUT_OF_DOMAIN);
        assert_int_equal(r.alpha_cdeg, 0);
    }
    static const double good[][2] = {{1.0, 0.0}, {60.0, 0.0}, {60.0, 15.0}, {11.0, -10.0},
                                     {26.0, 3.0}, {5.0, -4.0}};
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        const sl_incline_geom_t g = geom_deg(good[i][0], good[i][1]);
        assert_true(sl_incline_geom_ok(&g));
    }
    assert_false(sl_incline_geom_ok(NULL));
    // A corrupted entry (seam below the ambiguity bound) is refused too.
    sl_incline_geom_t g = geom_deg(26.0, 3.0);
    g.rho_seam_q28 = g.rho_amb_q28 - 1u;
    assert_false(sl_incline_geom_ok(&g));
}

static void test_incline_paper_reference_points(void **state)
{
    (void)state;
    // MATH.md s.2: theta 26, beta 0 (paper model). A vertical pole: rho = 1/cos(26) -> 0.
    sl_incline_geom_t g = geom_deg(26.0, 0.0);
    const uint32_t r1 = 2000000u;
    uint32_t r2 = (uint32_t)llround(r1 / cos(rad(26.0)));
    sl_incline_result_t r = sl_incline_estimate(r1, r2, &g, 12600u, 20u);
    assert_int_equal(r.flag, SL_INCLINE_VALID);
    assert_true(abs(r.alpha_cdeg) <= 1);
    // +10 deg (towards): rho = cos(alpha - beta) / cos(alpha + theta).
    g = geom_deg(26.0, 3.0);
    r2 = (uint32_t)llround(r1 * cos(rad(10.0 - 3.0)) / cos(rad(10.0 + 26.0)));
    r = sl_incline_estimate(r1, r2, &g, 12600u, 20u);
    assert_int_equal(r.flag, SL_INCLINE_VALID);
    assert_int_equal(r.branch, SL_INCLINE_BRANCH_1);
    assert_true(abs(r.alpha_cdeg - 1000) <= 1);
    // -10 deg (away), beta 3: branch 2, rho = 1/cos(alpha + theta).
    r2 = (uint32_t)llround(r1 / cos(rad(-10.0 + 26.0)));
    r = sl_incline_estimate(r1, r2, &g, 12600u, 20u);
    assert_int_equal(r.flag, SL_INCLINE_VALID);
    assert_int_equal(r.branch, SL_INCLINE_BRANCH_2);
    assert_true(abs(r.alpha_cdeg + 1000) <= 1);
    assert_true(r.sigma_cdeg > 20u); // at least the theta term (|d alpha/d theta| = 1)
    // The fold (MATH.md s.2 table, row 3): a pole leaning away by more than
    // (theta - beta)/2 = 11.5 deg has rho = 1/cos(beta - alpha) >= rho_amb, so it is NOT
    // flagged: -14 deg reads as its mirror image about -11.5 deg, i.e. -9 deg.
    r2 = (uint32_t)llround(r1 / cos(rad(3.0 + 14.0)));
    r = sl_incline_estimate(r1, r2, &g, 12600u, 20u);
    assert_int_equal(r.flag, SL_INCLINE_VALID);
    assert_int_equal(r.branch, SL_INCLINE_BRANCH_2);
    assert_true(abs(r.alpha_cdeg + 900) <= 1);
    // rho below the model's minimum 1/cos(14.5 deg) (noise around the fold): ambiguous.
    r2 = (uint32_t)llround(r1 / cos(rad(14.4)));
    r = sl_incline_estimate(r1, r2, &g, 12600u, 20u);
    assert_int_equal(r.flag, SL_INCLINE_AMBIGUOUS);
}

static void test_incline_sigma_saturates_and_scales(void **state)
{
    (void)state;
    const sl_incline_geom_t g = geom_deg(26.0, 3.0);
    const uint32_t r1 = 2000000u;
    const uint32_t r2 = 2600000u;
    sl_incline_result_t r = sl_incline_estimate(r1, r2, &g, r1, 20u);
    assert_int_equal(r.flag, SL_INCLINE_VALID);
    assert_int_equal(r.sigma_cdeg, UINT16_MAX);
    r = sl_incline_estimate(r1, r2, &g, 0u, 0u);
    assert_int_equal(r.sigma_cdeg, 0);
    // Theta term alone on branch 2 is exactly sigma_theta (d alpha / d theta = -1).
    r = sl_incline_estimate(r1, 2100000u, &g, 0u, 37u);
    assert_int_equal(r.branch, SL_INCLINE_BRANCH_2);
    assert_int_equal(r.sigma_cdeg, 37);
    // Theta term saturates rather than wrapping.
    r = sl_incline_estimate(r1, r2, &g, 0u, UINT16_MAX);
    assert_int_equal(r.sigma_cdeg, UINT16_MAX);
    // The range term grows linearly with sigma_r.
    const sl_incline_result_t a = sl_incline_estimate(r1, r2, &g, 10000u, 0u);
    const sl_incline_result_t b = sl_incline_estimate(r1, r2, &g, 40000u, 0u);
    assert_true(abs((int)b.sigma_cdeg - 4 * (int)a.sigma_cdeg) <= 2);
}

// sl_incline_bounds_sigma_um: the one range sigma that gives the same sigma of rho as
// independent bounds with sigmas s1 (r1) and s2 (r2), against double precision:
// sigma_rho^2 = (s2^2 + rho^2 s1^2) / r1^2 = s^2 (1 + rho^2) / r1^2.
static void test_incline_bounds_sigma_combines_the_two_bounds(void **state)
{
    (void)state;
    // equal sigmas: that sigma, exactly
    assert_int_equal(sl_incline_bounds_sigma_um(3000000U, 3600000U, 12640U, 12640U), 12640U);
    assert_int_equal(sl_incline_bounds_sigma_um(0U, 0U, 12640U, 25288U), // isqrt: floor
                     (uint32_t)floor(sqrt((12640.0 * 12640.0 + 25288.0 * 25288.0) / 2.0)));
    const uint32_t r1s[] = {1500000U, 3000000U, 2400000U, 9000000U, 40000000U};
    const uint32_t r2s[] = {1550000U, 3600000U, 5100000U, 30000000U, 41000000U};
    const uint32_t ss[][2] = {{12640U, 25288U}, {25288U, 12640U}, {12640U, 12640U},
                              {1U, 577347U}, {60000U, 300U}};
    for (size_t i = 0; i < sizeof r1s / sizeof r1s[0]; i++) {
        for (size_t j = 0; j < sizeof ss / sizeof ss[0]; j++) {
            const double r1 = r1s[i], r2 = r2s[i], s1 = ss[j][0], s2 = ss[j][1];
            const double rho = r2 / r1;
            const double want = sqrt((s2 * s2 + rho * rho * s1 * s1) / (1.0 + rho * rho));
            const double got = sl_incline_bounds_sigma_um(r1s[i], r2s[i], ss[j][0], ss[j][1]);
            // whole-mm ranges and the Q16 weight: within 0.01 % and 1 um
            assert_true(fabs(got - want) <= 1.0 + 1e-4 * want);
        }
    }
}

#if SL_CFG_FIT
// sl_incline_bounds_sigma_corr_um: correlated bounds (a fit of both to one return), against
// double precision: sigma_rho^2 r1^2 = s2^2 + rho^2 s1^2 - 2 rho c s1 s2 = s^2 (1 + rho^2);
// c = 0 is sl_incline_bounds_sigma_um; a fully correlated pair of equal sigmas at equal
// ranges cancels (a shift of the whole return leaves rho).
static void test_incline_bounds_sigma_with_correlation(void **state)
{
    (void)state;
    assert_int_equal(sl_incline_bounds_sigma_corr_um(3000000U, 3600000U, 12640U, 25288U, 0),
                     sl_incline_bounds_sigma_um(3000000U, 3600000U, 12640U, 25288U));
    assert_true(sl_incline_bounds_sigma_corr_um(3000000U, 3000000U, 20000U, 20000U, 32767) <= 160U);
    const int32_t cs[] = {-32767, -16384, 9830, 26214, 32767};
    const uint32_t r1s[] = {1500000U, 3000000U, 2400000U};
    const uint32_t r2s[] = {1550000U, 3600000U, 5100000U};
    for (size_t i = 0; i < sizeof r1s / sizeof r1s[0]; i++) {
        for (size_t j = 0; j < sizeof cs / sizeof cs[0]; j++) {
            const double r1 = r1s[i], r2 = r2s[i], s1 = 30000.0, s2 = 45000.0;
            const double rho = r2 / r1, c = cs[j] / 32768.0;
            const double v = (s2 * s2 + rho * rho * s1 * s1 - 2 * rho * c * s1 * s2) / (1 + rho * rho);
            const double want = sqrt(v > 0 ? v : 0);
            const double got = sl_incline_bounds_sigma_corr_um(r1s[i], r2s[i], 30000U, 45000U, cs[j]);
            assert_true(fabs(got - want) <= 2.0 + 1e-3 * 45000.0);
        }
    }
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_incline_bounds_sigma_combines_the_two_bounds),
#if SL_CFG_FIT
        cmocka_unit_test(test_incline_bounds_sigma_with_correlation),
#endif
        cmocka_unit_test(test_incline_atan_table_matches_libm_at_every_node),
        cmocka_unit_test(test_incline_atan2_is_accurate_in_all_octants),
        cmocka_unit_test(test_incline_bam32_to_cdeg_rounds_half_up),
        cmocka_unit_test(test_incline_alpha_and_sigma_match_double_oracle_over_sweep),
        cmocka_unit_test(test_incline_micrometre_bounds_match_oracle_over_whole_domain),
        cmocka_unit_test(test_incline_ambiguity_bound_is_exact_to_one_lsb),
        cmocka_unit_test(test_incline_rejects_invalid_bounds),
        cmocka_unit_test(test_incline_flags_rho_above_ten_as_out_of_domain),
        cmocka_unit_test(test_incline_rejects_geometry_outside_domain),
        cmocka_unit_test(test_incline_paper_reference_points),
        cmocka_unit_test(test_incline_sigma_saturates_and_scales),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
