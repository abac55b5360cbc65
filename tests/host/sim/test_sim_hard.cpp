// SPDX-License-Identifier: MIT
// The harder realistic condition (issue 11; sl-eval realistic --hard, HardCondition in
// sim_eval.h). First the simulator's new effects, each on its own (cheap): two-component
// smear with level-dependent decay and a front skirt, per-frame speckle on the frozen
// pattern, azimuth jitter, a segmented pole, and the perturbed true installation. Then
// (--only acceptance, labels sim;slow) a reduced hard run: the paper's own processing must
// show the real bench's spread (std 2.5-4 deg, paper Table II), and the pipeline's figures
// are printed and what holds is asserted (see the test's comment).
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <setjmp.h>
#include <string>
#include <vector>

extern "C" {
#include <cmocka.h>
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_track.h"
}

#include "sim_eval.h"
#include "sim_render.h"
#include "sim_scene.h"

using namespace sl;

// Measurements (of 30) in which the pipeline finds the pole: 30 measured. 16 before a drop at
// or beyond the shadow edge stopped being read as the pole's end (sl_profile.h step 3): the
// slow smear component's tail ends there and the pole was rejected as SHADOW.
static const int kMinDetected = 28;

namespace {

// A scene with one vertical pole, no noise, leakage or speckle: only what a test turns on.
Scene quiet_scene(double dist)
{
    Scene s = realistic_scene(dist, 0.0, 21, 2, 256);
    s.noise = false;
    s.leakage = false;
    s.speckle = false;
    s.ground = false;
    s.smear = false;
    validate_scene(s);
    return s;
}

int pole_azimuth(const Simulator &sim)
{
    for (const auto &g : sim.truth(0)) {
        if (g.nominal == 1) {
            return g.azimuth;
        }
    }
    return -1;
}

int last_at_least(const std::vector<uint8_t> &v, int t)
{
    int last = -1;
    for (size_t j = 0; j < v.size(); j++) {
        if (v[j] >= t) {
            last = static_cast<int>(j);
        }
    }
    return last;
}

int first_at_least(const std::vector<uint8_t> &v, int t)
{
    for (size_t j = 0; j < v.size(); j++) {
        if (v[j] >= t) {
            return static_cast<int>(j);
        }
    }
    return -1;
}

} // namespace

// Two-component smear: the tail past the pole is not a single exponential (far from the
// pole it falls at the slow component's rate, much slower than next to it), the bin before
// the pole is lit by the front skirt, and a stronger return decays more slowly.
static void test_hard_smear_two_component_skirt_and_level(void **)
{
    Scene s = quiet_scene(2.4);
    s.smear = true;
    s.smear_shape = 2;
    s.smear_width_bins = 60;
    s.smear_decay_db = 3.3;
    s.smear_slow_db = -15;
    s.smear_slow_decay_db = 1.5;
    s.smear_amp_decay_db = 0.5;
    s.smear_front_db = -6;
    validate_scene(s);
    const Simulator sim(s);
    const int az = pole_azimuth(sim);
    assert_true(az >= 0);
    const auto v = sim.render_bins(0, az);
    Scene u = quiet_scene(2.4);
    const Simulator plain(u);
    const auto p = plain.render_bins(0, az);
    const int f = first_at_least(p, 1), e = last_at_least(p, 1);
    assert_true(f > 0 && e > f);

    // front skirt: the bin before the pole's first lit bin reads about 6 dB (values ~ dB)
    // below that bin's own level
    assert_true(v[static_cast<size_t>(f) - 1] > 0);
    assert_true(std::abs(static_cast<int>(v[static_cast<size_t>(f)]) - 6 - v[static_cast<size_t>(f) - 1]) <= 3);
    // near tail (2-6 bins past the end) falls faster than the far tail (20-30 bins past):
    // values ~ dB; the slow component (1.5 dB/bin, slower for this strong return) dominates far
    const double near = (v[static_cast<size_t>(e) + 2] - v[static_cast<size_t>(e) + 6]) / 4.0;
    const double far = (v[static_cast<size_t>(e) + 20] - v[static_cast<size_t>(e) + 30]) / 10.0;
    std::printf("tail slope near %.2f far %.2f values/bin\n", near, far);
    assert_true(near > far + 0.7);
    assert_true(far > 0.5 && far < 1.5);
    // a 20 dB weaker pole: its far tail decays faster (level-dependent decay)
    Scene w = s;
    w.poles[0].reflectivity = 0.01;
    validate_scene(w);
    const auto vw = Simulator(w).render_bins(0, az);
    const double far_w = (vw[static_cast<size_t>(e) + 10] - vw[static_cast<size_t>(e) + 20]) / 10.0;
    assert_true(far_w > far + 0.2);
}

// Per-frame speckle on top of the frozen pattern: the pole's bins change from rotation to
// rotation by about speckle_frame_db, not more; without it they do not change at all.
static void test_hard_speckle_per_frame_on_frozen(void **)
{
    Scene s = quiet_scene(2.4);
    s.speckle = true;
    s.speckle_static = 1;
    s.speckle_db = 2.0;
    validate_scene(s);
    const Simulator a(s);
    const int az = pole_azimuth(a);
    assert_true(a.render_bins(0, az) == a.render_bins(1, az));
    s.speckle_frame_db = 1.0;
    validate_scene(s);
    const Simulator b(s);
    const auto r0 = b.render_bins(0, az), r1 = b.render_bins(1, az);
    double sq = 0;
    int n = 0;
    for (size_t j = 0; j < r0.size(); j++) {
        if (r0[j] > 40 && r1[j] > 40) {
            const double d = static_cast<double>(r0[j]) - r1[j];
            sq += d * d;
            n++;
        }
    }
    assert_true(n >= 5);
    const double rms = std::sqrt(sq / n); // values ~ dB: two draws of 1 dB differ by ~1.4
    assert_true(rms > 0.5 && rms < 3.0);
}

// Azimuth jitter: on the flank of the beam the pole's level changes between rotations;
// the reported azimuth (truth) does not.
static void test_hard_azimuth_jitter_moves_the_beam(void **)
{
    Scene s = quiet_scene(2.4);
    const Simulator a(s);
    const int az = pole_azimuth(a);
    const int flank = az + 1;
    auto total = [flank](const Simulator &sim, int k) {
        SimColumn c;
        sim.geometry_column(k, flank, c);
        double e = 0;
        for (double x : c.energy) {
            e += x;
        }
        return e;
    };
    assert_true(total(a, 0) > 0 && total(a, 0) == total(a, 1));
    s.az_jitter_deg = 0.1;
    validate_scene(s);
    const Simulator b(s);
    int differ = 0;
    for (int k = 1; k < 6; k++) {
        const double r = total(b, k) / total(a, 0);
        differ += std::fabs(r - 1.0) > 1e-4 ? 1 : 0;
        assert_true(r > 0.7 && r < 1.4); // 0.1 deg of a ~2 deg beam: a few per cent
    }
    assert_true(differ >= 4);
    assert_int_equal(pole_azimuth(b), az);
}

// Segmented pole: reflectors 2 cm every 6 cm; the range profile is lumpier than the
// uniform tube's (more variation bin to bin) and weaker overall.
static void test_hard_segmented_pole_is_lumpy(void **)
{
    Scene s = quiet_scene(2.4);
    s.amplitude = AmplitudeModel::Integral;
    const Simulator a(s);
    const int az = pole_azimuth(a);
    SimColumn ca, cb;
    a.geometry_column(0, az, ca);
    s.poles[0].segment_m = 0.06;
    s.poles[0].segment_fill_m = 0.02;
    s.poles[0].segment_gap = 0.1;
    validate_scene(s);
    const Simulator b(s);
    b.geometry_column(0, az, cb);

    double ea = 0, eb = 0, lo = 1e9, hi = 0;
    for (size_t j = 0; j < ca.energy.size(); j++) {
        ea += ca.energy[j];
        eb += cb.energy[j];
        if (ca.energy[j] > 0.05) {
            lo = std::min(lo, cb.energy[j] / ca.energy[j]);
            hi = std::max(hi, cb.energy[j] / ca.energy[j]);
        }
    }
    std::printf("segmented / uniform per bin: %.3f .. %.3f, total %.3f\n", lo, hi, eb / ea);
    assert_true(eb < 0.6 * ea && eb > 0.25 * ea); // 1/3 reflectors + 0.1 x 2/3 = 0.4
    assert_true(hi - lo > 0.03);                   // lumpy: the ratio differs bin to bin
}

// make_hard: the true installation differs from the board within the stated tolerances
// and differs between seeds; the board the processing uses is untouched.
static void test_hard_installation_perturbed_within_tolerance(void **)
{
    const HardCondition h;
    const Scene nom = realistic_scene(2.4, 0.0, 1, 2, 256);
    double max_dt = 0, max_dh = 0, max_db = 0;
    bool moved = false;
    for (uint64_t seed = 1; seed <= 20; seed++) {
        Scene s = realistic_scene(2.4, 0.0, seed, 2, 256);
        make_hard(s, h, seed);
        const double dt = s.board.theta_deg(0) - nom.board.theta_deg(0);
        const double dh = s.board.radar_height_m - nom.board.radar_height_m;
        const double db = s.elev_top_deg - nom.elev_top_deg;
        max_dt = std::max(max_dt, std::fabs(dt));
        max_dh = std::max(max_dh, std::fabs(dh));
        max_db = std::max(max_db, std::fabs(db));
        moved = moved || std::fabs(dt) > 0.05;
        assert_int_equal(s.smear_shape, 2);
        assert_true(s.poles[0].segment_m > 0);
    }
    assert_true(moved);
    assert_true(max_dt <= h.theta_tol_deg + 1e-9 && max_dt > 0.5 * h.theta_tol_deg);
    assert_true(max_dh <= h.height_tol_m + 1e-12 && max_dh > 0.5 * h.height_tol_m);
    assert_true(max_db <= h.beta_tol_deg + 1e-9 && max_db > 0.5 * h.beta_tol_deg);
    assert_true(load_board("paper-bench").radar_height_m == nom.board.radar_height_m);
}

static RealisticResult g_res;

// Warning level the true lean gives (paper-bench: CAUTION at |alpha| >= 5, DANGER >= 10).
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

// Acceptance of the condition as realistic, and the pipeline's figures on it (reduced run:
// 3 positions x 2 repetitions per angle, 160 bins per azimuth, 6 calibration positions).
static void test_hard_acceptance(void **)
{
    RealisticOptions o;
    o.hard = true;
    o.positions = 3;
    o.reps = 2;
    o.calib_positions = 6;
    o.range_bins = 160;
    o.progress = false;
    o.threads = 2;
    o.extract = Extract::Pipeline;
    o.bbox_table = true;
    g_res = run_realistic(o);
    print_realistic(stdout, g_res);
    // the paper's own processing shows the real bench's spread: the std over the 5 angles
    // averaged (each angle has only 6 measurements here) within the paper's 2.5-4 deg
    double ps = 0;
    for (int a = 0; a < 5; a++) {
        assert_true(g_res.paper_style[a].err.size() >= 4);
        ps += g_res.paper_style[a].std / 5;
    }
    std::printf("paper processing: average std %.2f deg (accept 2.5-4)\n", ps);
    assert_true(ps >= 2.5 && ps <= 4.0);
    // the pipeline's figures (the issue wants |mean| <= 1.0 and std <= 2.0 per angle)
    const sl_board_t *b = sl_board_find("paper-bench");
    assert_non_null(b);
    int meets = 0, detected = 0, runs = 0, checked = 0;
    for (int a = 0; a < 5; a++) {
        const RealisticPipe &p = g_res.pipe[a];
        double m = 0, q = 0;
        for (double x : p.raw) {
            m += x / static_cast<double>(p.raw.size());
        }
        for (double x : p.raw) {
            q += (x - m) * (x - m);
        }
        const double sd = p.raw.size() > 1 ? std::sqrt(q / static_cast<double>(p.raw.size() - 1)) : std::nan("");
        const bool ok = !p.raw.empty() && std::fabs(m - g_res.angles[a]) <= 1.0 && sd <= 2.0;
        std::printf("pipeline %+d deg: mean error %+.2f std %.2f detected %d/%d: %s\n", g_res.angles[a],
                    m - g_res.angles[a], sd, p.detected, p.runs, ok ? "meets 1.0/2.0" : "does NOT meet 1.0/2.0");
        meets += ok ? 1 : 0;
        detected += p.detected;
        runs += p.runs;
        // never a false warning: the tracker's level is never above what the true lean gives
        // within the reported sigma
        for (size_t i = 0; i < p.filt.size(); i++) {
            const double tr = p.filt_truth[i], sg = p.filt_sigma[i];
            const int allowed = std::max(level_of(b, tr + sg), level_of(b, tr - sg));
            checked++;
            if (p.filt_level[i] > allowed) {
                fail_msg("true %.2f deg, filtered %.2f sigma %.2f: level %d above %d", tr, p.filt[i], sg,
                         p.filt_level[i], allowed);
            }
        }
    }
    std::printf("pipeline: %d/5 angles meet 1.0/2.0; detected %d/%d; tracked %d\n", meets, detected, runs, checked);
    assert_true(detected >= kMinDetected);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest quick[] = {
        cmocka_unit_test(test_hard_smear_two_component_skirt_and_level),
        cmocka_unit_test(test_hard_speckle_per_frame_on_frozen),
        cmocka_unit_test(test_hard_azimuth_jitter_moves_the_beam),
        cmocka_unit_test(test_hard_segmented_pole_is_lumpy),
        cmocka_unit_test(test_hard_installation_perturbed_within_tolerance),
    };
    const struct CMUnitTest slow[] = {
        cmocka_unit_test(test_hard_acceptance),
    };
    if (argc > 1 && std::strcmp(argv[1], "--acceptance") == 0) {
        return cmocka_run_group_tests_name("sim_hard_acceptance", slow, nullptr, nullptr);
    }
    return cmocka_run_group_tests_name("sim_hard", quick, nullptr, nullptr);
}
