// SPDX-License-Identifier: MIT
// sl-view: what the module sees, as pictures.
//
//   sl-view CAPTURE|OXFORD_DIR --board NAME --out FILE.png|FILE.mp4|FILE.avi
//           [--rotation K | --all] [--truth GT.csv] [--calib CALIB.ini] [--roi-m M]
//           [--mask-frames N] [--threshold T] [--vmax V] [--fps F] [--bin-size-m M]
//           [--elongation D.ini] [--title TEXT]
//
// One picture per rotation: on the left the polar image (slant range across, azimuth down,
// the region of interest), on the right the top view around the vehicle (forward up), both
// with
//   - the 8-bit power in grey (display stretch fixed for the whole capture),
//   - the core's n-frame consistency mask (sl_thresh_u8 + sl_mask, board threshold and n;
//     stable-occupied bins tinted green),
//   - the chassis outline from the board file (top view),
//   - the board's theoretical shadow edge (amber): the slant range sqrt(R^2 + H^2) at which
//     the ground at the board's shadow radius R(az) = H / tan(theta(az)) appears,
//   - the near-field exclusion (blue, dashed),
//   - the calibrated shadow edge from `sl-calib shadow --out-ini` (magenta, --calib),
//   - the core's detections (sl_detect on the mask, red) with their alpha labels,
//   - the simulator's ground truth (cyan, --truth: the sl-sim CSV),
//   - a legend, a scale bar, and a line of numbers under the panels.
// --elongation D.ini runs the detector on a copy of the linked board whose d(r) table is the
// `elongation = r:d, ...` line of D.ini (sl-calib elongation --out-ini): the calibration loop
// without regenerating the board tables. --mask-frames / --threshold override the board's
// n and threshold; with fewer rotations than n, n becomes the rotation count (noted).
// Captures are read with capture.h (raw .colossus or pcap) and decoded by the core
// (sl_proto_feed + sl_scan); an Oxford folder is converted in memory by oxford.h first.
//
// --rotation K picks rotation K of the decoded frames (0-based; negative counts from the
// end; default: the last one, where the mask has the most history). --all renders every
// rotation into a video (.mp4 through OpenCV's FFmpeg backend, codec mp4v; when that
// writer cannot be opened, the same frames go to .avi with MJPG and a note says so) or, with
// a .png output, into FILE_0000.png, FILE_0001.png, ...
//
// Memory does not grow with the capture: it is streamed (sl::for_each_frame, "-", pipes and
// FIFOs too) through the core's mask and detector, and only what is drawn is kept (class
// Viewer). --rotation reads to the end (the rotation count is drawn and printed); --all
// draws each rotation as it comes, after a first pass over a file for that count; from a
// pipe its pictures say "rotation K" without the count. --motion runs the pipeline over the
// file first (a second pass): it needs a file, not a pipe (usage error).
//
// Exit status: 0 done, 1 error, 2 usage.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <filesystem>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "calib_board.h"
#include "calib_shadow.h"
#include "sl_cli.h"
#include "sl_progress.h"
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_detect.h"
#include "view_tilt.h"
#include "shadowlean/sl_mask.h"
#include "shadowlean/sl_thresh.h"
#include "sl_board_spec.h"
#include "view_draw.h"
#include "view_frames.h"
#ifdef SL_HAVE_SIM_TRUTH
#include "sim_truth.h"
#endif

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Args {
    std::string input, board, out, truth, calib, calibration, elongation, title;
    int rotation = -1;
    bool all = false, quiet = false;
    double roi_m = 0, vmax = 0, fps = 4, bin_size_m = 0;
    int mask_frames = 0, threshold = -1;
    bool motion = false;
    double motion_v = 0, motion_w = 0;
};

void usage(FILE *out)
{
    std::fputs(
        "usage: sl-view CAPTURE|OXFORD_DIR --board NAME --out FILE.png|FILE.mp4|FILE.avi\n"
        "               [--rotation K | --all] [--truth GT.csv] [--calib CALIB.ini]\n"
        "               [--roi-m M] [--mask-frames N] [--threshold T] [--vmax V] [--fps F]\n"
        "               [--bin-size-m M] [--elongation D.ini] [--calibration FILE] [--title TEXT]\n"
        "               [--motion V[,W]] [-q|--quiet]\n"
        "  --all: progress on stderr when it is a terminal (-q/--quiet: none).\n"
        "  --calibration FILE: detect on the board's calibrated view (a vehicle's calibration INI\n"
        "  from sl-calib --out-ini, or a blob from sl-tables --blob)\n"
        "  --motion V[,W]: run the core pipeline with this constant motion (m/s, deg/s; as\n"
        "  shadowleand --motion) and draw the fitted 3D tilt of each pole in the top view:\n"
        "  base, an arrow to the top of a 4 m pole, tilt and direction (CCW from forward);\n"
        "  it reads the capture twice: a file, not stdin (-), a pipe or a FIFO.\n",
        out);
}

std::string fmt(const char *f, double v)
{
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

bool ends_with(const std::string &s, const std::string &e)
{
    return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

/// Truth of one pole on one rotation (the nominal azimuth's row).
struct TruthMark {
    std::string name;
    int az = 0;
    double r1_m = 0, r2_m = 0, alpha_deg = 0;
    bool valid = false;
};

/// Everything drawn on one rotation.
struct RotationView {
    const sl::RadarFrame *frame = nullptr;
    int index = 0, count = 0;               ///< count 0: not known (--all from a pipe)
    std::vector<std::vector<uint32_t>> occ; ///< stable-occupied rows (empty: no history)
    std::vector<sl_target_t> targets;
    std::vector<TruthMark> truth;
    std::vector<slv::TiltMark> tilt; ///< fitted poles (--motion)
};

struct Scene {
    sl::BoardSpec board;
    const sl_board_t *core_board = nullptr;
    const sl::FrameSet *fs = nullptr;
    double roi_m = 10, vmax = 60;
    int mask_n = 16, threshold = 40;
    std::string mask_note, detect_note, truth_note;
    std::vector<double> board_slant_m, near_m;
    std::vector<double> calib_slant_m;
    bool have_calib = false;
    std::string elong_note;
    double theta_min = 0, theta_max = 0;
    std::string title;
};

const char *flag_name(int f)
{
    switch (f) {
    case SL_INCLINE_AMBIGUOUS:
        return "ambiguous";
    case SL_INCLINE_INVALID:
        return "invalid";
    case SL_INCLINE_OUT_OF_DOMAIN:
        return "out of domain";
    default:
        return "";
    }
}

std::string target_label(const sl_target_t &t)
{
    if (t.incline_flag == SL_INCLINE_VALID) {
        char b[64];
        std::snprintf(b, sizeof b, "%+.1f deg", t.alpha_cdeg / 100.0);
        return b;
    }
    return flag_name(t.incline_flag);
}

/// Greedy label placement: each label goes to the first candidate offset around its anchor
/// whose box overlaps no label placed before (readability when poles are close).
struct Labels {
    std::vector<cv::Rect> used;
    void put(cv::Mat &img, const std::string &s, cv::Point2d anchor, const cv::Scalar &c,
             double scale = 0.52)
    {
        int base = 0;
        const cv::Size sz = cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &base);
        const cv::Point a(static_cast<int>(anchor.x), static_cast<int>(anchor.y));
        const cv::Point offs[] = {{14, -10}, {14, sz.height + 12}, {-sz.width - 14, -10},
                                  {-sz.width - 14, sz.height + 12}, {14, -sz.height - 26},
                                  {14, 2 * sz.height + 30}, {-sz.width - 14, -sz.height - 26}};
        cv::Point org = a + offs[0];
        for (const auto &o : offs) {
            const cv::Rect r(a.x + o.x - 2, a.y + o.y - sz.height - 3, sz.width + 4, sz.height + 7);
            bool clash = false;
            for (const auto &u : used) {
                if ((u & r).area() > 0) {
                    clash = true;
                    break;
                }
            }
            if (!clash) {
                org = a + o;
                break;
            }
        }
        used.emplace_back(org.x - 2, org.y - sz.height - 3, sz.width + 4, sz.height + 7);
        sl::draw_text(img, s, org, scale, c);
    }
};

/// The `elongation = r:d, ...` line of an INI fragment (sl-calib elongation --out-ini) into
/// a board's table (micrometres). false + err when absent or malformed.
bool read_elongation(const std::string &path, sl_board_t &b, std::string &err)
{
    std::FILE *f = std::fopen(path.c_str(), "r");
    if (!f) {
        err = path + ": cannot open";
        return false;
    }
    char line[1024];
    std::string val;
    while (std::fgets(line, sizeof line, f)) {
        std::string l = line;
        const size_t p = l.find_first_not_of(" \t");
        if (p != std::string::npos && l.compare(p, 10, "elongation") == 0 && l.find('=') != std::string::npos) {
            val = l.substr(l.find('=') + 1);
        }
    }
    std::fclose(f);
    if (val.empty()) {
        err = path + ": no 'elongation =' line";
        return false;
    }
    int n = 0;
    const char *c = val.c_str();
    while (*c) {
        double r = 0, d = 0;
        int used = 0;
        if (std::sscanf(c, " %lf : %lf%n", &r, &d, &used) != 2) break;
        if (n >= SL_CFG_MAX_ELONG_POINTS || r <= 0 || (n > 0 && r * 1e6 <= b.elong_range_um[n - 1])) {
            err = path + ": elongation points must ascend, at most " + std::to_string(SL_CFG_MAX_ELONG_POINTS);
            return false;
        }
        b.elong_range_um[n] = static_cast<uint32_t>(std::lround(r * 1e6));
        b.elong_d_um[n] = static_cast<int32_t>(std::lround(d * 1e6));
        n++;
        c += used;
        while (*c == ' ' || *c == ',' || *c == '\t') c++;
        if (*c == '\n' || *c == '\r' || *c == ';') break;
    }
    if (n == 0) {
        err = path + ": no r:d pair in the elongation line";
        return false;
    }
    b.elong_points = static_cast<uint8_t>(n);
    return true;
}

cv::Mat render(const Scene &sc, const RotationView &rv)
{
    Labels labels;
    const sl::FrameSet &fs = *sc.fs;
    const int A = fs.azimuths;
    const double bin = fs.bin_size_m;
    const cv::Mat &pw = rv.frame->power;
    const double yaw = sc.board.radar_yaw_deg;
    // Polar BGR image with the mask tint.
    cv::Mat polar = sl::power_to_grey(pw, sc.vmax, 0.7);
    for (int a = 0; a < A && a < static_cast<int>(rv.occ.size()); a++) {
        if (rv.occ[a].empty()) {
            continue;
        }
        cv::Vec3b *row = polar.ptr<cv::Vec3b>(a);
        for (int k = 0; k < pw.cols; k++) {
            if (sl_bits_get(rv.occ[a].data(), static_cast<uint32_t>(k))) {
                const cv::Vec3b g = row[k];
                row[k] = cv::Vec3b(static_cast<uint8_t>(g[0] * 0.3),
                                   static_cast<uint8_t>(std::min(255.0, 90 + g[1] * 0.65)),
                                   static_cast<uint8_t>(g[2] * 0.3));
            }
        }
    }
    const int W = 1600, Ht = 1010;
    cv::Mat img(Ht, W, CV_8UC3, cv::Scalar(28, 28, 28));
    sl::draw_text(img, sc.title, cv::Point(20, 30), 0.62);
    {
        char b[256];
        const double t = rv.frame->t_first_us * 1e-6;
        if (rv.count > 0) {
            std::snprintf(b, sizeof b, "rotation %d of %d (frame #%u, t = %.3f s)", rv.index + 1,
                          rv.count, rv.frame->rotation, t);
        } else { // --all from a pipe: the count is not known while drawing
            std::snprintf(b, sizeof b, "rotation %d (frame #%u, t = %.3f s)", rv.index + 1,
                          rv.frame->rotation, t);
        }
        sl::draw_text(img, b, cv::Point(20, 55), 0.5, cv::Scalar(200, 200, 200));
    }
    sl::PolarAxes pa;
    pa.rect = cv::Rect(70, 75, 640, 800);
    pa.azimuths = A;
    pa.range_max_m = sc.roi_m;
    pa.yaw_deg = yaw;
    pa.draw_image(img, polar, bin);
    sl::CartAxes ca;
    ca.rect = cv::Rect(770, 75, 800, 800);
    ca.roi_m = sc.roi_m;
    ca.draw_image(img, polar, bin, yaw);
    // --- overlays: polar
    pa.curve(img, sc.near_m, sl::col::kNearField, 2, true);
    pa.curve(img, sc.board_slant_m, sl::col::kBoardShadow, 2);
    if (sc.have_calib) {
        pa.curve(img, sc.calib_slant_m, sl::col::kCalibShadow, 2);
    }
    pa.draw_axes(img);
    sl::draw_text(img, "azimuth (deg)", cv::Point(8, 70), 0.45);
    // --- overlays: top view
    ca.draw_axes(img);
    {
        cv::Mat sub = img(ca.rect);
        const cv::Point2d off(ca.rect.x, ca.rect.y);
        const auto &b = sc.board;
        if (b.chassis_type == "cylinder") {
            const int rad = static_cast<int>(b.cylinder_radius_m * ca.scale());
            cv::circle(sub, ca.centre() - off, rad, cv::Scalar(0, 0, 0), 5, cv::LINE_AA);
            cv::circle(sub, ca.centre() - off, rad, sl::col::kChassis, 2, cv::LINE_AA);
        } else {
            std::vector<cv::Point> poly;
            for (const auto &v : b.polygon) {
                const cv::Point2d p = ca.px_xy(v.x_m - b.radar_x_m, v.y_m - b.radar_y_m) - off;
                poly.emplace_back(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
            }
            cv::polylines(sub, poly, true, cv::Scalar(0, 0, 0), 5, cv::LINE_AA);
            cv::polylines(sub, poly, true, sl::col::kChassis, 2, cv::LINE_AA);
        }
        cv::drawMarker(sub, ca.centre() - off, sl::col::kChassis, cv::MARKER_TILTED_CROSS, 10, 2);
    }
    ca.curve(img, sc.near_m, yaw, sl::col::kNearField, 2, true);
    ca.curve(img, sc.board_slant_m, yaw, sl::col::kBoardShadow, 2);
    if (sc.have_calib) {
        ca.curve(img, sc.calib_slant_m, yaw, sl::col::kCalibShadow, 2);
    }
    // --- detections (boxes and circles first, labels after the truth marks)
    for (size_t i = 0; i < rv.targets.size(); i++) {
        const sl_target_t &t = rv.targets[i];
        const double r1 = t.r1_raw_um * 1e-6, r2 = t.r2_raw_um * 1e-6;
        const cv::Point2d p0 = pa.px(t.az_first, r1), p1 = pa.px(t.az_first + t.az_count, r2);
        cv::rectangle(img, cv::Rect(cv::Point(static_cast<int>(p0.x) - 2, static_cast<int>(p0.y) - 2),
                                    cv::Point(static_cast<int>(p1.x) + 2, static_cast<int>(p1.y) + 2)),
                      sl::col::kDetect, 2);
        const double az_deg = yaw + 360.0 * (t.az + 0.5) / A;
        cv::circle(img, ca.px_ra(0.5 * (r1 + r2), az_deg), 12, sl::col::kDetect, 2, cv::LINE_AA);
    }
    // --- truth: the visible axis r1..r2 on the nominal azimuth
    for (const auto &t : rv.truth) {
        const double az_deg = yaw + 360.0 * (t.az + 0.5) / A;
        const cv::Point2d a = pa.px(t.az + 0.5, t.r1_m), b2 = pa.px(t.az + 0.5, t.r2_m);
        cv::line(img, a, b2, sl::col::kTruth, 2, cv::LINE_AA);
        cv::drawMarker(img, a, sl::col::kTruth, cv::MARKER_CROSS, 10, 2);
        cv::line(img, ca.px_ra(t.r1_m, az_deg), ca.px_ra(t.r2_m, az_deg), sl::col::kTruth, 2, cv::LINE_AA);
        cv::drawMarker(img, ca.px_ra(t.r1_m, az_deg), sl::col::kTruth, cv::MARKER_CROSS, 14, 2);
    }
    for (size_t i = 0; i < rv.targets.size(); i++) {
        const sl_target_t &t = rv.targets[i];
        const double r1 = t.r1_raw_um * 1e-6, r2 = t.r2_raw_um * 1e-6;
        const std::string lab = std::string(1, static_cast<char>('A' + i % 26)) + " " + target_label(t);
        labels.put(img, lab, pa.px(t.az_first + t.az_count, r2), sl::col::kDetect, 0.5);
        const double az_deg = yaw + 360.0 * (t.az + 0.5) / A;
        labels.put(img, lab, ca.px_ra(0.5 * (r1 + r2), az_deg), sl::col::kDetect, 0.55);
    }
    slv::draw_tilt_marks(img, rv.tilt, sc.board.radar_x_m, sc.board.radar_y_m,
                         [&](double x, double y) { return ca.px_xy(x, y); });
    for (const auto &t : rv.truth) {
        const double az_deg = yaw + 360.0 * (t.az + 0.5) / A;
        const std::string lab = "truth " + t.name + " " +
                                (t.valid ? fmt("%+.1f deg", t.alpha_deg) : std::string("(not valid)"));
        labels.put(img, lab, ca.px_ra(t.r1_m, az_deg), sl::col::kTruth, 0.5);
        labels.put(img, t.name, pa.px(t.az + 0.5, t.r2_m), sl::col::kTruth, 0.45);
    }
    ca.scale_bar(img, sc.roi_m > 12 ? 5.0 : (sc.roi_m > 5 ? 2.0 : 1.0));
    // --- legend (top view, top-right)
    std::vector<sl::LegendItem> items = {
        {cv::Scalar(60, 200, 60), "stable-occupied (mask, n = " + std::to_string(sc.mask_n) + ")", 2},
        {sl::col::kChassis, "chassis outline (board file)", 0},
        {sl::col::kBoardShadow, "board shadow edge (slant range)", 0},
        {sl::col::kNearField, "near-field exclusion", 1},
    };
    if (sc.have_calib) {
        items.push_back({sl::col::kCalibShadow, "calibrated shadow edge (sl-calib)", 0});
    }
    items.push_back({sl::col::kDetect, "detection (core), alpha", 3});
    if (!rv.truth.empty() || !sc.truth_note.empty()) {
        items.push_back({sl::col::kTruth, "ground truth (sl-sim), alpha", 4});
    }
    if (!rv.tilt.empty()) {
        items.push_back({cv::Scalar(0, 140, 255), "fitted 3D tilt (base, lean of a 4 m pole)", 1});
    }
    sl::draw_legend(img, items, cv::Point(ca.rect.x + ca.rect.width - 330, ca.rect.y + 6), 326);
    // --- numbers
    int y = 930;
    auto line = [&](const std::string &s, const cv::Scalar &c = sl::col::kText) {
        sl::draw_text(img, s, cv::Point(20, y), 0.5, c);
        y += 22;
    };
    {
        char b[400];
        std::snprintf(b, sizeof b,
                      "board %s: H %.2f m, theta %.1f-%.1f deg, bin %.4f m (%s), threshold %d, "
                      "mask n = %d%s",
                      sc.board.name.c_str(), sc.board.radar_height_m, sc.theta_min, sc.theta_max,
                      bin, fs.bin_from_config ? "capture" : "board/option", sc.threshold, sc.mask_n,
                      sc.mask_note.c_str());
        line(b);
    }
    if (!sc.detect_note.empty()) {
        line(sc.detect_note, sl::col::kDetect);
    } else {
        // Three targets per line so the numbers stay inside the picture.
        std::string s = "detections" + sc.elong_note + ": " + std::to_string(rv.targets.size());
        for (size_t i = 0; i < rv.targets.size() && i < 6; i++) {
            const sl_target_t &t = rv.targets[i];
            char b[160];
            std::snprintf(b, sizeof b, "   %c: az %.1f deg r1 %.2f r2 %.2f m %s",
                          'A' + static_cast<int>(i % 26),
                          std::fmod(yaw + 360.0 * t.az / A + 360.0, 360.0), t.r1_um * 1e-6,
                          t.r2_um * 1e-6, target_label(t).c_str());
            s += b;
            if (i % 3 == 2 && i + 1 < rv.targets.size()) {
                line(s, sl::col::kDetect);
                s = "    ";
            }
        }
        line(s, sl::col::kDetect);
    }
    if (!sc.truth_note.empty()) {
        line(sc.truth_note, sl::col::kTruth);
    }
    return img;
}

/// True for an input that can be read only once: "-" (stdin), a pipe, a FIFO, a socket or
/// character device (not a regular file or an Oxford folder; a missing path is not one).
bool is_stream(const std::string &path)
{
    struct stat st {};
    return path == "-" || (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode));
}

/// The first `cols` columns of `power` (a copy): a capture's frames cropped to its widest row.
cv::Mat crop_cols(const cv::Mat &power, int cols)
{
    if (cols <= 0 || cols >= power.cols) {
        return power;
    }
    return power(cv::Rect(0, 0, cols, power.rows)).clone();
}

/// The core's consistency mask and detector over the rotations in order.
class CoreRun {
public:
    /// `frame_bins`: columns of the frames (the mask's width without a core board).
    bool init(Scene &sc, int azimuths, int frame_bins, double bin_size_m, std::string &err)
    {
        A_ = azimuths;
        threshold_ = sc.threshold;
        // The mask spans the board's region of interest (the detector's rows); captures with
        // shorter rows are padded with free bins.
        bins_ = sc.core_board ? std::min<int>(sc.core_board->roi_bins, SL_CFG_ROI_BINS) : frame_bins;
        padded_.assign(static_cast<size_t>(std::max(bins_, frame_bins)), 0);
        bits_.assign(SL_ROI_WORDS, 0);
        if (sl_mask_init(mask_.get(), static_cast<uint16_t>(A_), static_cast<uint16_t>(bins_),
                         static_cast<uint8_t>(sc.mask_n), SL_MASK_MAX_MISSED_DEFAULT) != SL_OK) {
            err = "sl_mask_init failed (azimuths " + std::to_string(A_) + ", bins " + std::to_string(bins_) +
                  ", n " + std::to_string(sc.mask_n) + ")";
            return false;
        }
        if (sc.core_board == nullptr) {
            sc.detect_note = "detections: none drawn (board " + sc.board.name + " is not linked into the core)";
        } else if (std::fabs(sc.core_board->bin_size_um * 1e-6 - bin_size_m) > 1e-6) {
            sc.detect_note = "detections: none drawn (capture bin " + fmt("%.4f", bin_size_m) +
                             " m / ROI differ from the board's tables)";
        } else if (sl_detect_init(det_.get(), sc.core_board, nullptr) == SL_OK) {
            have_det_ = true;
        } else {
            sc.detect_note = "detections: sl_detect_init rejected the board";
        }
        return true;
    }

    /// One rotation through the mask and the detector; its detections into `targets`.
    void step(const sl::RadarFrame &fr, std::vector<sl_target_t> &targets)
    {
        for (int az = 0; az < A_; az++) {
            if (!(fr.flags[az] & SL_SCAN_AZ_VALID)) continue;
            const int w = std::min(bins_, fr.power.cols);
            std::copy(fr.power.ptr<uint8_t>(az), fr.power.ptr<uint8_t>(az) + w, padded_.begin());
            std::fill(padded_.begin() + w, padded_.end(), 0);
            sl_thresh_u8(padded_.data(), static_cast<uint32_t>(bins_), static_cast<uint16_t>(threshold_),
                         bits_.data());
            (void)sl_mask_update(mask_.get(), static_cast<uint16_t>(az), bits_.data(), nullptr, nullptr);
        }
        sl_mask_end_rotation(mask_.get());
        targets.clear();
        if (have_det_) {
            const sl_ssize_t n = sl_detect_rotation_from_mask(det_.get(), mask_.get());
            for (sl_ssize_t i = 0; i < n; i++) targets.push_back(det_->targets[i]);
        }
    }

    /// The stable-occupied rows after the last step (empty row: no history).
    void occupied(std::vector<std::vector<uint32_t>> &occ) const
    {
        occ.assign(static_cast<size_t>(A_), {});
        std::vector<uint32_t> row(SL_ROI_WORDS);
        for (int az = 0; az < A_; az++) {
            if (sl_mask_stable(mask_.get(), static_cast<uint16_t>(az), row.data(), nullptr)) {
                occ[static_cast<size_t>(az)] = row;
            }
        }
    }

private:
    std::unique_ptr<sl_mask_t> mask_ = std::make_unique<sl_mask_t>();
    std::unique_ptr<sl_detect_t> det_ = std::make_unique<sl_detect_t>();
    bool have_det_ = false;
    int A_ = 0, bins_ = 0, threshold_ = 0;
    std::vector<uint8_t> padded_;
    std::vector<uint32_t> bits_;
};

/// A rotation kept to be drawn at the end (--rotation K): its frame and what the core saw.
struct Shot {
    sl::RadarFrame frame;
    int index = 0;
    std::vector<std::vector<uint32_t>> occ;
    std::vector<sl_target_t> targets;
};

/// sl-view's rotations one at a time, as sl::for_each_frame hands them over. Memory does not
/// follow the capture's length:
///   - the first n rotations (the mask window) are held only until the mask's n is known:
///     n rotations arrived (the board's n holds) or the capture ended first (n = its count);
///   - --all draws each rotation as it comes (the rotation count and the crop of short rows
///     come from a first pass over a file; from a pipe the count is not drawn and the crop is
///     the widest row of the rotations received before the first picture);
///   - --rotation K >= 0 keeps rotation K, --rotation -K a ring of the last K rotations, and
///     draws at the end (the count, drawn and printed, is known only there);
///   - the first rotation (display stretch) is kept.
class Viewer {
public:
    Viewer(const Args &a, Scene &sc, const std::vector<std::vector<TruthMark>> &truth,
           const std::vector<std::vector<slv::TiltMark>> &tilt)
        : a_(a), sc_(sc), truth_(truth), tilt_(tilt), progress_("sl-view", a.quiet || !a.all)
    {
        board_n_ = a.mask_frames > 0 ? a.mask_frames : sc.board.mask_frames;
        video_ = a.all && !ends_with(a.out, ".png");
    }

    /// --all from a file: what a first pass counted (rotations, columns after the crop).
    void know(const sl::FrameSet &first_pass)
    {
        count_ = first_pass.delivered;
        known_ = first_pass;
    }

    /// for_each_frame's callback. false stops reading (error() says why).
    bool on_frame(sl::RadarFrame &fr, const sl::FrameSet &meta)
    {
        if (received_++ == 0) {
            if (meta.azimuths != sc_.board.azimuths) {
                return fail("capture has " + std::to_string(meta.azimuths) + " azimuths, board " +
                            sc_.board.name + " has " + std::to_string(sc_.board.azimuths));
            }
            first_ = fr;
            first_.power = fr.power.clone();
        }
        if (!started_) {
            window_.push_back(std::move(fr));
            if (count_ > 0) {
                return start(std::min(count_, board_n_), meta);
            }
            if (static_cast<int>(window_.size()) >= board_n_ || a_.mask_frames > 0) {
                return start(board_n_, meta);
            }
            return true;
        }
        return take(fr);
    }

    /// At the end of the capture (`meta`: for_each_frame's final FrameSet). Exit status.
    int finish(const sl::FrameSet &meta)
    {
        const int N = meta.delivered;
        if (!started_ && !start(std::max(1, std::min(N, board_n_)), meta)) {
            return report();
        }
        if (a_.all) {
            progress_.finish();
            if (video_) {
                vw_.release();
                std::printf("sl-view: wrote %s (%d frames at %.1f fps)%s\n", video_path_.c_str(), written_,
                            a_.fps, video_note_.c_str());
            } else {
                std::printf("sl-view: wrote %d PNGs %s_NNNN.png\n", written_,
                            a_.out.substr(0, a_.out.size() - 4).c_str());
            }
            return 0;
        }
        const int k = a_.rotation < 0 ? N + a_.rotation : a_.rotation;
        if (k < 0 || k >= N) {
            std::fprintf(stderr, "sl-view: rotation %d out of range (0..%d)\n", a_.rotation, N - 1);
            return 1;
        }
        // --rotation K: the shot kept (K >= 0) or the oldest of the ring of the last -K.
        Shot &s = a_.rotation >= 0 ? ring_.front() : ring_[ring_next_ % ring_cap_];
        count_ = N;
        if (!prepare(meta)) {
            return report();
        }
        s.frame.power = crop_cols(s.frame.power, drawn_.roi_bins);
        return write_one(s);
    }

    const std::string &error() const { return err_; }
    bool failed() const { return !err_.empty(); }

private:
    bool fail(const std::string &why)
    {
        err_ = why;
        return false;
    }
    int report() const
    {
        std::fprintf(stderr, "sl-view: %s\n", err_.c_str());
        return 1;
    }

    /// The mask's n is known: the note when the capture is shorter, the core's mask and
    /// detector, and the rotations held back go through.
    bool start(int mask_n, const sl::FrameSet &meta)
    {
        started_ = true;
        sc_.mask_n = board_n_;
        if (a_.mask_frames <= 0 && mask_n < board_n_) {
            sc_.mask_note = " (board n = " + std::to_string(sc_.board.mask_frames) + "; the capture has " +
                            std::to_string(mask_n) + " rotations)";
            sc_.mask_n = mask_n;
        }
        std::string e;
        if (!core_.init(sc_, meta.azimuths, window_.front().power.cols, meta.bin_size_m, e)) {
            return fail(e);
        }
        if (a_.all && !prepare(count_ > 0 ? known_ : meta)) {
            return false;
        }
        if (!a_.all) {
            // The ring grows to -K as rotations arrive (a K beyond the capture costs nothing).
            ring_cap_ = a_.rotation >= 0 ? 1U : static_cast<size_t>(-static_cast<long long>(a_.rotation));
            ring_.resize(1);
        }
        std::vector<sl::RadarFrame> held;
        held.swap(window_);
        for (auto &f : held) {
            if (!take(f)) {
                return false;
            }
        }
        return true;
    }

    /// What the pictures need of the whole capture: the shadow curves, the calibrated
    /// shadow, the range shown, the display stretch (from the first rotation).
    bool prepare(const sl::FrameSet &meta)
    {
        drawn_ = meta;
        if (count_ <= 0) { // --all from a pipe: the widest row received so far
            int widest = first_.widest_row;
            for (const auto &f : window_) widest = std::max(widest, f.widest_row);
            if (widest > 0 && widest < drawn_.roi_bins) drawn_.roi_bins = widest;
        }
        sc_.fs = &drawn_;
        const int A = drawn_.azimuths;
        sc_.board_slant_m.resize(A);
        sc_.near_m.assign(A, sc_.board.near_exclusion_m);
        double smax = 0;
        sc_.theta_min = 1e9;
        sc_.theta_max = -1e9;
        for (int i = 0; i < A; i++) {
            sc_.theta_min = std::min(sc_.theta_min, sc_.board.theta_deg(i));
            sc_.theta_max = std::max(sc_.theta_max, sc_.board.theta_deg(i));
            const double R = sc_.board.shadow_radius_m(i);
            sc_.board_slant_m[i] = std::isfinite(R) ? std::hypot(R, sc_.board.radar_height_m) : kNaN;
            if (std::isfinite(sc_.board_slant_m[i])) smax = std::max(smax, sc_.board_slant_m[i]);
        }
        if (!a_.calib.empty()) {
            sl::ShadowCalibFile cf;
            std::string e;
            if (!sl::read_shadow_calib(a_.calib, cf, e)) {
                return fail(e);
            }
            if (cf.azimuths != A) {
                return fail(a_.calib + " has " + std::to_string(cf.azimuths) + " azimuths, the capture " +
                            std::to_string(A));
            }
            sc_.calib_slant_m.assign(A, kNaN);
            for (int i = 0; i < A; i++) {
                if (std::isfinite(cf.theta_deg[i])) {
                    sc_.calib_slant_m[i] = cf.ground_start_m[i];
                }
            }
            sc_.have_calib = true;
        }
        sc_.roi_m = a_.roi_m > 0 ? a_.roi_m : std::max(6.0, std::ceil(1.6 * smax));
        sc_.roi_m = std::min(sc_.roi_m, drawn_.roi_bins * drawn_.bin_size_m);
        sc_.vmax = a_.vmax > 0 ? a_.vmax : sl::display_max(crop_cols(first_.power, drawn_.roi_bins), 0.995);
        return true;
    }

    /// One rotation after the mask window: through the core, then drawn (--all) or kept.
    bool take(sl::RadarFrame &fr)
    {
        const int k = index_++;
        if (a_.all) {
            Shot s;
            s.index = k;
            core_.step(fr, s.targets);
            core_.occupied(s.occ);
            s.frame = std::move(fr);
            s.frame.power = crop_cols(s.frame.power, drawn_.roi_bins);
            return draw_next(s);
        }
        if (a_.rotation >= 0 && k > a_.rotation) {
            return true; // after the rotation drawn: only counted
        }
        const size_t slot = a_.rotation >= 0 ? 0U : ring_next_++ % ring_cap_;
        if (slot >= ring_.size()) {
            ring_.emplace_back();
        }
        Shot &s = ring_[slot];
        s.index = k;
        core_.step(fr, s.targets);
        if (a_.rotation < 0 || k == a_.rotation) {
            core_.occupied(s.occ);
            s.frame = std::move(fr);
        }
        return true;
    }

    RotationView view_of(const Shot &s) const
    {
        RotationView rv;
        rv.frame = &s.frame;
        rv.index = s.index;
        rv.count = std::max(0, count_);
        rv.occ = s.occ;
        rv.targets = s.targets;
        if (static_cast<int>(s.frame.rotation) < static_cast<int>(truth_.size())) {
            rv.truth = truth_[s.frame.rotation];
        }
        if (s.index < static_cast<int>(tilt_.size())) {
            rv.tilt = tilt_[static_cast<size_t>(s.index)];
        }
        return rv;
    }

    /// --all: one more video frame or PNG.
    bool draw_next(const Shot &s)
    {
        const RotationView rv = view_of(s);
        cv::Mat img = render(sc_, rv);
        progress_.update(static_cast<long long>(s.index + 1), static_cast<long long>(std::max(0, count_)),
                         video_ ? "video frame" : "picture");
        if (video_) {
            if (!vw_.isOpened()) {
                video_path_ = a_.out;
                if (ends_with(a_.out, ".mp4")) {
                    vw_.open(video_path_, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), a_.fps, img.size());
                }
                if (!vw_.isOpened()) {
                    const std::string base = a_.out.substr(0, a_.out.rfind('.'));
                    video_path_ = base + ".avi";
                    vw_.open(video_path_, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), a_.fps, img.size());
                    if (ends_with(a_.out, ".mp4")) {
                        video_note_ = " (mp4 writer unavailable in this OpenCV build: wrote MJPG .avi)";
                    }
                }
                if (!vw_.isOpened()) {
                    return fail("cannot open a video writer for " + a_.out);
                }
            }
            vw_.write(img);
            written_++;
            return true;
        }
        char b[32];
        std::snprintf(b, sizeof b, "_%04d.png", s.index);
        const std::string path = a_.out.substr(0, a_.out.size() - 4) + b;
        if (!cv::imwrite(path, img, {cv::IMWRITE_PNG_COMPRESSION, 9})) {
            return fail("cannot write " + path);
        }
        written_++;
        return true;
    }

    /// --rotation K: the picture, and one line per target with the truth of the nearest pole
    /// (within 3 azimuths).
    int write_one(const Shot &s)
    {
        const RotationView rv = view_of(s);
        cv::Mat img = render(sc_, rv);
        if (!cv::imwrite(a_.out, img, {cv::IMWRITE_PNG_COMPRESSION, 9})) {
            std::fprintf(stderr, "sl-view: cannot write %s\n", a_.out.c_str());
            return 1;
        }
        const int A = drawn_.azimuths;
        std::printf("sl-view: wrote %s (rotation %d of %d = --rotation %d, %zu detections)\n", a_.out.c_str(),
                    s.index + 1, count_, s.index, rv.targets.size());
        for (size_t i = 0; i < rv.targets.size(); i++) {
            const sl_target_t &t = rv.targets[i];
            const TruthMark *best = nullptr;
            int best_d = 4;
            for (const auto &m : rv.truth) {
                const int d = std::abs(((m.az - t.az) % A + A + A / 2) % A - A / 2);
                if (d < best_d) {
                    best_d = d;
                    best = &m;
                }
            }
            std::printf("sl-view: target %c az %u r1 %.3f r2 %.3f m alpha %s", 'A' + static_cast<int>(i % 26), t.az,
                        t.r1_um * 1e-6, t.r2_um * 1e-6,
                        t.incline_flag == SL_INCLINE_VALID ? fmt("%+.2f", t.alpha_cdeg / 100.0).c_str()
                                                           : flag_name(t.incline_flag));
            if (best) {
                std::printf(" truth %s %+.2f", best->name.c_str(), best->alpha_deg);
            }
            std::printf("\n");
        }
        return 0;
    }

    const Args &a_;
    Scene &sc_;
    const std::vector<std::vector<TruthMark>> &truth_;
    const std::vector<std::vector<slv::TiltMark>> &tilt_;
    sl::Progress progress_;
    int board_n_ = 16;
    bool video_ = false;
    int count_ = 0;            ///< rotations in the capture (0: not known yet)
    sl::FrameSet known_;       ///< --all from a file: the first pass's FrameSet
    sl::FrameSet drawn_;       ///< what the pictures are drawn with (Scene::fs)
    int received_ = 0, index_ = 0;
    bool started_ = false;
    std::vector<sl::RadarFrame> window_;
    sl::RadarFrame first_;
    CoreRun core_;
    std::vector<Shot> ring_;   ///< --rotation K >= 0: rotation K; K < 0: the last -K
    size_t ring_cap_ = 1, ring_next_ = 0;
    cv::VideoWriter vw_;
    std::string video_path_, video_note_;
    int written_ = 0;
    std::string err_;
};

} // namespace

int main(int argc, char **argv)
{
    Args a;
    const int info = sl_cli_info(argc, argv, "sl-view", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    static const char *const with_value[] = {"--board", "--out", "--truth", "--calib", "--calibration", "--motion",
                                             "--elongation", "--title", "--rotation", "--roi-m",
                                             "--vmax", "--fps", "--bin-size-m", "--mask-frames",
                                             "--threshold"};
    for (int i = 1; i < argc; i++) {
        const std::string o = argv[i];
        const bool has = i + 1 < argc;
        auto numv = [&](double &v) {
            if (!has) return false;
            char *e = nullptr;
            v = std::strtod(argv[i + 1], &e);
            if (e == argv[i + 1] || *e != '\0') return false;
            i++;
            return true;
        };
        double v = 0;
        if (o == "--board" && has) {
            a.board = argv[++i];
        } else if (o == "--out" && has) {
            a.out = argv[++i];
        } else if (o == "--truth" && has) {
            a.truth = argv[++i];
        } else if (o == "--calib" && has) {
            a.calib = argv[++i];
        } else if (o == "--calibration" && has) {
            a.calibration = argv[++i];
        } else if (o == "--elongation" && has) {
            a.elongation = argv[++i];
        } else if (o == "--title" && has) {
            a.title = argv[++i];
        } else if (o == "--all") {
            a.all = true;
        } else if (o == "--quiet" || o == "-q") {
            a.quiet = true;
        } else if (o == "--rotation" && numv(v)) {
            a.rotation = static_cast<int>(v);
        } else if (o == "--roi-m" && numv(v) && v > 0.5) {
            a.roi_m = v;
        } else if (o == "--vmax" && numv(v) && v > 0) {
            a.vmax = v;
        } else if (o == "--fps" && numv(v) && v > 0) {
            a.fps = v;
        } else if (o == "--bin-size-m" && numv(v) && v > 0) {
            a.bin_size_m = v;
        } else if (o == "--mask-frames" && numv(v) && v >= 1 && v <= SL_CFG_MASK_FRAMES_MAX) {
            a.mask_frames = static_cast<int>(v);
        } else if (o == "--threshold" && numv(v) && v >= 0 && v <= 255) {
            a.threshold = static_cast<int>(v);
        } else if (o == "--motion" && has) {
            const char *s = argv[++i];
            char *end = nullptr;
            a.motion_v = std::strtod(s, &end);
            if (end != s && *end == ',') {
                const char *s2 = end + 1;
                a.motion_w = std::strtod(s2, &end);
                if (end == s2) end = const_cast<char *>(s);
            }
            if (end == s || *end != '\0' || !std::isfinite(a.motion_v) || !std::isfinite(a.motion_w)) {
                return sl_cli_bad_value("sl-view", "--motion", "must be V or V,W (m/s, deg/s)", usage);
            }
            a.motion = true;
        } else if ((o[0] != '-' || o == "-") && a.input.empty()) {
            a.input = o;
        } else {
            for (const char *known : with_value) {
                if (o == known) {
                    return sl_cli_bad_value("sl-view", known, has ? "bad value" : "needs a value",
                                            usage);
                }
            }
            return sl_cli_unknown("sl-view", argv[i], usage);
        }
    }
    if (a.input.empty()) {
        return sl_cli_usage_error("sl-view", "missing CAPTURE|OXFORD_DIR", usage);
    }
    if (a.board.empty()) {
        return sl_cli_usage_error("sl-view", "missing --board NAME", usage);
    }
    if (a.out.empty()) {
        return sl_cli_usage_error("sl-view", "missing --out FILE", usage);
    }
    if (a.motion && is_stream(a.input)) {
        // The pipeline pass of --motion and the pictures' pass each read the capture.
        return sl_cli_usage_error(
            "sl-view", "--motion reads the capture twice: give a file, not stdin, a pipe or a FIFO", usage);
    }
    Scene sc;
    try {
        sc.board = sl::load_board(a.board);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sl-view: %s\n", e.what());
        return 1;
    }
    sc.core_board = sl_board_find(sc.board.name.c_str());
    if (!a.calibration.empty()) {
        // --calibration: the detector runs on the board's calibrated view (INI or blob).
        try {
            sc.core_board = sl::core_board(sc.board.name, a.calibration);
        } catch (const std::exception &e) {
            std::fprintf(stderr, "sl-view: %s\n", e.what());
            return 1;
        }
    }
    // --elongation: the detector runs on a copy of the linked board with this d(r) table
    // (the calibration loop without regenerating the board tables).
    sl_board_t board_copy{};
    if (!a.elongation.empty()) {
        if (sc.core_board == nullptr) {
            std::fprintf(stderr, "sl-view: --elongation needs a board linked into the core\n");
            return 1;
        }
        board_copy = *sc.core_board;
        std::string e;
        if (!read_elongation(a.elongation, board_copy, e)) {
            std::fprintf(stderr, "sl-view: %s\n", e.c_str());
            return 1;
        }
        sc.core_board = &board_copy;
        sc.elong_note = " (d from " + a.elongation.substr(a.elongation.find_last_of('/') + 1) + ")";
    }
    // Frames.
    sl::FrameOptions fo;
    fo.azimuths = sc.board.azimuths;
    fo.encoder_size = sc.board.encoder_size;
    fo.roi_bins = std::min(sc.board.roi_bins, SL_CFG_ROI_BINS);
    fo.bin_size_m = a.bin_size_m;
    // An Oxford folder has no bin size of its own: the board's (or --bin-size-m).
    {
        const bool dir = [&] {
            FILE *f = std::fopen((a.input + "/.").c_str(), "r");
            if (f) std::fclose(f);
            return f != nullptr;
        }();
        if (dir && fo.bin_size_m <= 0) {
            fo.bin_size_m = sc.board.bin_size_m;
        }
    }
    std::string err;
    sc.threshold = a.threshold >= 0 ? a.threshold : sc.board.threshold;
    // Default title: the input's file name, never the path of the machine it was made on.
    sc.title = a.title.empty() ? "sl-view  " + std::filesystem::path(a.input).filename().string()
                               : a.title;
    // Truth.
    std::vector<std::vector<TruthMark>> truth_by_rot;
    if (!a.truth.empty()) {
#ifdef SL_HAVE_SIM_TRUTH
        std::vector<sl::GtRow> rows;
        if (!sl::gt_read(a.truth, rows, err)) {
            std::fprintf(stderr, "sl-view: %s\n", err.c_str());
            return 1;
        }
        for (const auto &r : rows) {
            if (!r.nominal || r.rotation < 0) continue;
            if (static_cast<int>(truth_by_rot.size()) <= r.rotation) truth_by_rot.resize(r.rotation + 1);
            TruthMark t;
            t.name = r.pole_name;
            t.az = r.azimuth;
            t.r1_m = r.r1_m;
            t.r2_m = r.r2_m;
            t.alpha_deg = r.alpha_deg;
            t.valid = r.valid != 0;
            truth_by_rot[r.rotation].push_back(t);
        }
        sc.truth_note = "truth: " + a.truth.substr(a.truth.find_last_of('/') + 1) + " (nominal azimuth per pole; alpha = in-plane inclination, > 0 towards the radar)";
#else
        std::fprintf(stderr, "sl-view: this build has no simulator truth reader (sim_truth.cpp)\n");
        return 1;
#endif
    }
    // --motion: the whole core pipeline with that motion, for the fitted 3D tilt (a first
    // pass over the file).
    std::vector<std::vector<slv::TiltMark>> tilt_by_rot;
    if (a.motion) {
        if (sc.core_board == nullptr) {
            std::fprintf(stderr, "sl-view: --motion needs a board linked into the core\n");
            return 1;
        }
        if (!slv::tilt_marks(a.input, sc.core_board, a.motion_v, a.motion_w, tilt_by_rot, err)) {
            std::fprintf(stderr, "sl-view: --motion: %s\n", err.c_str());
            return 1;
        }
    }
    Viewer view(a, sc, truth_by_rot, tilt_by_rot);
    if (a.all && !is_stream(a.input)) {
        // --all from a file: a first pass counts the rotations (drawn on every picture) and
        // finds the crop of short rows; nothing is kept.
        sl::FrameSet first;
        if (!sl::for_each_frame(a.input, fo, first, [](sl::RadarFrame &, const sl::FrameSet &) { return true; },
                                err)) {
            std::fprintf(stderr, "sl-view: %s\n", err.c_str());
            return 1;
        }
        view.know(first);
    }
    // The core's mask and detector over the rotations in order, each rotation drawn as it
    // comes (--all) or the one asked for kept (--rotation).
    sl::FrameSet fs;
    const bool ok = sl::for_each_frame(
        a.input, fo, fs, [&](sl::RadarFrame &fr, const sl::FrameSet &meta) { return view.on_frame(fr, meta); },
        err);
    if (view.failed()) {
        std::fprintf(stderr, "sl-view: %s\n", view.error().c_str());
        return 1;
    }
    if (!ok) {
        std::fprintf(stderr, "sl-view: %s\n", err.c_str());
        return 1;
    }
    const int rc = view.finish(fs);
    if (rc != 0) {
        return rc;
    }
    if (!sc.detect_note.empty()) std::printf("sl-view: note: %s\n", sc.detect_note.c_str());
    if (!sc.mask_note.empty()) std::printf("sl-view: note: mask n = %d%s\n", sc.mask_n, sc.mask_note.c_str());
    return 0;
}
