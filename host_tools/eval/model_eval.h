// SPDX-License-Identifier: MIT
// model_eval.h: bounds from the forward model of a pole's return (the core's sl_rfit over
// the core's sensor model, sl_response) on a simulated capture, against its ground truth:
// `sl-eval run CAPTURE GT.csv --extract model`.
//
// Per pole and azimuth the rows of every rotation are summed in power (the value scale of
// the scene: linear, or log with its values per octave), the sensor model learns the
// response and the floor from the capture's rows beyond the poles (or keeps the CTS350-X
// prior), and one fit per (pole, azimuth) reads [r1, r2] and their sigmas; the core
// estimator turns them into alpha, whose sigma is the bounds' propagated through the
// estimator. A window of SL_RFIT_MAX_N bins around the strongest bin within 1 m of the
// truth's extent holds the fit; sample k of the capture is range (k + offset) x bin.
#pragma once

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "sim_truth.h"

extern "C" {
#include "shadowlean/sl_response.h"
}

namespace sl {

struct ModelEvalOptions {
    sl_vscale_t scale{(uint8_t)SL_VSCALE_LINEAR, 0}; ///< the capture's value scale
    bool learn = true;           ///< learn the response and floor from the capture's rows
    double looks = 1;            ///< independent speckle looks in the sum (1: frozen)
    double offset_bins = 0.5;    ///< sample k's range is (k + offset_bins) x bin
    int shape = 1;               ///< sl_rfit_shape_t (default SL_RFIT_FOOT)
};

struct ModelPoleResult {
    int fits = 0, ok = 0, out_of_model = 0, no_signal = 0, not_converged = 0, invalid = 0;
    std::vector<double> err, sigma; ///< alpha - truth and the stated sigma, VALID estimates
    int beyond = 0;                 ///< |err| > 3 sigma + 0.5 deg
};

/// Accumulates the capture's rows (feed every decoded row), then fits.
class ModelEval {
public:
    ModelEval(const std::vector<GtRow> &truth, double bin_m, const ModelEvalOptions &o);
    void row(int rotation, int azimuth, const uint8_t *v, uint32_t n);
    std::map<int, ModelPoleResult> finish(std::string &response_note);

private:
    struct Acc {
        const GtRow *gt = nullptr;
        std::vector<double> sum; ///< power per bin, summed over rotations
        int rows = 0;
    };
    ModelEvalOptions o_;
    double bin_m_;
    std::map<std::pair<int, int>, const GtRow *> want_; ///< (rotation, azimuth) -> truth
    std::map<std::pair<int, int>, Acc> acc_;            ///< (pole, azimuth)
    sl_response_t resp_{};
    int learn_min_bin_ = 0;
};

/// Prints the per-pole lines of `sl-eval run --extract model`.
void print_model_eval(std::FILE *f, const std::map<int, ModelPoleResult> &r);

} // namespace sl
