// SPDX-License-Identifier: MIT
// calib_elong.cpp: see calib_elong.h.
#include "calib_elong.h"

#include <algorithm>
#include <climits>
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

struct ElongStream::Pos {
    ElongTruth t;
    int frames = 0, mask_n = 0;
    bool closed = false, mask_failed = false;
    std::unique_ptr<sl_mask_t> mask;            ///< while the position's rotations arrive
    std::vector<std::vector<uint32_t>> held;    ///< thresholded rows of its first rotations
    std::vector<std::vector<uint8_t>> held_flags; ///< (until the mask's n is known)
    std::vector<int> rows_az;                   ///< the azimuths searched, in search order,
    std::vector<std::vector<uint32_t>> rows;    ///< and their stable rows (empty: none)
};

ElongStream::ElongStream(const std::vector<ElongTruth> &positions, const ElongOptions &opt) : opt_(opt)
{
    for (const ElongTruth &t : positions) {
        pos_.push_back(std::make_unique<Pos>());
        pos_.back()->t = t;
    }
}

ElongStream::~ElongStream() = default;

namespace {

/// n = min(mask_frames, rotations of the position), within the mask's limits.
int mask_n_for(int mask_frames, int frames)
{
    return std::clamp(std::min(mask_frames, frames), 1, SL_CFG_MASK_FRAMES_MAX);
}

void apply_rows(sl_mask_t *mask, const std::vector<uint32_t> &bits, const std::vector<uint8_t> &flags,
                int azimuths)
{
    for (int az = 0; az < azimuths; az++) {
        if (!(flags[static_cast<size_t>(az)] & SL_SCAN_AZ_VALID)) {
            continue;
        }
        (void)sl_mask_update(mask, static_cast<uint16_t>(az), bits.data() + static_cast<size_t>(az) * SL_ROI_WORDS,
                             nullptr, nullptr);
    }
    sl_mask_end_rotation(mask);
}

} // namespace

void ElongStream::start_mask(Pos &p, int n)
{
    p.mask_n = n;
    p.mask = std::make_unique<sl_mask_t>();
    if (sl_mask_init(p.mask.get(), static_cast<uint16_t>(azimuths_), static_cast<uint16_t>(bins_),
                     static_cast<uint8_t>(n), SL_MASK_MAX_MISSED_DEFAULT) != SL_OK) {
        p.mask_failed = true;
        p.mask.reset();
    }
    for (size_t i = 0; i < p.held.size() && p.mask; i++) {
        apply_rows(p.mask.get(), p.held[i], p.held_flags[i], azimuths_);
    }
    p.held.clear();
    p.held_flags.clear();
}

void ElongStream::close(Pos &p)
{
    p.closed = true;
    if (p.frames == 0) {
        return;
    }
    if (!p.mask && !p.mask_failed) {
        start_mask(p, mask_n_for(opt_.mask_frames, p.frames));
    }
    if (!p.mask) {
        return;
    }
    // The stable rows of the azimuths allowed by the truth (all when it has none).
    std::vector<uint32_t> occ(SL_ROI_WORDS);
    for (int j = 0; j < azimuths_; j++) {
        int az = j;
        if (p.t.az >= 0) {
            if (j > 2 * opt_.az_search) {
                break;
            }
            az = ((p.t.az - opt_.az_search + j) % azimuths_ + azimuths_) % azimuths_;
        }
        p.rows_az.push_back(az);
        p.rows.emplace_back();
        if (sl_mask_stable(p.mask.get(), static_cast<uint16_t>(az), occ.data(), nullptr)) {
            p.rows.back() = occ;
        }
    }
    p.mask.reset();
}

void ElongStream::add(const RadarFrame &f, int azimuths)
{
    azimuths_ = azimuths;
    bins_ = f.power.cols;
    const int rot = static_cast<int>(f.rotation);
    bool thresholded = false;
    for (auto &pp : pos_) {
        Pos &p = *pp;
        if (p.closed || rot < p.t.rot_first) {
            continue;
        }
        if (rot > p.t.rot_last) { // rotations arrive in order: the position is complete
            close(p);
            continue;
        }
        if (!thresholded) {
            bits_.assign(static_cast<size_t>(azimuths) * SL_ROI_WORDS, 0);
            for (int az = 0; az < azimuths; az++) {
                if (f.flags[static_cast<size_t>(az)] & SL_SCAN_AZ_VALID) {
                    sl_thresh_u8(f.power.ptr<uint8_t>(az), static_cast<uint32_t>(bins_),
                                 static_cast<uint16_t>(opt_.threshold),
                                 bits_.data() + static_cast<size_t>(az) * SL_ROI_WORDS);
                }
            }
            thresholded = true;
        }
        p.frames++;
        if (p.mask) {
            apply_rows(p.mask.get(), bits_, f.flags, azimuths);
        } else if (!p.mask_failed) {
            p.held.push_back(bits_);
            p.held_flags.push_back(f.flags);
            // Once the position has mask_frames rotations, n is known: no more holding back.
            const int cap = mask_n_for(opt_.mask_frames, INT_MAX);
            if (p.frames >= cap) {
                start_mask(p, cap);
            }
        }
    }
}

std::vector<ElongMeasurement> ElongStream::finish(const FrameSet &fs, const ElongOptions &opt)
{
    std::vector<ElongMeasurement> out;
    for (auto &pp : pos_) {
        Pos &p = *pp;
        if (!p.closed) {
            close(p);
        }
        out.push_back(measure(p, fs, opt));
    }
    return out;
}

ElongMeasurement ElongStream::measure(const Pos &p, const FrameSet &fs, const ElongOptions &opt)
{
    const ElongTruth &t = p.t;
    ElongMeasurement m;
    m.capture = fs.source;
    m.label = t.label;
    m.rot_first = t.rot_first;
    m.rot_last = t.rot_last;
    m.r1_true_m = t.r1_true_m;
    m.r2_true_m = t.r2_true_m;
    // The frames are not cropped: runs end at the capture's widest row, as on cropped frames.
    const int bins = fs.roi_bins;
    const double b = fs.bin_size_m;
    if (p.frames == 0) {
        m.why = "no decoded rotation in the truth's range";
        return m;
    }
    m.frames_used = p.frames;
    m.mask_n = p.mask_n;
    if (p.mask_failed) {
        m.why = "sl_mask_init failed";
        return m;
    }
    // Candidates per azimuth.
    const double k1_true = t.r1_true_m / b;
    const double tol = opt.r1_tolerance_m / b;
    struct Cand {
        int az;
        Run r;
    };
    std::vector<Cand> cands;
    for (size_t i = 0; i < p.rows.size(); i++) {
        if (p.rows[i].empty()) {
            continue;
        }
        for (const Run &r : runs_of(p.rows[i].data(), bins, opt.gap_bins)) {
            if (r.first < opt.near_exclusion_bins) {
                continue;
            }
            if (std::fabs(r.first + 0.5 - k1_true) <= tol) {
                cands.push_back({p.rows_az[i], r});
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

ElongMeasurement measure_elongation(const FrameSet &fs, const ElongTruth &t,
                                    const ElongOptions &opt)
{
    ElongStream st({t}, opt);
    for (const RadarFrame &f : fs.frames) {
        st.add(f, fs.azimuths);
    }
    return st.finish(fs, opt).front();
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
