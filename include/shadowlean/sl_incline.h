// SPDX-License-Identifier: MIT
/// @file sl_incline.h
/// @brief Inclination estimator (MATH.md s.2-3): (r1, r2, per-azimuth geometry) -> alpha.
///
/// A slender pole crossing the visible wedge [-theta, +beta] of one azimuth returns one
/// run of range bins from `r1` (inner bound) to `r2` (outer bound). With the ratio
/// `rho = r2 / r1` and the azimuth's geometry (theta = opening angle of the chassis
/// shadow, beta = upper emission bound) the pole's in-plane inclination is
///
///     branch 1 (rho >= 1/cos(t+b), alpha >= beta):
///         alpha = atan2(rho cos t - cos b, rho sin t + sin b)
///     branch 2 (1/cos((t+b)/2) <= rho < 1/cos(t+b), (b-t)/2 <= alpha < beta):
///         alpha = atan2(sqrt(rho^2 - 1), 1) - t
///     ambiguous (rho < 1/cos((t+b)/2)): below the smallest ratio the model produces; no number.
///
/// `alpha > 0` means the top of the pole leans TOWARDS the radar. Its uncertainty is the
/// first-order propagation of MATH.md s.3, generalised to beta (see sl_incline_estimate).
///
/// The fold (read this before trusting negative angles). rho is smallest, rho_amb =
/// 1/cos((t+b)/2), at alpha = (beta - theta)/2. A pole leaning away by MORE than that is
/// not flagged: its rho = 1/cos(beta - alpha) is >= rho_amb, so it reads as its mirror image
/// about (beta - theta)/2, alpha_read = beta - theta - alpha (theta 26, beta 3: a pole at
/// -14 deg reads -9 deg). Ratios below rho_amb cannot come from the ideal model at all; they
/// come from noise around the fold point (or a broken assumption), and are reported as
/// SL_INCLINE_AMBIGUOUS rather than as a number. Only the change of alpha over the vehicle's
/// motion, or a prior, separates the two sides of the fold.
///
/// Everything here is integer-only (no float anywhere in the core); the host builds the
/// geometry entries with `sl::make_geom()` (host_tools/board/sl_geom.h), which is the only
/// code path used by both the board table generator and the `sl-alpha` CLI.
///
/// Units: ranges are plain unsigned integers. The estimator only uses the ratio r2/r1 and
/// the ratio sigma_r/r1, so any unit works as long as r1, r2 and sigma_r share it; the
/// names say `_um` because the detection pipeline passes micrometres (r <= 4294 m).
///
/// Accuracy against double-precision libm (the oracle takes the exact theta, beta and r2/r1;
/// so this includes the rounding of the geometry entry and of rho):
/// - `alpha_bam32` (before the final rounding): |error| <= 7.3e-5 deg measured, asserted
///   <= 1e-4 deg; dominated by the linear interpolation of the atan table (1.24e-6 rad).
/// - `alpha_cdeg` (rounded half up to 0.01 deg): |error| <= 0.00507 deg measured, asserted
///   <= 0.01 deg.
/// - `sigma_cdeg`: |error| <= 0.5 cdeg + 1e-4 x sigma, asserted (measured: <= 0.5 cdeg +
///   1e-4 x sigma - 0.0007 cdeg), against the same linearised formula evaluated in double.
///   By analysis the error before the rounding to 1 cdeg is ~1e-5 relative + 2^-12 cdeg.
/// - ambiguity: the test is `rho_q28 < geom->rho_amb_q28`, exact in integers;
///   rho_amb_q28 = round(2^28/cos((t+b)/2)), so the classification matches the real bound to
///   one LSB of rho (3.7e-9).
/// Measured by tests/core/test_incline.c (201945 points: theta 5..34 deg step 0.5, beta 0..5
/// step 1, rho from the ambiguity bound to 10 incl. +-8 LSB around the seam; plus 18000
/// random micrometre pairs over the whole domain), tests/host/alpha/test_geom.cpp (191461 random
/// points over the whole domain) and tests/host/alpha/check_alpha.py (sl-alpha, 5000 lines).
///
/// Resources (Cortex-M0, arm-none-eabi-gcc -Os): code + table 2500 bytes of flash (the atan
/// table is 1028 of them), no RAM; stack <= 200 bytes (sl_incline_estimate's frame 88 B +
/// sl_incline_atan2_bam32 32 B or sl_fx_isqrt64 40 B + libgcc's 64-bit division).
#ifndef SHADOWLEAN_SL_INCLINE_H
#define SHADOWLEAN_SL_INCLINE_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_config.h"
#include "shadowlean/sl_fx.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Precomputed geometry of one azimuth (one entry of a board's theta table). Written by the
/// host (`sl::make_geom()` in host_tools/board/sl_geom.h, used by `sl-tables` and
/// `sl-alpha`): every field is the exact value rounded ONCE to nearest, ties away from
/// zero (llround). theta = opening angle of the chassis shadow (depression of the grazing
/// ray), beta = upper emission bound (elevation). Read-only to the core.
///
/// Q formats: `_q30` = sl_q30_t, int32 Q2.30 (value x 2^30); `_q28` = sl_uq4_28_t, uint32
/// UQ4.28 (value x 2^28, max < 16; saturated to UINT32_MAX when the value is >= 16);
/// `_bam32` = sl_bam32_t, 2^32 per turn (negative angles in two's complement).
/// Size: 40 bytes per entry (400 azimuths: 16000 bytes of flash).
typedef struct sl_incline_geom {
    sl_q30_t cos_theta_q30;    ///< cos(theta)
    sl_q30_t sin_theta_q30;    ///< sin(theta)
    sl_q30_t cos_beta_q30;     ///< cos(beta)
    sl_q30_t sin_beta_q30;     ///< sin(beta)
    sl_q30_t cos_tb_q30;       ///< cos(theta + beta)
    sl_q30_t sin_tb_q30;       ///< sin(theta + beta)
    sl_uq4_28_t rho_amb_q28;   ///< 1 / cos((theta + beta) / 2): below it, ambiguous
    sl_uq4_28_t rho_seam_q28;  ///< 1 / cos(theta + beta): branch seam (alpha = beta)
    sl_bam32_t theta_bam32;    ///< theta as a binary angle
    sl_bam32_t beta_bam32;     ///< beta as a binary angle (two's complement if negative)
} sl_incline_geom_t;

/// Supported geometry (the estimator returns SL_INCLINE_OUT_OF_DOMAIN outside it; the
/// limits are compared in bam32, i.e. exact to 1 LSB = 8.4e-8 deg):
/// theta in [1, 60] deg, beta in [-10, +15] deg, theta + beta in [1, 75] deg.
/// (theta + beta <= 75 deg keeps rho_seam <= 3.87 < SL_INCLINE_RHO_MAX; >= 1 deg bounds the
/// sensitivities used by sigma.)
#define SL_INCLINE_THETA_MIN_CDEG 100
#define SL_INCLINE_THETA_MAX_CDEG 6000
#define SL_INCLINE_BETA_MIN_CDEG (-1000)
#define SL_INCLINE_BETA_MAX_CDEG 1500
#define SL_INCLINE_WEDGE_MIN_CDEG 100   ///< minimum theta + beta
#define SL_INCLINE_WEDGE_MAX_CDEG 7500  ///< maximum theta + beta

/// Largest supported range ratio r2/r1 (UQ4.28): 10. Above it: SL_INCLINE_OUT_OF_DOMAIN.
#define SL_INCLINE_RHO_MAX_Q28 ((sl_uq4_28_t)10U << 28)

/// Outcome of one estimate.
typedef enum sl_incline_flag {
    SL_INCLINE_VALID = 0,         ///< alpha and sigma are set
    SL_INCLINE_AMBIGUOUS = 1,     ///< rho < rho_amb = 1/cos((theta+beta)/2), the model's
                                  ///< minimum, reached at the fold alpha = (beta-theta)/2
                                  ///< (see "The fold" above); no number
    SL_INCLINE_INVALID = 2,       ///< r1 == 0 or r1 >= r2 (not a run of bins)
    SL_INCLINE_OUT_OF_DOMAIN = 3, ///< rho > SL_INCLINE_RHO_MAX_Q28, or geometry outside
                                  ///< the supported domain (see SL_INCLINE_THETA_MIN_CDEG)
} sl_incline_flag_t;

/// Which closed form produced alpha.
typedef enum sl_incline_branch {
    SL_INCLINE_BRANCH_NONE = 0, ///< flag != SL_INCLINE_VALID
    SL_INCLINE_BRANCH_1 = 1,    ///< rho >= rho_seam: r1 is the top end (alpha >= beta)
    SL_INCLINE_BRANCH_2 = 2,    ///< rho_amb <= rho < rho_seam: r1 is the perpendicular foot
} sl_incline_branch_t;

/// Result of sl_incline_estimate(). Plain value; all fields are set on every call.
typedef struct sl_incline_result {
    int32_t alpha_cdeg;      ///< inclination, 0.01 deg, > 0 = top leans towards the radar;
                             ///< round half up of alpha_bam32. 0 unless VALID.
    sl_bam32_t alpha_bam32;  ///< same, full resolution (signed two's complement). 0 unless VALID.
    sl_uq4_28_t rho_q28;     ///< floor(r2 * 2^28 / r1), UQ4.28; saturated to UINT32_MAX when
                             ///< r2/r1 >= 16; 0 when INVALID or the geometry is out of domain.
    uint16_t sigma_cdeg;     ///< 1-sigma uncertainty of alpha, 0.01 deg, rounded half up,
                             ///< saturated at UINT16_MAX (also when sigma_r >= r1). 0 unless VALID.
    uint8_t branch;          ///< sl_incline_branch_t
    uint8_t flag;            ///< sl_incline_flag_t
} sl_incline_result_t;

/// Estimate the inclination of a pole from the bounds of its return on one azimuth.
///
/// @param r1_um   inner bound of the run (any unit shared with r2 and sigma_r; the
///                pipeline passes micrometres, after half-bin/elongation/radius corrections)
/// @param r2_um   outer bound, same unit; must be > r1_um
/// @param geom    the azimuth's geometry entry (borrowed for the call only); must not be
///                NULL (SL_ASSERT: caller bug)
/// @param sigma_r_um        1-sigma uncertainty of each bound, same unit as r1 (both
///                          bounds assumed independent with this sigma), MATH.md s.3:
///                          sigma_rho = (sigma_r / r1) * sqrt(1 + rho^2)
/// @param sigma_theta_cdeg  1-sigma calibration uncertainty of theta, 0.01 deg
/// @return the result; `flag` says which fields mean something.
///
/// Checks, in this order: geometry outside the domain -> OUT_OF_DOMAIN; r1 == 0 or
/// r1 >= r2 -> INVALID; rho_q28 > SL_INCLINE_RHO_MAX_Q28 -> OUT_OF_DOMAIN;
/// rho_q28 < rho_amb_q28 -> AMBIGUOUS; rho_q28 >= rho_seam_q28 -> branch 1; else branch 2.
///
/// sigma (radians, converted to 0.01 deg):
///   sigma_alpha = sqrt((d alpha/d rho * sigma_rho)^2 + (d alpha/d theta * sigma_theta)^2)
///   branch 1, with Q = N^2 + D^2 = rho^2 - 2 rho cos(t+b) + 1:
///     d alpha/d rho = sin(t+b) / Q,  d alpha/d theta = -rho (rho - cos(t+b)) / Q
///   branch 2: d alpha/d rho = 1 / (rho sqrt(rho^2 - 1)),  d alpha/d theta = -1
///
/// Internals: rho by one 64-bit division; branch 1 forms N, D in Q58 (64-bit) and narrows
/// them to Q27; branch 2 takes sl_fx_isqrt64(rho_q28^2 - 2^56) (Q28); both go through
/// sl_incline_atan2_bam32(). sigma uses Q56 for Q, Q24 for the derivatives, Q12 cdeg for
/// the two terms and sl_fx_isqrt64 for the root.
/// Cost: O(1): 4-5 64-bit divisions, 2 (branch 1) or 3 (branch 2) sl_fx_isqrt64 calls
/// (the bulk of the time), ~12 64-bit multiplies (measured counts: docs/PERFORMANCE.md,
/// "Core modules"). Stack: see the file banner.
/// Pure function: reentrant, no state, callable from any context.
sl_incline_result_t sl_incline_estimate(uint32_t r1_um, uint32_t r2_um,
                                        const sl_incline_geom_t *geom, uint32_t sigma_r_um,
                                        uint16_t sigma_theta_cdeg);

/// The one range sigma that gives sl_incline_estimate() the same sigma of rho as
/// independent bounds with sigmas `s1_um` (r1) and `s2_um` (r2): sigma_rho^2 = (s2^2 +
/// rho^2 s1^2) / r1^2 = s^2 (1 + rho^2) / r1^2, so s = sqrt(w s2^2 + (1 - w) s1^2) with
/// w = r1^2 / (r1^2 + r2^2) (Q16, ranges taken in whole mm; floor of the square root; the
/// same sigma back when s1 == s2). Pure, one 64-bit division and one isqrt.
uint32_t sl_incline_bounds_sigma_um(uint32_t r1_um, uint32_t r2_um, uint32_t s1_um,
                                    uint32_t s2_um);

/// sl_incline_bounds_sigma_um for bounds whose errors correlate with `corr_q15` (Q15, in
/// [-32767, 32767]; a fit of both bounds to one return, sl_rfit.h): sigma_rho^2 r1^2 = s2^2 +
/// rho^2 s1^2 - 2 rho corr s1 s2, so s^2 = w s2^2 + (1 - w) s1^2 - 2 corr s1 s2 r1 r2 /
/// (r1^2 + r2^2) (at least 0). corr 0, or a sigma above 2^24 um: sl_incline_bounds_sigma_um.
/// Pure, two 64-bit divisions and two isqrt. With SL_CFG_FIT only (its one user).
#if SL_CFG_FIT
uint32_t sl_incline_bounds_sigma_corr_um(uint32_t r1_um, uint32_t r2_um, uint32_t s1_um,
                                         uint32_t s2_um, int32_t corr_q15);
#endif

/// True when `geom` is inside the supported domain (see SL_INCLINE_THETA_MIN_CDEG): the
/// same test sl_incline_estimate() applies. Checks theta_bam32 and beta_bam32 and that
/// 2^28 < rho_amb_q28 <= rho_seam_q28 < UINT32_MAX. NULL -> false. O(1).
bool sl_incline_geom_ok(const sl_incline_geom_t *geom);

/// Four-quadrant arctangent atan2(y, x) as a binary angle (2^32 = one turn; as int32 it
/// is in [-180, 180) deg). Inputs: any int32 pair of the same scale (INT32_MIN is fine);
/// atan2(0, 0) = 0. Octant reduction, then a 257-entry table of atan(i/256) (bam32,
/// rounded to nearest) with linear interpolation in a Q30 ratio.
/// Error: <= 1.3e-6 rad (7.5e-5 deg, about 890 bam32 LSB) for all inputs; exact (== the
/// rounded table value) at ratios i/256. Cost: O(1), one 64-bit division, one 64-bit
/// multiply. Table ROM: 1028 bytes. Stack: a few words.
sl_bam32_t sl_incline_atan2_bam32(int32_t y, int32_t x);

/// A bam32 angle (signed interpretation) in 0.01 deg, rounded half up:
/// round(angle * 36000 / 2^32). O(1).
int32_t sl_incline_bam32_to_cdeg(sl_bam32_t angle);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_INCLINE_H
