// SPDX-License-Identifier: MIT
// calib_elong.cpp: see calib_elong.h.
#include "calib_elong.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "shadowlean/sl_mask.h"
#include "shadowlean/sl_thresh.h"

namespace sl {
namespace {

struct Run {
    int first = 0, last = 0, occupied = 0;
};

std::vector<Run> runs_of(const uint32_t *bits, int bins, int gap)
{
    std::vector<Run> out;
    int k = 0;
    while (k < bins) {
        if (!sl_bits_get(bits, static_cast<uint32_t>(k))) {
            k++;
            continue;
        }
        Run r;
        r.first = r.last = k;
        r.occupied = 0;
        int free_run = 0;
        for (; k < bins; k++) {
            if (sl_bits_get(bits, static_cast<uint32_t>(k))) {
                r.last = k;
                r.occupied++;
                free_run = 0;
            } else if (++free_run > gap) {
                break;
            }
        }
        out.push_back(r);
    }
    return out;
}

} // namespace

ElongMeasurement measure_elongation(const FrameSet &fs, const ElongTruth &t,
                                    const ElongOptions &opt)
{
    ElongMeasurement m;
    m.capture = fs.source;
    m.label = t.label;
    m.rot_first = t.rot_first;
    m.rot_last = t.rot_last;
    m.r1_true_m = t.r1_true_m;
    m.r2_true_m = t.r2_true_m;
    const int A = fs.azimuths, bins = fs.roi_bins;
    const double b = fs.bin_size_m;
    std::vector<const RadarFrame *> fr;
    for (const auto &f : fs.frames) {
        if (static_cast<int>(f.rotation) >= t.rot_first && static_cast<int>(f.rotation) <= t.rot_last) {
            fr.push_back(&f);
        }
    }
    if (fr.empty()) {
        m.why = "no decoded rotation in the truth's range";
        return m;
    }
    m.frames_used = static_cast<int>(fr.size());
    m.mask_n = std::clamp(std::min(opt.mask_frames, m.frames_used), 1, SL_CFG_MASK_FRAMES_MAX);
    auto mask = std::make_unique<sl_mask_t>();
    if (sl_mask_init(mask.get(), static_cast<uint16_t>(A), static_cast<uint16_t>(bins),
                     static_cast<uint8_t>(m.mask_n), SL_MASK_MAX_MISSED_DEFAULT) != SL_OK) {
        m.why = "sl_mask_init failed";
        return m;
    }
    std::vector<uint32_t> bits(SL_ROI_WORDS);
    for (const RadarFrame *f : fr) {
        for (int az = 0; az < A; az++) {
            if (!(f->flags[az] & SL_SCAN_AZ_VALID)) {
                continue;
            }
            sl_thresh_u8(f->power.ptr<uint8_t>(az), static_cast<uint32_t>(bins),
                         static_cast<uint16_t>(opt.threshold), bits.data());
            (void)sl_mask_update(mask.get(), static_cast<uint16_t>(az), bits.data(), nullptr,
                                 nullptr);
        }
        sl_mask_end_rotation(mask.get());
    }
    // Candidates per azimuth.
    const double k1_true = t.r1_true_m / b;
    const double tol = opt.r1_tolerance_m / b;
    struct Cand {
        int az;
        Run r;
    };
    std::vector<Cand> cands;
    std::vector<uint32_t> occ(SL_ROI_WORDS);
    for (int j = 0; j < A; j++) {
        int az = j;
        if (t.az >= 0) {
            if (j > 2 * opt.az_search) {
                break;
            }
            az = ((t.az - opt.az_search + j) % A + A) % A;
        }
        if (!sl_mask_stable(mask.get(), static_cast<uint16_t>(az), occ.data(), nullptr)) {
            continue;
        }
        for (const Run &r : runs_of(occ.data(), bins, opt.gap_bins)) {
            if (r.first < opt.near_exclusion_bins) {
                continue;
            }
            if (std::fabs(r.first + 0.5 - k1_true) <= tol) {
                cands.push_back({az, r});
            }
        }
    }
    if (cands.empty()) {
        m.why = "no stable run starts within " + std::to_string(opt.r1_tolerance_m) +
                " m of the true r1";
        return m;
    }
    // The target's azimuths: candidates whose first bin is nearest r1 (within 2 bins of the
    // best); representative = most occupied bins.
    double best = 1e30;
    for (const auto &c : cands) {
        best = std::min(best, std::fabs(c.r.first + 0.5 - k1_true));
    }
    const Cand *rep = nullptr;
    int count = 0;
    for (const auto &c : cands) {
        if (std::fabs(c.r.first + 0.5 - k1_true) > best + 2) {
            continue;
        }
        count++;
        if (!rep || c.r.occupied > rep->r.occupied ||
            (c.r.occupied == rep->r.occupied && std::fabs(c.r.first + 0.5 - k1_true) <
                                                     std::fabs(rep->r.first + 0.5 - k1_true))) {
            rep = &c;
        }
    }
    m.found = true;
    m.az = rep->az;
    m.az_count = count;
    m.bin_first = rep->r.first;
    m.bin_last = rep->r.last;
    m.r1_m = (rep->r.first + 0.5) * b;
    m.r2_m = (rep->r.last + 0.5) * b;
    m.d_m = m.r2_m - t.r2_true_m;
    m.d_r1_m = m.r1_m - t.r1_true_m;
    return m;
}

ElongTable fit_elongation(const std::vector<ElongMeasurement> &all, int points)
{
    ElongTable t;
    std::vector<const ElongMeasurement *> m;
    for (const auto &x : all) {
        if (x.found) {
            m.push_back(&x);
        }
    }
    t.n = static_cast<int>(m.size());
    if (m.empty()) {
        return t;
    }
    std::sort(m.begin(), m.end(), [](const ElongMeasurement *a, const ElongMeasurement *b) {
        return a->r2_m < b->r2_m;
    });
    double sx = 0, sy = 0, sxx = 0, sxy = 0, sr1 = 0;
    for (const auto *x : m) {
        sx += x->r2_m;
        sy += x->d_m;
        sxx += x->r2_m * x->r2_m;
        sxy += x->r2_m * x->d_m;
        sr1 += x->d_r1_m;
    }
    const double n = static_cast<double>(m.size());
    t.mean_m = sy / n;
    t.mean_d_r1_m = sr1 / n;
    double ss = 0;
    for (const auto *x : m) {
        ss += (x->d_m - t.mean_m) * (x->d_m - t.mean_m);
    }
    t.std_m = m.size() > 1 ? std::sqrt(ss / (n - 1)) : 0;
    const double den = n * sxx - sx * sx;
    if (m.size() > 2 && den > 1e-12) {
        t.slope = (n * sxy - sx * sy) / den;
        t.intercept_m = (sy - t.slope * sx) / n;
        double rs = 0;
        for (const auto *x : m) {
            const double e = x->d_m - (t.intercept_m + t.slope * x->r2_m);
            rs += e * e;
        }
        t.resid_std_m = std::sqrt(rs / (n - 2));
    } else {
        t.intercept_m = t.mean_m;
    }
    int k = points > 0 ? points : static_cast<int>(std::lround(n / 12.0));
    k = std::clamp(k, 1, std::min(8, static_cast<int>(m.size())));
    for (int g = 0; g < k; g++) {
        const size_t i0 = static_cast<size_t>(g * m.size() / k);
        const size_t i1 = static_cast<size_t>((g + 1) * m.size() / k);
        ElongTablePoint p;
        double r = 0, d = 0;
        for (size_t i = i0; i < i1; i++) {
            r += m[i]->r2_m;
            d += m[i]->d_m;
        }
        p.n = static_cast<int>(i1 - i0);
        p.r_m = r / p.n;
        p.d_m = d / p.n;
        double s = 0;
        for (size_t i = i0; i < i1; i++) {
            s += (m[i]->d_m - p.d_m) * (m[i]->d_m - p.d_m);
        }
        p.std_m = p.n > 1 ? std::sqrt(s / (p.n - 1)) : 0;
        p.r_min_m = m[i0]->r2_m;
        p.r_max_m = m[i1 - 1]->r2_m;
        // Keys must ascend strictly at the printed precision (2 decimals).
        if (!t.points.empty() && std::lround(p.r_m * 100) <= std::lround(t.points.back().r_m * 100)) {
            ElongTablePoint &q = t.points.back();
            const int nn = q.n + p.n;
            q.r_m = (q.r_m * q.n + p.r_m * p.n) / nn;
            q.d_m = (q.d_m * q.n + p.d_m * p.n) / nn;
            q.std_m = std::max(q.std_m, p.std_m);
            q.r_max_m = p.r_max_m;
            q.n = nn;
            continue;
        }
        t.points.push_back(p);
    }
    return t;
}

std::string elongation_line(const ElongTable &t)
{
    std::string s = "elongation =";
    for (size_t i = 0; i < t.points.size(); i++) {
        char b[48];
        std::snprintf(b, sizeof b, " %.2f:%.3f%s", t.points[i].r_m, t.points[i].d_m,
                      i + 1 < t.points.size() ? "," : "");
        s += b;
    }
    return s;
}

} // namespace sl
