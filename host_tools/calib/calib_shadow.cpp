// SPDX-License-Identifier: MIT
// calib_shadow.cpp: per-azimuth shadow calibration (see calib_shadow.h).
#include "calib_shadow.h"

#include <ini.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace sl {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

double quantile(std::vector<double> v, double q)
{
    if (v.empty()) {
        return kNaN;
    }
    std::sort(v.begin(), v.end());
    const double pos = q * (v.size() - 1);
    const size_t i = static_cast<size_t>(pos);
    const double f = pos - i;
    return (i + 1 < v.size()) ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

double median(std::vector<double> v) { return quantile(std::move(v), 0.5); }

/// Position (in bins, bin-centre coordinates: bin k is at k + 0.5) where the profile crosses
/// `level` between bins k - 1 and k (p[k-1] < level <= p[k] or the reverse).
double cross_at(const float *p, int k, double level)
{
    const double a = p[k - 1], b = p[k];
    const double f = (b != a) ? (level - a) / (b - a) : 0.5;
    return (k - 1) + 0.5 + std::clamp(f, 0.0, 1.0);
}

void smooth_row(const double *in, float *out, int n, int s)
{
    for (int k = 0; k < n; k++) {
        double acc = 0;
        int c = 0;
        for (int j = std::max(0, k - s); j <= std::min(n - 1, k + s); j++) {
            acc += in[j];
            c++;
        }
        out[k] = static_cast<float>(acc / c);
    }
}

struct Found {
    bool ok = false;
    double pos_bins = 0; // crossing position (bin coordinates)
    int k = 0;           // first bin at or above the level
};

/// Largest value of p over [k0, k1].
double max_in(const float *p, int k0, int k1, int *at = nullptr)
{
    double m = -1e30;
    for (int k = std::max(0, k0); k <= k1; k++) {
        if (p[k] > m) {
            m = p[k];
            if (at) {
                *at = k;
            }
        }
    }
    return m;
}

} // namespace

ShadowAccumulator::ShadowAccumulator(int azimuths, int bins, int az_half_window)
    : A_(azimuths), K_(bins), w_(std::max(0, az_half_window)),
      sum_(static_cast<size_t>(std::max(0, azimuths)) * std::max(0, bins), 0.0),
      cnt_(static_cast<size_t>(std::max(0, azimuths)), 0),
      wm_(sum_.size(), 0.0), wm2_(sum_.size(), 0.0), wn_(cnt_.size(), 0)
{
    if (azimuths <= 0 || bins <= 0) {
        throw std::invalid_argument("ShadowAccumulator: azimuths and bins must be > 0");
    }
}

void ShadowAccumulator::add(const cv::Mat &frame, const std::vector<uint8_t> &valid)
{
    if (frame.rows != A_ || frame.cols != K_ || frame.type() != CV_8U) {
        throw std::invalid_argument("calibrate_shadow: frames differ in shape or type");
    }
    auto is_valid = [&](int a) {
        return valid.empty() || (a < static_cast<int>(valid.size()) && valid[a] != 0);
    };
    const int A = A_, K = K_, w = w_;
    for (int a = 0; a < A; a++) {
        if (!is_valid(a)) {
            continue;
        }
        cnt_[a]++;
        const uint8_t *row = frame.ptr<uint8_t>(a);
        double *sr = &sum_[static_cast<size_t>(a) * K];
        for (int k = 0; k < K; k++) {
            sr[k] += row[k];
        }
    }
    // Band stability in time: per azimuth and bin, the window's mean of this rotation,
    // summed and squared across rotations (estimate() takes std/mean over its band).
    for (int a = 0; a < A; a++) {
        int na = 0;
        for (int j = -w; j <= w; j++) {
            na += is_valid(((a + j) % A + A) % A) ? 1 : 0;
        }
        if (na == 0) {
            continue;
        }
        wn_[a]++;
        double *m = &wm_[static_cast<size_t>(a) * K], *m2 = &wm2_[static_cast<size_t>(a) * K];
        for (int kk = 1; kk < K; kk++) {
            double acc = 0;
            for (int j = -w; j <= w; j++) {
                const int aa = ((a + j) % A + A) % A;
                if (is_valid(aa)) {
                    acc += frame.ptr<uint8_t>(aa)[kk];
                }
            }
            const double v = acc / na;
            m[kk] += v;
            m2[kk] += v * v;
        }
    }
    frames_++;
}

ShadowCalib calibrate_shadow(const std::vector<cv::Mat> &frames,
                             const std::vector<std::vector<uint8_t>> &valid,
                             const ShadowCalibOptions &opt)
{
    if (frames.empty()) {
        throw std::invalid_argument("calibrate_shadow: no frames");
    }
    if (!valid.empty() && valid.size() != frames.size()) {
        throw std::invalid_argument("calibrate_shadow: valid[] does not match frames");
    }
    ShadowAccumulator acc(frames[0].rows, frames[0].cols, opt.az_half_window);
    static const std::vector<uint8_t> all;
    for (size_t f = 0; f < frames.size(); f++) {
        acc.add(frames[f], valid.empty() ? all : valid[f]);
    }
    return acc.estimate(opt);
}

ShadowCalib ShadowAccumulator::estimate(const ShadowCalibOptions &opt, int bins) const
{
    if (frames_ == 0) {
        throw std::invalid_argument("calibrate_shadow: no frames");
    }
    if (!(opt.radar_height_m > 0) || !(opt.bin_size_m > 0)) {
        throw std::invalid_argument("calibrate_shadow: radar height and bin size must be > 0");
    }
    if (std::max(0, opt.az_half_window) != w_) {
        throw std::invalid_argument("calibrate_shadow: az_half_window differs from the accumulator's");
    }
    const int A = A_, N = frames_, KS = K_;
    const int K = bins > 0 ? std::min(bins, K_) : K_;
    const double b = opt.bin_size_m, H = opt.radar_height_m;
    const int w = w_, s = std::max(0, opt.range_smooth_bins);
    ShadowCalib c;
    c.opt = opt;
    c.frames = N;
    c.azimuths = A;
    c.bins = K;
    const std::vector<int> &cnt = cnt_;
    auto sum_at = [&](int a, int k) { return sum_[static_cast<size_t>(a) * KS + k]; };
    c.mean = cv::Mat(A, K, CV_32F, cv::Scalar(0));
    cv::Mat single(A, K, CV_32F, cv::Scalar(0)); // range-smoothed single-azimuth means
    cv::Mat raw(A, K, CV_32F, cv::Scalar(0));    // windowed, not range-smoothed
    c.profile = cv::Mat(A, K, CV_32F, cv::Scalar(0));
    std::vector<double> tmp(K);
    for (int a = 0; a < A; a++) {
        for (int k = 0; k < K; k++) {
            tmp[k] = cnt[a] ? sum_at(a, k) / cnt[a] : 0.0;
            c.mean.at<float>(a, k) = static_cast<float>(tmp[k]);
        }
        smooth_row(tmp.data(), single.ptr<float>(a), K, s);
        std::fill(tmp.begin(), tmp.end(), 0.0);
        int n = 0;
        for (int j = -w; j <= w; j++) {
            const int aa = ((a + j) % A + A) % A;
            n += cnt[aa];
            for (int k = 0; k < K; k++) {
                tmp[k] += sum_at(aa, k);
            }
        }
        for (int k = 0; k < K; k++) {
            tmp[k] = n ? tmp[k] / n : 0.0;
            raw.at<float>(a, k) = static_cast<float>(tmp[k]);
        }
        smooth_row(tmp.data(), c.profile.ptr<float>(a), K, s);
    }

    const int kmax = std::min(K - 1, static_cast<int>(opt.search_max_m / b));
    const int knear = std::max(1, std::min(kmax, static_cast<int>(opt.near_search_m / b)));
    const int confirm = std::max(2, static_cast<int>(std::lround(opt.confirm_m / b)));
    const int gwin = std::max(2, static_cast<int>(std::lround(opt.ground_window_m / b)));
    auto to_m = [&](double pos_bins) { return pos_bins * b; };

    c.az.resize(A);
    for (int a = 0; a < A; a++) {
        ShadowAz &r = c.az[a];
        r = ShadowAz{};
        r.az = a;
        r.theta_deg = r.theta_raw_deg = r.ground_start_m = r.ground_foot_m = r.ground_half_m =
            r.ground_radius_m = kNaN;
        const float *p = c.profile.ptr<float>(a);
        const float *pr = raw.ptr<float>(a);
        const float *p1 = single.ptr<float>(a);
        int kpk = 1;
        const double P = max_in(p, 1, knear, &kpk);
        double F = 1e30;
        for (int k = kpk; k <= kmax; k++) {
            F = std::min(F, static_cast<double>(p[k]));
        }
        r.near_peak_level = P;
        r.core_level = F;
        if (P - F < opt.min_ring_contrast) {
            r.reason = "no dark ring";
            continue;
        }
        // Near-field band end: half fall.
        const double half = F + 0.5 * (P - F);
        int k = kpk + 1;
        while (k <= kmax && p[k] >= half) {
            k++;
        }
        r.near_end_m = to_m(cross_at(p, k, half));
        // Band stability in time: median over its bins of std/mean across frames (window).
        {
            std::vector<double> cvs;
            const int kend = std::min(k, K);
            const int nf = wn_[a];
            for (int kk = 1; kk < kend; kk++) {
                double m = wm_[static_cast<size_t>(a) * KS + kk], m2 = wm2_[static_cast<size_t>(a) * KS + kk];
                if (nf > 1 && m > 0) {
                    m /= nf;
                    const double var = std::max(0.0, m2 / nf - m * m);
                    cvs.push_back(std::sqrt(var) / m);
                }
            }
            r.near_cv = cvs.empty() ? kNaN : median(cvs);
        }
        // Core: first bin after the band within 15 % of (P - F) of the floor.
        const double core_lvl = F + 0.15 * (P - F);
        const int core_len = std::max(1, static_cast<int>(std::lround(opt.min_core_m / b)));
        int kc = k;
        for (; kc <= kmax; kc++) {
            int n = 0;
            while (kc + n <= kmax && n < core_len && p[kc + n] <= core_lvl) {
                n++;
            }
            if (n >= core_len) {
                break;
            }
        }
        if (kc >= kmax) {
            r.reason = "no dark ring";
            continue;
        }
        r.core_m = to_m(kc + 0.5);
        // Noise of the dark core: robust sigma of the unsmoothed profile from its first
        // differences over the next 0.5 m (MAD / 0.6745 / sqrt 2; insensitive to a slope).
        double sigma = 0;
        {
            std::vector<double> v;
            for (int kk = kc + 1; kk <= std::min(kmax, kc + static_cast<int>(0.5 / b)); kk++) {
                v.push_back(std::fabs(pr[kk] - pr[kk - 1]));
            }
            if (v.size() > 2) {
                sigma = median(v) / 0.6745 / std::sqrt(2.0);
            }
        }
        const double d0 = std::max(opt.min_ground_contrast, 4.0 * sigma);
        r.rise_level = d0;
        // Inner edge: walking inwards from the core, last bin above Li.
        const double li = F + std::max(opt.min_ground_contrast, 0.1 * (P - F));
        int ki = kc;
        while (ki > kpk && p[ki] <= li) {
            ki--;
        }
        r.inner_edge_m = to_m(ki + 1 <= kc ? cross_at(p, ki + 1, li) : kc + 0.5);
        // Ground foot: the first bin after the core whose unsmoothed level reaches F + d0 and
        // that starts a confirmed rise (>= 90 % of the next confirm_m stays >= F + d0 / 2).
        // A rise that falls back is a return inside the ring: remembered, skipped.
        int kf = -1;
        double bright_m = 0, bright_lvl = 0;
        for (int kk = kc + 1; kk <= kmax; kk++) {
            if (pr[kk] < F + d0) {
                continue;
            }
            const int end = std::min(kmax, kk + confirm);
            int up = 0, run = 0;
            bool in_run = true;
            for (int j = kk; j <= end; j++) {
                const bool hi = p[j] >= F + 0.5 * d0;
                up += hi ? 1 : 0;
                if (in_run && hi) {
                    run++;
                } else {
                    in_run = false;
                }
            }
            if (up >= 0.9 * (end - kk + 1) && end - kk >= confirm / 2) {
                kf = kk;
                break;
            }
            int at = kk;
            const double m = max_in(pr, kk, kk + std::max(0, run - 1), &at);
            if (m - F > bright_lvl) {
                bright_lvl = m - F;
                bright_m = to_m(at + 0.5);
            }
            kk += std::max(0, run - 1);
        }
        if (kf < 0) {
            r.reason = "no ground edge";
            continue;
        }
        // Per-azimuth refinement: the window's foot is the earliest foot of the neighbouring
        // azimuths (biased short where S changes fast with azimuth); look again on this
        // azimuth's own mean within +-refine_bins of it.
        if (opt.refine_bins > 0) {
            const float *m1 = c.mean.ptr<float>(a);
            const int lo = std::max(kc + 1, kf - opt.refine_bins);
            const int hi = std::min(kmax - 1, kf + opt.refine_bins);
            std::vector<double> dv, fl;
            for (int kk = kc + 1; kk < lo && kk <= kc + static_cast<int>(0.5 / b); kk++) {
                dv.push_back(std::fabs(m1[kk] - m1[kk - 1]));
                fl.push_back(m1[kk]);
            }
            if (dv.size() > 4) {
                const double s1 = median(dv) / 0.6745 / std::sqrt(2.0);
                const double f1 = median(fl);
                const double d1 = std::max(opt.min_ground_contrast, 4.0 * s1);
                for (int kk = lo; kk <= hi; kk++) {
                    if (m1[kk] >= f1 + d1 && m1[kk + 1] >= f1 + 0.5 * d1) {
                        kf = kk;
                        break;
                    }
                }
            }
        }
        // Where ground returns start: the centre of the first ground bin (partly filled bins
        // count, as the half-bin rule for targets). The half rise uses the ground level G =
        // max of the smoothed profile over the first ground_window_m after the foot.
        const double S = to_m(kf + 0.5);
        r.ground_foot_m = S;
        r.ground_start_m = S;
        r.ground_level = max_in(p, kf, std::min(kmax, kf + gwin));
        const double G = r.ground_level;
        {
            const double L = F + 0.5 * (G - F);
            int kh = std::max(kc + 1, kf - 2);
            while (kh <= kmax && p[kh] < L) {
                kh++;
            }
            r.ground_half_m = kh <= kmax ? to_m(cross_at(p, kh, L)) : kNaN;
        }
        const double Suse = opt.edge_half_rise ? r.ground_half_m : S;
        r.ground_start_m = Suse;
        if (std::isfinite(Suse) && Suse > H) {
            r.ground_radius_m = std::sqrt(Suse * Suse - H * H);
            r.theta_raw_deg = std::asin(H / Suse) * 180.0 / kPi;
        }
        if (G - F < opt.min_ground_contrast) {
            r.reason = "no ground edge";
            continue;
        }
        // Bright return inside the ring: the strongest skipped rise, or on the single-azimuth
        // profile any bin between the first dark bin past the inner edge and the foot.
        {
            int kk = std::max(kpk, static_cast<int>(r.inner_edge_m / b));
            while (kk < kf && p[kk] > li) {
                kk++;
            }
            for (; kk < kf - 1; kk++) {
                if (p1[kk] - F > opt.single_az_factor * opt.bright_min &&
                    p1[kk] - F > bright_lvl) {
                    bright_lvl = p1[kk] - F;
                    bright_m = to_m(kk + 0.5);
                }
            }
        }
        r.bright_inside_m = bright_m;
        r.bright_level = bright_lvl;
        if (bright_lvl > opt.bright_min) {
            r.reason = "bright return inside the ring";
            continue;
        }
        if (!(Suse > H)) {
            r.reason = "ground start within the radar height";
            continue;
        }
        if (r.theta_raw_deg > opt.max_theta_deg) {
            r.reason = "steeper than the beam's lower bound";
            continue;
        }
        r.usable = true;
        r.theta_deg = r.theta_raw_deg;
    }
    // Outliers against the local median of usable neighbours.
    std::vector<bool> out(A, false);
    for (int a = 0; a < A; a++) {
        if (!c.az[a].usable) {
            continue;
        }
        std::vector<double> v;
        for (int j = -opt.outlier_half_window; j <= opt.outlier_half_window; j++) {
            const int aa = ((a + j) % A + A) % A;
            if (j != 0 && c.az[aa].usable) {
                v.push_back(c.az[aa].theta_deg);
            }
        }
        if (v.size() >= 3 && std::fabs(c.az[a].theta_deg - median(v)) > opt.outlier_deg) {
            out[a] = true;
        }
    }
    for (int a = 0; a < A; a++) {
        if (out[a]) {
            c.az[a].usable = false;
            c.az[a].theta_deg = kNaN;
            c.az[a].reason = "outlier";
        }
        c.usable_count += c.az[a].usable ? 1 : 0;
    }
    // Sectors of unusable azimuths (wrap-aware).
    if (c.usable_count == 0) {
        c.unusable.push_back({0, A, "no usable azimuth"});
        std::map<std::string, int> votes;
        for (const auto &r : c.az) votes[r.reason]++;
        int best = -1;
        for (const auto &kv : votes) {
            if (kv.second > best) {
                best = kv.second;
                c.unusable.back().reason = kv.first;
            }
        }
    } else {
        int start = 0;
        while (!c.az[start].usable) {
            start = (start + 1) % A; // start on a usable azimuth so runs do not split at 0
        }
        for (int i = 1; i <= A; i++) {
            const int a = (start + i) % A;
            if (c.az[a].usable) {
                continue;
            }
            ShadowSector sec;
            sec.az_first = a;
            std::map<std::string, int> votes;
            while (!c.az[(sec.az_first + sec.az_count) % A].usable) {
                votes[c.az[(sec.az_first + sec.az_count) % A].reason]++;
                sec.az_count++;
            }
            int best = -1;
            for (const auto &kv : votes) {
                if (kv.second > best) {
                    best = kv.second;
                    sec.reason = kv.first;
                }
            }
            c.unusable.push_back(sec);
            i += sec.az_count - 1;
        }
    }
    return c;
}

namespace {

std::string fmt(double v, int prec)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", prec, v);
    return buf;
}

/// "key = a, b, c" wrapped into continuation lines of `per_line` items (inih's 200-char
/// line limit; inih passes continuation lines to the handler as repeats of the key).
std::string wrapped(const std::string &key, const std::vector<std::string> &items, int per_line)
{
    std::string s = key + " =";
    for (size_t i = 0; i < items.size(); i++) {
        if (i > 0 && i % per_line == 0) {
            s += "\n   ";
        }
        s += " " + items[i] + (i + 1 < items.size() ? "," : "");
    }
    return s + "\n";
}

} // namespace

std::string shadow_calib_ini(const ShadowCalib &c, const std::string &board,
                             const std::string &source,
                             const std::vector<double> &board_theta_deg)
{
    std::ostringstream o;
    o << "; sl-calib shadow: chassis shadow measured from " << c.frames << " rotations of\n"
      << ";   " << source << "\n"
      << "; Format (host_tools/calib/README.md): per azimuth index 'az:value'; azimuths not\n"
      << "; listed in theta_table are unusable (see 'unusable'). Ranges are slant ranges (m),\n"
      << "; theta = asin(H / ground_start) = atan(H / R), R the horizontal radius.\n"
      << "[calib]\n"
      << "board = " << board << "\n"
      << "frames = " << c.frames << "\n"
      << "azimuths = " << c.azimuths << "\n"
      << "radar_height_m = " << fmt(c.opt.radar_height_m, 4) << "\n"
      << "bin_size_m = " << fmt(c.opt.bin_size_m, 5) << "\n"
      << "az_half_window = " << c.opt.az_half_window << "\n"
      << "usable_azimuths = " << c.usable_count << "\n";
    std::vector<std::string> th, gs, ne, bt;
    for (const auto &r : c.az) {
        if (r.usable) {
            th.push_back(std::to_string(r.az) + ":" + fmt(r.theta_deg, 2));
        }
        if (std::isfinite(r.ground_start_m)) {
            gs.push_back(std::to_string(r.az) + ":" + fmt(r.ground_start_m, 3));
        }
        if (r.near_end_m > 0) {
            ne.push_back(std::to_string(r.az) + ":" + fmt(r.near_end_m, 3));
        }
        if (r.az < static_cast<int>(board_theta_deg.size()) &&
            std::isfinite(board_theta_deg[r.az])) {
            bt.push_back(std::to_string(r.az) + ":" + fmt(board_theta_deg[r.az], 2));
        }
    }
    std::vector<std::string> un;
    for (const auto &sct : c.unusable) {
        const int last = (sct.az_first + sct.az_count - 1) % c.azimuths;
        un.push_back(std::to_string(sct.az_first) + "-" + std::to_string(last) + " " +
                     sct.reason);
    }
    o << wrapped("theta_table", th, 10);
    o << wrapped("ground_start_m", gs, 10);
    o << wrapped("near_end_m", ne, 10);
    if (!bt.empty()) {
        o << wrapped("board_theta_table", bt, 10);
    }
    o << wrapped("unusable", un, 3);
    return o.str();
}

namespace {

struct ReadCtx {
    std::map<std::string, std::string> kv;
};

int read_entry(void *user, const char *section, const char *name, const char *value)
{
    auto *c = static_cast<ReadCtx *>(user);
    if (std::string(section) != "calib") {
        return 1;
    }
    std::string &v = c->kv[name];
    if (!v.empty()) {
        v += " ";
    }
    v += value;
    return 1;
}

bool parse_table(const std::string &text, int n, std::vector<double> &out, std::string &err)
{
    out.assign(n, kNaN);
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        const size_t b0 = item.find_first_not_of(" \t");
        if (b0 == std::string::npos) {
            continue;
        }
        item = item.substr(b0);
        const size_t colon = item.find(':');
        char *e1 = nullptr, *e2 = nullptr;
        if (colon == std::string::npos) {
            err = "'" + item + "' is not az:value";
            return false;
        }
        const long az = std::strtol(item.c_str(), &e1, 10);
        const double v = std::strtod(item.c_str() + colon + 1, &e2);
        if (e1 != item.c_str() + colon || az < 0 || az >= n || !std::isfinite(v)) {
            err = "bad entry '" + item + "'";
            return false;
        }
        out[az] = v;
    }
    return true;
}

} // namespace

bool read_shadow_calib(const std::string &path, ShadowCalibFile &out, std::string &err)
{
    ReadCtx c;
    const int rc = ini_parse(path.c_str(), read_entry, &c);
    if (rc != 0) {
        err = path + (rc < 0 ? ": cannot open" : ":" + std::to_string(rc) + ": syntax error");
        return false;
    }
    auto num = [&](const char *k, double &v) {
        auto it = c.kv.find(k);
        if (it == c.kv.end()) {
            return false;
        }
        v = std::strtod(it->second.c_str(), nullptr);
        return true;
    };
    double az = 0;
    if (!num("azimuths", az) || az < 1 || az > 65535 || !num("radar_height_m", out.radar_height_m) ||
        !num("bin_size_m", out.bin_size_m)) {
        err = path + ": [calib] needs azimuths, radar_height_m, bin_size_m";
        return false;
    }
    out.azimuths = static_cast<int>(az);
    std::string e;
    if (!parse_table(c.kv["theta_table"], out.azimuths, out.theta_deg, e) ||
        !parse_table(c.kv["ground_start_m"], out.azimuths, out.ground_start_m, e) ||
        !parse_table(c.kv["near_end_m"], out.azimuths, out.near_end_m, e)) {
        err = path + ": " + e;
        return false;
    }
    return true;
}

} // namespace sl
