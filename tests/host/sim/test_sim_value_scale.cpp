// SPDX-License-Identifier: MIT
// The sensor's 8-bit value scale, from the real CTS350-X scans: which quantity the integer N of
// value = round(19.8 log10 N) is. Navtech's SDK reads an 8-bit FFT value as a fixed-point
// number with one fractional bit, in dB (value / 2 = dB): 0.5 dB per value, so N is a POWER,
// and the noise of a power is exponential. The simulator's round-1 model took N as a
// MAGNITUDE (1 dB per value, Rayleigh noise). This test reads the far range (bins 3000-3700,
// 130-160 m, nearly all noise) of the 11 Oxford scans and renders a noise-only scene on both
// scales with the noise sigma that gives the same fraction of zeros, then compares the
// fractions of the next values (6, 9, 12, 14, 15: N = 2 .. 6). Asserted: the power scale
// (output.log_quantity = power) within 35 % of the real fraction at every one of them, the
// magnitude scale off by more than half at N = 2 and with no tail (N >= 5 almost never).
// The data path comes from the command line (CMake: SL_OXFORD_RADAR_DIR, tests/CMakeLists.txt).
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <setjmp.h>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

extern "C" {
#include <cmocka.h>
}

#include "oxford.h"
#include "sim_render.h"
#include "sim_scene.h"

namespace {

constexpr int kValues[] = {0, 6, 9, 12, 14, 15};
constexpr int kNv = 6;
const char *g_dir = nullptr;

struct Hist {
    double f[256] = {};
};

Hist oxford_far_range()
{
    Hist h;
    std::string err;
    const std::vector<std::string> files = sl::oxford_list_pngs(g_dir, err);
    if (files.empty()) {
        std::fprintf(stderr, "%s\n", err.c_str());
    }
    assert_true(files.size() >= 10U);
    double n = 0;
    for (const auto &f : files) {
        const cv::Mat m = cv::imread(f, cv::IMREAD_GRAYSCALE);
        assert_int_equal(m.cols, 3779);
        for (int r = 0; r < m.rows; r++) {
            for (int b = 3000; b < 3700; b++) {
                h.f[m.at<uint8_t>(r, 11 + b)] += 1;
                n += 1;
            }
        }
    }
    for (double &x : h.f) {
        x /= n;
    }
    return h;
}

// A noise-only scene (no object, no ground) on one scale, the noise sigma giving `zeros`.
Hist rendered(bool power, double zeros)
{
    // zeros = P(round N <= 1) = P(N < 1.5): exponential power 1 - exp(-1.5 / 2s^2),
    // Rayleigh magnitude 1 - exp(-1.5^2 / 2s^2)
    const double q = -std::log(1.0 - zeros);
    const double sigma = std::sqrt((power ? 1.5 : 2.25) / q / 2.0);
    char buf[600];
    std::snprintf(buf, sizeof buf,
                  "[scene]\nboard = paper-sim\nrange_bins = 512\nrotations = 1\nrotation_hz = 4\n"
                  "seed = 5\n[vehicle]\nx_m = 0\ny_m = 0\nheading_deg = 90\nspeed_mps = 0\n"
                  "[ground]\nreflectivity = 0\n[beam]\nelevation = ideal\nazimuth_width_deg = 2\n"
                  "[output]\namplitude = integral\nmapping = log\nnormalize = none\n"
                  "log_quantity = %s\n[effects]\nnoise = on\nnoise_sigma = %.6f\n",
                  power ? "power" : "magnitude", sigma);
    const sl::Scene s = sl::parse_scene_string(buf, "value_scale");
    const sl::Simulator sim(s);
    Hist h;
    double n = 0;
    for (int az = 0; az < 400; az++) {
        const std::vector<uint8_t> row = sim.render_bins(0, az);
        for (size_t b = 100; b < row.size(); b++) {
            h.f[row[b]] += 1;
            n += 1;
        }
    }
    for (double &x : h.f) {
        x /= n;
    }
    return h;
}

void test_value_scale_is_power(void **)
{
    const Hist ox = oxford_far_range();
    const Hist pw = rendered(true, ox.f[0]);
    const Hist mg = rendered(false, ox.f[0]);
    std::printf("value   Oxford   power    magnitude\n");
    for (int v : kValues) {
        std::printf("%5d  %7.4f  %7.4f  %7.4f\n", v, ox.f[v], pw.f[v], mg.f[v]);
    }
    for (int i = 1; i < kNv; i++) {
        const int v = kValues[i];
        assert_true(std::fabs(pw.f[v] - ox.f[v]) <= 0.35 * ox.f[v]);
    }
    // the magnitude model: N = 2 far too often, no tail
    assert_true(mg.f[6] >= 1.5 * ox.f[6]);
    assert_true(mg.f[14] + mg.f[15] <= 0.2 * (ox.f[14] + ox.f[15]));
}

} // namespace

int main(int argc, char **argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: test_sim_value_scale OXFORD_DIR\n");
        return 2;
    }
    g_dir = argv[1];
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_value_scale_is_power)};
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
