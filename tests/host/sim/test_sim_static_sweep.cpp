// SPDX-License-Identifier: MIT
// Static noise-free sweep through the CORE PIPELINE (issue 11, "Must show"): the paper-sim
// vehicle parked (the demo's rendering: ideal emission, 2 deg beam, the sensor's 8-bit log
// mapping, column normalisation, no noise, no speckle), 2 cm poles leaning -10 / 0 / +10 deg
// in the radar's plane, the pole base swept over 40 sub-bin positions (one bin, 43.8 mm, in
// steps of bin/40). A static scene gives the same quantised bounds every rotation, so the
// error at each position is the extraction's quantisation error, not noise that averages
// out. 12 poles per scene (3 angles x 4 positions, 30 deg apart in azimuth: no two share a
// beam), 10 scenes. Reported: per angle mean, max |error| and the worst position; asserted:
// every pole found every rotation after the window fills, max |error| <= the bound below.
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <setjmp.h>
#include <string>

extern "C" {
#include <cmocka.h>
}

#include "sim_eval.h"
#include "sim_render.h"
#include "sim_scene.h"

using namespace sl;

namespace {

constexpr int kAngles[3] = {-10, 0, 10};
constexpr int kPositions = 40;
constexpr int kPerScene = 4; // positions per scene (x 3 angles = 12 poles)
constexpr double kBin = 0.0438;
constexpr double kRadius = 0.01; // m (2 cm poles)
constexpr double kBase = 3.0; // m, base of the first position (inside the 5.29 m shadow)
constexpr double kPi = 3.14159265358979323846;
// The n = 16 window fills at rotation 15; the profile of a target's azimuth (assigned at
// its first detection) replaces the mask's bounds from cfg.min_frames = 2 rows on.
constexpr int kSteady = 17;

struct Cell {
    double maxabs = 0, sum = 0; // every rotation with a target
    int n = 0;
    double steady_max = 0;      // rotations >= kSteady (the profile's bounds are in)
    int steady_n = 0;
    double track_max = 0;       // confirmed track on the pole (what PoleLean carries)
    int track_n = 0;
    int rows = 0, detected = 0;
    double dr1_mm = NAN, dr2_mm = NAN; // last target's r1 / r2 - the axis truth
    // Edge bins on the pole's azimuth (rotation 0): the fraction of r2's bin the axis fills
    // and its value with the bin before; the fraction of the first bin in front of the
    // front surface (axis r1 - radius) and its value with the bin after. The data a
    // sub-bin edge model has to explain (docs/DESIGN.md).
    double fill2 = NAN, fill1 = NAN;
    int v2 = -1, v2_prev = -1, v1 = -1, v1_next = -1;
};
Cell g_cell[3][kPositions];

std::string scene_text(int scene)
{
    std::string t = "[scene]\nboard = paper-sim\nrange_bins = 200\nrotations = 20\n"
                    "rotation_hz = 4\nseed = " + std::to_string(11 + scene) + "\n"
                    "[vehicle]\nx_m = 0\ny_m = 0\nheading_deg = 90\nspeed_mps = 0\n";
    for (int a = 0; a < 3; a++) {
        for (int k = 0; k < kPerScene; k++) {
            const int pos = scene * kPerScene + k;
            const double d = kBase + kBin * pos / kPositions;
            const double az = (15.0 + 30.0 * (a * kPerScene + k)) * kPi / 180.0; // clockwise
            const double x = d * std::sin(az), y = d * std::cos(az);
            // > 0: the top leans towards the radar (world direction from the base to it)
            const double to_radar = std::atan2(-y, -x) * 180.0 / kPi;
            const double lean = kAngles[a] >= 0 ? to_radar : to_radar + 180.0;
            char buf[400];
            std::snprintf(buf, sizeof buf,
                          "[pole.p%d_%d]\nx_m = %.6f\ny_m = %.6f\nat_height_m = 0\nlength_m = 4.0\n"
                          "radius_m = %.3f\ntilt_deg = %d\nlean_deg = %.6f\nreflectivity = 1.0\n",
                          a, pos, x, y, kRadius, std::abs(kAngles[a]), lean);
            t += buf;
        }
    }
    t += "[ground]\nreflectivity = 0.05\n[beam]\nelevation = ideal\nazimuth_width_deg = 2.0\n"
         "[output]\namplitude = integral\nmapping = log\nnormalize = column\n";
    return t;
}

int setup(void **)
{
    for (int sc = 0; sc < kPositions / kPerScene; sc++) {
        const Scene s = parse_scene_string(scene_text(sc), "static_sweep");
        PipeCfg c = pipe_cfg_for_scene(s);
        c.clip_ambiguous = false;
        // simulate_pipeline's loop, keeping the pipeline's targets (r1 / r2 diagnostics)
        const Simulator sim(s);
        PipelineEval pe(c);
        const auto cm = sim.config_message();
        pe.feed(0, cm.data(), cm.size());
        std::map<int, GtRow> truth; // per pole, the nominal row (static: every rotation alike)
        sim_run(sim, 0, s.rotations, 2, [&](int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &gt) {
            for (const auto &g : gt) {
                if (g.nominal == 1 && g.valid == 1) {
                    pe.add_truth(g);
                    truth[g.pole] = g;
                }
            }
            pe.feed(k, bytes.data(), bytes.size());
        });
        pe.finish();
        const std::map<int, PipeEval> res = pe.result();
        for (const auto &g : truth) {
            const int a = g.first / kPerScene, pos = sc * kPerScene + g.first % kPerScene;
            Cell &cell = g_cell[a][pos];
            const std::vector<uint8_t> row = sim.render_bins(0, g.second.azimuth);
            const double e2 = g.second.r2_m / kBin, e1 = (g.second.r1_m - kRadius) / kBin;
            const size_t b2 = static_cast<size_t>(e2), b1 = static_cast<size_t>(e1);
            if (b1 >= 1 && b2 + 1 < row.size()) {
                cell.fill2 = e2 - static_cast<double>(b2);
                cell.v2 = row[b2];
                cell.v2_prev = row[b2 - 1];
                cell.fill1 = 1.0 - (e1 - static_cast<double>(b1));
                cell.v1 = row[b1];
                cell.v1_next = row[b1 + 1];
            }
        }
        for (const auto &t : pe.targets()) {
            for (const auto &g : truth) {
                if (std::abs(t.az - g.second.azimuth) <= 1) {
                    const int a = g.first / kPerScene, pos = sc * kPerScene + g.first % kPerScene;
                    Cell &cell = g_cell[a][pos];
                    cell.dr1_mm = (t.r1_m - g.second.r1_m) * 1e3;
                    cell.dr2_mm = (t.r2_m - g.second.r2_m) * 1e3;
                    if (t.rotation >= kSteady) {
                        cell.steady_n++;
                        cell.steady_max =
                            std::fmax(cell.steady_max, std::fabs(t.alpha_deg - g.second.alpha_deg));
                    }
                }
            }
        }
        for (const auto &tk : pe.tracks()) {
            if (tk.confirmed == 0 || tk.valid_hits <= 0) {
                continue;
            }
            for (const auto &g : truth) {
                if (std::abs(tk.az - g.second.azimuth) <= 1) {
                    const int a = g.first / kPerScene, pos = sc * kPerScene + g.first % kPerScene;
                    Cell &cell = g_cell[a][pos];
                    cell.track_n++;
                    cell.track_max =
                        std::fmax(cell.track_max, std::fabs(tk.alpha_deg - g.second.alpha_deg));
                }
            }
        }
        for (const auto &kv : res) {
            const int idx = kv.first; // pole index in scene order: a * kPerScene + k
            const int a = idx / kPerScene, pos = sc * kPerScene + idx % kPerScene;
            Cell &cell = g_cell[a][pos];
            cell.rows = kv.second.truth_rows;
            cell.detected = kv.second.detected;
            for (double e : kv.second.err.err) {
                cell.sum += e;
                cell.n++;
                if (std::fabs(e) > cell.maxabs) {
                    cell.maxabs = std::fabs(e);
                }
            }
        }
    }
    std::printf("static sweep (paper-sim, noise-free, 40 sub-bin positions of the base)\n");
    std::printf("%6s %8s %8s %8s %6s %8s %6s %8s %6s\n", "alpha", "mean", "min", "max|e|", "@pos",
                "steady", "@pos", "track", "@pos");
    for (int a = 0; a < 3; a++) {
        double s = 0, mn = 1e9, mx = 0, smx = 0, tmx = 0;
        int n = 0, at = -1, sat = -1, tat = -1;
        for (int p = 0; p < kPositions; p++) {
            const Cell &c = g_cell[a][p];
            if (c.n == 0) {
                continue;
            }
            const double m = c.sum / c.n;
            s += m;
            n++;
            mn = std::fmin(mn, m);
            if (c.maxabs > mx) {
                mx = c.maxabs;
                at = p;
            }
            if (c.steady_max > smx) {
                smx = c.steady_max;
                sat = p;
            }
            if (c.track_max > tmx) {
                tmx = c.track_max;
                tat = p;
            }
        }
        std::printf("%+6d %+8.3f %+8.3f %8.3f %6d %8.3f %6d %8.3f %6d\n", kAngles[a],
                    n ? s / n : std::nan(""), mn, mx, at, smx, sat, tmx, tat);
        for (int p = 0; p < kPositions; p++) {
            const Cell &c = g_cell[a][p];
            std::printf("  pos %2d  rows %2d det %2d  mean %+7.3f  max %6.3f  steady %6.3f  dr1 %+6.1f dr2 %+6.1f mm"
                        "  | r2 fill %.3f v %3d prev %3d | r1 fill %.3f v %3d next %3d | track %6.3f (%d)\n",
                        p, c.rows, c.detected, c.n ? c.sum / c.n : std::nan(""), c.maxabs,
                        c.steady_max, c.dr1_mm,
                        c.dr2_mm, c.fill2, c.v2, c.v2_prev, c.fill1, c.v1, c.v1_next, c.track_max,
                        c.track_n);
        }
    }
    return 0;
}

} // namespace

// Every pole is found in every rotation once the board's n = 16 frame window has filled
// (static, noise-free: nothing may be missed).
static void test_static_sweep_every_pole_found(void **)
{
    for (int a = 0; a < 3; a++) {
        for (int p = 0; p < kPositions; p++) {
            const Cell &c = g_cell[a][p];
            assert_int_equal(c.rows, 20);
            assert_int_equal(c.detected, 20 - 15);
            assert_int_equal(c.n, c.detected);
            assert_int_equal(c.steady_n, 20 - kSteady);
        }
    }
}

// The goal: max |alpha error| <= 1.0 deg over 3 angles x 40 sub-bin positions, on
// every rotation whose target is refined from its range profile (kSteady on: sub-bin r1
// and r2, sl_profile.h step 6) and on every confirmed track (what PoleLean carries: a track
// confirms on its third hit, rotation 17, and restarts its filter on the first profile
// measurement, sl_track.h). The targets of the first two rotations after the window fills
// carry the mask's whole-bin bounds (their azimuth's profile starts when the target first
// appears): up to 2.03 deg at -10 deg, kept below kMaskMaxErr as a regression guard; they
// never reach CAN.
constexpr double kMaxErr = 1.0;
constexpr double kMaskMaxErr = 2.1;
static void test_static_sweep_max_error(void **)
{
    for (int a = 0; a < 3; a++) {
        for (int p = 0; p < kPositions; p++) {
            const Cell &c = g_cell[a][p];
            if (c.steady_max > kMaxErr || c.track_max > kMaxErr || c.maxabs > kMaskMaxErr) {
                std::printf("alpha %+d pos %d: max |error| profile %.3f track %.3f any %.3f\n",
                            kAngles[a], p, c.steady_max, c.track_max, c.maxabs);
            }
            assert_true(c.steady_max <= kMaxErr);
            assert_true(c.track_n >= 3); // confirmed from rotation 17 on
            assert_true(c.track_max <= kMaxErr);
            assert_true(c.maxabs <= kMaskMaxErr);
        }
    }
}

// Both edges within their bin (sl_profile.h step 6, the noise-free returns end in a cliff),
// over the 40 positions of the last rotation at every angle. Whole-bin centres give bin / 4
// = 11 mm (uniform over the sawtooth).
// - r2: mean |r2 - truth| <= 6 mm (measured 2.2 / 1.8 / 3.0 mm at -10 / 0 / +10 deg).
// - r1 reads the pole's FRONT surface (the board states no radius; truth is the axis, 10 mm
//   behind it): mean |r1 - (truth - R)| <= 8 mm (measured 4.8 / 6.8 / 4.5 mm; the first
//   bin's centre gives 11: the leading edge's models, sl_profile_lead_fill_q16, leave out
//   the radius, which rounds the foot's peak).
static void test_static_sweep_edges_within_the_bin(void **)
{
    for (int a = 0; a < 3; a++) {
        double s2 = 0, s1 = 0;
        for (int p = 0; p < kPositions; p++) {
            assert_false(std::isnan(g_cell[a][p].dr2_mm));
            s2 += std::fabs(g_cell[a][p].dr2_mm);
            s1 += std::fabs(g_cell[a][p].dr1_mm + kRadius * 1e3);
        }
        std::printf("alpha %+d: mean |r2 error| %.1f mm, mean |r1 - front| %.1f mm\n", kAngles[a],
                    s2 / kPositions, s1 / kPositions);
        assert_true(s2 / kPositions <= 6.0);
        assert_true(s1 / kPositions <= 8.0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_static_sweep_every_pole_found),
        cmocka_unit_test(test_static_sweep_max_error),
        cmocka_unit_test(test_static_sweep_edges_within_the_bin),
    };
    return cmocka_run_group_tests(tests, setup, nullptr);
}
