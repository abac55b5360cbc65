// SPDX-License-Identifier: MIT
/// @file sl_rfit.h
/// @brief A pole's range bounds fitted with a forward model of its return: the pole's own
/// range-intensity profile over [a, b] convolved with the radar's range response, plus the
/// noise floor, against the observed power profile, with the bounds' covariance from the
/// fit's information.
///
/// ## Model (sample coordinates: sample k of the window sees range k, in bins)
///   mu_k = f_k + A m_k(a, b),   m_k(a, b) = integral over [a, b] of g(x) R(k - x) dx
/// - R: the response of sl_response.h (linear, interpolated between taps; its integral is
///   the cumulative table, so a uniform piece of g costs two table reads per sample);
/// - g: the pole's power per unit range, normalised to integrate to 1 over [a, b]:
///   `SL_RFIT_UNIFORM` (flat) or `SL_RFIT_FOOT` (a straight slender target whose closest
///   point to the radar is at range a, with origin + a the absolute range: g(x) is
///   proportional to x / sqrt(x^2 - a^2), more power per bin near the closest point, where the
///   range changes slowest along the pole; approximated by SL_RFIT_PIECES uniform pieces of
///   equal mass);
/// - f_k: the noise floor's mean power per sample (given), A >= 0 the level (fitted).
///
/// ## Objective and solution
/// Speckle makes each independent look's power exponential around mu (Gamma with L looks when
/// L independent looks are averaged), so the fit minimises the negative log-likelihood of the
/// samples taken as independent
///   J = L sum_k (ln mu_k + y_k / mu_k)
/// where y_k is the observed mean power and L = `looks` the independent looks averaged into
/// it (rotations of a scene whose speckle changes, neighbouring rows inside the beam; 1 for
/// one frozen draw however many rotations were summed: the caller says which). Neighbouring
/// bins are not independent draws (one draw spans the response's correlation length); that
/// enters the covariance below, not the estimate.
/// Solved by Fisher scoring (Gauss-Newton with weights 1 / mu^2, the model's Jacobian
/// analytic: moving a bound moves a piece's end and its width), the level A a third
/// parameter (its logarithm) of each step;
/// start: the moments of the power above the floor (centroid and variance less the
/// response's own), or the caller's bounds (`warm`: an earlier fit of the same return, a few
/// iterations instead of many); steps halved while J grows (at most SL_RFIT_HALVINGS), at most
/// SL_RFIT_ITERS iterations. a and b are kept inside the window and b >= a + 1/8 bin.
///
/// ## Uncertainty and quality
/// The covariance of (a, b), the level profiled out, is the sandwich N^-1 M N^-1 of that
/// independence likelihood: N its Fisher information, M the score's covariance with the
/// speckle's correlation between bins (`rho2_q15` of sl_response.h): `sigma_a_q8`,
/// `sigma_b_q8`, `corr_q15`. Where the data do not pin a bound down (a return shorter than
/// the response is wide, one frozen speckle draw, a weak return), the information is small
/// and the sigma wide: a caller propagates it to the lean's sigma and sends the lean with
/// it, never as a confident number.
/// Where the return departs from the model by more than its noise explains (the deviance D
/// below above its expectation E), the bounds are known less well than the model says: both
/// sigmas are scaled by sqrt(D / E) (quasi-likelihood dispersion), never below the model's.
/// `quality`:
/// - SL_RFIT_OK: converged, the deviance within what the noise explains;
/// - SL_RFIT_OUT_OF_MODEL: the deviance D = 2 L sum (y/mu - 1 - ln(y/mu)) exceeds
///   E + 6 sqrt(V) + 8, E = n (1 + 1 / (6 L)) its expectation under the model and
///   V = 2 n `s4` its variance with the bins' correlation, or one sample lies below the
///   model by more than speckle makes over the window (y / mu < 1e-3 ncorr / n: one look's
///   power falls below x of its mean with probability ~x, over n / ncorr independent cells):
///   a return the model does not explain (two targets, a cut-off return, clutter); the bounds
///   are returned but must not be trusted;
/// - SL_RFIT_NO_SIGNAL: no power above the floor to fit (the sums of y - f <= 0);
/// - SL_RFIT_NOT_CONVERGED: the iteration limit was reached with steps still above 1/64 bin.
///
/// ## Numbers
/// Inputs are uint32 powers in any common binary scale (the caller's: sl_vscale_power);
/// the fit normalises them internally (peak ~2^20), so only ratios matter. Positions are
/// bins in Q8 from the window's sample 0; `origin_q8` (the absolute range of sample 0 in
/// bins, Q8) is read only by SL_RFIT_FOOT. All arithmetic is integer (64-bit products and
/// divisions); results are bit-identical on every target.
///
/// ## Ownership and cost
/// Pure: reads the caller's arrays and `sl_response_t`, writes `*out`; no allocation, no
/// state, reentrant. Work: at most SL_RFIT_ITERS Fisher steps, each one pass over the n
/// samples evaluating the model and its analytic derivatives by a and b (SL_RFIT_PIECES + 1
/// reads of the cumulative response and of the response each), then up to
/// SL_RFIT_HALVINGS + 1 objective evaluations (the model, one 64-bit division and one log
/// per sample); the covariance one more pass with the speckle correlation's lags
/// (<= SL_RESP_TAPS per sample). Stack and work memory: sl_rfit_ws(). Flash:
/// firmware/size_budget.txt.
#ifndef SHADOWLEAN_SL_RFIT_H
#define SHADOWLEAN_SL_RFIT_H

#include <stdint.h>

#include "shadowlean/sl_err.h"
#include "shadowlean/sl_response.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Samples per fit window at most.
#ifndef SL_RFIT_MAX_N
#define SL_RFIT_MAX_N 96
#endif
#define SL_RFIT_ITERS 16
#define SL_RFIT_HALVINGS 8
#define SL_RFIT_PIECES 8

typedef enum sl_rfit_shape {
    SL_RFIT_UNIFORM = 0, ///< flat power per unit range over [a, b]
    SL_RFIT_FOOT = 1,    ///< a slender straight target whose closest point is at a
} sl_rfit_shape_t;

typedef enum sl_rfit_quality {
    SL_RFIT_OK = 0,
    SL_RFIT_OUT_OF_MODEL = 1,
    SL_RFIT_NO_SIGNAL = 2,
    SL_RFIT_NOT_CONVERGED = 3,
} sl_rfit_quality_t;

/// One fit's input. Arrays are borrowed for the call.
typedef struct sl_rfit_in {
    const uint32_t *y;    ///< observed mean power per sample, n values
    const uint32_t *f;    ///< floor's mean power per sample (NULL: `floor` for all)
    uint32_t floor;       ///< used when f == NULL (must be > 0 then)
    uint16_t n;           ///< samples, [8, SL_RFIT_MAX_N]
    uint16_t looks_q8;    ///< independent looks averaged into y, Q8 (>= 256)
    uint8_t shape;        ///< sl_rfit_shape_t
    uint32_t origin_q8;   ///< absolute range of sample 0 in bins, Q8 (SL_RFIT_FOOT)
    uint8_t warm;         ///< 1: start from [a0_q8, b0_q8] (an earlier fit of the same
                          ///< return) instead of the moments; the level from the moments
    int32_t a0_q8, b0_q8; ///< the warm start, bins Q8 from sample 0 (kept inside the window)
} sl_rfit_in_t;

typedef struct sl_rfit_out {
    int32_t a_q8, b_q8;         ///< the bounds, bins Q8 from sample 0
    uint32_t sigma_a_q8;        ///< 1-sigma of a, bins Q8 (saturating)
    uint32_t sigma_b_q8;        ///< 1-sigma of b, bins Q8 (saturating)
    int32_t corr_q15;           ///< correlation of a and b, Q15
    uint32_t level;             ///< A: the return's total power (y's scale x bins)
    int64_t nll_q16;            ///< J at the optimum, nats Q16
    uint32_t dev_q8;            ///< the deviance D, Q8
    uint32_t dev_limit_q8;      ///< its OUT_OF_MODEL limit, Q8
    uint32_t dispersion_q8;     ///< D over its expectation E, at least 1, Q8: the sigmas
                                ///< above are scaled by its square root
    uint8_t quality;            ///< sl_rfit_quality_t
    uint8_t iters;              ///< iterations used
    uint16_t evals;             ///< objective evaluations used
} sl_rfit_out_t;

/// Work memory of one fit: the model's pieces, the normal equations and the covariance
/// pass's ring of SL_RESP_TAPS samples (layout private to rfit.c). Caller-owned; borrowed
/// for the call of sl_rfit_ws().
#define SL_RFIT_WS_BYTES (344U + 4U * (unsigned)SL_RESP_TAPS)
typedef struct sl_rfit_ws {
    uint64_t u[(SL_RFIT_WS_BYTES + 7U) / 8U];
} sl_rfit_ws_t;

/// Fits [a, b]. SL_ERR_ARG on NULL pointers, n out of range, looks < 1, or a zero floor;
/// otherwise SL_OK with `out->quality` saying what the result is worth. Its work memory
/// (sl_rfit_ws_t, 508 B with the default 41 taps) is on the stack: see sl_rfit_ws().
sl_err_t sl_rfit(const sl_response_t *r, const sl_rfit_in_t *in, sl_rfit_out_t *out);

/// sl_rfit() with the work memory in `ws` (the caller's, e.g. static): the same results bit
/// for bit, the stack that much shallower (a pipeline's deepest call chain). SL_ERR_ARG also
/// for a NULL `ws`.
sl_err_t sl_rfit_ws(const sl_response_t *r, const sl_rfit_in_t *in, sl_rfit_ws_t *ws,
                    sl_rfit_out_t *out);

/// The model profile m_k(a, b) for k < n (Q16 of the total: sum over all k of an interval
/// well inside the window is 65536 x area). Exposed for tests and the host tools. SL_ERR_ARG
/// on NULL or n out of range.
sl_err_t sl_rfit_model(const sl_response_t *r, uint8_t shape, uint32_t origin_q8, int32_t a_q8,
                       int32_t b_q8, uint16_t n, uint32_t *m_q16);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_RFIT_H
