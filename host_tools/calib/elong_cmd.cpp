// SPDX-License-Identifier: MIT
// elong_cmd.cpp: `sl-calib elongation` (see main.cpp and README.md).
#include "calib_cmds.h"
#include "calib_ini.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "calib_elong.h"
#include "sl_board_spec.h"
#include "sl_progress.h"
#include "view_draw.h"
#include "view_frames.h"
#ifdef SL_HAVE_SIM_TRUTH
#include "sim_truth.h"
#endif

namespace sl::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

std::string basename_of(const std::string &p)
{
    const size_t s = p.find_last_of('/');
    return s == std::string::npos ? p : p.substr(s + 1);
}

std::string first_line(const std::string &path)
{
    std::ifstream in(path);
    std::string l;
    std::getline(in, l);
    return l;
}

/// List format: header with columns capture, range_m and optionally r2_m (any order).
bool read_list(const std::string &path, std::map<std::string, std::pair<double, double>> &out,
               std::string &err)
{
    std::ifstream in(path);
    std::string line;
    if (!in || !std::getline(in, line)) {
        err = path + ": cannot read";
        return false;
    }
    std::vector<std::string> cols;
    {
        std::stringstream ss(line);
        std::string c;
        while (std::getline(ss, c, ',')) cols.push_back(c);
    }
    auto idx = [&](const char *n) {
        for (size_t i = 0; i < cols.size(); i++)
            if (cols[i] == n) return static_cast<int>(i);
        return -1;
    };
    const int ic = idx("capture"), ir = idx("range_m"), i2 = idx("r2_m");
    if (ic < 0 || ir < 0) {
        err = path + ": the list needs the columns capture,range_m[,r2_m]";
        return false;
    }
    int ln = 1;
    while (std::getline(in, line)) {
        ln++;
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> v;
        std::stringstream ss(line);
        std::string c;
        while (std::getline(ss, c, ',')) v.push_back(c);
        if (static_cast<int>(v.size()) <= std::max(ic, ir)) {
            err = path + ":" + std::to_string(ln) + ": too few columns";
            return false;
        }
        char *e = nullptr;
        const double r = std::strtod(v[ir].c_str(), &e);
        if (e == v[ir].c_str() || !(r > 0)) {
            err = path + ":" + std::to_string(ln) + ": bad range_m '" + v[ir] + "'";
            return false;
        }
        double r2 = kNaN;
        if (i2 >= 0 && i2 < static_cast<int>(v.size()) && !v[i2].empty()) {
            r2 = std::strtod(v[i2].c_str(), nullptr);
        }
        out[basename_of(v[ic])] = {r, r2};
    }
    return true;
}

std::string f3(double v)
{
    char b[32];
    std::snprintf(b, sizeof b, "%.3f", v);
    return b;
}

cv::Mat elong_png(const std::vector<ElongMeasurement> &m, const ElongTable &t,
                  const std::string &title)
{
    cv::Mat img(760, 1100, CV_8UC3, cv::Scalar(28, 28, 28));
    draw_text(img, title, cv::Point(70, 30), 0.6);
    PlotAxes pa;
    pa.rect = cv::Rect(90, 80, 960, 500);
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (const auto &x : m) {
        if (!x.found) continue;
        x0 = std::min(x0, x.r2_m);
        x1 = std::max(x1, x.r2_m);
        y0 = std::min(y0, x.d_m);
        y1 = std::max(y1, x.d_m);
    }
    if (x0 > x1) {
        x0 = 0;
        x1 = 1;
        y0 = 0;
        y1 = 1;
    }
    pa.x0 = std::floor((x0 - 0.05) * 10) / 10;
    pa.x1 = std::ceil((x1 + 0.05) * 10) / 10;
    pa.y0 = std::floor((y0 - 0.03) * 50) / 50;
    pa.y1 = std::ceil((y1 + 0.03) * 50) / 50;
    const double xs = (pa.x1 - pa.x0) > 1.5 ? 0.5 : 0.1;
    const double ys = (pa.y1 - pa.y0) > 0.3 ? 0.05 : 0.02;
    pa.draw(img, xs, ys, "observed r2 (half-bin, m): the key the core looks d up with",
            "elongation d = r2 observed - r2 true (m)");
    std::vector<double> xs_, ys_;
    for (const auto &x : m) {
        if (x.found) {
            xs_.push_back(x.r2_m);
            ys_.push_back(x.d_m);
        }
    }
    pa.dots(img, xs_, ys_, cv::Scalar(200, 200, 200), 3);
    pa.line(img, {pa.x0, pa.x1}, {t.intercept_m + t.slope * pa.x0, t.intercept_m + t.slope * pa.x1},
            col::kBoardShadow, 2);
    std::vector<double> px, py;
    for (const auto &p : t.points) {
        px.push_back(p.r_m);
        py.push_back(p.d_m);
        cv::line(img, pa.px(p.r_m, p.d_m - p.std_m), pa.px(p.r_m, p.d_m + p.std_m), col::kCalibShadow, 2);
        cv::line(img, pa.px(p.r_min_m, p.d_m), pa.px(p.r_max_m, p.d_m), col::kCalibShadow, 1);
    }
    pa.line(img, px, py, col::kCalibShadow, 2);
    pa.dots(img, px, py, col::kCalibShadow, 6);
    std::vector<LegendItem> items = {
        {cv::Scalar(200, 200, 200), "one position (" + std::to_string(t.n) + ")", 4},
        {col::kCalibShadow, "table points: group mean, +-1 std, r2 span", 0},
        {col::kBoardShadow, "least squares d = a + b r2", 0},
    };
    draw_legend(img, items, cv::Point(90, 660), 420);
    int y = 680;
    auto line = [&](const std::string &s) {
        draw_text(img, s, cv::Point(540, y), 0.5);
        y += 22;
    };
    line("d mean " + f3(t.mean_m) + " m, std " + f3(t.std_m) + " m over " + std::to_string(t.n) + " positions");
    line("fit: d = " + f3(t.intercept_m) + " + " + f3(t.slope) + " r2 (resid. std " + f3(t.resid_std_m) + " m)");
    line("r1 bias (r1 observed - true): " + f3(t.mean_d_r1_m) + " m");
    return img;
}

} // namespace

int cmd_elongation(const ElongArgs &a)
{
    BoardSpec board;
    try {
        board = load_board(a.board);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sl-calib: %s\n", e.what());
        return 1;
    }
    // Truth mode.
    const bool paired = a.truth.size() == a.captures.size() && a.truth.size() > 0 &&
                        first_line(a.truth[0]).rfind("rotation,", 0) == 0;
    std::map<std::string, std::pair<double, double>> list;
    std::string err;
    if (!paired) {
        if (a.truth.size() != 1) {
            std::fprintf(stderr, "sl-calib: give one list file (--truth LIST.csv) or one sl-sim "
                                 "truth per capture, in the same order\n");
            return 2;
        }
        if (first_line(a.truth[0]).rfind("rotation,", 0) == 0) {
            std::fprintf(stderr, "sl-calib: %s is an sl-sim truth file: give one per capture\n",
                         a.truth[0].c_str());
            return 2;
        }
        if (!read_list(a.truth[0], list, err)) {
            std::fprintf(stderr, "sl-calib: %s\n", err.c_str());
            return 1;
        }
    }
#ifndef SL_HAVE_SIM_TRUTH
    if (paired) {
        std::fprintf(stderr, "sl-calib: this build has no simulator truth reader\n");
        return 1;
    }
#endif
    ElongOptions eo;
    eo.threshold = a.threshold >= 0 ? a.threshold : board.threshold;
    eo.mask_frames = a.mask_frames > 0 ? a.mask_frames : board.mask_frames;
    std::vector<ElongMeasurement> all;
    Progress progress("sl-calib", a.quiet);
    for (size_t ci = 0; ci < a.captures.size(); ci++) {
        const std::string &cap = a.captures[ci];
        progress.update(static_cast<long long>(ci), static_cast<long long>(a.captures.size()), "capture");
        FrameOptions fo;
        fo.azimuths = board.azimuths;
        fo.encoder_size = board.encoder_size;
        fo.roi_bins = std::min(board.roi_bins, SL_CFG_ROI_BINS);
        fo.bin_size_m = a.bin_size_m;
        // The positions (truth segments) first, so that the capture is read once, rotation
        // by rotation, each position holding only its mask (ElongStream); a truth error is
        // reported after the capture's own.
        std::vector<ElongTruth> pos;
        std::string pos_err;
        if (paired) {
#ifdef SL_HAVE_SIM_TRUTH
            std::vector<GtRow> rows;
            if (!gt_read(a.truth[ci], rows, pos_err)) {
                rows.clear();
            }
            std::map<int, std::vector<const GtRow *>> by_pole;
            for (const auto &r : rows) {
                if (r.nominal && r.valid) by_pole[r.pole].push_back(&r);
            }
            for (auto &kv : by_pole) {
                auto &v = kv.second;
                std::sort(v.begin(), v.end(), [](const GtRow *x, const GtRow *y) { return x->rotation < y->rotation; });
                for (size_t i = 0; i < v.size();) {
                    size_t j = i + 1;
                    while (j < v.size() && v[j]->rotation == v[j - 1]->rotation + 1 &&
                           v[j]->azimuth == v[i]->azimuth && std::fabs(v[j]->r1_m - v[i]->r1_m) < 5e-4 &&
                           std::fabs(v[j]->r2_m - v[i]->r2_m) < 5e-4) {
                        j++;
                    }
                    ElongTruth t;
                    t.rot_first = v[i]->rotation;
                    t.rot_last = v[j - 1]->rotation;
                    t.az = v[i]->azimuth;
                    t.r1_true_m = v[i]->r1_m;
                    t.r2_true_m = v[i]->r2_m;
                    t.label = v[i]->pole_name;
                    pos.push_back(t);
                    i = j;
                }
            }
#endif
        } else {
            auto it = list.find(basename_of(cap));
            if (it == list.end()) {
                pos_err = cap + " is not in " + a.truth[0];
            }
            ElongTruth t;
            t.rot_first = 0;
            t.rot_last = INT_MAX;
            if (it != list.end()) {
                t.r1_true_m = it->second.first;
                t.r2_true_m = it->second.second; // NaN: from theta at the measured azimuth
                t.label = basename_of(cap);
                pos.push_back(t);
            }
        }
        FrameSet fs;
        ElongStream stream(pos_err.empty() ? pos : std::vector<ElongTruth>{}, eo);
        if (!for_each_frame(cap, fo, fs,
                            [&](RadarFrame &f, const FrameSet &meta) {
                                stream.add(f, meta.azimuths);
                                return true;
                            },
                            err)) {
            std::fprintf(stderr, "sl-calib: %s\n", err.c_str());
            return 1;
        }
        if (!pos_err.empty()) {
            std::fprintf(stderr, "sl-calib: %s\n", pos_err.c_str());
            return 1;
        }
        eo.near_exclusion_bins = static_cast<int>(std::ceil(board.near_exclusion_m / fs.bin_size_m - 1e-9));
        const std::vector<ElongMeasurement> found = stream.finish(fs, eo);
        for (size_t pi = 0; pi < pos.size(); pi++) {
            const ElongTruth &t = pos[pi];
            ElongMeasurement m = found[pi];
            if (m.found && !std::isfinite(t.r2_true_m)) {
                // A vertical pole at horizontal distance p: the -theta ray meets it at p / cos(theta).
                const double th = board.theta_deg(m.az);
                m.r2_true_m = t.r1_true_m / std::cos(th * kPi / 180.0);
                m.d_m = m.r2_m - m.r2_true_m;
            }
            all.push_back(m);
        }
    }
    progress.finish();
    int missing = 0;
    for (const auto &m : all) missing += m.found ? 0 : 1;
    const ElongTable t = fit_elongation(all, a.points);
    std::printf("sl-calib elongation: %zu positions from %zu captures, board %s, threshold %d, "
                "mask n <= %d\n",
                all.size(), a.captures.size(), board.name.c_str(), eo.threshold, eo.mask_frames);
    if (missing) {
        std::printf("  target not found at %d positions (listed in --csv)\n", missing);
    }
    if (t.n == 0) {
        std::fprintf(stderr, "sl-calib: no position measured\n");
        return 1;
    }
    std::printf("  d mean %.4f m, std %.4f m (n = %d); fit d = %.4f + %.4f r2 (residual std %.4f m)\n",
                t.mean_m, t.std_m, t.n, t.intercept_m, t.slope, t.resid_std_m);
    std::printf("  r1 observed - true: mean %.4f m\n", t.mean_d_r1_m);
    std::printf("  table (observed r2 -> d, +-std, positions):\n");
    for (const auto &p : t.points) {
        std::printf("    %.3f m (%.3f..%.3f): d %.4f m +- %.4f (n %d)\n", p.r_m, p.r_min_m, p.r_max_m,
                    p.d_m, p.std_m, p.n);
    }
    const std::string line = elongation_line(t);
    std::printf("  [detect] %s\n", line.c_str());
    if (!a.out_ini.empty()) {
        std::ostringstream o;
        o << "; sl-calib elongation: " << t.n << " positions from " << a.captures.size()
          << " capture(s), board " << board.name << "\n"
          << "; d = r2 observed (half-bin) - r2 true, keyed by the observed r2 (sl_detect_elong_um)\n"
          << "; mean " << f3(t.mean_m) << " m, std " << f3(t.std_m) << " m; fit d = " << f3(t.intercept_m)
          << " + " << f3(t.slope) << " r2, residual std " << f3(t.resid_std_m) << " m\n";
        for (const auto &p : t.points) {
            o << ";   r2 " << f3(p.r_min_m) << ".." << f3(p.r_max_m) << ": d " << f3(p.d_m) << " +- "
              << f3(p.std_m) << " (n " << p.n << ")\n";
        }
        o << "; " << sl::calib_tool_version() << ", " << sl::calib_utc_date() << "\n";
        o << "[detect]\n" << line << "\n";
        // One file per vehicle: this command's block replaces its previous one, sl-calib
        // shadow's [calib] block is kept.
        std::string why;
        if (!sl::write_calib_block(a.out_ini, "elongation", o.str(), "[detect]", &why)) {
            std::fprintf(stderr, "sl-calib: cannot write %s: %s\n", a.out_ini.c_str(), why.c_str());
            return 1;
        }
        std::printf("  wrote %s\n", a.out_ini.c_str());
    }
    if (!a.csv.empty()) {
        std::FILE *f = std::fopen(a.csv.c_str(), "w");
        if (!f) {
            std::fprintf(stderr, "sl-calib: cannot write %s\n", a.csv.c_str());
            return 1;
        }
        std::fprintf(f, "capture,label,rot_first,rot_last,frames,mask_n,found,why,az,bin_first,bin_last,"
                        "r1_true_m,r2_true_m,r1_m,r2_m,d_m,d_r1_m\n");
        for (const auto &m : all) {
            std::fprintf(f, "%s,%s,%d,%d,%d,%d,%d,%s,%d,%d,%d,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f\n",
                         m.capture.c_str(), m.label.c_str(), m.rot_first,
                         m.rot_last == INT_MAX ? -1 : m.rot_last, m.frames_used, m.mask_n,
                         m.found ? 1 : 0, m.why.c_str(), m.az, m.bin_first, m.bin_last, m.r1_true_m,
                         m.r2_true_m, m.r1_m, m.r2_m, m.d_m, m.d_r1_m);
        }
        std::fclose(f);
        std::printf("  wrote %s\n", a.csv.c_str());
    }
    if (!a.png.empty()) {
        cv::Mat img = elong_png(all, t, "sl-calib elongation: " + board.name + ", " +
                                            std::to_string(t.n) + " positions");
        if (!cv::imwrite(a.png, img, {cv::IMWRITE_PNG_COMPRESSION, 9})) {
            std::fprintf(stderr, "sl-calib: cannot write %s\n", a.png.c_str());
            return 1;
        }
        std::printf("  wrote %s\n", a.png.c_str());
    }
    return 0;
}

} // namespace sl::calib
