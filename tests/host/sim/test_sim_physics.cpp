// SPDX-License-Identifier: MIT
// The simulator's radar physics (scenes/README.md, "The range response and physical
// speckle"): the window and measured range responses, the coherent sum with physical speckle
// (exponential powers, frozen when parked, drawn anew when moving), knife-edge diffraction at
// the chassis edge, point returns and the Navtech value curve. With the paths of sl-sim and
// sl-calib on the command line, also: a Hann response rendered by sl-sim and measured by
// sl-calib response (the tool of the real scans) has the window's half-power width.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <setjmp.h>
#include <sstream>
#include <string>
#include <vector>

extern "C" {
#include <cmocka.h>
}

#include "shadowlean/sl_response.h"
#include "sim_render.h"
#include "sim_scene.h"

namespace {

const char *g_sim = nullptr, *g_calib = nullptr, *g_scenes = nullptr, *g_work = nullptr;

// A parked paper-sim vehicle, ground only, on the CTS350-X value scale.
std::string base_scene(const std::string &effects, const std::string &extra = "")
{
    return "[scene]\nboard = paper-sim\nrange_bins = 512\nrotations = 2\n"
           "[beam]\nazimuth_width_deg = 2\n"
           "[output]\nmapping = log\nnormalize = none\nlog_quantity = power\n"
           "log_db_per_decade = 20\nlog_curve = navtech\n" +
           extra + "[effects]\n" + effects;
}

// Half-power width of a response R(o) (bins): each side's crossing by bisection.
double half_power_width(const sl::Simulator &sim)
{
    double w = 0;
    for (int side = -1; side <= 1; side += 2) {
        double lo = 0, hi = 30;
        for (int it = 0; it < 60; it++) {
            const double m = 0.5 * (lo + hi);
            (sim.range_response(side * m) > 0.5 ? lo : hi) = m;
        }
        w += lo;
    }
    return w;
}

void test_window_responses(void **state)
{
    (void)state;
    // Hann: -6 dB amplitude one cell out, first null at 2 cells, first sidelobe -31.5 dB
    assert_true(std::fabs(sl::sim_window_amplitude(sl::RangeResponse::Hann, 1.0) - 0.5) < 1e-12);
    assert_true(std::fabs(sl::sim_window_amplitude(sl::RangeResponse::Hann, 2.0)) < 1e-12);
    double side = 0;
    for (double f = 2.0; f < 3.0; f += 0.001) {
        side = std::max(side, std::fabs(sl::sim_window_amplitude(sl::RangeResponse::Hann, f)));
    }
    assert_true(std::fabs(20 * std::log10(side) + 31.47) < 0.1);
    // the scene's response: Hann of 6 bins per cell has a half-power width of 1.4406 cells
    sl::Simulator sim(sl::parse_scene_string(
        base_scene("range_response = hann\nrange_cell_bins = 6\n")));
    const double w = half_power_width(sim);
    std::printf("Hann, 6 bins per cell: half-power width %.3f bins\n", w);
    assert_true(std::fabs(w - 1.44058 * 6) < 0.01);
    // a receiver tail adds power outward only
    sl::Simulator tail(sl::parse_scene_string(base_scene(
        "range_response = hann\nrange_cell_bins = 6\nreceiver_tail_db = -30\nreceiver_tail_bins = 10\n")));
    assert_true(std::fabs(tail.range_response(-30) - sim.range_response(-30)) < 1e-15);
    assert_true(tail.range_response(30) > sim.range_response(30) + 1e-3 * std::exp(-3.0) * 0.9);
}

void test_cts350x_table_is_the_cores(void **state)
{
    (void)state;
    sl::Simulator sim(sl::parse_scene_string(base_scene("range_response = cts350x\n")));
    uint16_t drop[SL_RESP_TAPS];
    sl_response_prior_cts350x(drop);
    for (int o = -SL_CFG_RESP_HALF; o <= SL_CFG_RESP_HALF; o++) {
        const double want = std::pow(2.0, -drop[o + SL_CFG_RESP_HALF] / 256.0);
        assert_true(std::fabs(sim.range_response(o) / want - 1.0) < 1e-9);
    }
    const double w = half_power_width(sim);
    std::printf("CTS350-X table: half-power width %.3f bins\n", w);
    assert_true(w > 7.5 && w < 8.6);
    assert_true(sim.range_response(SL_CFG_RESP_HALF + 1) == 0.0);
    // with a skirt of 20 bins: beyond the table falling on at the slope of its last two
    // taps, 0 past twice its width
    sl::Simulator sk(sl::parse_scene_string(base_scene("range_response = cts350x\nrange_skirt_bins = 20\n")));
    for (int side = -1; side <= 1; side += 2) {
        const double r20 = sk.range_response(side * SL_CFG_RESP_HALF);
        const double r19 = sk.range_response(side * (SL_CFG_RESP_HALF - 1));
        assert_true(std::fabs(sk.range_response(side * (SL_CFG_RESP_HALF + 1)) / (r20 * r20 / r19) - 1) < 1e-6);
        assert_true(sk.range_response(side * (2 * SL_CFG_RESP_HALF + 1)) == 0.0);
    }
}

// Values of the ground bins 6-20 m of every azimuth of rotation k.
std::vector<int> ground_values(const sl::Simulator &sim, int k)
{
    std::vector<int> v;
    for (int i = 0; i < sim.azimuths(); i++) {
        const std::vector<uint8_t> b = sim.render_bins(k, i);
        for (int j = 140; j < 450; j++) {
            v.push_back(b[static_cast<size_t>(j)]);
        }
    }
    return v;
}

void test_physical_speckle(void **state)
{
    (void)state;
    // ground only, a strong return (no noise): the power of a circular complex Gaussian field
    // is exponential, its 10 log10 has a standard deviation of 5.57 dB = 11.1 values about a
    // smooth trend; parked: the same draw every rotation; speckle_static = 0: a new one
    const std::string fx = "range_response = cts350x\nspeckle = on\nspeckle_model = physical\n";
    const std::string gnd = "[ground]\nreflectivity = 50\nmax_range_m = 40\n";
    sl::Simulator parked(sl::parse_scene_string(base_scene(fx, gnd)));
    const std::vector<int> a = ground_values(parked, 0), b = ground_values(parked, 1);
    assert_true(a == b);
    // the spread about each bin's mean over the azimuths (the ground is the same on every
    // azimuth of the cylinder board: only the speckle differs)
    const int nj = 450 - 140, na = parked.azimuths();
    double ss = 0;
    long n = 0;
    for (int j = 0; j < nj; j++) {
        double m = 0;
        for (int i = 0; i < na; i++) {
            m += a[static_cast<size_t>(i * nj + j)];
        }
        m /= na;
        for (int i = 0; i < na; i++) {
            const double d = a[static_cast<size_t>(i * nj + j)] - m;
            ss += d * d;
            n++;
        }
    }
    const double sd = std::sqrt(ss / static_cast<double>(n));
    std::printf("physical speckle: value standard deviation %.2f (exponential power: 11.1)\n", sd);
    assert_true(sd > 10.0 && sd < 12.2);
    sl::Simulator moving(sl::parse_scene_string(base_scene(fx + "speckle_static = 0\n", gnd)));
    const std::vector<int> c = ground_values(moving, 0), d = ground_values(moving, 1);
    long same = 0;
    for (size_t q = 0; q < c.size(); q++) {
        same += c[q] == d[q] ? 1 : 0;
    }
    assert_true(same < static_cast<long>(c.size() / 10));
}

void test_knife_edge(void **state)
{
    (void)state;
    assert_true(std::fabs(sl::sim_knife_edge_field(0.0) - 0.5) < 1e-6);
    assert_true(std::fabs(sl::sim_knife_edge_field(20.0) * 20.0 - 0.2251) < 1e-3);
    assert_true(std::fabs(sl::sim_knife_edge_field(-30.0) - 1.0) < 0.02);
    double mx = 0;
    for (double v = -3; v < 0; v += 0.001) {
        mx = std::max(mx, sl::sim_knife_edge_field(v));
    }
    assert_true(std::fabs(mx - 1.17) < 0.01); // the first lit-side ripple
    // a pole in the shadow: with the knife edge, power reaches past the geometric r2 (the
    // chassis ray) and falls smoothly; without it the return ends there
    const std::string pole = "[pole.p]\nx_m = 3.0\ny_m = 0\nat_height_m = 2.58\nlength_m = 4\nradius_m = 0.01\n"
                             "[ground]\nenabled = off\n";
    sl::Simulator hard(sl::parse_scene_string(base_scene("range_response = cts350x\n", pole)));
    sl::Simulator soft(sl::parse_scene_string(base_scene("range_response = cts350x\nknife_edge = on\n", pole)));
    const std::vector<sl::GtRow> gt = hard.truth(0);
    int az = -1;
    double r2 = 0;
    for (const auto &g : gt) {
        if (g.nominal != 0) {
            az = g.azimuth;
            r2 = g.r2_m;
        }
    }
    assert_true(az >= 0);
    sl::SimColumn ch, cs;
    hard.geometry_column(0, az, ch);
    soft.geometry_column(0, az, cs);
    const double bin = hard.bin_m();
    double beyond_h = 0, beyond_s = 0, total_h = 0;
    for (const auto &f : ch.fine) {
        total_h += f.second;
        beyond_h += (f.first + 0.5) / sl::kSimFineQ * bin > r2 + bin ? f.second : 0.0;
    }
    for (const auto &f : cs.fine) {
        beyond_s += (f.first + 0.5) / sl::kSimFineQ * bin > r2 + bin ? f.second : 0.0;
    }
    std::printf("knife edge: energy beyond r2 + 1 bin: %.3g (hard cut %.3g), total %.3g\n", beyond_s,
                beyond_h, total_h);
    assert_true(beyond_h == 0.0);
    assert_true(beyond_s > 1e-4 * total_h && beyond_s < 0.2 * total_h);
    // the truth stays geometric
    for (const auto &g : soft.truth(0)) {
        if (g.nominal != 0) {
            assert_true(std::fabs(g.r2_m - r2) < 1e-12);
        }
    }
}

void test_points_and_value_curve(void **state)
{
    (void)state;
    // one point return of energy 1000 at 10 m on azimuth 100 (world +x is azimuth 90):
    // without a response it reads 100 + 20 log10(1000 G) in its bin; through the CTS350-X
    // lobe its neighbours fall as the table says
    const double a = 100.0 * sl::kSimPi / 180.0, R = 10.0, z = 0.5;
    char pt[256];
    std::snprintf(pt, sizeof pt, "[point.p]\nx_m = %.6f\ny_m = %.6f\nz_m = %.1f\nenergy = 1000\n"
                  "[ground]\nenabled = off\n", R * std::sin(a), R * std::cos(a), z);
    sl::Simulator plain(sl::parse_scene_string(base_scene("", pt)));
    sl::Simulator lobe(sl::parse_scene_string(base_scene("range_response = cts350x\n", pt)));
    const double r = std::hypot(R, 2.58 - z);
    const int j = static_cast<int>(std::floor(r / plain.bin_m()));
    const std::vector<uint8_t> p = plain.render_bins(0, 111), l = lobe.render_bins(0, 111);
    std::printf("point at bin %d: %d (no response), lobe %d %d %d\n", j, p[static_cast<size_t>(j)],
                l[static_cast<size_t>(j - 5)], l[static_cast<size_t>(j)], l[static_cast<size_t>(j + 5)]);
    assert_true(p[static_cast<size_t>(j)] >= 155 && p[static_cast<size_t>(j)] <= 161);
    assert_int_equal(p[static_cast<size_t>(j + 3)], 0);
    assert_true(std::abs(l[static_cast<size_t>(j)] - p[static_cast<size_t>(j)]) <= 1);
    for (int o : {-8, -4, 4, 8}) {
        assert_true(l[static_cast<size_t>(j + o)] > 0);
        assert_true(l[static_cast<size_t>(j + o)] < l[static_cast<size_t>(j)]);
    }
    // Navtech's curve is exact at powers of two: N = 2^e reads round(6.02 e); N = 3 = 2 (1 +
    // 1/2) reads round(6.02 x 1.5) = 9 where round(20 log10 3) = 10
    for (int e = 1; e < 40; e++) {
        assert_true(plain.log_value(1L << e) == std::round(20.0 * std::log10(2.0) * e));
    }
    assert_true(plain.log_value(3) == 9.0);
    assert_true(plain.log_value(0) == 0.0 && plain.log_value(1) == 0.0);
    // the values that never occur on the real scans below 20 (1-5, 7, 8, 10, 11, 13, 16) are
    // exactly those no integer power reaches on this curve (round(20 log10 6) = 16 would)
    std::vector<int> hit(256, 0);
    for (long n = 0; n < 100000; n++) {
        hit[static_cast<size_t>(plain.log_value(n))] = 1;
    }
    const std::vector<int> missing = {1, 2, 3, 4, 5, 7, 8, 10, 11, 13, 16};
    for (int v = 0; v < 20; v++) {
        const bool miss = std::find(missing.begin(), missing.end(), v) != missing.end();
        assert_int_equal(hit[static_cast<size_t>(v)], miss ? 0 : 1);
    }
}

// Runs a command, returns its stdout.
std::string run(const std::string &cmd, int *rc)
{
    std::string out;
    FILE *f = popen(cmd.c_str(), "r");
    if (f == nullptr) {
        *rc = -1;
        return out;
    }
    std::array<char, 4096> buf{};
    size_t n = 0;
    while ((n = std::fread(buf.data(), 1, buf.size(), f)) > 0) {
        out.append(buf.data(), n);
    }
    *rc = pclose(f);
    return out;
}

void test_hann_width_measured_by_sl_calib(void **state)
{
    (void)state;
    if (g_sim == nullptr) {
        skip();
    }
    // scenes/cts350x_physics.ini with a Hann response of 5.6 bins per resolution cell
    std::ifstream in(std::string(g_scenes) + "/cts350x_physics.ini");
    assert_true(in.good());
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    const std::string key = "\nrange_response = cts350x\n";
    const size_t at = text.find(key);
    assert_true(at != std::string::npos);
    text.replace(at, key.size(), "\nrange_response = hann\nrange_cell_bins = 5.6\n");
    const std::string ini = std::string(g_work) + "/hann_physics.ini";
    const std::string cap = std::string(g_work) + "/hann_physics.colossus";
    {
        std::ofstream o(ini);
        o << text;
    }
    sl::Simulator sim(sl::parse_scene_string(text));
    const double want = half_power_width(sim);
    int rc = 0;
    (void)run(std::string(g_sim) + " " + ini + " -o " + cap + " -q", &rc);
    assert_int_equal(rc, 0);
    const std::string out =
        run(std::string(g_calib) + " response " + cap + " --board paper-sim -q", &rc);
    assert_int_equal(rc, 0);
    const size_t h = out.find("half-power width ");
    assert_true(h != std::string::npos);
    const double got = std::atof(out.c_str() + h + 17);
    std::printf("Hann, 5.6 bins per cell: half-power width measured by sl-calib %.2f bins, the "
                "window's %.2f\n",
                got, want);
    assert_true(std::fabs(got - want) < 0.3);
}

} // namespace

int main(int argc, char **argv)
{
    if (argc >= 5) {
        g_sim = argv[1];
        g_calib = argv[2];
        g_scenes = argv[3];
        g_work = argv[4];
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_window_responses),
        cmocka_unit_test(test_cts350x_table_is_the_cores),
        cmocka_unit_test(test_physical_speckle),
        cmocka_unit_test(test_knife_edge),
        cmocka_unit_test(test_points_and_value_curve),
        cmocka_unit_test(test_hann_width_measured_by_sl_calib),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
