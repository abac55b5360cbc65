// SPDX-License-Identifier: MIT
// Tests of host_tools/board/sl_geom.{h,cpp}: sl::make_geom's rounding rule and limits, the
// double oracles against brute-force ray geometry (MATH.md s.2), and the core estimator fed
// by make_geom against the oracles over the whole supported domain.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "sl_geom.h"
#include "shadowlean/sl_incline.h"
#include "check.hpp"

namespace {

using sl_test::failures;

constexpr double kPi = 3.14159265358979323846;
double rad(double d) { return d * kPi / 180.0; }

void test_geom_make_rounds_each_field_once_to_nearest()
{
    const sl_incline_geom_t g = sl::make_geom(60.0, 0.0);
    CHECK(g.cos_theta_q30 == (1 << 29));        // cos 60 = 0.5 exactly
    CHECK(g.sin_theta_q30 == 929887697);        // round(sin 60 * 2^30)
    CHECK(g.cos_beta_q30 == (1 << 30));
    CHECK(g.sin_beta_q30 == 0);
    CHECK(g.rho_seam_q28 == (1u << 29));        // 1/cos 60 = 2
    CHECK(g.rho_amb_q28 == 309962566u);         // round(2^28 / cos 30)
    CHECK(g.theta_bam32 == 715827883u);         // round(60/360 * 2^32)
    const sl_incline_geom_t n = sl::make_geom(26.0, -10.0);
    CHECK(n.beta_bam32 == 4175662649u);         // 2^32 - round(10/360 * 2^32)
    CHECK(n.sin_beta_q30 == -186453311);
    CHECK(n.cos_theta_q30 == 965072759);
    // Angles at or beyond 90 deg: the 1/cos bounds saturate; the core refuses the entry.
    const sl_incline_geom_t s = sl::make_geom(90.0, 5.0);
    CHECK(s.rho_seam_q28 == UINT32_MAX);
    CHECK(!sl_incline_geom_ok(&s));
    CHECK(sl_incline_geom_ok(&g));
    int thrown = 0;
    for (double bad : {std::nan(""), HUGE_VAL, 180.5, -200.0}) {
        try {
            (void)sl::make_geom(bad, 0.0);
        } catch (const std::domain_error &) {
            thrown++;
        }
        try {
            (void)sl::make_geom(20.0, bad);
        } catch (const std::domain_error &) {
            thrown++;
        }
    }
    CHECK(thrown == 8);
}

// Brute force: the pole's line has its perpendicular foot at distance p and elevation
// alpha; the visible part spans elevations [-theta, beta]; r = p / cos(phi - alpha).
void ray_bounds(double alpha_deg, double theta_deg, double beta_deg, double *r1, double *r2)
{
    const double p = 2.5;
    *r1 = INFINITY;
    *r2 = 0.0;
    const int n = 200000;
    for (int i = 0; i <= n; i++) {
        const double phi = -theta_deg + (theta_deg + beta_deg) * i / n;
        const double r = p / std::cos(rad(phi - alpha_deg));
        *r1 = std::fmin(*r1, r);
        *r2 = std::fmax(*r2, r);
    }
}

void test_oracle_inverts_ray_geometry_and_folds_beyond_the_bound()
{
    const double cases[][2] = {{26.0, 0.0}, {26.0, 3.0}, {10.0, 5.0}, {45.0, -5.0}};
    for (const auto &c : cases) {
        const double t = c[0], b = c[1];
        for (double a = (b - t) / 2.0 + 0.25; a < 80.0 - t; a += 1.0) {
            double r1, r2;
            ray_bounds(a, t, b, &r1, &r2);
            int flag = -1, branch = 0;
            const double got = sl::alpha_oracle_deg(r1, r2, t, b, &flag, &branch);
            CHECK(flag == SL_INCLINE_VALID);
            CHECK(branch == (a >= b ? 1 : 2));
            // The brute-force minimum is sampled: allow for its discretisation.
            if (std::fabs(got - a) > 2e-3) {
                std::printf("theta %g beta %g alpha %g: oracle %.6f\n", t, b, a, got);
            }
            CHECK(std::fabs(got - a) <= 2e-3);
        }
        // Leaning away beyond (theta - beta)/2 gives no smaller rho: it reads as the mirror
        // image about (beta - theta)/2 (the fold), never as ambiguous.
        const double a = (b - t) / 2.0 - 3.0;
        double r1, r2;
        ray_bounds(a, t, b, &r1, &r2);
        int flag = -1;
        const double got = sl::alpha_oracle_deg(r1, r2, t, b, &flag);
        CHECK(flag == SL_INCLINE_VALID);
        CHECK(std::fabs(got - (b - t - a)) <= 2e-3);
    }
    int flag = -1;
    CHECK(std::isnan(sl::alpha_oracle_deg(2.0, 2.0001, 26.0, 3.0, &flag)));
    CHECK(flag == SL_INCLINE_AMBIGUOUS);
    (void)sl::alpha_oracle_deg(2.0, 1.0, 26.0, 3.0, &flag);
    CHECK(flag == SL_INCLINE_INVALID);
    (void)sl::alpha_oracle_deg(1.0, 10.5, 26.0, 3.0, &flag);
    CHECK(flag == SL_INCLINE_OUT_OF_DOMAIN);
    (void)sl::alpha_oracle_deg(1.0, 2.0, 61.0, 3.0, &flag);
    CHECK(flag == SL_INCLINE_OUT_OF_DOMAIN);
}

void test_oracle_sigma_matches_numeric_derivatives()
{
    // Central differences of the alpha oracle in rho and theta.
    const double pts[][3] = {{26.0, 3.0, 1.05}, {26.0, 3.0, 1.4}, {10.0, 0.0, 3.0},
                             {45.0, -5.0, 1.2}, {5.0, 2.0, 9.0}};
    for (const auto &p : pts) {
        const double t = p[0], b = p[1], rho = p[2];
        const double r1 = 2.0, sr = 0.01, st = 0.3;
        int f = 0;
        const double h = 1e-6;
        const double da_drho = (sl::alpha_oracle_deg(r1, r1 * (rho + h), t, b, &f) -
                                sl::alpha_oracle_deg(r1, r1 * (rho - h), t, b, &f)) /
                               (2 * h);
        const double da_dth = (sl::alpha_oracle_deg(r1, r1 * rho, t + h, b, &f) -
                               sl::alpha_oracle_deg(r1, r1 * rho, t - h, b, &f)) /
                              (2 * h);
        const double srho = sr / r1 * std::sqrt(1 + rho * rho);
        const double want = std::hypot(da_drho * srho, da_dth * st);
        const double got = sl::sigma_oracle_deg(r1, r1 * rho, t, b, sr, st, &f);
        CHECK(f == SL_INCLINE_VALID);
        if (std::fabs(got - want) > 1e-5 * want) {
            std::printf("sigma at theta %g beta %g rho %g: %.8f vs numeric %.8f\n", t, b, rho,
                        got, want);
        }
        CHECK(std::fabs(got - want) <= 1e-5 * want);
    }
}

void test_core_on_make_geom_matches_oracle_over_domain()
{
    std::mt19937_64 rng(12345);
    std::uniform_real_distribution<double> th(1.0, 60.0), be(-10.0, 15.0), u(0.0, 1.0);
    double max_err = 0.0, max_sig = 0.0;
    long valid = 0;
    for (int k = 0; k < 200000; k++) {
        const double t = th(rng), b = be(rng);
        if (t + b < 1.0) {
            continue;
        }
        const sl_incline_geom_t g = sl::make_geom(t, b);
        const double amb = 1.0 / std::cos(rad(t + b) / 2.0);
        const double rho = amb * std::pow(10.2 / amb, u(rng)) * 0.999;
        const uint32_t r1 = 1u << 28;
        const double r2d = std::floor(rho * r1);
        const sl_incline_result_t r =
            sl_incline_estimate(r1, static_cast<uint32_t>(r2d), &g, 1u << 21, 25u);
        int flag = -1;
        const double a = sl::alpha_oracle_deg(r1, r2d, t, b, &flag);
        const double s = sl::sigma_oracle_deg(r1, r2d, t, b, 1u << 21, 0.25, &flag);
        const double q = r2d / r1;
        if (std::fabs(q / amb - 1) < 1e-6 || std::fabs(q / 10 - 1) < 1e-6) {
            continue;
        }
        CHECK(r.flag == flag);
        if (flag != SL_INCLINE_VALID || r.flag != SL_INCLINE_VALID) {
            continue;
        }
        valid++;
        max_err = std::fmax(max_err, std::fabs(r.alpha_cdeg / 100.0 - a));
        max_sig = std::fmax(max_sig, std::fabs(r.sigma_cdeg - 100.0 * s) - 1e-4 * 100.0 * s);
    }
    std::printf("core vs oracle: %ld valid points, max |alpha error| %.5f deg, max sigma "
                "excess over 1e-4 rel %.4f cdeg\n", valid, max_err, max_sig);
    CHECK(valid > 150000);
    CHECK(max_err <= 0.01);
    CHECK(max_sig <= 0.5);
}

} // namespace

int main()
{
    test_geom_make_rounds_each_field_once_to_nearest();
    test_oracle_inverts_ray_geometry_and_folds_beyond_the_bound();
    test_oracle_sigma_matches_numeric_derivatives();
    test_core_on_make_geom_matches_oracle_over_domain();
    std::printf("%s (%d failures)\n", failures ? "FAIL" : "OK", failures);
    return failures ? 1 : 0;
}
