// SPDX-License-Identifier: MIT
// The realistic bench (paper Table II condition) through the CORE PIPELINE
// (sl-eval realistic --extract pipeline): simulator bytes (static bench, smear, speckle,
// noise floor, leakage, 16 frames) -> sl_pipeline_feed (paper-bench, speed 0: the board's
// n = 16 window) -> targets of the last rotations at the pole's azimuth. Reduced run
// (3 positions x 1 repetition, 160 bins per azimuth, no bbox calibration) to stay a few seconds.
// Asserted: detection in most measurements, the static window, and that the estimates are
// ordered like the truth. Accuracy is asserted by sim_extraction_smear_robust
// (test_sim_extraction.cpp); the full runs are in docs/RESULTS.md.
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <setjmp.h>

extern "C" {
#include <cmocka.h>
#include "shadowlean/sl_board.h"
}

#include "sim_eval.h"

using namespace sl;

static RealisticResult g_res;

static int setup(void **)
{
    RealisticOptions o;
    o.positions = 3;
    o.reps = 1;
    o.range_bins = 160; // the pole and its shadow end within 4 m: same estimates as 512 bins
    o.progress = false;
    o.threads = 2;
    o.extract = Extract::Pipeline;
    o.bbox_table = false;
    g_res = run_realistic(o);
    print_realistic(stdout, g_res);
    return 0;
}

static double mean_of(const std::vector<double> &v)
{
    double s = 0;
    for (double x : v) {
        s += x;
    }
    return v.empty() ? std::nan("") : s / static_cast<double>(v.size());
}

// The pole yields a target at its azimuth in >= 80 % of the measurements at every angle,
// and nothing else in the static scene is reported.
static void test_realistic_pipeline_detects_the_pole_in_most_positions(void **)
{
    assert_true(g_res.have_pipe);
    for (int a = 0; a < 5; a++) {
        const RealisticPipe &p = g_res.pipe[a];
        assert_int_equal(p.runs, 3);
        assert_true(p.rate() >= 0.8);
        assert_true(p.raw.size() * 5 >= static_cast<size_t>(p.runs) * 4);
        assert_true(p.unmatched <= p.runs);
    }
}

// Static bench: speed 0 reached the pipeline, so the window is the board's n.
static void test_realistic_pipeline_uses_the_boards_window_when_static(void **)
{
    const sl_board_t *b = sl_board_find("paper-bench");
    assert_non_null(b);
    assert_int_equal(g_res.pipe_mask_frames, b->mask_frames);
    assert_true(g_res.pipe_cfg.speed_mps == 0.0);
    for (int a = 0; a < 5; a++) {
        assert_int_equal(g_res.pipe[a].frames_eff_min, b->mask_frames);
        assert_int_equal(g_res.pipe[a].frames_eff_max, b->mask_frames);
    }
}

// The mean estimate increases with the true angle from -10 to +10 deg (sign and ordering
// follow the truth; the size of the error is only reported).
static void test_realistic_pipeline_estimates_follow_the_truths_ordering(void **)
{
    double prev = -1e9;
    for (int a = 0; a < 5; a++) {
        const double m = mean_of(g_res.pipe[a].raw);
        assert_false(std::isnan(m));
        assert_true(m > prev);
        prev = m;
    }
    assert_true(mean_of(g_res.pipe[4].raw) > 0.0);
    assert_true(mean_of(g_res.pipe[4].raw) - mean_of(g_res.pipe[0].raw) > 5.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_realistic_pipeline_detects_the_pole_in_most_positions),
        cmocka_unit_test(test_realistic_pipeline_uses_the_boards_window_when_static),
        cmocka_unit_test(test_realistic_pipeline_estimates_follow_the_truths_ordering),
    };
    return cmocka_run_group_tests(tests, setup, nullptr);
}
