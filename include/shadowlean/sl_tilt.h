// SPDX-License-Identifier: MIT
/// @file sl_tilt.h
/// @brief 3D pole tilt from the in-plane inclinations seen while driving (MATH.md s.5).
///
/// One rotation measures only the pole's IN-PLANE inclination alpha: the angle of the
/// pole's direction projected onto the vertical half-plane of the azimuth it is seen on.
/// Write the pole as the line P(z) = B + z (tx, ty, 1) (B its base on the ground, z the
/// height, t = (tx, ty) = tan(psi) (cos phi, sin phi) its tilt vector: psi the tilt from
/// vertical, phi the direction its top leans towards). Seen from a radar in horizontal
/// direction e = (cos a, sin a) (a = bearing of the pole from the radar), MATH.md s.5 gives
///
///     tan(alpha) = -(t . e) = -(tx cos a + ty sin a)                        (1)
///
/// (alpha > 0 = top towards the radar). (1) is LINEAR in t: every rotation on which a
/// tracked pole is measured adds one equation, and as the vehicle moves the bearing a turns,
/// so two or more bearings determine t, hence psi and phi, by weighted least squares. No
/// single rotation can: it sees only the component of t along e.
///
/// The fold. The estimator cannot tell a pole leaning away by more than (theta - beta)/2
/// from its mirror image alpha' = beta - theta - alpha (sl_incline.h, "The fold"): every
/// measurement on branch 2 (or on branch 1 within two sigma of the seam, where noise crosses
/// it) has two candidate values of tan alpha. Which ones are mirrored is not free: by (1),
/// tan(alpha) = -|t| cos(a - phi) is below the fold on ONE arc of bearings around phi, so in
/// bearing order the mirrored measurements form one circular interval of the mirrorable
/// ones. The fit scores every interval (m (m - 1) + 2 candidates for m mirrorable
/// measurements) in O(1) each from prefix sums without a division, solves the best
/// SL_TILT_TOP_K of them exactly from the measurements and keeps the smallest chi-square.
/// Over a pass the true tilt traces a sinusoid in bearing and its mirror does not, so the
/// residuals separate them; when another candidate with a different answer (|t - t'| >
/// max(0.035, 0.3 |t|)) fits within the ambiguity margin of the best, the quality is
/// SL_TILT_AMBIGUOUS and the result carries BOTH readings: the best as the result's own
/// fields, the other (the best-scoring candidate with a different answer, solved exactly
/// from the measurements like the best) in `mirror`, with its own sigmas and base. An
/// AMBIGUOUS result is an answer, not a failure: the pole is one of the two readings
/// (`sl-eval driveby` scores it so), and a consumer that acts on the lean must consider
/// both (LeanWarning takes the more dangerous one: sl_pipeline.h, "LeanWarning and the
/// fitted tilt"). Never a confident wrong direction.
///
/// The ambiguity margin. The stated sigmas are a floor, not the whole error: quantised range
/// bounds, the group's union extent and the azimuth cells add errors that are neither
/// Gaussian nor independent from one rotation to the next, and a pass's residuals often
/// exceed the sigmas (the fits of `sl-eval driveby`: chi2 / dof median 1.0, 90th percentile
/// 1.9, 99th 5.6). A fixed chi-square difference of 9 would let the mirror win by chance
/// with a margin of 10-17 and say FITTED (`test_issue12_recorded_mirror_passes_are_not_fitted`). So the
/// chi-square's scale is estimated from the best fit's residuals, s^2 = max(1, chi2 / dof)
/// (dof = n - 2; the same inflation as the sigmas), and with a scale estimated from dof
/// residuals the 3-sigma test of the difference is Student's t: margin = t^2 s^2, t^2 the
/// square of t_dof at the normal's 3-sigma tail (0.00135): 85.0 at dof 3, 13.2 at 14, 10.7
/// at 30, tending to SL_TILT_AMBIGUITY_CHI2_Q8 / 256 = 9. A best fit that is INCONSISTENT is
/// reported as such before the ambiguity (its scale estimate would call every reading
/// ambiguous).
///
/// The stated sigmas. The errors of the measurements drift slowly along a pass (a quantised
/// bound stays in its bin over several rotations, the union extent and the azimuth cells
/// change stepwise), so they do not average out as 1 / sqrt(n); over a few close bearings
/// such a drift is a trend in bearing, which the fit turns into tilt across the line of sight
/// (a fit of a pass's first 5-14 observations can read several degrees, or the direction
/// tens of degrees, off by many of its covariance sigmas). So each direction p's variance is
/// the covariance of the fit (inflated by chi2 / dof > 1) PLUS the square of the worst-case
/// effect of a bias of up to each measurement's own sigma, shaped in any way over the pass:
///     b_p = sum(w_k sigma_k |p' M^-1 e_k|) / W     (M the weighted bearing moment matrix)
/// which shrinks only with the bearing spread, not with n. Tilt and direction sigmas are the
/// linearisations d psi = d|t| / (1 + |t|^2), d phi = d(across t) / |t|, valid only when |t|
/// is well above its error in every direction: when |t| < 3 x the larger of the two sigmas
/// the direction is not determined (`phi_sigma_cdeg` = 18000) and the tilt sigma is the
/// larger one (a small fitted |t| can hide a tilt across it). With that, a FITTED result
/// holds the truth within 3 of its stated sigmas (tests/core/test_tilt.c: every prefix of
/// 400 quantised-bound drive-bys, 1 of 3,938 at 3.01 sigma; the sweep's 4,322 FITTED fits:
/// none outside, 667 before); the price is sigmas 2-3x what a pass's final errors are.
///
/// Position. Each measurement also places the pole: with the fitted in-plane inclination
/// alpha^ (from (1)) and the inner bound r1, the pole's horizontal distance at radar height
/// is d0 = r1 (cos beta + sin beta tan alpha^) when alpha^ >= beta (r1 is the top of the
/// visible segment, on the +beta ray) and d0 = r1 sqrt(1 + tan^2 alpha^) otherwise (r1 is
/// the perpendicular foot); the point R + d0 e (R = radar position) is averaged over the
/// measurements, and the base is that point minus H (tx, ty).
///
/// Frames and units. Positions are in micrometres in an odometry frame chosen by the caller
/// (x forward at the start, y left, CCW angles; `sl_tilt_odom_t` integrates one in fixed
/// point), usually made relative to an anchor near the track so that int32 is ample
/// (+-2147 m). Angles are sl_bam32_t (2^32 per turn) or 0.01 deg (`_cdeg`). Q formats are in
/// the names: `_q15` int16 value x 2^15, `_q12` int16 value x 2^12 (tan, |tan| < 8),
/// `_q16` uint16 value x 2^16 (sigma of tan alpha), `_q24` int32 value x 2^24.
///
/// Accuracy (tests/core/test_tilt.c): given the same stored measurements, the fixed-point
/// tilt vector agrees with a double-precision implementation of the same estimator to
/// 2e-5 in tan units (0.001 deg; measured 2.6e-6), the base to 2 mm (measured 0.74 mm); an
/// AMBIGUOUS result's other reading agrees with the double solution of its reading of the
/// fold to the same 2e-5.
/// Against simulated drive-bys (bearing quantised to 0.9 deg azimuth cells): tilt within
/// 1 deg and direction within 10 deg for tilts of 5-20 deg, also for poles leaning away
/// beyond the fold; with 1 deg of noise on every alpha, within 2 deg and 20 deg.
///
/// Cost: sl_tilt_obs_make O(1) (three sine/cosine lookups, two 64-bit divisions);
/// sl_tilt_fit O(n + m^2) (about 30 multiply-adds per interval candidate) plus O(TOP_K x n)
/// for the exact solves, divisions only outside the candidate loop except for candidates
/// near the best; each measurement's weight is recomputed where it is read (one 32-bit
/// division), and an AMBIGUOUS fit solves and reports its second reading too (O(n)). No
/// state, no allocation: pure functions, reentrant, any context.
#ifndef SHADOWLEAN_SL_TILT_H
#define SHADOWLEAN_SL_TILT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_err.h"
#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_incline.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Largest number of measurements one fit takes (more is an argument error).
#define SL_TILT_MAX_OBS 32U
/// Candidates solved exactly after the O(1) scoring pass.
#define SL_TILT_TOP_K 8U
/// Fewest measurements for a fit (two unknowns plus redundancy for the residual).
#define SL_TILT_MIN_OBS 5U
/// Bearing spread needed: the determinant of the weighted normalised bearing moment matrix
/// (= the weighted variance of the bearing, for small spreads, in rad^2) must reach
/// sin^2(3 deg) = 0.00274 (Q30: 2,941,974). Below it: SL_TILT_INSUFFICIENT_MOTION.
#define SL_TILT_MIN_SPREAD_Q30 2941974
/// Two hypotheses are told apart when their chi-square values differ by at least 9
/// (3 sigma) with known sigmas, Q8: the large-dof limit of the ambiguity margin (file
/// comment, "The ambiguity margin"); 16 x this is the smallest window searched for
/// `chi2_other_q8`.
#define SL_TILT_AMBIGUITY_CHI2_Q8 (9 * 256)
/// A fit whose chi-square per degree of freedom exceeds 25 (residuals 5x the stated
/// sigmas) is reported as SL_TILT_INCONSISTENT (not a straight pole, a wrong association,
/// or wrong motion input), Q8.
#define SL_TILT_INCONSISTENT_CHI2_Q8 (25 * 256)

/// What a fit says.
typedef enum sl_tilt_quality {
    SL_TILT_FITTED = 0,              ///< tilt, direction and base from a well-posed fit
    SL_TILT_AMBIGUOUS = 1,           ///< the mirror hypothesis fits as well: the pole is
                                     ///< the reported reading or `mirror` (both set)
    SL_TILT_INSUFFICIENT_MOTION = 2, ///< the bearings do not spread enough (parked, or the
                                     ///< pole straight ahead); nothing but `n_obs` is set
    SL_TILT_TOO_FEW = 3,             ///< fewer than SL_TILT_MIN_OBS measurements
    SL_TILT_INCONSISTENT = 4,        ///< residuals far above the measurement sigmas
} sl_tilt_quality_t;

/// One measurement of a tracked pole on one rotation, prepared for the fit by
/// sl_tilt_obs_make() (24 bytes; a per-track ring of these is the history).
typedef struct sl_tilt_obs {
    int32_t radar_x_um;     ///< radar position, odometry frame (anchor-relative)
    int32_t radar_y_um;
    uint32_t r1_um;         ///< inner bound of the run (corrected), slant range
    sl_q15_t cos_a_q15;     ///< cos of the pole's bearing from the radar, odometry frame
    sl_q15_t sin_a_q15;     ///< sin of it
    int16_t tan_q12;        ///< tan(alpha) as measured
    int16_t tan_mirror_q12; ///< tan(beta - theta - alpha), the fold's other reading
                            ///< (== tan_q12 when not mirrorable)
    uint16_t sigma_q16;     ///< 1-sigma of tan(alpha), >= SL_TILT_SIGMA_MIN_Q16
    uint8_t mirrorable;     ///< 1: measured on branch 2 (the fold applies)
    uint8_t mark;           ///< SL_TILT_OBS_* bits (set by sl_tiltobs.h, 0 from
                            ///< sl_tilt_obs_make; sl_tilt_fit does not read them)
} sl_tilt_obs_t;

/// `sl_tilt_obs_t.mark`: recorded while its track was not confirmed (sl_tiltobs.h, 2.).
#define SL_TILT_OBS_UNCONFIRMED 0x01U
/// `sl_tilt_obs_t.mark`: its target had a ramp at a bound (SL_TARGET_RAMP): the bound lies
/// anywhere along it; in the fit, but not among the SL_TILT_MIN_OBS a result needs
/// (sl_tiltobs.h).
#define SL_TILT_OBS_RAMP 0x02U

/// Smallest sigma of tan(alpha) a measurement is credited with: 0.001 (0.06 deg), so one
/// measurement can never dominate a fit through an optimistic sigma (Q16: 66).
#define SL_TILT_SIGMA_MIN_Q16 66U

/// Builds a measurement. `alpha_bam32`, `alpha_sigma_cdeg` and `branch` come from
/// sl_incline_estimate() on this rotation (VALID results only); `geom` is the azimuth's
/// geometry entry (for the fold); `bearing_bam32` the pole's bearing from the radar in the
/// odometry frame (CCW from +x); `r1_um` the corrected inner bound.
/// Returns false (and leaves `out` zeroed) when the inputs cannot be a measurement: NULL
/// pointers, |alpha| >= 80 deg, r1 == 0. O(1).
bool sl_tilt_obs_make(sl_tilt_obs_t *out, int32_t radar_x_um, int32_t radar_y_um,
                      sl_bam32_t bearing_bam32, uint32_t r1_um, sl_bam32_t alpha_bam32,
                      uint16_t alpha_sigma_cdeg, uint8_t branch, const sl_incline_geom_t *geom);

/// Scratch memory of a fit (caller-owned, so the fit's stack stays small: ~150 bytes).
/// 416 bytes; one per pipeline is enough (fits do not overlap).
typedef struct sl_tilt_work {
    int32_t du_q24[SL_TILT_MAX_OBS];  ///< per mirrorable measurement, in bearing order:
    int32_t dv_q24[SL_TILT_MAX_OBS];  ///< the change of mean(w c T), mean(w s T),
    int32_t ds_q24[SL_TILT_MAX_OBS];  ///< mean(w T^2) when it is read as its mirror
    uint8_t order[SL_TILT_MAX_OBS];   ///< mirrorable measurements sorted by bearing
} sl_tilt_work_t;

/// Fit parameters (board constants).
typedef struct sl_tilt_params {
    uint32_t radar_height_um; ///< H: radar above flat ground
    sl_q30_t cos_beta_q30;    ///< upper emission bound beta (sl_incline_geom_t has them)
    sl_q30_t sin_beta_q30;
} sl_tilt_params_t;

/// One reading of a fit: tilt vector, tilt, direction, their sigmas and the base (the
/// fields of the same names in `sl_tilt_result_t`). 28 bytes.
typedef struct sl_tilt_reading {
    int32_t tx_q24;           ///< tilt vector, odometry frame, Q24
    int32_t ty_q24;
    int32_t psi_cdeg;         ///< tilt from vertical, 0..9000
    int32_t phi_cdeg;         ///< direction the top leans towards, CCW from +x, 0..35999
    uint16_t psi_sigma_cdeg;  ///< 1-sigma (file comment, "The stated sigmas")
    uint16_t phi_sigma_cdeg;  ///< 1-sigma; 18000 when not oriented
    int32_t base_x_um;        ///< pole base on the ground, odometry frame
    int32_t base_y_um;
} sl_tilt_reading_t;

/// Result of a fit. Every field is set on every call (0 when not meaningful).
typedef struct sl_tilt_result {
    uint8_t quality;          ///< sl_tilt_quality_t
    uint8_t n_obs;            ///< measurements used
    uint8_t n_mirrored;       ///< branch-2 measurements the fit read as the fold's mirror
    uint8_t reserved;
    uint32_t mirrored_mask;   ///< bit k: measurement k was read as the fold's mirror
    int32_t tx_q24;           ///< tilt vector t = tan(psi) (cos phi, sin phi), odometry frame
    int32_t ty_q24;
    int32_t psi_cdeg;         ///< tilt from vertical, 0..9000
    int32_t phi_cdeg;         ///< direction the top leans towards, CCW from +x, 0..35999
    uint16_t psi_sigma_cdeg;  ///< 1-sigma: covariance of the fit (inflated by chi2/dof > 1)
                              ///< plus the bias bound (file comment, "The stated sigmas")
    uint16_t phi_sigma_cdeg;  ///< 1-sigma, the same; 18000 when |t| < 3 sigma (not oriented)
    int32_t base_x_um;        ///< pole base on the ground, odometry frame
    int32_t base_y_um;
    uint32_t chi2_q8;         ///< chi-square of the reported fit, Q8
    uint32_t chi2_other_q8;   ///< chi-square of the other hypothesis (UINT32_MAX if none
                              ///< within max(16 x 9, the ambiguity margin) of the best)
    sl_tilt_reading_t mirror; ///< SL_TILT_AMBIGUOUS only: the other hypothesis's reading,
                              ///< its sigmas inflated by its own chi2 / dof (all 0 otherwise)
    uint32_t mirror_mask;     ///< SL_TILT_AMBIGUOUS only: its reading of the fold (as
                              ///< `mirrored_mask`)
} sl_tilt_result_t;

/// Fits tilt, direction and base to `n` measurements (any order). `n` <= SL_TILT_MAX_OBS.
/// @return SL_OK, or SL_ERR_ARG (NULL pointers, n > SL_TILT_MAX_OBS); the quality says
///         whether the numbers mean something.
/// Cost: see the file comment (O(n + m^2)). Pure; `work` is scratch only.
sl_err_t sl_tilt_fit(const sl_tilt_obs_t *obs, size_t n, const sl_tilt_params_t *prm,
                     sl_tilt_work_t *work, sl_tilt_result_t *out);

/// Sine and cosine of a binary angle, Q30, from a 257-entry quarter-wave table with linear
/// interpolation: |error| <= 5e-6. O(1), no division.
void sl_tilt_sincos_q30(sl_bam32_t a, sl_q30_t *s, sl_q30_t *c);

/// Fixed-point odometry: the vehicle's pose integrated from speed and yaw rate.
typedef struct sl_tilt_odom {
    int64_t x_um;     ///< position, odometry frame
    int64_t y_um;
    sl_bam32_t yaw;   ///< heading, CCW from +x
} sl_tilt_odom_t;

/// Advances the pose by `dt_us` at `speed_mm_s` (forward, signed) and `yaw_rate_mdeg_s`
/// (CCW positive, milli-degrees per second): midpoint rule (the heading at half the step),
/// so a constant-rate arc closes to < 1e-4 relative over a turn. dt_us is clamped to 1 s
/// (a longer gap is a stale input, not motion). O(1).
void sl_tilt_odom_step(sl_tilt_odom_t *o, int32_t speed_mm_s, int32_t yaw_rate_mdeg_s,
                       uint32_t dt_us);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_TILT_H
