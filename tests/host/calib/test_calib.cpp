// SPDX-License-Identifier: MIT
// test_calib.cpp: calibration tests on generated captures with known theta and d
// (gen_scans.h), and the helpers the CLI tests (CMakeLists.txt) use.
//
//   test_calib CASE                       run one named case (ctest runs each separately)
//   test_calib gen-shadow BOARD OUT [--self-return] [--rotations N] [--bins N]
//   test_calib check-shadow-ini INI BOARD MAX_ERR_DEG MIN_USABLE
//   test_calib gen-elong BOARD DIR POSITIONS  (DIR/pos_NNN.colossus + DIR/list.csv)
//   test_calib check-elong-ini INI BOARD MAX_ERR_M
//
// Every case prints the numbers it measured; a failure prints what was expected.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "calib_elong.h"
#include "calib_file.h"
#include "geom.h"
#include "calib_shadow.h"
#include "gen_scans.h"
#include "sl_board_spec.h"
#include "sl_geom.h"
#include "view_frames.h"

namespace {

using sl::test::GenSpec;

int g_fail = 0;

#define CHECK(cond, ...)                                                                   \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            std::printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);                   \
            std::printf(__VA_ARGS__);                                                      \
            std::printf("\n");                                                             \
            g_fail++;                                                                      \
        }                                                                                  \
    } while (0)

/// The elongation the generator applies, as a function of the true outer bound: the paper's
/// 80.6 cm with a slight negative slope (paper Sec. V-B).
double d_of_r2_true(double r2_true_m) { return 0.806 - 0.12 * (r2_true_m - 2.2); }

sl::FrameSet decode(const std::vector<uint8_t> &bytes, const sl::BoardSpec &b)
{
    sl::FrameOptions fo;
    fo.azimuths = b.azimuths;
    fo.encoder_size = b.encoder_size;
    sl::FrameSet fs;
    std::string err;
    if (!sl::decode_frames(bytes, fo, fs, err)) {
        std::printf("FAIL decode: %s\n", err.c_str());
        std::exit(1);
    }
    return fs;
}

sl::ShadowCalib run_shadow(const GenSpec &g)
{
    const sl::FrameSet fs = decode(sl::test::generate_capture(g), g.board);
    std::vector<cv::Mat> frames;
    std::vector<std::vector<uint8_t>> valid;
    for (const auto &f : fs.frames) {
        frames.push_back(f.power);
        std::vector<uint8_t> v(f.flags.size());
        for (size_t i = 0; i < v.size(); i++) v[i] = f.flags[i] & SL_SCAN_AZ_VALID;
        valid.push_back(v);
    }
    sl::ShadowCalibOptions o;
    o.radar_height_m = g.board.radar_height_m;
    o.bin_size_m = fs.bin_size_m;
    return sl::calibrate_shadow(frames, valid, o);
}

struct ThetaStats {
    int usable = 0, within = 0;
    double max_err = 0, mean_err = 0;
};

ThetaStats theta_stats(const sl::ShadowCalib &c, const sl::BoardSpec &b, double tol,
                       const std::vector<bool> *only = nullptr)
{
    ThetaStats s;
    double sum = 0;
    for (const auto &r : c.az) {
        if (!r.usable || (only && !(*only)[r.az])) continue;
        const double e = r.theta_deg - b.theta_deg(r.az);
        s.usable++;
        s.within += std::fabs(e) <= tol ? 1 : 0;
        s.max_err = std::max(s.max_err, std::fabs(e));
        sum += e;
    }
    s.mean_err = s.usable ? sum / s.usable : 0;
    return s;
}

// ------------------------------------------------------------------------------- cases
void test_shadow_recovers_theta_on_a_cylinder_board()
{
    GenSpec g;
    g.board = sl::load_board("paper-sim");
    g.rotations = 12;
    g.bins = 220;
    const sl::ShadowCalib c = run_shadow(g);
    const ThetaStats s = theta_stats(c, g.board, 0.5);
    std::printf("cylinder (theta 26 deg): usable %d/%d, max |error| %.3f deg, mean error %+.3f deg\n",
                s.usable, c.azimuths, s.max_err, s.mean_err);
    CHECK(s.usable == c.azimuths, "all %d azimuths usable, got %d", c.azimuths, s.usable);
    CHECK(s.max_err <= 0.5, "max error %.3f deg > 0.5", s.max_err);
    double ne = 0;
    for (const auto &r : c.az) ne += r.near_end_m / c.azimuths;
    std::printf("  near-field band end (mean) %.3f m (generated 1.5 m)\n", ne);
    CHECK(std::fabs(ne - 1.5) < 0.1, "near-field band end %.3f, expected 1.5 +- 0.1", ne);
}

void test_shadow_recovers_theta_per_azimuth_on_a_polygon_board()
{
    GenSpec g;
    g.board = sl::load_board("robotcar-leaf");
    g.rotations = 12;
    g.bins = 170;
    const sl::ShadowCalib c = run_shadow(g);
    const ThetaStats s = theta_stats(c, g.board, 0.5);
    std::printf("robotcar-leaf polygon (theta 22-33 deg): usable %d/%d, within 0.5 deg %d, "
                "max |error| %.3f deg, mean error %+.3f deg\n",
                s.usable, c.azimuths, s.within, s.max_err, s.mean_err);
    CHECK(s.usable >= 0.95 * c.azimuths, "at least 95 %% usable, got %d", s.usable);
    CHECK(s.within == s.usable, "every usable azimuth within 0.5 deg: %d of %d (max %.3f)",
          s.within, s.usable, s.max_err);
}

void test_shadow_reports_a_self_return_sector_as_unusable()
{
    GenSpec g;
    g.board = sl::load_board("paper-sim");
    g.rotations = 12;
    g.bins = 220;
    g.self_returns.push_back({50, 59, 3.00, 3.15, 300});  // a bright bracket inside the ring
    g.self_returns.push_back({250, 254, 4.50, 4.60, 60}); // a weaker one (v ~ 35)
    const sl::ShadowCalib c = run_shadow(g);
    int bad = 0;
    for (int a : {50, 55, 59, 250, 252, 254}) {
        const auto &r = c.az[a];
        std::printf("  az %d: usable %d reason '%s' bright at %.2f m (+%.1f)\n", a, r.usable,
                    r.reason.c_str(), r.bright_inside_m, r.bright_level);
        if (r.usable || r.reason != "bright return inside the ring") bad++;
    }
    CHECK(bad == 0, "%d of the self-return azimuths not reported as bright return inside", bad);
    bool sector = false;
    for (const auto &s : c.unusable) {
        std::printf("  unusable sector az %d..%d (%d): %s\n", s.az_first,
                    (s.az_first + s.az_count - 1) % c.azimuths, s.az_count, s.reason.c_str());
        if (s.az_first <= 50 && s.az_first + s.az_count - 1 >= 59 &&
            s.reason == "bright return inside the ring")
            sector = true;
    }
    CHECK(sector, "a sector covering azimuths 50..59 reported with its reason");
    // Away from the returns (and the +-2 azimuth window) every azimuth stays usable and right.
    std::vector<bool> far(c.azimuths, true);
    for (int a = 45; a <= 64; a++) far[a] = false;
    for (int a = 245; a <= 259; a++) far[a] = false;
    const ThetaStats s = theta_stats(c, g.board, 0.5, &far);
    int far_count = 0;
    for (bool f : far) far_count += f ? 1 : 0;
    std::printf("  elsewhere: usable %d/%d, max |error| %.3f deg\n", s.usable, far_count, s.max_err);
    CHECK(s.usable == far_count, "all %d other azimuths usable, got %d", far_count, s.usable);
    CHECK(s.max_err <= 0.5, "max error %.3f", s.max_err);
}

void test_shadow_reports_no_ground_edge_where_the_platform_hides_the_ground()
{
    GenSpec g;
    g.board = sl::load_board("paper-sim");
    g.rotations = 12;
    g.bins = 220;
    g.no_ground.push_back({120, 160});
    const sl::ShadowCalib c = run_shadow(g);
    int bad = 0;
    for (int a = 123; a <= 157; a++) {
        if (c.az[a].usable) bad++;
    }
    std::printf("  az 140: usable %d reason '%s'\n", c.az[140].usable, c.az[140].reason.c_str());
    CHECK(bad == 0, "%d azimuths of the hidden sector given a theta", bad);
    CHECK(c.az[140].reason == "no ground edge", "reason '%s'", c.az[140].reason.c_str());
}

void test_shadow_ini_round_trips()
{
    GenSpec g;
    g.board = sl::load_board("paper-sim");
    g.rotations = 6;
    g.bins = 220;
    g.self_returns.push_back({10, 14, 3.0, 3.1, 300});
    const sl::ShadowCalib c = run_shadow(g);
    std::vector<double> bt(c.azimuths);
    for (int i = 0; i < c.azimuths; i++) bt[i] = g.board.theta_deg(i);
    const std::string path = "shadow_roundtrip.ini";
    std::ofstream(path) << sl::shadow_calib_ini(c, "paper-sim", "generated", bt);
    sl::ShadowCalibFile f;
    std::string err;
    CHECK(sl::read_shadow_calib(path, f, err), "read back: %s", err.c_str());
    int diff = 0;
    for (int i = 0; i < c.azimuths; i++) {
        const bool a = c.az[i].usable, b = std::isfinite(f.theta_deg[i]);
        if (a != b || (a && std::fabs(f.theta_deg[i] - c.az[i].theta_deg) > 0.006)) diff++;
    }
    CHECK(diff == 0, "%d azimuths differ after the round trip", diff);
    CHECK(f.azimuths == 400 && std::fabs(f.radar_height_m - 2.58) < 1e-9, "header fields");
}

std::vector<sl::ElongMeasurement> elong_positions(const sl::BoardSpec &b, int n, int rotations)
{
    std::vector<sl::ElongMeasurement> out;
    for (int i = 0; i < n; i++) {
        GenSpec g;
        g.board = b;
        g.rotations = rotations;
        g.bins = 128;
        g.seed = 100 + static_cast<uint64_t>(i);
        sl::test::Target t;
        t.az = 0;
        t.p_m = 1.75 + 0.01 * i;
        t.d_m = d_of_r2_true(sl::test::target_r2_true_m(b, t));
        g.targets.push_back(t);
        const sl::FrameSet fs = decode(sl::test::generate_capture(g), b);
        sl::ElongTruth tr;
        tr.rot_first = 0;
        tr.rot_last = 1 << 30;
        tr.az = -1;
        tr.r1_true_m = t.p_m;
        tr.r2_true_m = sl::test::target_r2_true_m(b, t);
        sl::ElongOptions eo;
        eo.threshold = b.threshold;
        eo.mask_frames = b.mask_frames;
        eo.near_exclusion_bins = static_cast<int>(std::ceil(b.near_exclusion_m / fs.bin_size_m));
        out.push_back(sl::measure_elongation(fs, tr, eo));
    }
    return out;
}

void test_elongation_recovers_d_within_1cm_over_110_positions()
{
    const sl::BoardSpec b = sl::load_board("paper-bench");
    const auto m = elong_positions(b, 110, 2);
    int found = 0;
    for (const auto &x : m) found += x.found ? 1 : 0;
    CHECK(found == 110, "target found at %d of 110 positions", found);
    const sl::ElongTable t = sl::fit_elongation(m, 8);
    std::printf("110 positions, 1 cm steps from 1.75 m: d mean %.4f m std %.4f; fit %.4f + %.4f r2 "
                "(resid %.4f); r1 bias %+.4f m\n",
                t.mean_m, t.std_m, t.intercept_m, t.slope, t.resid_std_m, t.mean_d_r1_m);
    double worst = 0;
    for (const auto &p : t.points) {
        // The true d at this table point: d(r2_true) with r2_true + d = the observed r2.
        double d = 0.8;
        for (int it = 0; it < 50; it++) d = d_of_r2_true(p.r_m - d);
        std::printf("  r2 %.3f: d %.4f (true %.4f, error %+.4f) +- %.4f n %d\n", p.r_m, p.d_m, d,
                    p.d_m - d, p.std_m, p.n);
        worst = std::max(worst, std::fabs(p.d_m - d));
    }
    CHECK(worst <= 0.01, "table point error %.4f m > 1 cm", worst);
    CHECK(std::fabs(t.mean_d_r1_m) <= 0.01, "r1 bias %.4f m", t.mean_d_r1_m);
    // The table is a valid board line: written into a copy of the board file, the board
    // parser reads the same points back.
    const std::string line = sl::elongation_line(t);
    CHECK(line.size() < 190, "board line %zu chars (inih limit 200)", line.size());
    std::ifstream in(b.source_file);
    std::ofstream o("elong_board.ini");
    std::string l;
    bool replaced = false;
    while (std::getline(in, l)) {
        if (l.rfind("elongation", 0) == 0) {
            l = line;
            replaced = true;
        }
        o << l << "\n";
    }
    o.close();
    CHECK(replaced, "board file has an elongation line");
    try {
        const sl::BoardSpec nb = sl::load_board("elong_board.ini");
        CHECK(nb.elongation.size() == t.points.size(), "%zu points read back, %zu written",
              nb.elongation.size(), t.points.size());
        for (size_t i = 0; i < nb.elongation.size() && i < t.points.size(); i++) {
            CHECK(std::fabs(nb.elongation[i].d_m - t.points[i].d_m) < 0.0006, "point %zu", i);
        }
    } catch (const std::exception &e) {
        CHECK(false, "board parser rejected the line: %s", e.what());
    }
}

// ------------------------------------------------------------------------- CLI helpers
int gen_shadow(int argc, char **argv)
{
    GenSpec g;
    g.board = sl::load_board(argv[2]);
    g.rotations = 12;
    g.bins = 220;
    for (int i = 4; i < argc; i++) {
        if (!std::strcmp(argv[i], "--self-return")) {
            g.self_returns.push_back({50, 59, 3.00, 3.15, 300});
        } else if (!std::strcmp(argv[i], "--rotations") && i + 1 < argc) {
            g.rotations = std::atoi(argv[++i]);
        } else if (!std::strcmp(argv[i], "--bins") && i + 1 < argc) {
            g.bins = std::atoi(argv[++i]);
        } else if (!std::strcmp(argv[i], "--poles")) {
            // Three leaning-pole-like targets inside the ring (for the sl-view picture).
            g.targets.push_back({60, 3.2, 0.5});
            g.targets.push_back({180, 3.6, 0.5});
            g.targets.push_back({300, 2.9, 0.5});
        }
    }
    return sl::test::write_file(argv[3], sl::test::generate_capture(g)) ? 0 : 1;
}

int check_shadow_ini(char **argv)
{
    const sl::BoardSpec b = sl::load_board(argv[3]);
    const double tol = std::atof(argv[4]);
    const int min_usable = std::atoi(argv[5]);
    sl::ShadowCalibFile f;
    std::string err;
    if (!sl::read_shadow_calib(argv[2], f, err)) {
        std::printf("FAIL %s\n", err.c_str());
        return 1;
    }
    int usable = 0;
    double worst = 0;
    for (int i = 0; i < f.azimuths; i++) {
        if (!std::isfinite(f.theta_deg[i])) continue;
        usable++;
        worst = std::max(worst, std::fabs(f.theta_deg[i] - b.theta_deg(i)));
    }
    std::printf("%s: %d usable azimuths, max |theta - board| %.3f deg\n", argv[2], usable, worst);
    CHECK(usable >= min_usable, "usable %d < %d", usable, min_usable);
    CHECK(worst <= tol, "max error %.3f > %.3f", worst, tol);
    return g_fail ? 1 : 0;
}

int gen_elong(char **argv)
{
    const sl::BoardSpec b = sl::load_board(argv[2]);
    const std::string dir = argv[3];
    const int n = std::atoi(argv[4]);
    std::ofstream list(dir + "/list.csv");
    list << "capture,range_m\n";
    for (int i = 0; i < n; i++) {
        GenSpec g;
        g.board = b;
        g.rotations = 2;
        g.bins = 128;
        g.seed = 100 + static_cast<uint64_t>(i);
        sl::test::Target t;
        t.az = 0;
        t.p_m = 1.75 + 0.01 * i;
        t.d_m = d_of_r2_true(sl::test::target_r2_true_m(b, t));
        g.targets.push_back(t);
        char name[64];
        std::snprintf(name, sizeof name, "pos_%03d.colossus", i);
        if (!sl::test::write_file(dir + "/" + name, sl::test::generate_capture(g))) return 1;
        list << name << "," << t.p_m << "\n";
    }
    return 0;
}

int check_elong_ini(char **argv)
{
    std::ifstream in(argv[2]);
    const double tol = std::atof(argv[4]);
    std::string l, line;
    while (std::getline(in, l)) {
        if (l.rfind("elongation", 0) == 0) line = l;
    }
    CHECK(!line.empty(), "no elongation line in %s", argv[2]);
    const size_t eq = line.find('=');
    std::string rest = line.substr(eq + 1);
    int n = 0;
    double worst = 0;
    size_t pos = 0;
    while (pos < rest.size()) {
        const size_t comma = rest.find(',', pos);
        const std::string item = rest.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
        double r = 0, d = 0;
        if (std::sscanf(item.c_str(), " %lf:%lf", &r, &d) == 2) {
            double dt = 0.8;
            for (int it = 0; it < 50; it++) dt = d_of_r2_true(r - dt);
            worst = std::max(worst, std::fabs(d - dt));
            n++;
        }
        if (comma == std::string::npos) break;
        pos = comma + 1;
    }
    std::printf("%s: %d points, max |d - true| %.4f m\n", argv[2], n, worst);
    CHECK(n >= 1, "points");
    CHECK(worst <= tol, "error %.4f > %.4f", worst, tol);
    (void)argv[3];
    return g_fail ? 1 : 0;
}

// The calibration reader (C, calib_file.c: what the daemon runs on a calibration INI) and
// the board generator (C++, sl::make_geom: what sl-tables runs on a board file) must give
// the same geometry entry bit for bit, or a calibrated azimuth would differ from a board's:
// both call slp_geom_make (geom.h); sl::make_geom adds only the angle checks.
void test_calib_file_geom_equals_sl_make_geom()
{
    long n = 0, diff = 0;
    for (double beta : {0.0, 3.0, -5.0, 12.5}) {
        for (int c = 100; c <= 6000; c++) {
            const double theta = c / 100.0;
            const sl_incline_geom_t a = slp_geom_make(theta, beta);
            const sl_incline_geom_t b = sl::make_geom(theta, beta);
            n++;
            if (std::memcmp(&a, &b, sizeof a) != 0) {
                diff++;
            }
        }
    }
    std::printf("slp_geom_make vs sl::make_geom: %ld entries, %ld differ\n", n, diff);
    CHECK(n == 4 * 5901, "entries %ld", n);
    CHECK(diff == 0, "%ld entries differ", diff);
}

} // namespace

int main(int argc, char **argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: test_calib CASE | gen-shadow | check-shadow-ini | gen-elong | check-elong-ini\n");
        return 2;
    }
    const std::string c = argv[1];
    try {
        if (c == "gen-shadow" && argc >= 4) return gen_shadow(argc, argv);
        if (c == "check-shadow-ini" && argc >= 6) return check_shadow_ini(argv);
        if (c == "gen-elong" && argc >= 5) return gen_elong(argv);
        if (c == "check-elong-ini" && argc >= 5) return check_elong_ini(argv);
        const std::map<std::string, std::function<void()>> cases = {
            {"shadow_recovers_theta_on_a_cylinder_board", test_shadow_recovers_theta_on_a_cylinder_board},
            {"shadow_recovers_theta_per_azimuth_on_a_polygon_board", test_shadow_recovers_theta_per_azimuth_on_a_polygon_board},
            {"shadow_reports_a_self_return_sector_as_unusable", test_shadow_reports_a_self_return_sector_as_unusable},
            {"shadow_reports_no_ground_edge_where_the_platform_hides_the_ground", test_shadow_reports_no_ground_edge_where_the_platform_hides_the_ground},
            {"shadow_ini_round_trips", test_shadow_ini_round_trips},
            {"elongation_recovers_d_within_1cm_over_110_positions", test_elongation_recovers_d_within_1cm_over_110_positions},
            {"file_geom_equals_sl_make_geom", test_calib_file_geom_equals_sl_make_geom},
        };
        auto it = cases.find(c);
        if (it == cases.end()) {
            std::fprintf(stderr, "test_calib: unknown case %s\n", c.c_str());
            return 2;
        }
        it->second();
    } catch (const std::exception &e) {
        std::printf("FAIL exception: %s\n", e.what());
        return 1;
    }
    std::printf("%s: %s\n", c.c_str(), g_fail ? "FAILED" : "ok");
    return g_fail ? 1 : 0;
}
