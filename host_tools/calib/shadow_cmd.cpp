// SPDX-License-Identifier: MIT
// shadow_cmd.cpp: `sl-calib shadow` (see main.cpp for the usage text).
#include "calib_cmds.h"
#include "calib_ini.h"

#include <cmath>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <memory>
#include <vector>

#include <sys/stat.h>

#include <opencv2/imgcodecs.hpp>

#include "calib_shadow.h"
#include "sl_board_spec.h"
#include "sl_progress.h"
#include "view_draw.h"
#include "view_frames.h"

namespace sl::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string f2(double v, int p = 2)
{
    char b[32];
    std::snprintf(b, sizeof b, "%.*f", p, v);
    return b;
}

double median_of(std::vector<double> v)
{
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }),
            v.end());
    if (v.empty()) {
        return kNaN;
    }
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

/// The comparison picture: mean power (azimuth across, range up) with the measured edges
/// and the board's; theta(az) measured against the board's.
cv::Mat shadow_png(const ShadowCalib &c, const BoardSpec &b, const std::string &title,
                   double range_max_m)
{
    const int A = c.azimuths;
    const int W = 1360, L = 80, PW = 1200;
    const int H = 1110;
    cv::Mat img(H, W, CV_8UC3, cv::Scalar(28, 28, 28));
    draw_text(img, title, cv::Point(L, 30), 0.65);
    // --- panel A: mean image
    PlotAxes pa;
    pa.rect = cv::Rect(L, 70, PW, 420);
    pa.x0 = 0;
    pa.x1 = 360;
    pa.y0 = 0;
    pa.y1 = range_max_m;
    {
        const double bin = c.opt.bin_size_m;
        const int bins = std::min(c.bins, static_cast<int>(std::ceil(range_max_m / bin)));
        cv::Mat m = c.mean(cv::Rect(0, 0, bins, A)).clone();
        cv::Mat grey = power_to_grey(m, std::max(20.0, display_max(m, 0.99)), 0.6);
        // Rows are azimuth index (at yaw + 360 i / A); roll so that x = vehicle azimuth.
        cv::Mat t;
        cv::transpose(grey, t);  // bins x A
        cv::flip(t, t, 0);       // range up
        const int hpx = static_cast<int>(std::lround(bins * bin / range_max_m * pa.rect.height));
        cv::Mat s;
        cv::resize(t, s, cv::Size(PW, hpx), 0, 0, cv::INTER_NEAREST);
        const int shift = static_cast<int>(std::lround(std::fmod(b.radar_yaw_deg + 360.0, 360.0) / 360.0 * PW)) % PW;
        if (shift != 0) {
            cv::Mat r(s.size(), s.type());
            s(cv::Rect(PW - shift, 0, shift, s.rows)).copyTo(r(cv::Rect(0, 0, shift, s.rows)));
            s(cv::Rect(0, 0, PW - shift, s.rows)).copyTo(r(cv::Rect(shift, 0, PW - shift, s.rows)));
            s = r;
        }
        const int y0 = pa.rect.y + pa.rect.height - std::min(hpx, pa.rect.height);
        s(cv::Rect(0, std::max(0, hpx - pa.rect.height), PW, std::min(hpx, pa.rect.height)))
            .copyTo(img(cv::Rect(pa.rect.x, y0, PW, std::min(hpx, pa.rect.height))));
    }
    std::vector<double> x(A), near(A), inner(A), gs(A), bslant(A), th(A), thr(A), bth(A);
    for (int i = 0; i < A; i++) {
        const ShadowAz &r = c.az[i];
        x[i] = std::fmod(b.azimuth_vehicle_deg(i) + 360.0, 360.0);
        near[i] = r.near_end_m > 0 ? r.near_end_m : kNaN;
        inner[i] = r.inner_edge_m > 0 ? r.inner_edge_m : kNaN;
        gs[i] = r.usable ? r.ground_start_m : kNaN;
        const double R = b.shadow_radius_m(i);
        bslant[i] = std::isfinite(R) ? std::hypot(R, b.radar_height_m) : kNaN;
        th[i] = r.theta_deg;
        thr[i] = r.usable ? kNaN : r.theta_raw_deg;
        bth[i] = b.theta_deg(i);
    }
    // Sorted by x for line drawing (yaw may rotate the order).
    auto by_x = [&](std::vector<double> v) {
        std::vector<std::pair<double, double>> p;
        for (int i = 0; i < A; i++) p.push_back({x[i], v[i]});
        std::sort(p.begin(), p.end());
        std::vector<double> xs, ys;
        for (auto &q : p) {
            xs.push_back(q.first);
            ys.push_back(q.second);
        }
        return std::make_pair(xs, ys);
    };
    for (const auto &sct : c.unusable) {
        for (int j = 0; j < sct.az_count; j++) {
            const int i = (sct.az_first + j) % A;
            pa.band(img, x[i], x[i] + 360.0 / A, col::kUnusable, 0.3);
        }
    }
    {
        auto [xs, ys] = by_x(near);
        pa.line(img, xs, ys, col::kNearField, 2);
        std::tie(xs, ys) = by_x(bslant);
        pa.line(img, xs, ys, col::kBoardShadow, 2);
        std::tie(xs, ys) = by_x(inner);
        pa.dots(img, xs, ys, cv::Scalar(200, 200, 200), 1);
        std::tie(xs, ys) = by_x(gs);
        pa.dots(img, xs, ys, col::kCalibShadow, 2);
    }
    // Where the beam's lower emission bound reaches the ground: nothing nearer is lit.
    const cv::Scalar kBeam(140, 220, 140);
    const double s_beam = c.opt.radar_height_m / std::sin(b.lower_bound_deg * 3.14159265358979 / 180.0);
    for (double x0 = 0; x0 < 360; x0 += 4) {
        pa.line(img, {x0, x0 + 2}, {s_beam, s_beam}, kBeam, 1);
    }
    pa.draw(img, 45, 1, "azimuth (deg, vehicle frame, clockwise from forward)",
            "mean power over " + std::to_string(c.frames) + " rotations; slant range (m)");
    // --- panel B: theta
    PlotAxes pb;
    pb.rect = cv::Rect(L, 580, PW, 300);
    pb.x0 = 0;
    pb.x1 = 360;
    double lo = 1e9, hi = -1e9;
    for (int i = 0; i < A; i++) {
        for (double v : {th[i], bth[i]}) {
            if (std::isfinite(v)) {
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
        }
    }
    if (lo > hi) {
        lo = 0;
        hi = 45;
    }
    pb.y0 = std::floor(lo / 5) * 5 - 5;
    pb.y1 = std::max(std::ceil(hi / 5) * 5 + 5, b.lower_bound_deg + 5);
    for (const auto &sct : c.unusable) {
        for (int j = 0; j < sct.az_count; j++) {
            const int i = (sct.az_first + j) % A;
            pb.band(img, x[i], x[i] + 360.0 / A, col::kUnusable, 0.3);
        }
    }
    {
        auto [xs, ys] = by_x(bth);
        pb.line(img, xs, ys, col::kBoardShadow, 2);
        std::tie(xs, ys) = by_x(thr);
        pb.dots(img, xs, ys, cv::Scalar(120, 120, 120), 2);
        std::tie(xs, ys) = by_x(th);
        pb.dots(img, xs, ys, col::kCalibShadow, 2);
    }
    for (double x0 = 0; x0 < 360; x0 += 4) {
        pb.line(img, {x0, x0 + 2}, {b.lower_bound_deg, b.lower_bound_deg}, kBeam, 1);
    }
    pb.draw(img, 45, (pb.y1 - pb.y0) > 30 ? 10 : 5,
            "azimuth (deg, vehicle frame, clockwise from forward)",
            "opening angle theta (deg) = asin(H / ground start), H = " +
                f2(c.opt.radar_height_m) + " m");
    // --- legend and numbers
    std::vector<LegendItem> items = {
        {col::kCalibShadow, "measured ground start (slant) / theta", 4},
        {col::kBoardShadow, "board geometry (" + b.name + ")", 0},
        {col::kNearField, "near-field band end (half fall)", 0},
        {cv::Scalar(200, 200, 200), "inner edge of the dark ring", 4},
        {cv::Scalar(120, 120, 120), "theta of unusable azimuths (not kept)", 4},
        {col::kUnusable, "unusable azimuths", 2},
        {kBeam, "beam's lower bound (-" + f2(b.lower_bound_deg, 0) + " deg): H / sin = " +
                    f2(s_beam) + " m", 1},
    };
    draw_legend(img, items, cv::Point(L, 930), 420);
    std::vector<double> dth, mth, mbt, mgs, mne;
    for (int i = 0; i < A; i++) {
        if (c.az[i].usable) {
            mth.push_back(th[i]);
            mgs.push_back(gs[i]);
            if (std::isfinite(bth[i])) {
                dth.push_back(th[i] - bth[i]);
                mbt.push_back(bth[i]);
            }
        }
        if (std::isfinite(near[i])) {
            mne.push_back(near[i]);
        }
    }
    int y = 950;
    auto line = [&](const std::string &s) {
        draw_text(img, s, cv::Point(L + 450, y), 0.5);
        y += 24;
    };
    line("usable azimuths: " + std::to_string(c.usable_count) + " / " + std::to_string(A) +
         " (window +-" + std::to_string(c.opt.az_half_window) + " az, " +
         std::to_string(c.unusable.size()) + " unusable sectors)");
    line("median ground start " + f2(median_of(mgs)) + " m slant, theta " + f2(median_of(mth)) +
         " deg (board " + f2(median_of(mbt)) + "), median difference " + f2(median_of(dth)) +
         " deg");
    line("near-field band ends at " + f2(median_of(mne)) + " m (median)");
    return img;
}

} // namespace

int cmd_shadow(const ShadowArgs &a)
{
    BoardSpec board;
    try {
        board = load_board(a.board);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sl-calib: %s\n", e.what());
        return 1;
    }
    FrameOptions fo;
    fo.azimuths = board.azimuths;
    fo.encoder_size = board.encoder_size;
    fo.roi_bins = std::min(board.roi_bins, SL_CFG_ROI_BINS);
    fo.bin_size_m = a.bin_size_m;
    FrameSet fs;
    std::string err;
    // An Oxford folder carries no bin size: it is the board's unless given; a capture's
    // Configuration gives its own.
    {
        struct stat st {};
        if (fo.bin_size_m <= 0 && ::stat(a.input.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
            fo.bin_size_m = board.bin_size_m;
        }
    }
    Progress progress("sl-calib", a.quiet); // two steps: read the capture, fit the shadow
    progress.update(0, 2, "reading the capture");
    // Rotations are accumulated as they arrive (bounded memory whatever the capture's length).
    std::unique_ptr<ShadowAccumulator> acc;
    std::vector<uint8_t> valid;
    const bool read_ok = for_each_frame(a.input, fo, fs, [&](RadarFrame &f, const FrameSet &) {
        if (!acc) {
            acc = std::make_unique<ShadowAccumulator>(f.power.rows, f.power.cols, a.opt.az_half_window);
        }
        valid.resize(f.flags.size());
        for (size_t i = 0; i < valid.size(); i++) {
            valid[i] = (f.flags[i] & SL_SCAN_AZ_VALID) ? 1 : 0;
        }
        acc->add(f.power, valid);
        return true;
    }, err);
    if (!read_ok) {
        std::fprintf(stderr, "sl-calib: %s\n", err.c_str());
        return 1;
    }
    if (std::fabs(fs.bin_size_m - board.bin_size_m) > 1e-6) {
        std::fprintf(stderr,
                     "sl-calib: note: bin size %.5f m (%s) differs from the board's %.5f m; "
                     "ranges use %.5f m\n",
                     fs.bin_size_m, fs.bin_from_config ? "capture" : "option",
                     board.bin_size_m, fs.bin_size_m);
    }
    if (fs.azimuths != board.azimuths) {
        std::fprintf(stderr, "sl-calib: capture has %d azimuths, board %s has %d\n",
                     fs.azimuths, board.name.c_str(), board.azimuths);
        return 1;
    }
    ShadowCalibOptions so = a.opt;
    so.radar_height_m = a.height_m > 0 ? a.height_m : board.radar_height_m;
    so.bin_size_m = fs.bin_size_m;
    so.max_theta_deg = board.lower_bound_deg + 3.0;
    ShadowCalib c;
    progress.update(1, 2, "fitting the shadow");
    try {
        c = acc->estimate(so, fs.roi_bins);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sl-calib: %s\n", e.what());
        return 1;
    }
    progress.finish();
    std::vector<double> bth(board.azimuths);
    for (int i = 0; i < board.azimuths; i++) {
        bth[i] = board.theta_deg(i);
    }
    // Text report.
    std::vector<double> th, dth, gs, gh, ne, cvs;
    for (const auto &r : c.az) {
        if (r.usable) {
            th.push_back(r.theta_deg);
            gs.push_back(r.ground_foot_m);
            gh.push_back(r.ground_half_m);
            if (std::isfinite(bth[r.az])) {
                dth.push_back(r.theta_deg - bth[r.az]);
            }
        }
        if (r.near_end_m > 0) {
            ne.push_back(r.near_end_m);
            cvs.push_back(r.near_cv);
        }
    }
    std::printf("sl-calib shadow: %s (%s), %zu rotations, %d azimuths, bin %.4f m, H %.3f m, "
                "board %s\n",
                a.input.c_str(), fs.kind.c_str(), static_cast<size_t>(fs.delivered), c.azimuths, so.bin_size_m,
                so.radar_height_m, board.name.c_str());
    std::printf("  usable azimuths: %d / %d\n", c.usable_count, c.azimuths);
    std::printf("  near-field band end (median): %.2f m; band std/mean over time (median): "
                "%.3f\n",
                median_of(ne), median_of(cvs));
    std::printf("  ground start (slant, median over usable): foot %.3f m, half rise %.3f m; "
                "theta from the %s\n",
                median_of(gs), median_of(gh), so.edge_half_rise ? "half rise" : "foot");
    std::printf("  theta (median over usable): %.2f deg; board median over the same azimuths: "
                "%.2f deg; median(measured - board) %.2f deg\n",
                median_of(th), median_of([&] {
                    std::vector<double> v;
                    for (const auto &r : c.az)
                        if (r.usable) v.push_back(bth[r.az]);
                    return v;
                }()),
                median_of(dth));
    // Sectors of 45 deg (vehicle frame).
    std::printf("  by 45-deg sector (vehicle azimuth centre): usable, median ground start, "
                "median theta, board theta\n");
    for (int s = 0; s < 8; s++) {
        std::vector<double> g, t, bt;
        int n = 0, total = 0;
        for (const auto &r : c.az) {
            double az = std::fmod(board.azimuth_vehicle_deg(r.az) + 22.5 + 720.0, 360.0);
            if (static_cast<int>(az / 45.0) != s) continue;
            total++;
            bt.push_back(bth[r.az]);
            if (!r.usable) continue;
            n++;
            g.push_back(r.ground_start_m);
            t.push_back(r.theta_deg);
        }
        std::printf("    %3d deg: %3d/%3d  %6.2f m  %6.2f deg  (board %6.2f deg)\n", s * 45, n,
                    total, median_of(g), median_of(t), median_of(bt));
    }
    for (const auto &sct : c.unusable) {
        const int last = (sct.az_first + sct.az_count - 1) % c.azimuths;
        std::printf("  unusable: az %d-%d (%.1f-%.1f deg, %d azimuths): %s\n", sct.az_first, last,
                    std::fmod(board.azimuth_vehicle_deg(sct.az_first) + 360.0, 360.0),
                    std::fmod(board.azimuth_vehicle_deg(last) + 360.0, 360.0), sct.az_count,
                    sct.reason.c_str());
    }
    if (!a.out_ini.empty()) {
        // One file per vehicle: this command's block ([calib]: theta per azimuth, with
        // provenance) replaces its previous one, sl-calib elongation's block is kept.
        std::string text = shadow_calib_ini(c, board.name, a.input, bth);
        const std::string prov = "version = 1\ntool = " + sl::calib_tool_version() + "\ndate = " +
                                 sl::calib_utc_date() + "\n";
        const size_t at = text.find("[calib]\n");
        if (at != std::string::npos) {
            text.insert(at + 8, prov);
        }
        std::string why;
        if (!sl::write_calib_block(a.out_ini, "shadow", text, "[calib]", &why)) {
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
        std::fprintf(f, "az,az_vehicle_deg,usable,reason,near_peak,near_end_m,near_cv,"
                        "inner_edge_m,core_m,core_level,rise_level,ground_start_m,ground_foot_m,ground_level,"
                        "ground_half_m,ground_radius_m,theta_deg,theta_raw_deg,board_theta_deg,"
                        "bright_inside_m,bright_level\n");
        for (const auto &r : c.az) {
            std::fprintf(f, "%d,%.2f,%d,%s,%.2f,%.3f,%.3f,%.3f,%.3f,%.2f,%.2f,%.3f,%.3f,%.2f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.2f\n",
                         r.az, std::fmod(board.azimuth_vehicle_deg(r.az) + 360.0, 360.0),
                         r.usable ? 1 : 0, r.reason.c_str(), r.near_peak_level, r.near_end_m,
                         r.near_cv, r.inner_edge_m, r.core_m, r.core_level, r.rise_level, r.ground_start_m, r.ground_foot_m,
                         r.ground_level, r.ground_half_m, r.ground_radius_m, r.theta_deg, r.theta_raw_deg,
                         bth[r.az], r.bright_inside_m, r.bright_level);
        }
        std::fclose(f);
        std::printf("  wrote %s\n", a.csv.c_str());
    }
    if (!a.png.empty()) {
        // The input's name only: a picture must not carry the path of the machine it was
        // made on.
        const std::string input_name =
            std::filesystem::path(a.input).lexically_normal().filename().empty()
                ? std::filesystem::path(a.input).lexically_normal().parent_path().filename().string()
                : std::filesystem::path(a.input).lexically_normal().filename().string();
        const std::string title = "sl-calib shadow: " + board.name + ", " +
                                  std::to_string(c.frames) + " rotations of " + input_name;
        double rmax = 2.0 * median_of(gs);
        if (!std::isfinite(rmax)) rmax = 8;
        rmax = std::clamp(std::ceil(rmax), 4.0, so.search_max_m);
        cv::Mat img = shadow_png(c, board, title, rmax);
        if (!cv::imwrite(a.png, img, {cv::IMWRITE_PNG_COMPRESSION, 9})) {
            std::fprintf(stderr, "sl-calib: cannot write %s\n", a.png.c_str());
            return 1;
        }
        std::printf("  wrote %s\n", a.png.c_str());
    }
    return 0;
}

} // namespace sl::calib
