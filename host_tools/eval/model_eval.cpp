// SPDX-License-Identifier: MIT
// model_eval.cpp: sl-eval run --extract model (model_eval.h).
#include "model_eval.h"

#include <algorithm>
#include <cmath>

#include "sim_eval.h"

extern "C" {
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_rfit.h"
}

namespace sl {

namespace {

double power_of(const sl_vscale_t &s, uint8_t v)
{
    if (s.kind == SL_VSCALE_LINEAR) {
        return v;
    }
    const double t = v / (s.cpo_q8 / 256.0);
    const double e = std::floor(t);
    return std::ldexp(1.0 + (t - e), static_cast<int>(e));
}

Est estimate(double r1, double r2, const GtRow &g)
{
    return core_estimate(r1, r2, g.theta_deg, g.beta_deg, 0.0, 0.0);
}

} // namespace

ModelEval::ModelEval(const std::vector<GtRow> &truth, double bin_m, const ModelEvalOptions &o)
    : o_(o), bin_m_(bin_m)
{
    double far = 0;
    for (const GtRow &g : truth) {
        if (g.nominal == 1 && g.valid == 1) {
            want_[{g.rotation, g.azimuth}] = &g;
            far = std::max(far, g.r2_m);
        }
    }
    learn_min_bin_ = static_cast<int>(std::ceil((far + 2.0) / bin_m_));
    (void)sl_response_init(&resp_, &o_.scale, nullptr, nullptr);
}

void ModelEval::row(int rotation, int azimuth, const uint8_t *v, uint32_t n)
{
    if (o_.learn && static_cast<int>(n) > learn_min_bin_ + 2 * (SL_CFG_RESP_HALF + 32)) {
        (void)sl_response_learn_row(&resp_, v, n, static_cast<uint32_t>(learn_min_bin_), n);
    }
    const auto it = want_.find({rotation, azimuth});
    if (it == want_.end()) {
        return;
    }
    Acc &a = acc_[{it->second->pole, azimuth}];
    a.gt = it->second;
    if (a.sum.size() < n) {
        a.sum.resize(n, 0.0);
    }
    for (uint32_t k = 0; k < n; k++) {
        a.sum[k] += power_of(o_.scale, v[k]);
    }
    a.rows++;
}

std::map<int, ModelPoleResult> ModelEval::finish(std::string &note)
{
    if (o_.learn) {
        (void)sl_response_update(&resp_);
    }
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "range response: %s (%u isolated peaks), half-power width %.2f bins",
                  resp_.source == SL_RESPONSE_LEARNED ? "learned from the capture"
                                                      : "the CTS350-X prior",
                  resp_.learn_n, sl_response_hpw_q8(&resp_) / 256.0);
    note = buf;
    std::map<int, ModelPoleResult> out;
    for (auto &kv : acc_) {
        const Acc &a = kv.second;
        const GtRow &g = *a.gt;
        ModelPoleResult &pr = out[g.pole];
        const int nb = static_cast<int>(a.sum.size());
        std::vector<double> mean(a.sum.size());
        for (int k = 0; k < nb; k++) {
            mean[static_cast<size_t>(k)] = a.sum[static_cast<size_t>(k)] / a.rows;
        }
        const int lo = std::max(0, static_cast<int>(std::floor((g.r1_surf_m - 1.0) / bin_m_)));
        const int hi = std::min(nb - 1, static_cast<int>(std::ceil((g.r2_m + 1.0) / bin_m_)));
        int pk = lo;
        for (int k = lo; k <= hi; k++) {
            pk = mean[static_cast<size_t>(k)] > mean[static_cast<size_t>(pk)] ? k : pk;
        }
        const int n = std::min<int>(SL_RFIT_MAX_N, nb);
        const int start = std::max(0, std::min(pk - n / 2, nb - n));
        double peak = 0;
        for (int k = 0; k < n; k++) {
            peak = std::max(peak, mean[static_cast<size_t>(start + k)]);
        }
        if (peak <= 0) {
            pr.fits++;
            pr.no_signal++;
            continue;
        }
        // the floor: the learned band's mean noise power, else a tenth of the window's
        // lowest decile (a noise-free capture: a floor far below every return)
        double floor_p = 0;
        const int32_t flp = sl_response_floor_lp(&resp_, static_cast<uint32_t>(start + n / 2));
        if (o_.learn && flp != INT32_MIN) {
            floor_p = std::exp2(flp / 256.0); // lp is log2 of power on either scale
        } else {
            std::vector<double> w(mean.begin() + start, mean.begin() + start + n);
            std::sort(w.begin(), w.end());
            floor_p = w[static_cast<size_t>(n / 10)];
        }
        floor_p = std::max(floor_p, peak * 1e-6);
        const double s = 1048576.0 / peak;
        std::vector<uint32_t> y(static_cast<size_t>(n));
        for (int k = 0; k < n; k++) {
            y[static_cast<size_t>(k)] =
                static_cast<uint32_t>(std::lround(mean[static_cast<size_t>(start + k)] * s));
        }
        sl_rfit_in_t in{};
        in.y = y.data();
        in.floor = std::max<uint32_t>(1U, static_cast<uint32_t>(std::lround(floor_p * s)));
        in.n = static_cast<uint16_t>(n);
        in.looks_q8 = static_cast<uint16_t>(std::lround(std::max(1.0, o_.looks) * 256.0));
        in.shape = static_cast<uint8_t>(o_.shape);
        in.origin_q8 = static_cast<uint32_t>(std::lround((start + o_.offset_bins) * 256.0));
        if (in.origin_q8 == 0U) {
            in.origin_q8 = 1U;
        }
        sl_rfit_out_t f{};
        pr.fits++;
        if (sl_rfit(&resp_, &in, &f) != SL_OK || f.quality == SL_RFIT_NO_SIGNAL) {
            pr.no_signal++;
            continue;
        }
        pr.out_of_model += f.quality == SL_RFIT_OUT_OF_MODEL;
        pr.not_converged += f.quality == SL_RFIT_NOT_CONVERGED;
        pr.ok += f.quality == SL_RFIT_OK;
        const double r1 = (start + f.a_q8 / 256.0 + o_.offset_bins) * bin_m_;
        const double r2 = (start + f.b_q8 / 256.0 + o_.offset_bins) * bin_m_;
        const double s1 = f.sigma_a_q8 == UINT32_MAX ? 1e3 : f.sigma_a_q8 / 256.0 * bin_m_;
        const double s2 = f.sigma_b_q8 == UINT32_MAX ? 1e3 : f.sigma_b_q8 / 256.0 * bin_m_;
        const Est e = estimate(r1, r2, g);
        if (e.flag != SL_INCLINE_VALID) {
            pr.invalid++;
            continue;
        }
        // the bounds' covariance through the estimator (numerical derivatives)
        const double h = 0.1 * bin_m_;
        const Est e1 = estimate(r1 + h, r2, g), e2 = estimate(r1, r2 + h, g);
        const double d1 = e1.flag == SL_INCLINE_VALID ? (e1.alpha_deg - e.alpha_deg) / h : 0.0;
        const double d2 = e2.flag == SL_INCLINE_VALID ? (e2.alpha_deg - e.alpha_deg) / h : 0.0;
        const double rho = f.corr_q15 / 32768.0;
        const double var = d1 * d1 * s1 * s1 + d2 * d2 * s2 * s2 + 2 * rho * d1 * d2 * s1 * s2;
        const double sig = std::sqrt(std::max(var, 0.0));
        const double err = e.alpha_deg - g.alpha_deg;
        pr.err.push_back(err);
        pr.sigma.push_back(sig);
        pr.beyond += std::fabs(err) > 3 * sig + 0.5;
    }
    return out;
}

void print_model_eval(std::FILE *f, const std::map<int, ModelPoleResult> &r)
{
    for (const auto &kv : r) {
        const ModelPoleResult &p = kv.second;
        double mean = 0, rmse = 0, maxabs = 0;
        for (double e : p.err) {
            mean += e;
            rmse += e * e;
            maxabs = std::max(maxabs, std::fabs(e));
        }
        std::vector<double> sg = p.sigma;
        std::sort(sg.begin(), sg.end());
        const size_t n = p.err.size();
        std::fprintf(f,
                     "pole %d: fits %d (ok %d, out of model %d, not converged %d, no signal %d, "
                     "invalid %d): error mean %.3f rmse %.3f max %.3f deg, median sigma %.3f deg, "
                     "beyond 3 sigma + 0.5 deg %d\n",
                     kv.first, p.fits, p.ok, p.out_of_model, p.not_converged, p.no_signal,
                     p.invalid, n ? mean / n : 0.0, n ? std::sqrt(rmse / n) : 0.0, maxabs,
                     n ? sg[n / 2] : 0.0, p.beyond);
    }
}

} // namespace sl
