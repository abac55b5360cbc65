// SPDX-License-Identifier: MIT
// Smear-robust extraction through the CORE PIPELINE (range profiles, sl_profile.h) on the
// realistic bench (paper Table II condition, sl-eval realistic --extract pipeline) and its
// variations, with one and the same configuration (no constant refitted per condition):
// smear decay 3.3 and 4.5 dB per bin, speckle drawn anew every frame at n = 4 and 16.
// Reduced runs (3 positions x 2 repetitions, 160 bins per azimuth) to stay well under a
// minute each; the full runs are in docs/RESULTS.md.
// Asserted per true angle (at -10 deg the estimator's ambiguity fold at (beta - theta) / 2
// = -11.5 deg flags part of the measurements AMBIGUOUS, counted at the bound: that angle is
// only required to stay within 1.6 deg): |mean error| <= 1.0 deg on the paper condition
// (6 measurements per angle; the full run's figure is in docs/RESULTS.md), <= 1.5 deg on the
// variations (the criterion), std <= 1.5 deg, the pole found in >= 5 of 6
// measurements; the n = 4 -> 16 shift <= 0.5 deg. On the paper condition the
// same bounds with the profile off are NOT met (the mask + board d(r) path is biased), so
// the test fails if the refinement is not applied.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <setjmp.h>
#include <string>
#include <vector>

extern "C" {
#include <cmocka.h>
}

#include "sim_eval.h"

extern "C" {
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_profile.h"
#include "shadowlean/sl_track.h"
}

using namespace sl;

static RealisticOptions quick()
{
    RealisticOptions o;
    o.positions = 3;
    o.reps = 2;
    o.range_bins = 160;
    o.progress = false;
    o.threads = 2;
    o.extract = Extract::Pipeline;
    o.bbox_table = false;
    return o;
}

static void mean_sd(const std::vector<double> &v, double *m, double *s)
{
    double a = 0, b = 0;
    for (double x : v) {
        a += x;
    }
    a /= static_cast<double>(v.size());
    for (double x : v) {
        b += (x - a) * (x - a);
    }
    *m = a;
    *s = v.size() > 1 ? std::sqrt(b / static_cast<double>(v.size() - 1)) : 0.0;
}

// Checks the accuracy bounds; returns the mean error per angle in `err`.
static bool within(const RealisticResult &r, double err[5], bool assert_it, double lim_mean)
{
    bool ok = true;
    for (int a = 0; a < 5; a++) {
        const RealisticPipe &p = r.pipe[a];
        if (p.raw.empty()) {
            if (assert_it) {
                fail_msg("angle %d: no estimate", r.angles[a]);
            }
            return false;
        }
        double m, s;
        mean_sd(p.raw, &m, &s);
        err[a] = m - r.angles[a];
        const double lim = r.angles[a] == -10 ? std::max(1.6, lim_mean) : lim_mean;
        const bool this_ok = std::fabs(err[a]) <= lim && s <= 1.5 && p.detected * 6 >= p.runs * 5;
        std::printf("  %+3d deg: mean error %+6.2f std %5.2f detected %d/%d -> %s\n", r.angles[a], err[a], s,
                    p.detected, p.runs, this_ok ? "ok" : "OUT");
        if (assert_it && !this_ok) {
            fail_msg("angle %d: mean error %.2f (limit %.1f) std %.2f detected %d/%d", r.angles[a], err[a], lim, s,
                     p.detected, p.runs);
        }
        ok = ok && this_ok;
    }
    return ok;
}

static void test_extraction_paper_condition_within_1_deg(void **)
{
    RealisticOptions o = quick();
    const RealisticResult r = run_realistic(o);
    double e[5];
    std::printf("smear 3.3 dB/bin, frozen speckle, n = 16 (walk-end offset %+.1f mm from %u upright poles):\n",
                r.pipe_r2_offset_um / 1000.0, static_cast<unsigned>(r.pipe_resid_samples));
    within(r, e, true, 1.0);
    // The calibration pass taught the profile its walk's end (sl_profile.h, "Online
    // calibration": r2 read short on upright poles), and the measurements are nearer the
    // truth for it than with nothing calibrated.
    assert_true(r.pipe_resid_samples >= SL_PROFILE_RESID_MIN);
    assert_true(r.pipe_r2_offset_um > 0 && r.pipe_r2_offset_um < 43800);
    o.cold = true;
    const RealisticResult rc = run_realistic(o);
    double ec[5], sum = 0, sum_cold = 0;
    std::printf("same, --cold (nothing calibrated):\n");
    within(rc, ec, false, 1.0);
    for (int a = 0; a < 5; a++) {
        sum += std::fabs(e[a]);
        sum_cold += std::fabs(ec[a]);
    }
    std::printf("  average |mean error|: %.2f calibrated, %.2f cold\n", sum / 5, sum_cold / 5);
    assert_true(sum < sum_cold);
    o.cold = false;
    // The same captures without the profile: the mask's bounds and the board's d(r).
    o.pipe_profile = false;
    const RealisticResult r0 = run_realistic(o);
    double e0[5];
    std::printf("same, profile off (mask + board d(r)):\n");
    assert_false(within(r0, e0, false, 1.0));
}

static void test_extraction_steeper_smear_same_configuration(void **)
{
    RealisticOptions o = quick();
    o.smear_decay_db = 4.5;
    const RealisticResult r = run_realistic(o);
    double e[5];
    std::printf("smear 4.5 dB/bin:\n");
    within(r, e, true, 1.5);
}

// A shallow smear (2.5 dB/bin): the tail of the far positions crosses the shadow edge by
// more than the board's d(S) allows. The pole is still found at every angle (the run beyond
// the edge decays like a tail of its inside part: sl_detect.h stage 1, TAIL_EDGE; the
// refined r2 decides), where the d(S) rule alone rejected it SHADOW (4 of 6 detected at
// -10/-5/0 deg). The accuracy criterion (<= 1.5 deg) is NOT met at this decay yet (the
// walk cannot tell the pole's last bins from a 2.5-value tail in integer values): printed.
static void test_extraction_shallow_smear_found_at_the_shadow_edge(void **)
{
    RealisticOptions o = quick();
    o.smear_decay_db = 2.5;
    const RealisticResult r = run_realistic(o);
    double e[5];
    std::printf("smear 2.5 dB/bin (accuracy printed, detection asserted):\n");
    within(r, e, false, 1.5);
    for (int a = 0; a < 5; a++) {
        const RealisticPipe &p = r.pipe[a];
        if (p.detected != p.runs) {
            fail_msg("angle %d: detected %d/%d", r.angles[a], p.detected, p.runs);
        }
    }
}

// Per-frame speckle: the profile is a mean, not the AND's minimum statistic, so the estimate
// does not drift with n (the mask's r2 shortens with n: docs/DESIGN.md, "Range extraction").
static void test_extraction_does_not_drift_with_n_under_per_frame_speckle(void **)
{
    double e[2][5];
    const int ns[2] = {4, 16};
    for (int i = 0; i < 2; i++) {
        RealisticOptions o = quick();
        o.speckle_static = 0;
        o.frames = ns[i];
        const RealisticResult r = run_realistic(o);
        std::printf("speckle per frame, n = %d:\n", ns[i]);
        within(r, e[i], true, 1.5);
    }
    for (int a = 1; a < 5; a++) {
        const double shift = std::fabs(e[1][a] - e[0][a]);
        std::printf("  %+3d deg: mean shift n = 4 -> 16: %.2f deg\n", -10 + 5 * a, shift);
        assert_true(shift <= 0.5);
    }
}

// Never a false warning: with the pole tracked over several rotations (6 simulated beyond
// the window), on every condition above (smear 3.3 / 4.5 / 2.5 dB per bin, per-frame
// speckle at n = 4), the tracker's warning level after the last rotation is never above the
// level the true lean gives anywhere within the reported sigma (board paper-bench: CAUTION
// at |alpha| >= 5 deg, DANGER at alpha >= 10 deg). Levels must be raised somewhere (the
// tracker confirmed the poles), so the check is not vacuous.
static int level_of(const sl_board_t *b, double a_deg)
{
    const double a = a_deg * 100.0;
    if (b->danger_lean_cdeg > 0 && a >= b->danger_lean_cdeg) {
        return SL_WARN_DANGER;
    }
    if (b->caution_lean_cdeg > 0 && std::fabs(a) >= b->caution_lean_cdeg) {
        return SL_WARN_CAUTION;
    }
    return SL_WARN_NONE;
}

static void test_extraction_never_a_false_warning(void **)
{
    const sl_board_t *b = sl_board_find("paper-bench");
    assert_non_null(b);
    struct Cond {
        const char *name;
        double decay;
        int speckle_static, frames;
    };
    const Cond conds[4] = {{"smear 3.3 dB/bin", 3.3, 1, 16},
                           {"smear 4.5 dB/bin", 4.5, 1, 16},
                           {"smear 2.5 dB/bin", 2.5, 1, 16},
                           {"per-frame speckle, n = 4", 3.3, 0, 4}};
    int raised = 0, checked = 0;
    for (const Cond &c : conds) {
        RealisticOptions o = quick();
        o.positions = 2;
        o.reps = 1;
        o.smear_decay_db = c.decay;
        o.speckle_static = c.speckle_static;
        o.frames = c.frames;
        o.track_rotations = 6;
        const RealisticResult r = run_realistic(o);
        std::printf("%s:\n", c.name);
        for (int a = 0; a < 5; a++) {
            const RealisticPipe &p = r.pipe[a];
            for (size_t i = 0; i < p.filt.size(); i++) {
                const double t = p.filt_truth[i], sg = p.filt_sigma[i];
                const int allowed = std::max(level_of(b, t + sg), level_of(b, t - sg));
                std::printf("  true %+6.2f filtered %+6.2f sigma %.2f level %d (allowed <= %d)\n", t,
                            p.filt[i], sg, p.filt_level[i], allowed);
                checked++;
                raised += p.filt_level[i] > SL_WARN_NONE ? 1 : 0;
                if (p.filt_level[i] > allowed) {
                    fail_msg("%s: true %.2f deg, filtered %.2f sigma %.2f: level %d above %d", c.name, t,
                             p.filt[i], sg, p.filt_level[i], allowed);
                }
            }
        }
    }
    std::printf("tracked measurements %d, with a level raised %d\n", checked, raised);
    assert_true(checked >= 30);
    assert_true(raised >= 8);
}

// argv: "--only SUBSTR" or "--skip SUBSTR" (repeatable): runs the tests whose names contain
// one of the --only strings (all when none) and none of the --skip strings, so one
// executable gives several ctest entries that each stay near ~1 min on the loaded machine.
int main(int argc, char **argv)
{
    const struct CMUnitTest all[] = {
        cmocka_unit_test(test_extraction_paper_condition_within_1_deg),
        cmocka_unit_test(test_extraction_steeper_smear_same_configuration),
        cmocka_unit_test(test_extraction_shallow_smear_found_at_the_shadow_edge),
        cmocka_unit_test(test_extraction_never_a_false_warning),
        cmocka_unit_test(test_extraction_does_not_drift_with_n_under_per_frame_speckle),
    };
    std::vector<std::string> only, skip;
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        if ((a == "--only" || a == "--skip") && i + 1 < argc) {
            (a == "--only" ? only : skip).push_back(argv[++i]);
        } else {
            std::fprintf(stderr, "usage: test_sim_extraction [--only SUBSTR]... [--skip SUBSTR]...\n");
            return 2;
        }
    }
    std::vector<CMUnitTest> run;
    for (const CMUnitTest &t : all) {
        const std::string name = t.name;
        bool in = only.empty();
        for (const auto &o : only) {
            in = in || name.find(o) != std::string::npos;
        }
        for (const auto &k : skip) {
            in = in && name.find(k) == std::string::npos;
        }
        if (in) {
            run.push_back(t);
        }
    }
    if (run.empty()) {
        std::fprintf(stderr, "test_sim_extraction: no test selected\n");
        return 2;
    }
    return _cmocka_run_group_tests("test_sim_extraction", run.data(), run.size(), nullptr, nullptr);
}
