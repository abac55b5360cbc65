// SPDX-License-Identifier: MIT
// sim_eval.cpp: see sim_eval.h.
#include "sim_eval.h"
#include "calib_board.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_pipeline.h"
#include "sim_geom.h"
#include "sim_render.h"
#include "sl_geom.h"

namespace sl {

// ------------------------------------------------------------------------------------------
// decoding

CaptureRows::CaptureRows(RowFn on_row)
    : on_row_(std::move(on_row)), dec_([this](const sl_proto_msg_t &m) { on_msg(this, &m); })
{
}

void CaptureRows::feed(const uint8_t *data, size_t n) { dec_.feed(data, n); }

void CaptureRows::finish() { dec_.finish(); }

void CaptureRows::on_msg(void *ctx, const sl_proto_msg_t *m)
{
    auto *self = static_cast<CaptureRows *>(ctx);
    if (m->id == SL_PROTO_ID_CONFIGURATION) {
        sl_proto_config_t c;
        if (sl_proto_parse_config(m, &c) == SL_OK) {
            self->cfg_ = c;
            self->cfg_.protobuf = sl_bytes_t{nullptr, 0};
            self->have_cfg_ = true;
            self->bin_um_ = sl_proto_config_bin_size_um(&c);
        }
        return;
    }
    if (m->id != SL_PROTO_ID_FFT_DATA) {
        return;
    }
    sl_proto_fft_t f;
    if (!self->have_cfg_ || sl_proto_parse_fft(m, &f) != SL_OK || self->cfg_.encoder_size == 0) {
        self->bad_fft_++;
        return;
    }
    const long az = std::lround(static_cast<double>(f.azimuth_ticks) * self->cfg_.azimuths /
                                self->cfg_.encoder_size) %
                    std::max<long>(1, self->cfg_.azimuths);
    if (self->rot_ < 0 || az <= self->last_az_) {
        self->rot_++;
    }
    self->last_az_ = static_cast<int>(az);
    self->on_row_(self->rot_, static_cast<int>(az), f.bin_data, f.bins);
}

// ------------------------------------------------------------------------------------------
// extraction

BinRun bbox_run(const double *v, int n, double threshold, int lo_bin, int hi_bin, int want_lo,
                int want_hi, int gap_bins)
{
    BinRun best;
    lo_bin = std::max(0, lo_bin);
    hi_bin = std::min(n - 1, hi_bin);
    int best_ov = -1;
    int i = lo_bin;
    while (i <= hi_bin) {
        if (v[i] < threshold) {
            i++;
            continue;
        }
        int j = i;
        for (;;) {
            int k = j + 1;
            while (k <= hi_bin && v[k] >= threshold) {
                k++;
            }
            j = k - 1;
            // merge across a short gap
            int g = k;
            while (g <= hi_bin && g - k < gap_bins && v[g] < threshold) {
                g++;
            }
            if (g <= hi_bin && g - k <= gap_bins && g > k && v[g] >= threshold) {
                j = g;
                continue;
            }
            break;
        }
        const int ov = std::min(j, want_hi) - std::max(i, want_lo);
        if (ov > best_ov || (ov == best_ov && !best.found)) {
            best_ov = ov;
            best.found = ov >= 0;
            best.i1 = i;
            best.i2 = j;
        }
        i = j + 1;
    }
    if (best_ov < 0) {
        best.found = false;
    }
    return best;
}

namespace {

// Energy of bins [lo, hi] of the planar model, or empty when (r1, r2) has no valid alpha.
std::vector<double> model_bins(const SubbinModel &m, double r1, double r2, int lo, int hi)
{
    int flag = 0;
    const double a_deg = alpha_oracle_deg(r1, r2, m.theta_deg, m.beta_deg, &flag);
    if (flag != SL_INCLINE_VALID) {
        return {};
    }
    const double al = sim_d2r(a_deg), be = sim_d2r(m.beta_deg), th = sim_d2r(m.theta_deg);
    const double p = al >= be ? r1 * std::cos(be - al) : r1;
    const double b = m.bin_m, R = m.radius_m;
    std::vector<double> out(static_cast<size_t>(hi - lo + 1), 0.0);
    const double rlo = lo * b, rhi = (hi + 1) * b + 1.5 * R;
    const double u0 = rlo <= p ? 0.0 : std::acos(std::min(1.0, p / rlo));
    const double u1 = rhi <= p ? 0.0 : std::acos(std::min(1.0, p / rhi));
    if (!(u1 > u0)) {
        return out;
    }
    const double ints[2][2] = {{al + u0, al + u1}, {al - u1, al - u0}};
    for (const auto &iv : ints) {
        const double ea = std::max(iv[0], -th), eb = std::min(iv[1], be);
        if (!(eb > ea)) {
            continue;
        }
        constexpr int N = 96;
        double pr = 0, pre = 0, peps = 0;
        for (int j = 0; j <= N; j++) {
            const double e = ea + (eb - ea) * j / N;
            const double c = std::cos(e - al);
            const double r = p / c;
            const double h = r * std::cos(e);
            const double eps = m.gain(sim_r2d(e)) * 2.0 * sim_r2d(std::asin(std::min(1.0, R / h)));
            const double re = R / c;
            if (j > 0) {
                sim_splat_profile(out, b, pr, r, 0.5 * (pre + re), 0.5 * (peps + eps) * sim_r2d((eb - ea) / N), lo);
            }
            pr = r;
            pre = re;
            peps = eps;
        }
    }
    return out;
}

} // namespace

std::vector<double> subbin_model_bins(const SubbinModel &m, double r1, double r2, int lo, int hi)
{
    return model_bins(m, r1, r2, lo, hi);
}

bool subbin_bounds(const double *v, int n, int i1, int i2, const SubbinModel &m, double *r1p,
                   double *r2p)
{
    const double b = m.bin_m, R = m.radius_m;
    // Thin poles only: a cross-section wider than a quarter bin spreads each edge over
    // several bins, and the edge bin's fill no longer locates the bound (measured: biased).
    if (i2 - i1 < 2 || i1 < 0 || i2 >= n || R > 0.25 * b || v[i1 + 1] <= 0 || v[i2 - 1] <= 0) {
        return false;
    }
    // An edge bin reading 1 may be the detection floor (a touched bin reads >= 1 even when
    // its energy rounds to 0): its value is then anywhere in (0, 1.5); take the middle.
    const double v1 = v[i1] <= 1.0 ? 0.75 : v[i1], v2 = v[i2] <= 1.0 ? 0.75 : v[i2];
    const double obs1 = v1 / v[i1 + 1], obs2 = v2 / v[i2 - 1];
    double r1 = (i1 + 0.5) * b + R, r2 = (i2 + 0.5) * b;
    for (int it = 0; it < 3; it++) {
        // r1: the front edge (axis - R_e) lies in bin i1; E(i1)/E(i1+1) falls as r1 grows
        {
            int flag = 0;
            const double a = alpha_oracle_deg(r1, r2, m.theta_deg, m.beta_deg, &flag);
            if (flag != SL_INCLINE_VALID) {
                return false;
            }
            const double e1 = a >= m.beta_deg ? m.beta_deg : a;
            const double re = R / std::cos(sim_d2r(e1 - a));
            double lo = i1 * b + re, hi = (i1 + 1) * b + re;
            for (int k = 0; k < 26; k++) { // 1 bin / 2^26: < 1 nm
                const double mid = 0.5 * (lo + hi);
                const auto e = model_bins(m, mid, r2, i1, i1 + 1);
                if (e.empty() || e[1] <= 0) {
                    hi = mid;
                    continue;
                }
                if (e[0] / e[1] > obs1) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            r1 = 0.5 * (lo + hi);
        }
        // r2: the silhouette (axis) lies in bin i2; E(i2)/E(i2-1) grows with r2
        {
            double lo = i2 * b, hi = (i2 + 1) * b;
            for (int k = 0; k < 26; k++) {
                const double mid = 0.5 * (lo + hi);
                const auto e = model_bins(m, r1, mid, i2 - 1, i2);
                if (e.empty() || e[0] <= 0) {
                    lo = mid;
                    continue;
                }
                if (e[1] / e[0] < obs2) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            r2 = 0.5 * (lo + hi);
        }
    }
    *r1p = r1;
    *r2p = r2;
    return true;
}

// ------------------------------------------------------------------------------------------
// estimator

double elong_at(const std::vector<ElongPoint> &t, double r)
{
    if (t.empty()) {
        return 0;
    }
    if (r <= t.front().range_m) {
        return t.front().d_m;
    }
    if (r >= t.back().range_m) {
        return t.back().d_m;
    }
    for (size_t i = 1; i < t.size(); i++) {
        if (r <= t[i].range_m) {
            const double f = (r - t[i - 1].range_m) / (t[i].range_m - t[i - 1].range_m);
            return t[i - 1].d_m + f * (t[i].d_m - t[i - 1].d_m);
        }
    }
    return t.back().d_m;
}

Est core_estimate(double r1_m, double r2_m, double theta_deg, double beta_deg, double sigma_r_m,
                  double sigma_theta_deg)
{
    Est e;
    e.extracted = true;
    e.r1_m = r1_m;
    e.r2_m = r2_m;
    const sl_incline_geom_t g = make_geom(theta_deg, beta_deg);
    const auto um = [](double m) {
        return static_cast<uint32_t>(std::clamp(std::llround(m * 1e6), 0LL, 4294967295LL));
    };
    const sl_incline_result_t r =
        sl_incline_estimate(um(r1_m), um(r2_m), &g, um(sigma_r_m),
                            static_cast<uint16_t>(std::lround(sigma_theta_deg * 100)));
    e.flag = r.flag;
    e.amb_bound_deg = 0.5 * (beta_deg - theta_deg);
    e.alpha_deg = static_cast<double>(static_cast<int32_t>(r.alpha_bam32)) * (360.0 / 4294967296.0);
    e.sigma_deg = r.sigma_cdeg / 100.0;
    return e;
}

Est estimate_row(const double *v, int n, const GtRow &gt, const BoardSpec &b, double threshold,
                 int lo_bin, int hi_bin, const Proc &proc, const SubbinModel *sub)
{
    const double bin = b.bin_size_m;
    const int want_lo = static_cast<int>(std::floor(gt.r1_surf_m / bin));
    const int want_hi = static_cast<int>(std::floor(gt.r2_m / bin));
    const BinRun run = bbox_run(v, n, threshold, lo_bin, hi_bin, want_lo, want_hi, proc.gap_bins);
    if (!run.found) {
        return Est{};
    }
    double r1 = run.i1 * bin, r2 = (run.i2 + 1) * bin;
    const double r2_obs = r2;
    bool subbin = false;
    if (proc.bounds == Proc::Bounds::HalfBin || proc.bounds == Proc::Bounds::SubBin) {
        r1 += 0.5 * bin;
        if (!proc.r2_raw) {
            r2 -= 0.5 * bin;
        }
    }
    if (proc.bounds == Proc::Bounds::SubBin && sub != nullptr) {
        double a = r1, c = r2;
        if (subbin_bounds(v, n, run.i1, run.i2, *sub, &a, &c)) {
            r1 = a;
            r2 = c;
            subbin = true;
        }
    }
    if (!subbin) {
        r1 += proc.r1_add_m;
    }
    r2 -= proc.d_table.empty() ? proc.d_const_m : elong_at(proc.d_table, r2_obs);
    Est e = core_estimate(r1, r2, gt.theta_deg, proc.beta_model_deg, b.range_sigma_m,
                          b.theta_sigma_deg);
    return e;
}

void ErrStats::add(const Est &e, double truth)
{
    rows++;
    if (!e.extracted) {
        missed++;
    } else if (e.flag == SL_INCLINE_AMBIGUOUS) {
        ambiguous++;
        if (clip_ambiguous) {
            err.push_back(e.amb_bound_deg - truth);
        }
    } else if (e.flag != SL_INCLINE_VALID) {
        invalid++;
    } else {
        err.push_back(e.alpha_deg - truth);
    }
}

void ErrStats::finish()
{
    const size_t n = err.size();
    mean = std = rmse = maxabs = 0;
    if (n == 0) {
        mean = std = rmse = maxabs = std::nan("");
        return;
    }
    double s = 0, s2 = 0;
    for (double x : err) {
        s += x;
        s2 += x * x;
        maxabs = std::max(maxabs, std::fabs(x));
    }
    mean = s / n;
    rmse = std::sqrt(s2 / n);
    double v = 0;
    for (double x : err) {
        v += (x - mean) * (x - mean);
    }
    std = n > 1 ? std::sqrt(v / (n - 1)) : 0.0;
}

void simulate_decode(const Scene &scene, int threads,
                     const std::function<void(int k, const std::vector<GtRow> &gt)> &on_gt,
                     const CaptureRows::RowFn &on_row,
                     const std::function<void(int done, int total)> &progress,
                     const std::function<void(int k, const uint8_t *bytes, size_t n)> &on_bytes)
{
    const Simulator sim(scene);
    CaptureRows dec(on_row);
    const auto cfg = sim.config_message();
    dec.feed(cfg.data(), cfg.size());
    if (on_bytes) {
        on_bytes(0, cfg.data(), cfg.size());
    }
    sim_run(
        sim, 0, scene.rotations, threads,
        [&](int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &gt) {
            on_gt(k, gt);
            dec.feed(bytes.data(), bytes.size());
            if (on_bytes) {
                on_bytes(k, bytes.data(), bytes.size());
            }
        },
        progress);
    dec.finish();
    if (!dec.have_config() || dec.bad_fft() != 0 || dec.rotations_seen() != scene.rotations ||
        dec.stats().bytes_skipped != 0) {
        throw std::runtime_error("simulated capture did not decode cleanly (config " +
                                 std::to_string(dec.have_config()) + ", bad fft " +
                                 std::to_string(dec.bad_fft()) + ", rotations " +
                                 std::to_string(dec.rotations_seen()) + ")");
    }
}

// ------------------------------------------------------------------------------------------
// core pipeline

const char *const kPipelineLabel =
    "core pipeline (sl_pipeline: mask + detection + corrections + alpha; n_eff from motion)";

sl_vscale_t scene_value_scale(const Scene &s)
{
    if (s.mapping == OutputMapping::Linear) {
        return sl_vscale_t{static_cast<uint8_t>(SL_VSCALE_LINEAR), 0U};
    }
    const double cpo = s.log_db_per_decade * std::log10(2.0) / (s.log_power ? 1.0 : 2.0);
    return sl_vscale_t{static_cast<uint8_t>(SL_VSCALE_LOG2),
                       static_cast<uint16_t>(std::lround(cpo * 256.0))};
}

PipeCfg pipe_cfg_for_scene(const Scene &s)
{
    PipeCfg c;
    c.board = s.board.name.empty() ? s.board_name : s.board.name;
    c.beam_deg = 2.0 * scene_az_cutoff_deg(s);
    c.threshold = s.mapping == OutputMapping::Linear ? std::max(1, s.detect_floor) : -1;
    // The range profile's tail model reads the sensor's log magnitude (a smear tail falls by
    // a constant number of values per bin); a linear rendering (the paper's simulation
    // style, no smear) is read from the mask's bounds.
    c.profile = s.mapping == OutputMapping::Log ? -1 : 0;
    c.value_scale = scene_value_scale(s);
    c.speed_mps = s.speed_mps;
    c.rotation_hz = s.rotation_hz;
    return c;
}

struct PipelineEval::Impl {
    PipeCfg cfg;
    std::unique_ptr<sl_pipeline_t> p{new sl_pipeline_t()};
    std::map<int, std::vector<sl_target_t>> targets; // by rotation
    std::map<int, int> frames_eff;                    // by rotation
    std::map<int, std::vector<sl_track_t>> tracks;    // live tracks after each rotation
    std::vector<GtRow> truth;
    uint64_t period_us = 250000;

    static void on_rotation(void *ctx, const sl_pipeline_rotation_t *r)
    {
        auto *self = static_cast<Impl *>(ctx);
        auto &v = self->targets[static_cast<int>(r->rotation)];
        v.assign(r->targets, r->targets + r->n_targets);
        self->frames_eff[static_cast<int>(r->rotation)] = r->frames_eff;
        auto &tr = self->tracks[static_cast<int>(r->rotation)];
        tr.clear();
        for (uint16_t i = 0; i < r->n_track_slots; i++) {
            if (r->tracks[i].live != 0) {
                tr.push_back(r->tracks[i]);
            }
        }
    }
    uint64_t now_for(int rotation) const
    {
        return 1000000U + static_cast<uint64_t>(std::max(0, rotation)) * period_us;
    }
};

PipelineEval::PipelineEval(const PipeCfg &c) : m_(new Impl)
{
    m_->cfg = c;
    m_->period_us = static_cast<uint64_t>(std::llround(1e6 / (c.rotation_hz > 0 ? c.rotation_hz : 4.0)));
    const sl_board_t *b = nullptr;
    try {
        b = core_board(c.board, c.calibration); // the linked board, or its calibrated view
    } catch (...) {
        delete m_;
        throw;
    }
    sl_pipeline_cfg_t pc;
    sl_pipeline_cfg_default(&pc, b);
    pc.port.on_rotation = &Impl::on_rotation;
    pc.port.ctx = m_;
    if (c.beam_deg > 0) {
        pc.detect.beam_width_cdeg = static_cast<uint16_t>(std::clamp(std::lround(c.beam_deg * 100), 1L, 36000L));
    }
    if (c.threshold >= 0) {
        pc.threshold = static_cast<uint16_t>(c.threshold);
    }
    if (c.radius_from_width >= 0) {
        pc.detect.radius_from_width = c.radius_from_width != 0;
    }
    if (c.mask_frames > 0) {
        pc.mask_frames = static_cast<uint8_t>(c.mask_frames);
    }
    if (c.profile >= 0) {
        pc.profile = c.profile != 0;
    }
    pc.fit = c.fit;
    pc.profile_cfg.prior_r2_offset_um = c.prior_r2_offset_um;
    if (c.value_scale.kind != static_cast<uint8_t>(SL_VSCALE_LOG2) || c.value_scale.cpo_q8 != 0U) {
        pc.value_scale = c.value_scale;
    }
    const sl_err_t e = sl_pipeline_init(m_->p.get(), b, &pc);
    if (e != SL_OK) {
        const std::string msg = m_->p->last_err_msg != nullptr ? m_->p->last_err_msg : "?";
        delete m_;
        throw std::runtime_error("sl_pipeline_init(" + c.board + "): " + sl_err_str(e) + " (" + msg + ")");
    }
}

PipelineEval::~PipelineEval() { delete m_; }

void PipelineEval::carry_walk_calibration(const PipelineEval &from)
{
    const sl_profile_t &f = from.m_->p->prof;
    sl_profile_t &t = m_->p->prof;
    std::memcpy(t.resid_n, f.resid_n, sizeof t.resid_n);
    t.r2_offset_um = f.r2_offset_um;
    t.stats.resid_samples = f.stats.resid_samples;
}

int32_t PipelineEval::r2_offset_um() const { return m_->p->prof.r2_offset_um; }

uint32_t PipelineEval::resid_samples() const { return m_->p->prof.stats.resid_samples; }

void PipelineEval::add_truth(const GtRow &g) { m_->truth.push_back(g); }

void PipelineEval::feed(int rotation, const uint8_t *data, size_t n)
{
    const uint64_t now = m_->now_for(rotation);
    if (m_->cfg.motion) {
        sl_pipeline_set_motion(m_->p.get(), static_cast<int32_t>(std::lround(m_->cfg.speed_mps * 1000)), true,
                               0, true, now);
    }
    sl_pipeline_feed(m_->p.get(), data, n, now + m_->period_us / 2);
}

void PipelineEval::finish()
{
    int last = m_->targets.empty() ? 0 : m_->targets.rbegin()->first + 1;
    const uint64_t now = m_->now_for(last);
    if (m_->cfg.motion) {
        sl_pipeline_set_motion(m_->p.get(), static_cast<int32_t>(std::lround(m_->cfg.speed_mps * 1000)), true,
                               0, true, now);
    }
    sl_pipeline_finish(m_->p.get(), now + m_->period_us / 2);
}

std::map<int, PipeEval> PipelineEval::result() const
{
    const sl_pipeline_t &p = *m_->p;
    std::map<int, PipeEval> out;
    PipeEval base;
    base.rotations = static_cast<int>(p.stats.rotations);
    base.targets = static_cast<int>(p.stats.targets);
    for (int i = 0; i < 4; i++) {
        base.rejected[i] = p.detect.stats.rejected[i];
    }
    base.geometry_rejected = p.stats.geometry_rejected;
    base.beam_cdeg = p.cfg.detect.beam_width_cdeg;
    base.threshold = p.cfg.threshold;
    base.frames_eff_min = 255;
    for (const auto &kv : m_->frames_eff) {
        base.frames_eff_min = std::min(base.frames_eff_min, kv.second);
        base.frames_eff_max = std::max(base.frames_eff_max, kv.second);
    }
    if (m_->frames_eff.empty()) {
        base.frames_eff_min = 0;
    }
    const int az_n = std::max<int>(1, p.board->azimuths);
    std::map<int, std::vector<bool>> used;
    for (const auto &kv : m_->targets) {
        used[kv.first].assign(kv.second.size(), false);
    }
    for (const auto &g : m_->truth) {
        PipeEval &pe = out.emplace(g.pole, base).first->second;
        pe.err.clip_ambiguous = m_->cfg.clip_ambiguous;
        pe.truth_rows++;
        auto it = m_->targets.find(g.rotation);
        if (it == m_->targets.end()) {
            continue;
        }
        int best = -1, best_d = m_->cfg.assoc_az + 1;
        for (size_t j = 0; j < it->second.size(); j++) {
            if (used[g.rotation][j]) {
                continue;
            }
            int d = std::abs(static_cast<int>(it->second[j].az) - g.azimuth) % az_n;
            d = std::min(d, az_n - d);
            if (d < best_d) {
                best_d = d;
                best = static_cast<int>(j);
            }
        }
        if (best < 0) {
            if (std::getenv("SL_EVAL_PIPE_DEBUG") != nullptr) {
                std::fprintf(stderr, "rot %d az %d: no target within %d az (%zu in the rotation)\n",
                             g.rotation, g.azimuth, m_->cfg.assoc_az, it->second.size());
                for (const auto &t : it->second) {
                    std::fprintf(stderr, "  az %u bins %u-%u alpha %.2f flag %d tflags 0x%02x\n", t.az,
                                 t.bin_first, t.bin_last, t.alpha_cdeg / 100.0, t.incline_flag, t.flags);
                }
            }
            continue;
        }
        used[g.rotation][static_cast<size_t>(best)] = true;
        const sl_target_t &t = it->second[static_cast<size_t>(best)];
        pe.detected++;
        Est e;
        e.extracted = true;
        e.flag = t.incline_flag;
        e.alpha_deg = t.alpha_cdeg / 100.0;
        e.sigma_deg = t.sigma_cdeg / 100.0;
        e.r1_m = t.r1_um * 1e-6;
        e.r2_m = t.r2_um * 1e-6;
        e.amb_bound_deg = 0.5 * (g.beta_deg - g.theta_deg);
        pe.err.add(e, g.alpha_deg);
        if (std::getenv("SL_EVAL_PIPE_DEBUG") != nullptr) {
            std::fprintf(stderr, "rot %d az %d/%d n %u bins %u-%u r1 %.4f/%.4f r2 %.4f/%.4f R %u alpha %.2f truth %.2f model %.2f flag %d tflags 0x%02x\n",
                         g.rotation, t.az, g.azimuth, t.az_count, t.bin_first, t.bin_last, e.r1_m, g.r1_m, e.r2_m, g.r2_m,
                         t.radius_um, e.alpha_deg, g.alpha_deg, g.alpha_model_deg, e.flag, t.flags);
        }
    }
    if (std::getenv("SL_EVAL_PIPE_DEBUG") != nullptr) {
        for (uint32_t si = 0; si < SL_CFG_PROFILE_SLOTS; si++) {
            const sl_profile_slot_t &sl = p.prof.slot[si];
            if (sl.live == 0U || sl.frames == 0U) continue;
            std::fprintf(stderr, "slot az %u bin0 %u frames %u:", sl.az, sl.bin0, sl.frames);
            for (uint32_t k = 0; k < SL_CFG_PROFILE_BINS; k++) std::fprintf(stderr, " %.1f", sl.sum[k] / (double)sl.frames);
            std::fprintf(stderr, "\n");
        }
        const sl_profile_stats_t &ps = p.prof.stats;
        std::fprintf(stderr, "profile: claims %u full %u released %u extracted %u fallback slot/lead/norun/tailcut/notail %u/%u/%u/%u/%u slope %u/256 (n %u)\n",
                     ps.claims, ps.claim_full, ps.released, ps.extracted, ps.fallback[1], ps.fallback[2], ps.fallback[3],
                     ps.fallback[4], ps.fallback[5], p.prof.slope_q8, p.prof.cal_n);
        const sl_detect_stats_t &ds = p.detect.stats;
        std::fprintf(stderr, "detect: groups %u targets %u rejected near/shadow/wide/broken/short/rho/weak %u/%u/%u/%u/%u/%u/%u\n",
                     ds.groups, ds.targets, ds.rejected[SL_DETECT_REJ_NEAR], ds.rejected[SL_DETECT_REJ_SHADOW],
                     ds.rejected[SL_DETECT_REJ_WIDE], ds.rejected[SL_DETECT_REJ_BROKEN], ds.rejected[SL_DETECT_REJ_SHORT],
                     ds.rejected[SL_DETECT_REJ_RHO], ds.rejected[SL_DETECT_REJ_WEAK]);
    }
    int unmatched = 0;
    for (const auto &kv : used) {
        for (bool u : kv.second) {
            unmatched += u ? 0 : 1;
        }
    }
    for (auto &kv : out) {
        kv.second.unmatched = unmatched;
        kv.second.err.finish();
    }
    return out;
}

std::vector<PipelineEval::Target> PipelineEval::targets() const
{
    std::vector<Target> out;
    for (const auto &kv : m_->targets) {
        for (const auto &t : kv.second) {
            Target x;
            x.rotation = kv.first;
            x.az = t.az;
            x.flag = t.incline_flag;
            x.alpha_deg = t.alpha_cdeg / 100.0;
            x.sigma_deg = t.sigma_cdeg / 100.0;
            x.r1_m = t.r1_um * 1e-6;
            x.r2_m = t.r2_um * 1e-6;
            x.bin_first = t.bin_first;
            x.bin_last = t.bin_last;
            x.tflags = t.flags;
            out.push_back(x);
        }
    }
    return out;
}

std::vector<PipelineEval::Track> PipelineEval::tracks() const
{
    std::vector<Track> out;
    for (const auto &kv : m_->tracks) {
        for (const auto &t : kv.second) {
            Track x;
            x.rotation = kv.first;
            x.az = t.az;
            x.id = t.id;
            x.hits = t.hits;
            x.valid_hits = t.valid_hits;
            x.last_flag = t.last_flag;
            x.confirmed = t.confirmed;
            x.alpha_deg = t.alpha_cdeg / 100.0;
            x.sigma_deg = t.sigma_cdeg / 100.0;
            x.level = t.level;
            out.push_back(x);
        }
    }
    return out;
}

std::map<int, int> PipelineEval::frames_eff() const { return m_->frames_eff; }

std::map<int, PipeEval> simulate_pipeline(const Scene &scene, const PipeCfg &c, int threads, int *boundary,
                                          const std::function<void(int done, int total)> &progress)
{
    const Simulator sim(scene);
    PipelineEval pe(c);
    const auto cfg = sim.config_message();
    pe.feed(0, cfg.data(), cfg.size());
    const double bin = scene.board.bin_size_m;
    const int ground_bin = static_cast<int>(
        std::floor(scene.board.radar_height_m / std::sin(sim_d2r(scene.board.theta_deg(0))) / bin));
    int nb = 0;
    sim_run(
        sim, 0, scene.rotations, threads,
        [&](int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &gt) {
            for (const auto &g : gt) {
                if (g.nominal == 1 && g.valid == 1) {
                    if (static_cast<int>(std::floor(g.r2_m / bin)) >= ground_bin - 1) {
                        nb++;
                        continue;
                    }
                    pe.add_truth(g);
                }
            }
            pe.feed(k, bytes.data(), bytes.size());
        },
        progress);
    pe.finish();
    if (boundary != nullptr) {
        *boundary = nb;
    }
    return pe.result();
}

// ------------------------------------------------------------------------------------------
// table 1

Scene table1_scene(int cond, int angle, int rotations, double lateral_m, int range_bins)
{
    Scene s;
    s.board_name = "paper-sim";
    s.board = load_board(s.board_name);
    const double H = s.board.radar_height_m;
    s.bin_size_override_m = cond == 0 ? 0.002 : 0.0;
    s.range_bins_override = range_bins;
    s.rotations = rotations;
    s.rotation_hz = 4;
    s.seed = static_cast<uint64_t>(1000 + 10 * cond + angle);
    const double length_m = 10.0;
    s.vehicle_x_m = 0;
    s.vehicle_y_m = -0.5 * length_m;
    s.heading_deg = 90;
    s.speed_mps = length_m / (rotations / s.rotation_hz);
    ScenePole p;
    p.name = "pole";
    p.x_m = lateral_m;
    p.y_m = 0;
    p.at_height_m = H;
    p.length_m = 4.0;
    p.radius_m = cond <= 2 ? 0.005 : (cond == 3 ? 0.05 : 0.10);
    p.tilt_deg = std::abs(angle);
    p.lean_deg = angle > 0 ? 180.0 : 0.0; // towards the path (-x) = towards the radar
    p.reflectivity = 1.0;
    s.poles.push_back(p);
    s.ground = true;
    s.ground_reflectivity = 0.05;
    s.elevation = cond >= 2 ? ElevationProfile::Measured : ElevationProfile::Ideal;
    s.elev_top_deg = cond >= 2 ? 3.0 : 0.0;
    s.elev_bottom_deg = -35;
    s.az_width_deg = 8;
    s.amplitude = AmplitudeModel::Integral;
    s.mapping = OutputMapping::Linear;
    s.normalize = Normalize::Column;
    s.peak_counts = 250;
    s.detect_floor = 1;
    validate_scene(s);
    return s;
}

namespace {

struct Sample {
    GtRow gt;
    std::vector<double> v;
};

using Clock = std::chrono::steady_clock;

const char *kT1Names[6] = {"Ideal", "Real res. (raw)", "Real res. (corrected)", "Emission model",
                           "10 cm pole", "20 cm pole"};
const double kT1PaperMean[6][3] = {{0.034, -0.009, -0.057}, {2.011, 1.371, 1.143},
                                   {0.044, 0.035, -0.047},  {0.078, 0.048, 0.619},
                                   {1.777, 1.244, 1.808},   {3.765, 2.720, 3.186}};
const double kT1PaperStd[6][3] = {{0.105, 0.107, 0.099}, {0.907, 0.593, 0.490},
                                  {0.831, 0.543, 0.470}, {0.843, 0.513, 0.546},
                                  {0.964, 0.626, 0.642}, {1.234, 0.752, 0.726}};

} // namespace

Table1Result run_table1(const Table1Options &o)
{
    Table1Result res;
    res.rotations = o.rotations;
    const auto t0 = Clock::now();
    // captures: 0 ideal (2 mm), 1 real res, 2 measured emission, 3 10 cm, 4 20 cm
    std::vector<Sample> samples[5][3];
    int n_boundary[5][3] = {};
    int ncap = 0;
    for (int c = 0; c < 5; c++) {
        ncap += (o.captures >> c) & 1U;
    }
    int cap_i = 0;
    for (int c = 0; c < 5; c++) {
        if (((o.captures >> c) & 1U) == 0U) {
            continue;
        }
        for (int a = 0; a < 3; a++) {
            cap_i++;
            const Scene s = table1_scene(c, res.angles[a], o.rotations, o.lateral_m, o.range_bins);
            const double bin = s.board.bin_size_m;
            const int ground_bin = static_cast<int>(
                std::floor(s.board.radar_height_m / std::sin(sim_d2r(s.board.theta_deg(0))) / bin));
            std::map<std::pair<int, int>, GtRow> want;
            auto &out = samples[c][a];
            int &nb = n_boundary[c][a];
            std::unique_ptr<PipelineEval> pipe, pipe_nr;
            if (o.extract == Extract::Pipeline && c != 0) {
                res.pipe_cfg[c] = pipe_cfg_for_scene(s);
                pipe.reset(new PipelineEval(res.pipe_cfg[c]));
                PipeCfg nr = res.pipe_cfg[c];
                nr.radius_from_width = 0;
                pipe_nr.reset(new PipelineEval(nr));
            }
            simulate_decode(
                s, o.threads,
                [&](int, const std::vector<GtRow> &gt) {
                    for (const auto &g : gt) {
                        if (g.nominal == 1 && g.valid == 1) {
                            if (static_cast<int>(std::floor(g.r2_m / bin)) >= ground_bin - 1) {
                                nb++; // touches the ground's first bin: cannot be segmented
                                continue;
                            }
                            want[{g.rotation, g.azimuth}] = g;
                            if (pipe) {
                                pipe->add_truth(g); // the same rows as the bbox path
                                pipe_nr->add_truth(g);
                            }
                        }
                    }
                },
                [&](int rot, int az, const uint8_t *bins, uint32_t n) {
                    auto it = want.find({rot, az});
                    if (it == want.end()) {
                        return;
                    }
                    Sample sm;
                    sm.gt = it->second;
                    const uint32_t keep = std::min<uint32_t>(n, static_cast<uint32_t>(ground_bin + 2));
                    sm.v.assign(bins, bins + keep);
                    out.push_back(std::move(sm));
                    want.erase(it);
                },
                [&](int done, int total) {
                    if (o.progress && (done == total || done % 50 == 0)) {
                        std::fprintf(stderr, "\rsl-eval table1: capture %d/%d (%s, %+d deg) rotation %d/%d   ",
                                     cap_i, 3 * ncap, c == 0 ? "ideal" : c == 1 ? "real res" : c == 2 ? "emission" : c == 3 ? "10 cm" : "20 cm",
                                     res.angles[a], done, total);
                    }
                },
                [&](int k, const uint8_t *bytes, size_t n) {
                    if (pipe) {
                        pipe->feed(k, bytes, n);
                        pipe_nr->feed(k, bytes, n);
                    }
                });
            if (pipe) {
                pipe->finish();
                pipe_nr->finish();
                const auto pr = pipe->result();
                if (!pr.empty()) {
                    res.pipe[0][c][a] = pr.begin()->second;
                }
                const auto pn = pipe_nr->result();
                if (!pn.empty()) {
                    res.pipe[1][c][a] = pn.begin()->second;
                }
                res.have_pipe = true;
            }
        }
    }
    res.bbox_table = o.bbox_table;
    if (o.progress) {
        std::fprintf(stderr, "\n");
    }
    for (int c = 0; c < 5; c++) {
        for (int a = 0; a < 3; a++) {
            double sm = 0;
            for (const auto &x : samples[c][a]) {
                sm += x.gt.alpha_model_deg - x.gt.alpha_deg;
            }
            res.model_err[c][a] = samples[c][a].empty() ? std::nan("") : sm / samples[c][a].size();
            res.boundary[c][a] = n_boundary[c][a];
        }
    }
    // processing per table row
    struct RowSpec {
        int cap;
        Proc paper, a, b;
    };
    auto mk = [](Proc::Bounds bo, double r1add, double beta) {
        Proc p;
        p.bounds = bo;
        p.r1_add_m = r1add;
        p.beta_model_deg = beta;
        return p;
    };
    using B = Proc::Bounds;
    const RowSpec specs[6] = {
        {0, mk(B::Raw, 0, 0), mk(B::HalfBin, 0.005, 0), mk(B::SubBin, 0.005, 0)},
        {1, mk(B::Raw, 0, 0), mk(B::HalfBin, 0.005, 0), mk(B::SubBin, 0.005, 0)},
        {1, mk(B::HalfBin, 0, 0), mk(B::HalfBin, 0.005, 0), mk(B::SubBin, 0.005, 0)},
        {2, mk(B::HalfBin, 0, 0), mk(B::HalfBin, 0.005, 3), mk(B::SubBin, 0.005, 3)},
        {3, mk(B::HalfBin, 0, 0), mk(B::HalfBin, 0.05, 3), mk(B::SubBin, 0.05, 3)},
        {4, mk(B::HalfBin, 0, 0), mk(B::HalfBin, 0.10, 3), mk(B::SubBin, 0.10, 3)},
    };
    for (int rI = 0; rI < 6; rI++) {
        Table1Row row;
        row.name = kT1Names[rI];
        const RowSpec &sp = specs[rI];
        row.paper_proc = sp.paper.bounds == B::Raw ? "bbox raw, beta 0" : "bbox half-bin, beta 0";
        {
            std::ostringstream s1, s2;
            s1 << "half-bin, r1 += R (" << sp.a.r1_add_m * 100 << " cm), beta " << sp.a.beta_model_deg;
            s2 << "sub-bin fill fit if R <= bin/4 (else as A), beta " << sp.b.beta_model_deg;
            row.a_proc = s1.str();
            row.b_proc = s2.str();
        }
        for (int a = 0; a < 3; a++) {
            row.paper_mean[a] = kT1PaperMean[rI][a];
            row.paper_std[a] = kT1PaperStd[rI][a];
            const Scene s = table1_scene(sp.cap, res.angles[a], 8, o.lateral_m);
            const BoardSpec &b = s.board;
            const double bin = b.bin_size_m;
            SubbinModel sm;
            sm.bin_m = bin;
            sm.radius_m = s.poles[0].radius_m;
            sm.beta_deg = s.elev_top_deg;
            sm.gain = [s](double e) { return sim_elevation_gain(s, e); };
            for (const auto &smp : samples[sp.cap][a]) {
                const GtRow &g = smp.gt;
                sm.theta_deg = g.theta_deg;
                const int n = static_cast<int>(smp.v.size());
                const int lo = std::max(0, static_cast<int>(std::floor((g.r1_surf_m - 0.5) / bin)));
                const int hi = n - 3; // up to the bin before the ground's first bin
                const Est ep = estimate_row(smp.v.data(), n, g, b, 1.0, lo, hi, sp.paper, nullptr);
                const Est ea = estimate_row(smp.v.data(), n, g, b, 1.0, lo, hi, sp.a, nullptr);
                const Est eb = estimate_row(smp.v.data(), n, g, b, 1.0, lo, hi, sp.b, &sm);
                row.paper_style[a].add(ep, g.alpha_deg);
                row.improved_a[a].add(ea, g.alpha_deg);
                row.improved_b[a].add(eb, g.alpha_deg);
                const int ci = rI == 0 ? 0 : (rI == 2 ? 1 : -1);
                if (ci >= 0) {
                    res.curves[ci][a].push_back(
                        {g.along_m, g.alpha_deg,
                         ep.flag == SL_INCLINE_VALID && ep.extracted ? ep.alpha_deg : std::nan(""),
                         eb.flag == SL_INCLINE_VALID && eb.extracted ? eb.alpha_deg : std::nan("")});
                }
            }
            row.paper_style[a].finish();
            row.improved_a[a].finish();
            row.improved_b[a].finish();
        }
        res.rows.push_back(std::move(row));
    }
    res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return res;
}

namespace {

std::string cell(const ErrStats &e)
{
    char b[64];
    std::snprintf(b, sizeof b, "%6.3f / %5.3f", e.mean, e.std);
    return b;
}

std::string jnum(double x)
{
    if (!std::isfinite(x)) {
        return "null";
    }
    char b[32];
    std::snprintf(b, sizeof b, "%.5f", x);
    return b;
}

std::string jstats(const ErrStats &e)
{
    std::ostringstream o;
    o << "{\"mean\": " << jnum(e.mean) << ", \"std\": " << jnum(e.std) << ", \"rmse\": "
      << jnum(e.rmse) << ", \"max_abs\": " << jnum(e.maxabs) << ", \"n\": " << e.err.size()
      << ", \"rows\": " << e.rows << ", \"missed\": " << e.missed << ", \"ambiguous\": "
      << e.ambiguous << ", \"invalid\": " << e.invalid << "}";
    return o.str();
}

} // namespace

namespace {

void print_table1_pipeline(std::FILE *f, const Table1Result &r)
{
    std::fprintf(f,
                 "Table I captures through the %s.\n"
                 "Capture bytes -> sl_pipeline_feed (board paper-sim, sl_board_find); speed of the pass\n"
                 "given with sl_pipeline_set_motion (consistency window n_eff adapted); detection beam\n"
                 "width = the simulated azimuth window (2 x cutoff), threshold = the linear mapping's\n"
                 "detect floor. Per rotation, the raw target list (not the tracks): the target nearest\n"
                 "the truth's nominal azimuth (within 3 azimuths) is the pole's; its alpha is compared\n"
                 "with that rotation's truth. Same truth rows as the bbox table (pole in the shadow,\n"
                 "valid, r2 not touching the ground's first bin). The pipeline always applies its\n"
                 "own corrections (half-bin; radius from the azimuthal width; beta from the board =\n"
                 "0). The ideal capture (2 mm bins) is not run: the pipeline uses the board's bins.\n"
                 "Cells: error mean / std (deg), detection rate = rotations with the pole detected /\n"
                 "rotations the truth has it in the shadow; amb/inv = AMBIGUOUS / other non-VALID\n"
                 "flags among the detections (not in mean/std).\n\n",
                 kPipelineLabel);
    const char *cap[5] = {"Ideal", "Real res.", "Emission model", "10 cm pole", "20 cm pole"};
    const char *var[2] = {"A: detection defaults (radius from the azimuthal width, r1 += R)",
                          "B: radius_from_width off (R = 0: the front surface is taken as the axis)"};
    for (int v = 0; v < 2; v++) {
        std::fprintf(f, "%s\n", var[v]);
        std::fprintf(f, "%-15s |", "condition");
        for (int a = 0; a < 3; a++) {
            std::fprintf(f, " %+3d deg: mean / std   det.rate  amb/inv |", r.angles[a]);
        }
        std::fprintf(f, " n_eff beam\n");
        for (int c = 1; c < 5; c++) {
            const auto &pc = r.pipe[v][c];
            if (pc[0].truth_rows == 0 && pc[1].truth_rows == 0 && pc[2].truth_rows == 0) {
                continue;
            }
            std::fprintf(f, "%-15s |", cap[c]);
            for (int a = 0; a < 3; a++) {
                const PipeEval &e = pc[a];
                std::fprintf(f, " %6.3f / %5.3f  %3d/%-3d=%3.0f%%  %2d/%-2d |", e.err.mean, e.err.std, e.detected,
                             e.truth_rows, 100.0 * e.rate(), e.err.ambiguous, e.err.invalid);
            }
            std::fprintf(f, " %d-%d  %.2f deg\n", pc[1].frames_eff_min, pc[1].frames_eff_max, pc[1].beam_cdeg / 100.0);
        }
        std::fprintf(f, "\n");
    }
    std::fprintf(f, "per pass (variant A): rotations, targets, unmatched targets, rejected NEAR/SHADOW/WIDE/BROKEN\n");
    for (int c = 1; c < 5; c++) {
        for (int a = 0; a < 3; a++) {
            const PipeEval &e = r.pipe[0][c][a];
            if (e.truth_rows == 0) {
                continue;
            }
            std::fprintf(f, "  %-15s %+3d deg: rotations %d, targets %d, unmatched %d, rejected %u/%u/%u/%u, "
                            "speed %.3f m/s, threshold %u\n",
                         cap[c], r.angles[a], e.rotations, e.targets, e.unmatched, e.rejected[0], e.rejected[1],
                         e.rejected[2], e.rejected[3], r.pipe_cfg[c].speed_mps, e.threshold);
        }
    }
}

} // namespace

void print_table1(std::FILE *f, const Table1Result &r)
{
    if (!r.bbox_table) {
        print_table1_pipeline(f, r);
        std::fprintf(f, "run time %.1f s\n", r.seconds);
        return;
    }
    std::fprintf(f,
                 "Table I reproduction -- bbox extraction (detection pipeline not used): first/last\n"
                 "bin above threshold on the pole's ground-truth azimuth, inside the ground shadow;\n"
                 "core decoder (sl_proto) + core estimator (sl_incline_estimate). Board paper-sim\n"
                 "(theta 26 deg, H 2.58 m); a pole leaning in the vertical plane across the path,\n"
                 "axis at radar height 3 m from the path; vehicle passes 10 m at constant speed,\n"
                 "%d rotations per pass; rows = nominal azimuth of each rotation with the pole's\n"
                 "base inside the shadow. Error = estimate - in-plane alpha (MATH.md s.5).\n"
                 "Cells: mean / std (deg). Ours use the paper's processing for that row.\n\n",
                 r.rotations);
    std::fprintf(f, "%-22s | %-35s | %-35s\n", "condition", "paper  -10 | 0 | +10",
                 "ours (paper processing)  -10 | 0 | +10");
    for (const auto &row : r.rows) {
        char p[3][32];
        for (int a = 0; a < 3; a++) {
            std::snprintf(p[a], sizeof p[a], "%.3f/%.3f", row.paper_mean[a], row.paper_std[a]);
        }
        std::fprintf(f, "%-22s | %-11s %-11s %-11s | %s %s %s   n=%zu,%zu,%zu\n", row.name.c_str(), p[0],
                     p[1], p[2], cell(row.paper_style[0]).c_str(), cell(row.paper_style[1]).c_str(),
                     cell(row.paper_style[2]).c_str(), row.paper_style[0].err.size(),
                     row.paper_style[1].err.size(), row.paper_style[2].err.size());
    }
    std::fprintf(f, "\nImprovements (same captures):\n");
    std::fprintf(f, "%-22s | %-47s | %-47s\n", "condition",
                 "A: half-bin + r1 += R + beta  -10 | 0 | +10", "B: sub-bin fill fit + beta  -10 | 0 | +10");
    for (const auto &row : r.rows) {
        std::fprintf(f, "%-22s | %s %s %s | %s %s %s\n", row.name.c_str(), cell(row.improved_a[0]).c_str(),
                     cell(row.improved_a[1]).c_str(), cell(row.improved_a[2]).c_str(),
                     cell(row.improved_b[0]).c_str(), cell(row.improved_b[1]).c_str(),
                     cell(row.improved_b[2]).c_str());
    }
    std::fprintf(f, "\nThe closed form's own error on the exact axis bounds, mean(alpha_model - alpha), part\n"
                    "of every cell above (an oblique pole is not in one vertical plane):\n");
    const char *cap[5] = {"ideal", "real res.", "emission", "10 cm", "20 cm"};
    for (int c = 0; c < 5; c++) {
        if (std::isfinite(r.model_err[c][0])) {
            std::fprintf(f, "  %-10s %+.3f %+.3f %+.3f deg\n", cap[c], r.model_err[c][0], r.model_err[c][1],
                         r.model_err[c][2]);
        }
    }
    std::fprintf(f, "\nrows per angle: ");
    for (int a = 0; a < 3; a++) {
        const auto &e = r.rows[1].paper_style[a];
        std::fprintf(f, "%+d deg: %d (missed %d, ambiguous %d, invalid %d)  ", r.angles[a], e.rows,
                     e.missed, e.ambiguous, e.invalid);
    }
    if (r.have_pipe) {
        std::fprintf(f, "\n\n");
        print_table1_pipeline(f, r);
    }
    std::fprintf(f, "\nrun time %.1f s\n", r.seconds);
}

std::string table1_json(const Table1Result &r)
{
    std::ostringstream o;
    o << "{\n  \"schema\": \"shadowlean-eval-table1/1\",\n  \"experiment\": \"table1\",\n  \"extraction\": \"bbox extraction (detection pipeline not used)\",\n"
      << "  \"rotations_per_pass\": " << r.rotations << ",\n  \"angles_deg\": [-10, 0, 10],\n  \"rows\": [\n";
    for (size_t i = 0; i < r.rows.size(); i++) {
        const auto &row = r.rows[i];
        o << "    {\"condition\": \"" << row.name << "\",\n";
        o << "     \"paper\": [";
        for (int a = 0; a < 3; a++) {
            o << (a ? ", " : "") << "{\"mean\": " << row.paper_mean[a] << ", \"std\": " << row.paper_std[a] << "}";
        }
        o << "],\n     \"paper_processing\": \"" << row.paper_proc << "\", \"ours\": [";
        for (int a = 0; a < 3; a++) {
            o << (a ? ", " : "") << jstats(row.paper_style[a]);
        }
        o << "],\n     \"improved_a_processing\": \"" << row.a_proc << "\", \"improved_a\": [";
        for (int a = 0; a < 3; a++) {
            o << (a ? ", " : "") << jstats(row.improved_a[a]);
        }
        o << "],\n     \"improved_b_processing\": \"" << row.b_proc << "\", \"improved_b\": [";
        for (int a = 0; a < 3; a++) {
            o << (a ? ", " : "") << jstats(row.improved_b[a]);
        }
        o << "]}" << (i + 1 < r.rows.size() ? "," : "") << "\n";
    }
    o << "  ],\n  \"model_error_deg\": [";
    for (int c = 0; c < 5; c++) {
        o << (c ? ", " : "") << "[" << jnum(r.model_err[c][0]) << ", " << jnum(r.model_err[c][1]) << ", "
          << jnum(r.model_err[c][2]) << "]";
    }
    o << "],\n";
    if (r.have_pipe) {
        const char *cap[5] = {"ideal", "real_res", "emission", "10cm", "20cm"};
        o << "  \"pipeline\": {\"extraction\": \"" << kPipelineLabel << "\", \"captures\": [\n";
        bool first = true;
        for (int v = 0; v < 2; v++)
        for (int c = 1; c < 5; c++) {
            if (r.pipe[v][c][1].truth_rows == 0) {
                continue;
            }
            o << (first ? "" : ",\n") << "    {\"capture\": \"" << cap[c] << "\", \"radius_from_width\": "
              << (v == 0 ? "true" : "false") << ", \"beam_deg\": "
              << jnum(r.pipe[v][c][1].beam_cdeg / 100.0) << ", \"speed_mps\": " << jnum(r.pipe_cfg[c].speed_mps)
              << ", \"angles\": [";
            first = false;
            for (int a = 0; a < 3; a++) {
                const PipeEval &e = r.pipe[v][c][a];
                o << (a ? ", " : "") << "{\"error\": " << jstats(e.err) << ", \"truth_rows\": " << e.truth_rows
                  << ", \"detected\": " << e.detected << ", \"detection_rate\": " << jnum(e.rate())
                  << ", \"targets\": " << e.targets << ", \"unmatched\": " << e.unmatched
                  << ", \"frames_eff\": [" << e.frames_eff_min << ", " << e.frames_eff_max << "]}";
            }
            o << "]}";
        }
        o << "\n  ]},\n";
    }
    o << "  \"seconds\": " << jnum(r.seconds) << "\n}\n";
    return o.str();
}

} // namespace sl


namespace sl {

bool plot_table1(const std::string &png, const Table1Result &r, std::string &err)
{
    const int pw = 520, ph = 340, ml = 60, mt = 40, mb = 45, mr = 15;
    const int W = 3 * pw, Hh = 2 * ph + 40;
    cv::Mat img(Hh, W, CV_8UC3, cv::Scalar(255, 255, 255));
    const char *rowname[2] = {"Ideal (2 mm bins)", "Real resolution 0.0438 m, corrected"};
    const cv::Scalar cTruth(40, 150, 40), cPaper(40, 40, 220), cImp(200, 90, 20), cGrid(225, 225, 225);
    cv::putText(img, "alpha (deg) vs y (m) as the vehicle passes the pole (cf. paper Figs. 7-8): truth "
                     "(green line), paper processing (red), improved B (blue)",
                cv::Point(10, 24), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    for (int row = 0; row < 2; row++) {
        for (int a = 0; a < 3; a++) {
            const auto &pts = r.curves[row][a];
            const int x0 = a * pw + ml, y0 = 40 + row * ph + mt;
            const int w = pw - ml - mr, h = ph - mt - mb;
            double ymin = 1e9, ymax = -1e9, xmin = -5, xmax = 5;
            for (const auto &p : pts) {
                for (double v : {p.truth_deg, p.paper_deg, p.improved_deg}) {
                    if (std::isfinite(v)) {
                        ymin = std::min(ymin, v);
                        ymax = std::max(ymax, v);
                    }
                }
            }
            if (!(ymax > ymin)) {
                ymin = -1;
                ymax = 1;
            }
            ymin = std::floor(ymin - 0.5);
            ymax = std::ceil(ymax + 0.5);
            auto X = [&](double x) { return x0 + static_cast<int>(std::lround((x - xmin) / (xmax - xmin) * w)); };
            auto Y = [&](double y) { return y0 + h - static_cast<int>(std::lround((y - ymin) / (ymax - ymin) * h)); };
            for (int gx = -5; gx <= 5; gx++) {
                cv::line(img, {X(gx), y0}, {X(gx), y0 + h}, cGrid);
                if (gx % 1 == 0) {
                    cv::putText(img, std::to_string(gx), {X(gx) - 6, y0 + h + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
                }
            }
            const double ystep = (ymax - ymin) > 8 ? 2.0 : 1.0;
            for (double gy = ymin; gy <= ymax + 1e-9; gy += ystep) {
                cv::line(img, {x0, Y(gy)}, {x0 + w, Y(gy)}, cGrid);
                char t[16];
                std::snprintf(t, sizeof t, "%.0f", gy);
                cv::putText(img, t, {x0 - 35, Y(gy) + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
            }
            cv::rectangle(img, {x0, y0}, {x0 + w, y0 + h}, cv::Scalar(0, 0, 0));
            char title[96];
            std::snprintf(title, sizeof title, "%s, pole %+d deg", rowname[row], r.angles[a]);
            cv::putText(img, title, {x0, y0 - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
            cv::putText(img, "y (m)", {x0 + w - 40, y0 + h + 34}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
            std::vector<CurvePoint> sorted(pts);
            std::sort(sorted.begin(), sorted.end(), [](const CurvePoint &p, const CurvePoint &q) { return p.along_m < q.along_m; });
            for (size_t i = 1; i < sorted.size(); i++) {
                cv::line(img, {X(sorted[i - 1].along_m), Y(sorted[i - 1].truth_deg)},
                         {X(sorted[i].along_m), Y(sorted[i].truth_deg)}, cTruth, 2, cv::LINE_AA);
            }
            for (const auto &p : sorted) {
                if (std::isfinite(p.paper_deg)) {
                    cv::circle(img, {X(p.along_m), Y(p.paper_deg)}, 2, cPaper, cv::FILLED, cv::LINE_AA);
                }
                if (std::isfinite(p.improved_deg)) {
                    cv::circle(img, {X(p.along_m), Y(p.improved_deg)}, 2, cImp, cv::FILLED, cv::LINE_AA);
                }
            }
        }
    }
    try {
        if (!cv::imwrite(png, img)) {
            err = "cannot write " + png;
            return false;
        }
    } catch (const cv::Exception &e) {
        err = e.what();
        return false;
    }
    return true;
}

// ------------------------------------------------------------------------------------------
// realistic (Table II)

Scene realistic_scene(double dist_m, double alpha_deg, uint64_t seed, int frames, int range_bins)
{
    Scene s;
    s.board_name = "paper-bench";
    s.board = load_board(s.board_name);
    s.range_bins_override = range_bins;
    s.rotations = frames;
    s.rotation_hz = 4;
    s.seed = seed;
    s.vehicle_x_m = 0;
    s.vehicle_y_m = 0;
    s.heading_deg = 90; // azimuth 0 (vehicle forward) = world +y
    s.speed_mps = 0;
    ScenePole p;
    p.name = "pole";
    p.x_m = 0;
    p.y_m = dist_m;
    p.length_m = 2.0;
    p.radius_m = 0.025;
    p.tilt_deg = std::fabs(alpha_deg);
    p.lean_deg = alpha_deg > 0 ? 270.0 : 90.0; // > 0: top towards the radar (-y)
    p.reflectivity = 1.0;
    s.poles.push_back(p);
    s.ground = true;
    s.ground_reflectivity = 2e-7; // smooth floor at grazing incidence: ~70 dB below the pole
    s.ground_max_range_m = 15;
    s.elevation = ElevationProfile::Measured;
    s.elev_top_deg = 3;
    s.elev_bottom_deg = -35;
    s.az_width_deg = 2.0; // CTS350-X: about 1.8 deg
    s.amplitude = AmplitudeModel::Integral;
    s.mapping = OutputMapping::Log;
    s.normalize = Normalize::None;
    s.log_ref_energy = 1.0;
    s.log_ref_value = 100;
    s.smear = true;
    s.smear_shape = 1;
    s.smear_width_bins = 40;
    s.smear_mode_frac = 0;
    s.smear_decay_db = 3.3;
    s.speckle = true;
    s.speckle_db = 2.0;
    s.speckle_static = 1;
    s.speckle_seed = sim_hash(seed, 0xB0A7);
    s.noise = true;
    s.leakage = true;
    validate_scene(s);
    return s;
}

bool HardCondition::set(const std::string &name, double v)
{
    struct F {
        const char *name;
        double *p;
        double lo, hi;
    };
    const F fs[] = {{"fast_decay_db", &fast_decay_db, 0.1, 50},    {"slow_db", &slow_db, -100, 0},
                    {"slow_decay_db", &slow_decay_db, 0.1, 50},    {"amp_decay_db", &amp_decay_db, 0, 10},
                    {"front_db", &front_db, -200, 0},              {"speckle_frame_db", &speckle_frame_db, 0, 20},
                    {"az_jitter_deg", &az_jitter_deg, 0, 5},       {"segment_m", &segment_m, 0, 1},
                    {"segment_fill_m", &segment_fill_m, 0.001, 1}, {"segment_gap", &segment_gap, 0, 1},
                    {"theta_tol_deg", &theta_tol_deg, 0, 5},       {"beta_tol_deg", &beta_tol_deg, 0, 5},
                    {"height_tol_m", &height_tol_m, 0, 0.5},       {"bearing_tol_deg", &bearing_tol_deg, 0, 5},
                    {"refl_tol_db", &refl_tol_db, 0, 20}};
    for (const F &f : fs) {
        if (name == f.name) {
            if (!(v >= f.lo && v <= f.hi)) {
                return false;
            }
            *f.p = v;
            return true;
        }
    }
    return false;
}

void make_hard(Scene &s, const HardCondition &h, uint64_t seed)
{
    s.smear_shape = 2;
    s.smear_decay_db = h.fast_decay_db;
    s.smear_slow_db = h.slow_db;
    s.smear_slow_decay_db = h.slow_decay_db;
    s.smear_amp_decay_db = h.amp_decay_db;
    s.smear_front_db = h.front_db;
    s.speckle_frame_db = h.speckle_frame_db;
    s.az_jitter_deg = h.az_jitter_deg;
    for (auto &p : s.poles) {
        p.segment_m = h.segment_m;
        p.segment_fill_m = h.segment_fill_m;
        p.segment_gap = h.segment_gap;
    }
    auto draw = [seed](uint64_t salt, double tol) {
        return tol * (2.0 * sim_uniform(sim_hash(seed, 0x4A2D, salt)) - 1.0);
    };
    // H first (theta depends on it), then the chassis scaled about the radar so that theta
    // towards the pole (azimuth 0) is the nominal one plus its draw; beta = the emission's top
    const double theta0 = s.board.theta_deg(0);
    s.board.radar_height_m += draw(1, h.height_tol_m);
    double w = 0, eh = 0;
    s.board.edge_along(0, &w, &eh);
    const double want = sim_d2r(theta0 + draw(2, h.theta_tol_deg));
    const double k = (s.board.radar_height_m - eh) / std::tan(want) / w;
    for (auto &v : s.board.polygon) {
        v.x_m = s.board.radar_x_m + (v.x_m - s.board.radar_x_m) * k;
        v.y_m = s.board.radar_y_m + (v.y_m - s.board.radar_y_m) * k;
    }
    s.elev_top_deg += draw(3, h.beta_tol_deg);
    // the pole: bearing offset d (clockwise from azimuth 0 = world +y) about the radar, its
    // lean turned with it (still in the radar's plane), and its reflectivity
    const double d = draw(4, h.bearing_tol_deg), g = std::pow(10.0, 0.1 * draw(5, h.refl_tol_db));
    for (auto &p : s.poles) {
        const double dist = std::hypot(p.x_m - s.vehicle_x_m, p.y_m - s.vehicle_y_m);
        p.x_m = s.vehicle_x_m + dist * std::sin(sim_d2r(d));
        p.y_m = s.vehicle_y_m + dist * std::cos(sim_d2r(d));
        p.lean_deg -= d;
        p.reflectivity *= g;
    }
    validate_scene(s);
}

namespace {

// A bin is the pole's own when >= 12 % of its power is not the tail of the bins before it
// (the 8-bit log quantisation leaves a residual of about 3 % of the power in a pure tail).
constexpr double kDeconvKeep = 0.12;

struct Frames {
    GtRow gt;
    std::vector<double> mean, all; // mean value; fraction of frames above threshold
    bool have = false;
};

Frames run_frames(const Scene &s, int threads, double threshold,
                  const std::function<void(int k, const uint8_t *bytes, size_t n)> &on_bytes = {})
{
    Frames fr;
    int az = -1, nframes = 0;
    simulate_decode(
        s, threads,
        [&](int, const std::vector<GtRow> &gt) {
            for (const auto &g : gt) {
                if (g.nominal == 1) {
                    fr.gt = g;
                    az = g.azimuth;
                    fr.have = true;
                }
            }
        },
        [&](int, int a, const uint8_t *bins, uint32_t n) {
            if (a != az) {
                return;
            }
            if (fr.mean.empty()) {
                fr.mean.assign(n, 0.0);
                fr.all.assign(n, 0.0);
            }
            for (uint32_t j = 0; j < n && j < fr.mean.size(); j++) {
                fr.mean[j] += bins[j];
                fr.all[j] += bins[j] >= threshold ? 1.0 : 0.0;
            }
            nframes++;
        },
        {}, on_bytes);
    for (size_t j = 0; j < fr.mean.size(); j++) {
        fr.mean[j] /= std::max(1, nframes);
        fr.all[j] = fr.all[j] >= nframes ? 1.0 : 0.0; // consistent in every frame
    }
    return fr;
}

// One measurement through the core pipeline: the targets of the last `last` reported
// rotations at the pole's azimuth (nearest within `assoc_az`), their mean alpha
// (ambiguous = the bound (beta - theta)/2, as the bbox columns), and the tracker's filtered
// alpha after the last rotation.
void realistic_pipe_add(const PipelineEval &pe, const GtRow &gt, int assoc_az, int last, int azimuths,
                        RealisticPipe &out)
{
    const auto fe = pe.frames_eff();
    out.runs++;
    if (fe.empty()) {
        return;
    }
    for (const auto &kv : fe) {
        out.frames_eff_min = out.frames_eff_min == 0 ? kv.second : std::min(out.frames_eff_min, kv.second);
        out.frames_eff_max = std::max(out.frames_eff_max, kv.second);
    }
    const int r_last = fe.rbegin()->first;
    const int r_first = std::max(fe.begin()->first, r_last - std::max(1, last) + 1);
    const int az_n = std::max(1, azimuths);
    auto az_dist = [az_n](int a, int b) {
        int d = std::abs(a - b) % az_n;
        return std::min(d, az_n - d);
    };
    const double bound = 0.5 * (gt.beta_deg - gt.theta_deg);
    const auto tg = pe.targets();
    double sum = 0;
    int cnt = 0;
    bool any = false;
    for (int r = r_first; r <= r_last; r++) {
        out.rot_checked++;
        int best = -1, best_d = assoc_az + 1, in_rot = 0;
        for (size_t j = 0; j < tg.size(); j++) {
            if (tg[j].rotation != r) {
                continue;
            }
            in_rot++;
            const int d = az_dist(tg[j].az, gt.azimuth);
            if (d < best_d) {
                best_d = d;
                best = static_cast<int>(j);
            }
        }
        out.unmatched += in_rot - (best >= 0 ? 1 : 0);
        if (best < 0) {
            continue;
        }
        any = true;
        out.rot_detected++;
        const auto &t = tg[static_cast<size_t>(best)];
        if (std::getenv("SL_EVAL_PIPE_DEBUG") != nullptr) {
            std::fprintf(stderr, "  target rot %d az %d/%d bins %d-%d r1 %.4f/%.4f (%+.1f mm) r2 %.4f/%.4f (%+.1f mm) alpha %.2f flag %d tflags 0x%02x\n",
                         r, t.az, gt.azimuth, t.bin_first, t.bin_last, t.r1_m, gt.r1_m, (t.r1_m - gt.r1_m) * 1e3, t.r2_m,
                         gt.r2_m, (t.r2_m - gt.r2_m) * 1e3, t.alpha_deg, t.flag, t.tflags);
        }
        if (t.flag == SL_INCLINE_VALID) {
            out.valid++;
            sum += t.alpha_deg;
            cnt++;
            if (t.sigma_deg > 0) {
                out.raw_z.push_back((t.alpha_deg - gt.alpha_deg) / t.sigma_deg);
            }
        } else if (t.flag == SL_INCLINE_AMBIGUOUS) {
            out.ambiguous++;
            sum += bound;
            cnt++;
        } else {
            out.other++;
        }
    }
    out.detected += any ? 1 : 0;
    if (cnt > 0) {
        out.raw.push_back(sum / cnt);
    }
    if (std::getenv("SL_EVAL_PIPE_DEBUG") != nullptr) {
        std::fprintf(stderr, "measurement: truth %.2f at %.2f m: %s %.2f\n", gt.alpha_deg, gt.r1_m,
                     cnt > 0 ? "alpha" : "missed", cnt > 0 ? sum / cnt : 0.0);
        (void)pe.result();
    }
    int best_d = assoc_az + 1;
    double filt = std::nan(""), filt_sigma = 0;
    int filt_level = 0;
    for (const auto &t : pe.tracks()) {
        if (t.rotation != r_last || t.valid_hits <= 0) {
            continue;
        }
        const int d = az_dist(t.az, gt.azimuth);
        if (d < best_d) {
            best_d = d;
            filt = t.alpha_deg;
            filt_sigma = t.sigma_deg;
            filt_level = t.level;
        }
    }
    if (!std::isnan(filt)) {
        out.filt.push_back(filt);
        out.filt_sigma.push_back(filt_sigma);
        out.filt_level.push_back(filt_level);
        out.filt_truth.push_back(gt.alpha_deg);
    }
}

} // namespace

RealisticResult run_realistic(const RealisticOptions &o)
{
    RealisticResult res;
    res.frames = o.frames;
    res.bbox_table = o.bbox_table;
    res.pipe_last = o.pipe_last;
    int pipe_az = 400;
    if (const sl_board_t *pb = sl_board_find("paper-bench")) {
        res.pipe_mask_frames = pb->mask_frames;
        pipe_az = pb->azimuths;
    }
    res.positions = o.positions;
    res.reps = o.reps;
    res.hard = o.hard;
    res.hard_cond = o.hard_cond;
    res.power_scale = o.power_scale;
    // On the power scale the per-placement return spread keeps its values too (the
    // acceptance spread was set in values): half the dB (scene_to_power_scale)
    HardCondition hc = res.hard_cond;
    if (o.power_scale) {
        hc.refl_tol_db *= 0.5;
    }
    const auto t0 = Clock::now();
    const BoardSpec b = load_board("paper-bench");
    const double bin = b.bin_size_m, H = b.radar_height_m;
    const double thr = b.threshold;
    const int lo = static_cast<int>(std::floor(b.near_exclusion_m / bin));
    const int hi = static_cast<int>(std::floor((H / std::sin(sim_d2r(b.theta_deg(0))) + 1.5) / bin));
    auto window = [&](const Frames &f, const std::vector<double> &v, double t) {
        const int want_lo = static_cast<int>(std::floor(f.gt.r1_surf_m / bin));
        const int want_hi = static_cast<int>(std::floor(f.gt.r2_m / bin));
        return bbox_run(v.data(), static_cast<int>(v.size()), t, lo, hi, want_lo, want_hi, 1);
    };
    // 1. calibration of d with vertical poles (paper Sec. V-B): r2_obs - r2_true
    std::vector<std::pair<double, double>> cal_paper, cal_ours;
    std::vector<Frames> cal_frames;
    std::vector<double> slopes;
    // The calibration poles also run through the core pipeline, one after another as one
    // radar's stream (what its range profile learns of its walk's end on upright poles is
    // carried from each to the next: sl_profile.h, "Online calibration"); what it learned is
    // every measurement's prior, as a vehicle that has driven before has it saved
    // (shadowleand --r2-offset). Not with --cold, nor on the mask's bounds.
    const bool pipe_cal = o.extract == Extract::Pipeline && o.pipe_profile && !o.cold && !o.have_r2_offset;
    std::unique_ptr<PipelineEval> cal_pipe;
    const int nc = (o.bbox_table || pipe_cal) ? std::max(2, o.calib_positions) : 0;
    int done = 0;
    const int total = nc * 2 + 5 * o.positions * o.reps;
    for (int c = 0; c < nc; c++) {
        double dist = 1.75 + (2.85 - 1.75) * c / (nc - 1);
        if (o.hard) {
            // disjoint from the measurements' 2.2-2.6 m: half below, half above
            const int nlo = (nc + 1) / 2, nhi = nc - nlo;
            dist = c < nlo ? 1.75 + (hc.calib_gap_lo_m - 1.75) * c / std::max(1, nlo - 1)
                           : hc.calib_gap_hi_m + (3.0 - hc.calib_gap_hi_m) * (c - nlo) / std::max(1, nhi - 1);
        }
        for (int rep = 0; rep < 2; rep++) {
            const uint64_t cseed = 5000 + static_cast<uint64_t>(c * 10 + rep);
            Scene s = realistic_scene(dist, 0.0, cseed, o.frames, o.range_bins);
            s.smear_decay_db = o.smear_decay_db;
            s.speckle_static = o.speckle_static;
            if (o.hard) {
                make_hard(s, hc, cseed);
            }
            if (o.power_scale) {
                scene_to_power_scale(s);
            }
            std::unique_ptr<PipelineEval> pipe;
            std::function<void(int, const uint8_t *, size_t)> on_bytes;
            if (pipe_cal) {
                PipeCfg pc = pipe_cfg_for_scene(s);
                pc.mask_frames = o.frames;
                pc.profile = 1;
                pipe.reset(new PipelineEval(pc));
                if (cal_pipe) {
                    pipe->carry_walk_calibration(*cal_pipe);
                }
                on_bytes = [&pipe](int k, const uint8_t *d, size_t n) { pipe->feed(k, d, n); };
            }
            const Frames f = run_frames(s, o.threads, thr, on_bytes);
            if (pipe) {
                pipe->finish();
                cal_pipe = std::move(pipe);
            }
            done++;
            if (o.progress) {
                std::fprintf(stderr, "\rsl-eval realistic: run %d/%d (calibration, vertical pole at %.2f m)   ", done, total, dist);
            }
            if (!f.have || !o.bbox_table) {
                continue; // pipeline only: no bbox calibration (the pole ran for the pipeline's)
            }
            const BinRun rm = window(f, f.mean, thr);
            const BinRun rc = window(f, f.all, 0.5);
            if (rm.found) {
                const double r2o = (rm.i2 + 1) * bin;
                cal_ours.emplace_back(r2o, r2o - f.gt.r2_m);
                res.calib.emplace_back(r2o, r2o - f.gt.r2_m);
            }
            if (rc.found && dist <= (o.hard ? hc.calib_gap_lo_m : 2.30) + 1e-9) {
                const double r2o = (rc.i2 + 1) * bin;
                cal_paper.emplace_back(r2o, r2o - f.gt.r2_m);
            }
            // smear tail slope (value per bin) behind the pole's true end
            {
                const int j0 = static_cast<int>(std::floor(f.gt.r2_m / bin)) + 3;
                int j1 = j0;
                while (j1 + 1 < static_cast<int>(f.mean.size()) && f.mean[static_cast<size_t>(j1) + 1] >= thr + 5) {
                    j1++;
                }
                if (j1 - j0 >= 4) {
                    double sx = 0, sy = 0, sxx = 0, sxy = 0;
                    const int m = j1 - j0 + 1;
                    for (int j = j0; j <= j1; j++) {
                        sx += j;
                        sy += f.mean[static_cast<size_t>(j)];
                        sxx += static_cast<double>(j) * j;
                        sxy += j * f.mean[static_cast<size_t>(j)];
                    }
                    slopes.push_back(-(m * sxy - sx * sy) / (m * sxx - sx * sx));
                }
            }
            cal_frames.push_back(f);
        }
    }
    double sd = 0;
    for (const auto &p : cal_paper) {
        sd += p.second;
    }
    res.d_const_m = cal_paper.empty() ? 0.0 : sd / cal_paper.size();
    if (cal_ours.size() >= 2) {
        // least-squares line d = a + k r2_obs, stored as a two-point table over the data
        double sx = 0, sy = 0, sxx = 0, sxy = 0, mn = 1e9, mx = -1e9;
        for (const auto &p : cal_ours) {
            sx += p.first;
            sy += p.second;
            sxx += p.first * p.first;
            sxy += p.first * p.second;
            mn = std::min(mn, p.first);
            mx = std::max(mx, p.first);
        }
        const double n = static_cast<double>(cal_ours.size());
        const double k = (n * sxy - sx * sy) / std::max(1e-12, n * sxx - sx * sx);
        const double a = (sy - k * sx) / n;
        res.d_table = {{mn, a + k * mn}, {mx, a + k * mx}};
    }
    // deconvolution of the exponential smear: value = (c/2) log10(power), so a tail falling
    // s values per bin is a power kernel a^j with a = 10^(-2 s / c)
    const double c_log = 19.8;
    double s_mean = 0;
    for (double x : slopes) {
        s_mean += x / static_cast<double>(slopes.size());
    }
    res.tail_slope = s_mean;
    res.kernel_a = slopes.empty() ? 0.0 : std::pow(10.0, -2.0 * s_mean / c_log);
    auto deconv = [&](const std::vector<double> &v) {
        std::vector<double> m(v.size(), 0.0);
        double prev = 0;
        for (size_t j = 0; j < v.size(); j++) {
            const double P = std::pow(10.0, 2.0 * v[j] / c_log);
            const double own = P - res.kernel_a * prev;
            m[j] = (v[j] >= thr && own >= kDeconvKeep * P) ? 1.0 : 0.0;
            prev = P;
        }
        return m;
    };
    {
        double sum = 0;
        int cnt = 0;
        for (const auto &f : cal_frames) {
            const auto m = deconv(f.mean);
            const BinRun rd = bbox_run(m.data(), static_cast<int>(m.size()), 0.5, lo, hi,
                                       static_cast<int>(std::floor(f.gt.r1_surf_m / bin)),
                                       static_cast<int>(std::floor(f.gt.r2_m / bin)), 3);
            if (rd.found) {
                sum += (rd.i2 + 0.5) * bin - f.gt.r2_m;
                cnt++;
            }
        }
        res.d_resid_m = cnt > 0 ? sum / cnt : 0.0;
    }
    if (cal_pipe) {
        res.pipe_resid_samples = cal_pipe->resid_samples();
        res.pipe_r2_offset_um = res.pipe_resid_samples >= SL_PROFILE_RESID_MIN ? cal_pipe->r2_offset_um() : 0;
    } else if (o.have_r2_offset && o.pipe_profile) {
        res.pipe_r2_offset_um = o.r2_offset_um; // given, as shadowleand --r2-offset
    }
    // 2. inclination experiments
    Proc paper;
    paper.bounds = Proc::Bounds::Raw;
    paper.d_const_m = res.d_const_m;
    paper.beta_model_deg = 0;
    Proc ours;
    ours.bounds = Proc::Bounds::HalfBin;
    ours.r1_add_m = 0.025;
    ours.d_const_m = res.d_resid_m;
    ours.gap_bins = 3;
    ours.beta_model_deg = b.beta_up_deg;
    for (int a = 0; a < 5; a++) {
        for (int pI = 0; pI < o.positions; pI++) {
            const double dist = o.positions == 1 ? 2.4 : 2.2 + 0.4 * pI / (o.positions - 1);
            for (int rep = 0; rep < o.reps; rep++) {
                const uint64_t seed = 7000 + static_cast<uint64_t>(a * 1000 + pI * 10 + rep);
                Scene s = realistic_scene(dist, res.angles[a], seed, o.frames, o.range_bins);
                s.smear_decay_db = o.smear_decay_db;
                s.speckle_static = o.speckle_static;
                if (o.hard) {
                    make_hard(s, hc, seed);
                }
                if (o.power_scale) {
                    scene_to_power_scale(s);
                }
                s.rotations += std::max(0, o.track_rotations);
                std::unique_ptr<PipelineEval> pipe;
                std::function<void(int, const uint8_t *, size_t)> on_bytes;
                if (o.extract == Extract::Pipeline) {
                    PipeCfg pc = pipe_cfg_for_scene(s);
                    pc.mask_frames = o.frames; // the window is the measurement's frames
                    pc.profile = o.pipe_profile ? 1 : 0;
                    pc.prior_r2_offset_um = res.pipe_r2_offset_um;
                    if (!res.have_pipe) {
                        res.pipe_cfg = pc;
                        res.have_pipe = true;
                    }
                    pipe.reset(new PipelineEval(pc));
                    on_bytes = [&pipe](int k, const uint8_t *d, size_t n) { pipe->feed(k, d, n); };
                }
                Frames f = run_frames(s, o.threads, thr, on_bytes);
                // the processing knows the board's installation, not the perturbed true one
                // (the truth row keeps the true alpha and bounds)
                f.gt.theta_deg = b.theta_deg(f.gt.azimuth);
                f.gt.beta_deg = b.beta_up_deg;
                if (pipe && f.have) {
                    pipe->finish();
                    realistic_pipe_add(*pipe, f.gt, res.pipe_cfg.assoc_az, o.pipe_last, pipe_az, res.pipe[a]);
                }
                done++;
                if (o.progress) {
                    std::fprintf(stderr, "\rsl-eval realistic: run %d/%d (pole %+d deg at %.2f m, rep %d)      ",
                                 done, total, res.angles[a], dist, rep + 1);
                }
                if (!f.have) {
                    continue;
                }
                const int n = static_cast<int>(f.mean.size());
                const Est ep = estimate_row(f.all.data(), n, f.gt, b, 0.5, lo, hi, paper, nullptr);
                const auto dm = deconv(f.mean);
                const Est eo = estimate_row(dm.data(), n, f.gt, b, 0.5, lo, hi, ours, nullptr);
                res.paper_style[a].add(ep, f.gt.alpha_deg);
                res.improved[a].add(eo, f.gt.alpha_deg);
                auto value = [](const Est &e) {
                    return e.flag == SL_INCLINE_AMBIGUOUS ? e.amb_bound_deg : e.alpha_deg;
                };
                if (ep.extracted && (ep.flag == SL_INCLINE_VALID || ep.flag == SL_INCLINE_AMBIGUOUS)) {
                    res.est_paper[a].push_back(value(ep));
                }
                if (eo.extracted && (eo.flag == SL_INCLINE_VALID || eo.flag == SL_INCLINE_AMBIGUOUS)) {
                    res.est_improved[a].push_back(value(eo));
                }
            }
        }
        res.paper_style[a].finish();
        res.improved[a].finish();
    }
    if (o.progress) {
        std::fprintf(stderr, "\n");
    }
    res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return res;
}

namespace {

void mean_sd(const std::vector<double> &v, double *mean, double *sd)
{
    *mean = *sd = std::nan("");
    if (v.empty()) {
        return;
    }
    double s = 0;
    for (double x : v) {
        s += x;
    }
    *mean = s / static_cast<double>(v.size());
    double q = 0;
    for (double x : v) {
        q += (x - *mean) * (x - *mean);
    }
    *sd = v.size() > 1 ? std::sqrt(q / static_cast<double>(v.size() - 1)) : 0.0;
}

// Per angle and processing path: mean / std of the error, median / p90 of |error|, missed and
// ambiguous rates (of measurements; ambiguous estimates count as the bound in the errors).
struct ErrSummary {
    double mean = std::nan(""), std = std::nan(""), median_abs = std::nan(""), p90_abs = std::nan("");
    size_t n = 0;
    double missed_rate = std::nan(""), ambiguous_rate = std::nan("");
};

ErrSummary summarize(const std::vector<double> &err, int runs, int missed, int ambiguous)
{
    ErrSummary s;
    mean_sd(err, &s.mean, &s.std);
    s.n = err.size();
    std::vector<double> e;
    for (double x : err) {
        e.push_back(std::fabs(x));
    }
    std::sort(e.begin(), e.end());
    auto q = [&e](double t) {
        return e.empty() ? std::nan("")
                         : e[std::min(e.size() - 1, static_cast<size_t>(std::ceil(t * static_cast<double>(e.size())) - 1))];
    };
    s.median_abs = q(0.5);
    s.p90_abs = q(0.9);
    if (runs > 0) {
        s.missed_rate = static_cast<double>(missed) / runs;
        s.ambiguous_rate = static_cast<double>(ambiguous) / runs;
    }
    return s;
}

ErrSummary summarize(const ErrStats &e) { return summarize(e.err, e.rows, e.missed, e.ambiguous); }

ErrSummary summarize(const RealisticPipe &p, int angle)
{
    std::vector<double> err;
    for (double x : p.raw) {
        err.push_back(x - angle);
    }
    // ambiguous: measurements whose matched targets were AMBIGUOUS in majority
    const int matched = p.valid + p.ambiguous + p.other;
    ErrSummary s = summarize(err, p.runs, p.runs - p.detected, 0);
    s.ambiguous_rate = matched > 0 ? static_cast<double>(p.ambiguous) / matched : std::nan("");
    return s;
}

std::string jsummary(const ErrSummary &s)
{
    std::ostringstream o;
    o << "{\"mean\": " << jnum(s.mean) << ", \"std\": " << jnum(s.std) << ", \"median_abs\": " << jnum(s.median_abs)
      << ", \"p90_abs\": " << jnum(s.p90_abs) << ", \"n\": " << s.n << ", \"missed_rate\": " << jnum(s.missed_rate)
      << ", \"ambiguous_rate\": " << jnum(s.ambiguous_rate) << "}";
    return o.str();
}

void print_summary_line(std::FILE *f, const char *what, const ErrSummary &s)
{
    std::fprintf(f, "       | %-17s mean %+6.2f std %5.2f | |err| median %5.2f p90 %5.2f | n %3zu | missed %3.0f %% | ambiguous %3.0f %%\n",
                 what, s.mean, s.std, s.median_abs, s.p90_abs, s.n, 100.0 * s.missed_rate, 100.0 * s.ambiguous_rate);
}

void print_hard(std::FILE *f, const RealisticResult &r)
{
    if (!r.hard) {
        return;
    }
    const HardCondition &h = r.hard_cond;
    std::fprintf(f,
                 "HARD condition (--hard): two-component smear (%.1f dB/bin + a %.1f dB/bin component at %.0f dB,\n"
                 "both decays %.1f dB/bin slower per 20 dB of level), a one-bin front skirt at %.0f dB; per-frame\n"
                 "speckle %.1f dB on the frozen 2 dB; azimuth jitter +-%.2f deg; segmented pole (%.0f mm\n"
                 "reflectors every %.0f mm, %.2f between); true theta +-%.1f deg, beta +-%.1f deg, H +-%.0f mm per\n"
                 "measurement (uniform; the processing uses the board); the pole placed by hand: bearing\n"
                 "+-%.2f deg off the azimuth, return +-%.1f dB; calibration on vertical poles at 1.75-%.2f and\n"
                 "%.2f-3.00 m with their own seeds (the paper's constant d from the near ones).\n\n",
                 h.fast_decay_db, h.slow_decay_db, h.slow_db, h.amp_decay_db, h.front_db, h.speckle_frame_db, h.az_jitter_deg,
                 h.segment_fill_m * 1e3, h.segment_m * 1e3, h.segment_gap, h.theta_tol_deg, h.beta_tol_deg,
                 h.height_tol_m * 1e3, h.bearing_tol_deg, h.refl_tol_db, h.calib_gap_lo_m, h.calib_gap_hi_m);
}

// Share of errors (in units of their stated sigma) within 1 / 2 / 3 sigma (%), and the largest.
struct SigmaCover {
    double within[3] = {std::nan(""), std::nan(""), std::nan("")};
    double max = std::nan("");
};

SigmaCover sigma_cover(const std::vector<double> &z)
{
    SigmaCover c;
    if (z.empty()) {
        return c;
    }
    c.max = 0;
    int n[3] = {0, 0, 0};
    for (double x : z) {
        const double a = std::fabs(x);
        c.max = std::max(c.max, a);
        for (int k = 0; k < 3; k++) {
            n[k] += a <= k + 1 ? 1 : 0;
        }
    }
    for (int k = 0; k < 3; k++) {
        c.within[k] = 100.0 * n[k] / static_cast<double>(z.size());
    }
    return c;
}

void print_realistic_pipeline(std::FILE *f, const RealisticResult &r)
{
    const PipeCfg &c = r.pipe_cfg;
    std::fprintf(f,
                 "Realistic bench (paper Table II) -- %s.\n"
                 "Board %s (core table: elongation d(r) keyed by observed r2, beta +3 deg), speed 0 (static\n"
                 "bench: board n = %u), detection beam width %.2f deg (the simulated azimuth window), threshold %s;\n"
                 "%d positions x %d repetitions per angle, %d frames per measurement. Per measurement: the\n"
                 "targets of the last %d rotation(s) at the pole's azimuth (+-%d az), their mean raw alpha\n"
                 "(ambiguous = the bound (beta - theta)/2), and the tracker's filtered alpha after the last one.\n\n",
                 kPipelineLabel, c.board.c_str(), r.pipe_mask_frames, c.beam_deg,
                 c.threshold >= 0 ? std::to_string(c.threshold).c_str() : "board's", r.positions, r.reps, r.frames,
                 r.pipe_last, c.assoc_az);
    if (r.power_scale) {
        std::fprintf(f, "Rendered on the sensor's value scale (--power-scale: 0.5 dB per value, exponential noise;\n"
                        "the effects' dB halved so their values per bin are the same).\n\n");
    }
    if (r.pipe_resid_samples != 0U) {
        std::fprintf(f, "Walk-end offset of r2 learned by the range profile on the calibration poles (upright, own\n"
                        "seeds): %+.1f mm from %u upright residuals; every measurement starts from it (--cold: none).\n\n",
                     r.pipe_r2_offset_um / 1000.0, static_cast<unsigned>(r.pipe_resid_samples));
    } else if (r.pipe_r2_offset_um != 0) {
        std::fprintf(f, "Walk-end offset of r2: %+.1f mm given (--r2-offset), no calibration pass.\n\n",
                     r.pipe_r2_offset_um / 1000.0);
    } else {
        std::fprintf(f, "Walk-end offset of r2: none (--cold, or the mask's bounds).\n\n");
    }
    std::fprintf(f, "%-6s | %-18s | %-33s | %-33s | %-8s | %s\n", "true", "paper mean / std",
                 "core pipeline raw: mean / std", "core pipeline filtered: mean / std", "detected",
                 "rotations with target / checked; targets valid/amb/other; unmatched; n_eff");
    for (int a = 0; a < 5; a++) {
        const RealisticPipe &p = r.pipe[a];
        double rm, rs, fm, fs;
        mean_sd(p.raw, &rm, &rs);
        mean_sd(p.filt, &fm, &fs);
        std::fprintf(f, "%+4d   | %+7.2f / %5.2f    | %+7.2f / %5.2f (err %+6.2f) n=%-3zu | %+7.2f / %5.2f (err %+6.2f) n=%-3zu | %3d/%-3d  | %d/%d; %d/%d/%d; %d; %d-%d\n",
                     r.angles[a], r.paper_mean[a], r.paper_std[a], rm, rs, rm - r.angles[a], p.raw.size(), fm, fs,
                     fm - r.angles[a], p.filt.size(), p.detected, p.runs, p.rot_detected, p.rot_checked, p.valid,
                     p.ambiguous, p.other, p.unmatched, p.frames_eff_min, p.frames_eff_max);
    }
    double sm = 0, ss = 0;
    for (int a = 0; a < 5; a++) {
        double m, sd;
        mean_sd(r.pipe[a].raw, &m, &sd);
        sm += std::fabs(m - r.angles[a]) / 5;
        ss += sd / 5;
    }
    std::fprintf(f, "\ncore pipeline raw: average |mean error| / std over the 5 angles: %.2f / %.2f deg\n", sm, ss);
    std::fprintf(f, "core pipeline raw |error| per angle: median / p90 (deg); missed = measurements without a\n"
                    "target at the pole; ambiguous = matched targets flagged AMBIGUOUS\n");
    for (int a = 0; a < 5; a++) {
        const RealisticPipe &p = r.pipe[a];
        std::vector<double> e;
        for (double x : p.raw) {
            e.push_back(std::fabs(x - r.angles[a]));
        }
        std::sort(e.begin(), e.end());
        auto q = [&e](double t) {
            return e.empty() ? std::nan("")
                             : e[std::min(e.size() - 1, static_cast<size_t>(std::ceil(t * static_cast<double>(e.size())) - 1))];
        };
        const int matched = p.valid + p.ambiguous + p.other;
        std::fprintf(f, "%+4d   | median %5.2f  p90 %5.2f | missed %d/%d (%.0f %%) | ambiguous %d/%d (%.0f %%)\n", r.angles[a],
                     q(0.5), q(0.9), p.runs - p.detected, p.runs,
                     p.runs > 0 ? 100.0 * (p.runs - p.detected) / p.runs : 0.0, p.ambiguous, matched,
                     matched > 0 ? 100.0 * p.ambiguous / matched : 0.0);
    }
    // Is the stated sigma honest? |error| in units of the sigma each value carried: a normal
    // error is within 1 / 2 / 3 sigma 68 / 95 / 99.7 % of the time.
    std::fprintf(f, "core pipeline sigma: |error| / stated sigma, %% within 1 / 2 / 3 sigma and the largest; targets\n"
                    "(VALID, each rotation) and the tracker's filtered alpha (what PoleLean carries)\n");
    for (int a = 0; a < 5; a++) {
        const RealisticPipe &p = r.pipe[a];
        std::vector<double> fz;
        for (size_t i = 0; i < p.filt.size(); i++) {
            if (p.filt_sigma[i] > 0) {
                fz.push_back((p.filt[i] - p.filt_truth[i]) / p.filt_sigma[i]);
            }
        }
        const SigmaCover tc = sigma_cover(p.raw_z), fc = sigma_cover(fz);
        std::fprintf(f, "%+4d   | targets %3.0f / %3.0f / %3.0f %%, max %5.1f (n %zu) | tracker %3.0f / %3.0f / %3.0f %%, max %5.1f (n %zu)\n",
                     r.angles[a], tc.within[0], tc.within[1], tc.within[2], tc.max, p.raw_z.size(), fc.within[0],
                     fc.within[1], fc.within[2], fc.max, fz.size());
    }
}

} // namespace

void print_realistic(std::FILE *f, const RealisticResult &r)
{
    if (r.have_pipe) {
        print_hard(f, r);
        print_realistic_pipeline(f, r);
        if (!r.bbox_table) {
            std::fprintf(f, "run time %.1f s\n", r.seconds);
            return;
        }
        std::fprintf(f, "\n");
    }
    std::fprintf(f,
                 "Realistic bench (paper Table II) -- bbox extraction (detection pipeline not used).\n"
                 "Board paper-bench (theta 26 deg, H 1.45 m, beta +3); 5 cm pole, base at 2.2-2.6 m\n"
                 "(%d positions x %d repetitions per angle), %d frames per measurement; simulated\n"
                 "CTS350-X effects: measured emission, exponential range smear, frozen speckle (2 dB),\n"
                 "noise floor (log-magnitude 8-bit, ~35%% zeros), near-field leakage. Ambiguous estimates\n"
                 "(rho below the model's bound) count as the bound (beta - theta)/2, as in the paper.\n"
                 "Paper processing: n-frame consistency mask, raw bounds, r2 -= d (constant, calibrated\n"
                 "on vertical poles at 1.75-%.2f m: d = %.3f m), beta = 0.\n"
                 "Ours: n-frame mean, threshold %d, smear deconvolved (exponential kernel calibrated on the\n"
                 "vertical poles' tails: %.2f values/bin, a = %.3f; a bin is kept when >= 12%% of its power is\n"
                 "its own; gaps <= 3 bins merged), half-bin on both bounds, r1 += R, r2 -= residual offset %.3f m (same\n"
                 "calibration set), beta = +3. (For reference, a linear d(r2_obs) fit would give d = %.3f m\n"
                 "at %.2f m .. %.3f m at %.2f m.)\n\n",
                 r.positions, r.reps, r.frames, r.hard ? r.hard_cond.calib_gap_lo_m : 2.30, r.d_const_m, 40, r.tail_slope, r.kernel_a, r.d_resid_m,
                 r.d_table.empty() ? 0.0 : r.d_table.front().d_m, r.d_table.empty() ? 0.0 : r.d_table.front().range_m,
                 r.d_table.empty() ? 0.0 : r.d_table.back().d_m, r.d_table.empty() ? 0.0 : r.d_table.back().range_m);
    print_hard(f, r);
    std::fprintf(f, "%-6s | %-18s | %-34s | %-34s\n", "true", "paper mean / std", "ours, paper processing: mean / std",
                 "ours, improved: mean / std");
    for (int a = 0; a < 5; a++) {
        auto m = [](const std::vector<double> &v, double *mean, double *sd) {
            *mean = *sd = std::nan("");
            if (v.empty()) {
                return;
            }
            double s = 0;
            for (double x : v) {
                s += x;
            }
            *mean = s / v.size();
            double q = 0;
            for (double x : v) {
                q += (x - *mean) * (x - *mean);
            }
            *sd = v.size() > 1 ? std::sqrt(q / (v.size() - 1)) : 0.0;
        };
        double pm, ps, om, os;
        m(r.est_paper[a], &pm, &ps);
        m(r.est_improved[a], &om, &os);
        std::fprintf(f, "%+4d   | %+7.2f / %5.2f    | %+7.2f / %5.2f (err %+6.2f) n=%-3zu | %+7.2f / %5.2f (err %+6.2f) n=%-3zu\n",
                     r.angles[a], r.paper_mean[a], r.paper_std[a], pm, ps, r.paper_style[a].mean,
                     r.est_paper[a].size(), om, os, r.improved[a].mean, r.est_improved[a].size());
        if (r.paper_style[a].missed + r.paper_style[a].ambiguous + r.paper_style[a].invalid +
                r.improved[a].missed + r.improved[a].ambiguous + r.improved[a].invalid >
            0) {
            std::fprintf(f, "       | paper processing: missed %d, ambiguous %d (clipped to the bound), invalid %d; ours: missed %d, ambiguous %d (clipped), invalid %d\n",
                         r.paper_style[a].missed, r.paper_style[a].ambiguous, r.paper_style[a].invalid,
                         r.improved[a].missed, r.improved[a].ambiguous, r.improved[a].invalid);
        }
        print_summary_line(f, "paper processing:", summarize(r.paper_style[a]));
        print_summary_line(f, "research path:", summarize(r.improved[a]));
        if (r.have_pipe) {
            print_summary_line(f, "pipeline (raw):", summarize(r.pipe[a], r.angles[a]));
        }
    }
    double sm = 0, ss = 0, pm = 0, ps = 0;
    for (int a = 0; a < 5; a++) {
        sm += std::fabs(r.improved[a].mean) / 5;
        ss += r.improved[a].std / 5;
        pm += std::fabs(r.paper_style[a].mean) / 5;
        ps += r.paper_style[a].std / 5;
    }
    std::fprintf(f, "\naverage |mean error| / std over the 5 angles: paper processing %.2f / %.2f deg, ours %.2f / %.2f deg\n",
                 pm, ps, sm, ss);
    std::fprintf(f, "run time %.1f s\n", r.seconds);
}

std::string realistic_json(const RealisticResult &r)
{
    std::ostringstream o;
    o << "{\n  \"schema\": \"shadowlean-eval-realistic/1\",\n  \"experiment\": \"realistic\",\n  \"extraction\": \"bbox extraction (detection pipeline not used)\",\n"
      << "  \"condition\": \"" << (r.hard ? "hard" : "table2") << "\",\n"
      << "  \"frames\": " << r.frames << ", \"positions\": " << r.positions << ", \"reps\": " << r.reps << ",\n"
      << "  \"d_const_m\": " << jnum(r.d_const_m) << ", \"tail_slope\": " << jnum(r.tail_slope)
      << ", \"kernel_a\": " << jnum(r.kernel_a) << ", \"d_resid_m\": " << jnum(r.d_resid_m)
      << ",\n  \"d_table\": [";
    for (size_t i = 0; i < r.d_table.size(); i++) {
        o << (i ? ", " : "") << "[" << jnum(r.d_table[i].range_m) << ", " << jnum(r.d_table[i].d_m) << "]";
    }
    o << "],\n  \"rows\": [\n";
    for (int a = 0; a < 5 && r.bbox_table; a++) {
        o << "    {\"true_deg\": " << r.angles[a] << ", \"paper\": {\"mean\": " << r.paper_mean[a]
          << ", \"std\": " << r.paper_std[a] << "}, \"paper_processing\": " << jstats(r.paper_style[a])
          << ", \"improved\": " << jstats(r.improved[a]) << ",\n     \"summary\": {\"paper_processing\": "
          << jsummary(summarize(r.paper_style[a])) << ", \"improved\": " << jsummary(summarize(r.improved[a])) << "}}"
          << (a < 4 ? "," : "") << "\n";
    }
    o << "  ]";
    if (r.have_pipe) {
        o << ",\n  \"pipeline\": {\"label\": \"" << kPipelineLabel << "\", \"board\": \"" << r.pipe_cfg.board
          << "\", \"beam_deg\": " << jnum(r.pipe_cfg.beam_deg) << ", \"mask_frames\": " << r.pipe_mask_frames
          << ", \"r2_offset_um\": " << r.pipe_r2_offset_um << ", \"resid_samples\": " << r.pipe_resid_samples
          << ", \"last_rotations\": " << r.pipe_last << ", \"rows\": [\n";
        for (int a = 0; a < 5; a++) {
            const RealisticPipe &p = r.pipe[a];
            double rm, rs, fm, fs;
            mean_sd(p.raw, &rm, &rs);
            mean_sd(p.filt, &fm, &fs);
            o << "    {\"true_deg\": " << r.angles[a] << ", \"raw\": {\"mean\": " << jnum(rm) << ", \"std\": " << jnum(rs)
              << ", \"n\": " << p.raw.size() << "}, \"filtered\": {\"mean\": " << jnum(fm) << ", \"std\": " << jnum(fs)
              << ", \"n\": " << p.filt.size() << "}, \"runs\": " << p.runs << ", \"detected\": " << p.detected
              << ", \"valid\": " << p.valid << ", \"ambiguous\": " << p.ambiguous << ", \"other\": " << p.other
              << ", \"unmatched\": " << p.unmatched << ", \"rotations_checked\": " << p.rot_checked
              << ", \"rotations_detected\": " << p.rot_detected << ", \"frames_eff\": [" << p.frames_eff_min << ", "
              << p.frames_eff_max << "],\n     \"summary\": " << jsummary(summarize(p, r.angles[a])) << "}"
              << (a < 4 ? "," : "") << "\n";
        }
        o << "  ]}";
    }
    if (r.hard) {
        const HardCondition &h = r.hard_cond;
        o << ",\n  \"hard\": {\"fast_decay_db\": " << jnum(h.fast_decay_db) << ", \"slow_db\": " << jnum(h.slow_db)
          << ", \"slow_decay_db\": " << jnum(h.slow_decay_db) << ", \"amp_decay_db\": " << jnum(h.amp_decay_db)
          << ", \"front_db\": " << jnum(h.front_db) << ", \"speckle_frame_db\": " << jnum(h.speckle_frame_db)
          << ", \"az_jitter_deg\": " << jnum(h.az_jitter_deg) << ", \"segment_m\": " << jnum(h.segment_m)
          << ", \"segment_fill_m\": " << jnum(h.segment_fill_m) << ", \"segment_gap\": " << jnum(h.segment_gap)
          << ", \"theta_tol_deg\": " << jnum(h.theta_tol_deg) << ", \"beta_tol_deg\": " << jnum(h.beta_tol_deg)
          << ", \"height_tol_m\": " << jnum(h.height_tol_m) << ", \"bearing_tol_deg\": " << jnum(h.bearing_tol_deg)
          << ", \"refl_tol_db\": " << jnum(h.refl_tol_db) << ", \"calib_gap_m\": [" << jnum(h.calib_gap_lo_m) << ", "
          << jnum(h.calib_gap_hi_m) << "]}";
    }
    o << ",\n  \"seconds\": " << jnum(r.seconds) << "\n}\n";
    return o.str();
}

} // namespace sl
