// SPDX-License-Identifier: MIT
// Simulator tests against closed-form geometry (MATH.md s.1, s.2, s.5), the capture format
// (NAVTECH_PROTOCOL.md s.4-5, decoded by the core decoder), the noise floor of the real
// sensor (REAL_SCANS.md s.1) and determinism. Black-box tests of the host simulator API.
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <dirent.h>
#include <map>
#include <set>
#include <setjmp.h>
#include <string>
#include <vector>

extern "C" {
#include <cmocka.h>
}

#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_proto.h"
#include "sim_eval.h"
#include "sim_geom.h"
#include "sim_render.h"
#include "sim_scene.h"
#include "sl_paths.h"

using namespace sl;

namespace {

// A paper-sim scene with a static vehicle at the origin heading +y (azimuth 90 = +x).
Scene static_scene(double bin_m = 0)
{
    Scene s;
    s.board_name = "paper-sim";
    s.bin_size_override_m = bin_m;
    s.rotations = 1;
    s.heading_deg = 90;
    s.speed_mps = 0;
    s.ground = false;
    s.az_width_deg = 8;
    validate_scene(s);
    return s;
}

ScenePole pole_at(double x, double y, double tilt, double lean, double radius)
{
    ScenePole p;
    p.name = "p";
    p.x_m = x;
    p.y_m = y;
    p.length_m = 4.0;
    p.radius_m = radius;
    p.tilt_deg = tilt;
    p.lean_deg = lean;
    return p;
}

const GtRow *nominal(const std::vector<GtRow> &gt)
{
    for (const auto &g : gt) {
        if (g.nominal == 1) {
            return &g;
        }
    }
    return nullptr;
}

} // namespace

// MATH.md s.2 with alpha = 0, beta = 0: a vertical pole inside the shadow gives
// rho = r2 / r1 = 1 / cos(theta), exactly in the truth and to quantisation in the capture.
static void test_sim_vertical_pole_gives_rho_inverse_cos_theta(void **)
{
    Scene s = static_scene(0.002);
    s.poles.push_back(pole_at(3.0, 0.0, 0, 0, 0.0005));
    const Simulator sim(s);
    const auto gt = sim.truth(0);
    const GtRow *g = nominal(gt);
    assert_non_null(g);
    assert_int_equal(g->valid, 1);
    assert_string_equal(g->r1_end.c_str(), "top");
    assert_string_equal(g->r2_end.c_str(), "wedge");
    const double theta = s.board.theta_deg(g->azimuth);
    assert_true(std::fabs(theta - 26.0) < 1e-5);
    assert_true(std::fabs(g->r2_m / g->r1_m - 1.0 / std::cos(sim_d2r(theta))) < 1e-9);
    assert_true(std::fabs(g->r1_m - 3.0) < 1e-9);
    assert_true(std::fabs(g->alpha_deg) < 1e-9);
    assert_true(std::fabs(g->alpha_model_deg) < 1e-6);
    assert_true(std::fabs(g->alpha_paper_deg) < 1e-9);
    // from the rendered bins: the run spans [r1 - R, r2] to a bin, and the half-bin
    // corrected bounds give alpha ~ 0 through the core estimator
    const auto bins = sim.render_bins(0, g->azimuth);
    int i1 = -1, i2 = -1;
    for (int i = 0; i < static_cast<int>(bins.size()); i++) {
        if (bins[static_cast<size_t>(i)] > 0) {
            if (i1 < 0) {
                i1 = i;
            }
            i2 = i;
        }
    }
    const double b = s.board.bin_size_m;
    assert_int_equal(i1, static_cast<int>(std::floor((g->r1_m - 0.0005) / b)));
    assert_int_equal(i2, static_cast<int>(std::floor(g->r2_m / b)));
    const Est e = core_estimate((i1 + 0.5) * b + 0.0005, (i2 + 0.5) * b, theta, 0, 0.0006, 0.1);
    assert_int_equal(e.flag, SL_INCLINE_VALID);
    assert_true(std::fabs(e.alpha_deg) < 0.05);
}

// The ground shadow (MATH.md s.1): no ground return closer than H / sin(theta) slant,
// i.e. H / tan(theta) horizontally; the first ground bin is the one holding that range.
static void test_sim_ground_shadow_starts_at_h_over_tan_theta(void **)
{
    for (const char *board : {"paper-sim", "paper-bench"}) {
        Scene s;
        s.board_name = board;
        s.rotations = 1;
        s.ground = true;
        s.ground_reflectivity = 1.0;
        validate_scene(s);
        const Simulator sim(s);
        const int az = 0; // paper-bench: theta = 26 deg at azimuth 0 (the edge's middle)
        SimColumn col;
        sim.geometry_column(0, az, col);
        int first = -1;
        for (size_t i = 0; i < col.energy.size(); i++) {
            if (col.energy[i] > 0) {
                first = static_cast<int>(i);
                break;
            }
        }
        const double H = s.board.radar_height_m, th = sim_d2r(s.board.theta_deg(az));
        const double slant = H / std::sin(th);
        assert_true(std::fabs(s.board.shadow_radius_m(az) - H / std::tan(th)) < 1e-9);
        assert_int_equal(first, static_cast<int>(std::floor(slant / s.board.bin_size_m)));
        // and the horizontal distance of that bin's near edge is within a bin of H / tan(theta)
        const double rb = first * s.board.bin_size_m;
        assert_true(std::sqrt(std::max(0.0, rb * rb - H * H)) <= H / std::tan(th) + 1e-9);
    }
}

// Partial fill: a bin is occupied when any part of the visible extent falls in it.
static void test_sim_partial_fill_marks_a_bin_reached_by_1_mm(void **)
{
    const double b = 0.0438, th = sim_d2r(load_board("paper-sim").theta_deg(0));
    const int k = 80;
    // vertical pole: r2 (axis at -theta) = d / cos(theta) lies 1 mm into bin k
    const double d = (k * b + 0.001) * std::cos(th);
    Scene s = static_scene();
    s.poles.push_back(pole_at(d, 0.0, 0, 0, 0.0001));
    const Simulator sim(s);
    const auto gtv = sim.truth(0);
    const GtRow *g = nominal(gtv);
    assert_non_null(g);
    assert_true(std::fabs(g->r2_m - (k * b + 0.001)) < 1e-9);
    const auto bins = sim.render_bins(0, g->azimuth);
    assert_true(bins[static_cast<size_t>(k)] >= 1);
    assert_int_equal(bins[static_cast<size_t>(k) + 1], 0);
    // the energy in that bin is the sliver's: far below a full bin's
    SimColumn col;
    sim.geometry_column(0, g->azimuth, col);
    assert_true(col.energy[static_cast<size_t>(k)] > 0);
    assert_true(col.energy[static_cast<size_t>(k)] < 0.1 * col.energy[static_cast<size_t>(k) - 2]);
}

// Same seed -> same bytes (also across thread counts); another seed -> other noise.
static void test_sim_is_deterministic_with_a_seed(void **)
{
    Scene s = realistic_scene(2.4, 5.0, 11, 3, 256);
    auto run = [](const Scene &sc, int threads) {
        const Simulator sim(sc);
        std::vector<uint8_t> all = sim.config_message();
        sim_run(sim, 0, sc.rotations, threads, [&](int, std::vector<uint8_t> &b, std::vector<GtRow> &) {
            all.insert(all.end(), b.begin(), b.end());
        });
        return all;
    };
    const auto a = run(s, 1), b = run(s, 2);
    assert_true(a == b);
    s.seed = 12;
    const auto c = run(s, 1);
    assert_int_equal(a.size(), c.size());
    assert_false(a == c);
}

// REAL_SCANS.md s.1: about 35 % exact zeros, low values quantised to 0, 6, 9, 12, 14, 15,
// 17, 18, ... (1-5, 7, 8, 10, 11, 13 and 16 never occur).
static void test_sim_noise_floor_matches_the_real_sensor(void **)
{
    Scene s = realistic_scene(2.4, 0.0, 3, 1, 512);
    s.ground = false;
    s.leakage = false;
    const Simulator sim(s);
    size_t zeros = 0, n = 0;
    std::set<int> seen;
    for (int i = 100; i < 140; i++) {
        const auto v = sim.render_bins(0, i);
        for (size_t j = 200; j < v.size(); j++) {
            zeros += v[j] == 0;
            n++;
            seen.insert(v[j]);
        }
    }
    const double zf = static_cast<double>(zeros) / static_cast<double>(n);
    assert_true(zf > 0.32 && zf < 0.38);
    for (int never : {1, 2, 3, 4, 5, 7, 8, 10, 11, 13, 16}) {
        assert_int_equal(seen.count(never), 0);
    }
    for (int v : {0, 6, 9, 12}) {
        assert_int_equal(seen.count(v), 1);
    }
}

// The near-field leakage band is bright, then a shoulder, and the same in every rotation.
static void test_sim_leakage_band_is_stable_in_time(void **)
{
    Scene s = realistic_scene(2.4, 0.0, 3, 2, 256);
    s.rotations = 2;
    const Simulator sim(s);
    const auto a = sim.render_bins(0, 200), b = sim.render_bins(1, 200);
    double m0 = 0, m1 = 0, diff = 0;
    const int band = static_cast<int>(1.2 / s.board.bin_size_m);
    for (int j = 0; j < band; j++) {
        m0 += a[static_cast<size_t>(j)] / static_cast<double>(band);
        m1 += b[static_cast<size_t>(j)] / static_cast<double>(band);
        diff += std::fabs(a[static_cast<size_t>(j)] - b[static_cast<size_t>(j)]) / band;
    }
    assert_true(m0 > 33 && m0 < 43);
    assert_true(diff < 2.0); // noise only, no new pattern
    const int sh = static_cast<int>(1.95 / s.board.bin_size_m);
    assert_true(a[static_cast<size_t>(sh)] > 12 && a[static_cast<size_t>(sh)] < 26);
}

// The stream is what the radar sends: config first, then 400 FFT messages per rotation
// with encoder ticks 14 i, sweep counter + 1, little-endian timestamps; the core decoder
// reads it without a single skipped byte.
static void test_sim_capture_decodes_with_the_core_decoder(void **)
{
    Scene s = static_scene();
    s.rotations = 2;
    s.poles.push_back(pole_at(3.0, 0.0, 0, 0, 0.005));
    const Simulator sim(s);
    std::vector<uint8_t> bytes = sim.config_message();
    std::vector<GtRow> gt;
    for (int k = 0; k < 2; k++) {
        sim.render_rotation(k, bytes, gt);
    }
    int rows = 0, last_rot = -1;
    CaptureRows dec([&](int rot, int az, const uint8_t *, uint32_t n) {
        assert_int_equal(az, rows % 400);
        assert_int_equal(rot, rows / 400);
        assert_int_equal(n, 3768);
        last_rot = rot;
        rows++;
    });
    dec.feed(bytes.data(), bytes.size());
    dec.finish();
    assert_true(dec.have_config());
    assert_int_equal(dec.config().azimuths, 400);
    assert_int_equal(dec.config().encoder_size, 5600);
    assert_int_equal(dec.config().bin_size_100um, 438);
    assert_int_equal(dec.config().range_bins, 3768);
    assert_int_equal(dec.config().rotation_mhz, 4000);
    assert_int_equal(dec.config().packet_rate, 1600);
    assert_int_equal(dec.config().data_width, 1);
    assert_int_equal(rows, 800);
    assert_int_equal(last_rot, 1);
    assert_int_equal(dec.stats().bytes_skipped, 0);
    assert_int_equal(dec.stats().fft8, 800);
    // message 2 (rotation 0, azimuth 1) by hand: ticks, sweep, LE seconds / nanoseconds
    const size_t cfg = sim.config_message().size();
    const size_t msg = 22 + 14 + 3768;
    const uint8_t *p = bytes.data() + cfg + msg + 22;
    assert_int_equal((p[0] << 8) | p[1], 14);               // data offset, BE
    assert_int_equal((p[2] << 8) | p[3], 1);                // sweep counter, BE
    assert_int_equal((p[4] << 8) | p[5], 14);               // azimuth ticks, BE
    const uint32_t sec = static_cast<uint32_t>(p[6] | (p[7] << 8) | (p[8] << 16)) | (static_cast<uint32_t>(p[9]) << 24);
    const uint32_t ns = static_cast<uint32_t>(p[10] | (p[11] << 8) | (p[12] << 16)) | (static_cast<uint32_t>(p[13]) << 24);
    const double t = s.start_time_s + 1.0 / 400 / 4.0;
    assert_int_equal(sec, static_cast<uint32_t>(std::floor(t)));
    assert_true(std::fabs(ns - (t - std::floor(t)) * 1e9) < 2.0);
}

// Every board's theta at the azimuth centres equals the board loader's.
static void test_sim_chassis_theta_matches_the_board_loader(void **)
{
    for (const char *name : {"paper-sim", "paper-bench", "robotcar-leaf"}) {
        const BoardSpec b = load_board(name);
        for (int i = 0; i < b.azimuths; i++) {
            assert_true(std::fabs(chassis_theta_deg(b, b.azimuth_vehicle_deg(i)) - b.theta_deg(i)) < 1e-9);
        }
    }
}

// For a pole leaning in the radar's vertical plane every truth agrees with the tilt:
// in-plane alpha, the closed form on the exact bounds and the paper's alpha_gt.
static void test_sim_truths_agree_for_an_in_plane_pole(void **)
{
    for (double a : {-10.0, -5.0, 5.0, 10.0}) {
        Scene s = static_scene();
        s.poles.push_back(pole_at(3.0, 0.0, std::fabs(a), a > 0 ? 180.0 : 0.0, 0.005));
        const Simulator sim(s);
        const auto gtv = sim.truth(0);
    const GtRow *g = nominal(gtv);
        assert_non_null(g);
        assert_int_equal(g->valid, 1);
        assert_true(std::fabs(g->alpha_deg - a) < 1e-9);
        assert_true(std::fabs(g->alpha_model_deg - a) < 1e-6);
        assert_true(std::fabs(g->alpha_paper_deg - a) < 1e-9);
        assert_string_equal(g->r1_end.c_str(), a > 0 ? "top" : "foot");
    }
}

// A pole whose base is outside the shadow is flagged: r2 is its base on the ground.
static void test_sim_base_outside_the_shadow_is_not_valid(void **)
{
    Scene s = static_scene();
    s.poles.push_back(pole_at(5.6, 0.0, 0, 0, 0.005)); // shadow radius 2.58 / tan 26 = 5.29 m
    const Simulator sim(s);
    const auto gtv = sim.truth(0);
    const GtRow *g = nominal(gtv);
    assert_non_null(g);
    assert_int_equal(g->valid, 0);
    assert_string_equal(g->r2_end.c_str(), "ground");
}

// A wall between the radar and the pole hides it; boxes return energy.
static void test_sim_wall_occludes_a_pole(void **)
{
    Scene s = static_scene();
    s.poles.push_back(pole_at(4.0, 0.0, 0, 0, 0.005));
    SceneBox w;
    w.name = "w";
    w.cx_m = 3.0;
    w.cy_m = 0;
    w.size_x_m = 0.1;
    w.size_y_m = 2.0;
    w.height_m = 3.0;
    s.boxes.push_back(w);
    const Simulator sim(s);
    const auto gt = sim.truth(0);
    for (const auto &g : gt) {
        assert_true(g.runs == 0 || g.valid == 0);
    }
    SimColumn col;
    sim.geometry_column(0, 100, col); // azimuth 90 deg: towards +x
    double e = 0;
    for (size_t i = static_cast<size_t>(2.8 / 0.0438); i < static_cast<size_t>(3.6 / 0.0438); i++) {
        e += col.energy[i];
    }
    assert_true(e > 0);
}

// The sub-bin model of sl-eval predicts the renderer's bin energies.
static void test_sim_subbin_model_matches_the_renderer(void **)
{
    Scene s = static_scene();
    s.elevation = ElevationProfile::Measured;
    s.elev_top_deg = 3;
    validate_scene(s);
    s.poles.push_back(pole_at(3.2, 0.0, 10, 180, 0.005));
    const Simulator sim(s);
    const auto gtv = sim.truth(0);
    const GtRow *g = nominal(gtv);
    assert_non_null(g);
    SimColumn col;
    sim.geometry_column(0, g->azimuth, col);
    SubbinModel m;
    m.theta_deg = g->theta_deg;
    m.beta_deg = 3;
    m.radius_m = 0.005;
    m.bin_m = s.board.bin_size_m;
    m.gain = [&](double e) { return sim_elevation_gain(s, e); };
    const int i1 = static_cast<int>(std::floor(g->r1_surf_m / m.bin_m));
    const int i2 = static_cast<int>(std::floor(g->r2_m / m.bin_m));
    const auto p = subbin_model_bins(m, g->r1_m, g->r2_m, i1, i2);
    assert_int_equal(p.size(), static_cast<size_t>(i2 - i1 + 1));
    const double k = col.energy[static_cast<size_t>(i1) + 2] / p[2];
    for (int i = i1; i <= i2; i++) {
        const double rel = col.energy[static_cast<size_t>(i)] / (k * p[static_cast<size_t>(i - i1)]);
        assert_true(std::fabs(rel - 1.0) < 0.01);
    }
    // and the sub-bin bounds recover the axis bounds to a millimetre
    const auto bins = sim.render_bins(0, g->azimuth);
    std::vector<double> v(bins.begin(), bins.end());
    double r1 = 0, r2 = 0;
    assert_true(subbin_bounds(v.data(), static_cast<int>(v.size()), i1, i2, m, &r1, &r2));
    assert_true(std::fabs(r1 - g->r1_m) < 0.001);
    assert_true(std::fabs(r2 - g->r2_m) < 0.001);
}

// Scene files: documented errors, and every shipped scene loads.
static void test_sim_scene_files_are_checked(void **)
{
    const std::string ok = "[scene]\nboard = paper-sim\n[pole.a]\nx_m = 3\ny_m = 0\n";
    const Scene s = parse_scene_string(ok);
    assert_int_equal(s.poles.size(), 1);
    auto fails = [](const std::string &text, const char *needle) {
        try {
            parse_scene_string(text);
        } catch (const SceneError &e) {
            return std::string(e.what()).find(needle) != std::string::npos;
        }
        return false;
    };
    assert_true(fails(ok + "radius = 1\n", "pole.a.radius: unknown key"));
    assert_true(fails(ok + "[polee.b]\nx_m = 1\n", "unknown section"));
    assert_true(fails(ok + "x_m = 4\n", "duplicate key"));
    assert_true(fails(ok + "tilt_deg = 75\n", "tilt_deg: 75 outside"));
    assert_true(fails("[scene]\nboard = no-such-board\n", "scene.board"));
    assert_true(fails(ok + "[effects]\nnoise = on\n", "mapping = log"));
    int n = 0;
    const std::string dir = source_dir() + "/scenes";
    DIR *d = opendir(dir.c_str());
    assert_non_null(d);
    while (dirent *e = readdir(d)) {
        const std::string f = e->d_name;
        if (f.size() > 4 && f.compare(f.size() - 4, 4, ".ini") == 0) {
            const Scene sc = load_scene(dir + "/" + f);
            assert_true(sc.rotations >= 1);
            n++;
        }
    }
    closedir(d);
    assert_true(n >= 3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sim_vertical_pole_gives_rho_inverse_cos_theta),
        cmocka_unit_test(test_sim_ground_shadow_starts_at_h_over_tan_theta),
        cmocka_unit_test(test_sim_partial_fill_marks_a_bin_reached_by_1_mm),
        cmocka_unit_test(test_sim_is_deterministic_with_a_seed),
        cmocka_unit_test(test_sim_noise_floor_matches_the_real_sensor),
        cmocka_unit_test(test_sim_leakage_band_is_stable_in_time),
        cmocka_unit_test(test_sim_capture_decodes_with_the_core_decoder),
        cmocka_unit_test(test_sim_chassis_theta_matches_the_board_loader),
        cmocka_unit_test(test_sim_truths_agree_for_an_in_plane_pole),
        cmocka_unit_test(test_sim_base_outside_the_shadow_is_not_valid),
        cmocka_unit_test(test_sim_wall_occludes_a_pole),
        cmocka_unit_test(test_sim_subbin_model_matches_the_renderer),
        cmocka_unit_test(test_sim_scene_files_are_checked),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
