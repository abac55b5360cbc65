// SPDX-License-Identifier: MIT
/// @file sl_tiltobs.h
/// @brief Per-track observation history for the 3D tilt fit (sl_tilt.h) while driving.
///
/// The pipeline owns one `sl_tiltobs_t`. Once per rotation, after the tracker's update:
///
/// 1. `sl_tiltobs_advance()`: the vehicle pose is integrated in fixed point
///    (`sl_tilt_odom_step`, midpoint rule) over the rotation's period from the motion input
///    of the rotation (speed, yaw rate). A rotation WITHOUT a valid motion input breaks the
///    odometry: every history is cleared (observations on either side of the gap would be
///    placed in inconsistent frames), and nothing is recorded until motion returns.
/// 2. `sl_tiltobs_update()`: for every live track matched on this rotation whose
///    target has a VALID inclination, one observation (`sl_tilt_obs_t`, 24 bytes) is pushed
///    into the track's ring: the radar's position and the pole's bearing in the odometry
///    frame AT THE CENTRE AZIMUTH OF THE TARGET'S DETECTION GROUP (az_first + (az_count -
///    1) / 2, in half azimuths; the pose interpolated linearly between the rotation's start
///    and end by that azimuth / azimuths: at 3 m/s a rotation is 0.75 m), and r1, alpha, its
///    sigma and branch (for the fold) of the group's UNION EXTENT: r1 less `ext_grow`'s low
///    nibble in bins, r2 plus its high nibble (elongation d(r2) re-evaluated there unless a
///    profile refined the bounds), a radius estimated from the width (RADIUS_WIDTH) taken
///    out of both (a leaning pole's bearing spread is not its diameter), alpha, sigma and
///    branch from sl_incline_estimate() on the geometry of the centre azimuth, with the
///    board's range sigma for both bounds, but two bins (sl_profile_coarse_sigma_um) for a
///    far bound where the range profile's walk over a smear tail stopped (SL_TARGET_WALKED:
///    the pole ends in that bin or the next; measured on the realistic drive-bys, r2 errors
///    of sd 0.68-0.73 bins against the board's 0.29; with the board's sigma, once evidence
///    claimed profile slots while moving, two early fits said FITTED 4.2 and 4.3 of their
///    sigmas off in direction, 20 and 24 deg; now the worst of the 96-pass sweeps' 772 /
///    624 FITTED fits is 1.34 / 1.87 sigma, magnitude / value scale). A saturated
///    nibble or bounds without a VALID alpha: not stored, counted in `stats.rejected`.
///    `board` must be the board detection uses (the pipeline's, with the radar's bin size). Positions are stored relative to the ring's anchor (the
///    vehicle position when the ring was opened) so int32 micrometres suffice. A ring
///    belongs to a track id; a ring whose track is gone (or whose slot now holds another
///    id) is freed. The ring keeps the newest SL_CFG_TILT_OBS_PER_TRACK observations.
///    Tracks beyond SL_CFG_TILT_TRACKS rings get none (counted in `stats.no_ring`).
///    **Before confirmation** (the tracker's `confirmed`: three consistent rotations by
///    default) a track's observations go into a PROVISIONAL ring: never fitted nor
///    reported, so nothing reaches CAN for an unconfirmed object; restarted when the track's
///    evidence falls back to 1 (an association inconsistent with a static object: what was
///    held may be another object's); taken from the track by a confirmed track that finds
///    no free ring (clutter's tentative tracks never starve a pole's history; counted in
///    `stats.evicted`); a provisional track itself only takes a free ring. When the track
///    confirms, the ring stops being provisional and is fitted with everything it holds:
///    a fast pass keeps the rotations before confirmation (at 3 m/s a pole is in the
///    shadow for about ten rotations, two of them before its track confirms). Those
///    observations carry SL_TILT_OBS_UNCONFIRMED (`sl_tilt_obs_t.mark`) and are trusted
///    less: a fit that comes out INCONSISTENT with them is redone without them, and they are dropped
///    (sl_tiltobs_fit_pending; `stats.unconfirmed_dropped`). A track that loses its
///    confirmation later (its evidence restarts) records nothing until it is confirmed
///    again (recording on through such gaps moved the curved-path test's inside pole from
///    -1.00 to -1.10 deg, outside the 1 deg bound, for 7 more passes of 432 in the sweep).
/// 3. `sl_tiltobs_fit_pending()`: the fit (`sl_tilt_fit`) runs on rings that received an
///    observation since their last fit, at most SL_CFG_TILT_FITS_PER_ROTATION per call
///    (round robin over the rings; the others keep their previous result until their turn;
///    an INCONSISTENT fit, or a FITTED one with a gross outlier, may drop its worst
///    observation and fit again, within the same bound, see "Outlier rejection" below):
///    never per azimuth. The pipeline calls it when control returns from the decoder (end
///    of sl_pipeline_feed / _on_msg / _finish), not from inside the rotation callback: the
///    fit's stack (~800 B on Cortex-M0) then does not add to the decoder's call chain. So a
///    rotation's PoleTilt carries the fit of the observations up to the previous rotation.
///    A FITTED or AMBIGUOUS result needs SL_TILT_MIN_OBS observations without a ramp at a
///    bound (SL_TILT_OBS_RAMP, from SL_TARGET_RAMP: the bound lies anywhere along the
///    ramp), else it is TOO_FEW. Observations with ramps stay in the fit (one rotation's
///    rows of a pole leaning towards the path often rise after r1, and excluding them loses
///    realistic drive-by passes), but a kernel the profile cannot read, whose every bound
///    is a ramp, makes no FITTED tilt of the few that are not (RadaRays' Maxwell-Boltzmann
///    kernel with a 10-bin front part would read poles of 10 deg far too steep). And a FITTED or AMBIGUOUS result
///    whose tilt exceeds `max_tan_q16` (the largest lean the detector keeps a pole for,
///    30 deg) is INCONSISTENT (`stats.too_steep`): no pole leans so far, and a kernel of
///    finite support whose ends the profile reads as the pole's puts r1 and r2 up to a
///    metre apart (a 50-bin Gaussian kernel: a fit of 45 deg or more at TiltSigma 0.4,
///    DANGER for a pole leaning 10 deg away).
///
/// Outputs per ring: `res` (the last fit, odometry frame relative to the anchor) and, via
/// `sl_tiltobs_vehicle()`, the tilt in the vehicle frame at the current pose (what the
/// PoleTilt CAN message carries: direction CCW from forward, base x forward / y left of the
/// vehicle origin) and the lean towards the vehicle's path (what LeanWarning uses); for an
/// AMBIGUOUS fit the same of its other reading via `sl_tiltobs_vehicle_mirror()` (PoleTilt
/// MIRROR; LeanWarning takes the more dangerous of the two).
///
/// Units: um, bam32 (2^32 per turn), cdeg (0.01 deg). No allocation, no float; every array
/// is inside the struct. RAM: SL_CFG_TILT_TRACKS x (SL_CFG_TILT_OBS_PER_TRACK x 24 + 104)
/// + 544 bytes (x86-64: firmware configuration 4 x 16: 2,496 B; host default 8 x 32: 7,520 B).
/// Cost per rotation: O(tracks x targets) for the matching (only for updated tracks) + O(1)
/// per observation (three table sine/cosine, two 64-bit divisions) + at most
/// SL_CFG_TILT_FITS_PER_ROTATION fits (sl_tilt.h: O(n + m^2)), each of 8 observations or
/// more followed by the outlier test (O(n): three 64-bit divisions per observation for its
/// deleted residual). Not reentrant per instance.
#ifndef SHADOWLEAN_SL_TILTOBS_H
#define SHADOWLEAN_SL_TILTOBS_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_config.h"
#include "shadowlean/sl_detect.h"
#include "shadowlean/sl_tilt.h"
#include "shadowlean/sl_track.h"

#ifdef __cplusplus
extern "C" {
#endif

#if SL_CFG_TILT_OBS_PER_TRACK > SL_TILT_MAX_OBS
#error "SL_CFG_TILT_OBS_PER_TRACK must be <= SL_TILT_MAX_OBS"
#endif

/// One track's history. Fields read-only to the application.
typedef struct sl_tiltobs_ring {
    int64_t anchor_x_um;    ///< odometry position the stored positions are relative to
    int64_t anchor_y_um;
    sl_tilt_result_t res;   ///< last fit (valid when `fitted`), anchor-relative
    uint16_t track_id;      ///< owning track's id; 0 = free ring
    uint8_t slot;           ///< owning track's tracker slot
    uint8_t count;          ///< observations held (<= SL_CFG_TILT_OBS_PER_TRACK)
    uint8_t head;           ///< next slot written
    uint8_t fresh;          ///< an observation was added since the last fit
    uint8_t fitted;         ///< `res` holds a fit of this ring's observations
    uint8_t dropped;        ///< observations removed as outliers (sl_tiltobs_fit_pending)
    uint8_t provisional;    ///< 1: the track has not been confirmed yet (file comment, 2.)
    sl_tilt_obs_t obs[SL_CFG_TILT_OBS_PER_TRACK];
} sl_tiltobs_ring_t;

/// Outlier rejection (sl_tiltobs_fit_pending): a ring whose fit is INCONSISTENT and holds at
/// least SL_TILTOBS_OUTLIER_MIN_N observations loses the one with the largest residual in
/// sigmas and is fitted again, while the ring's drops stay within 1 / SL_TILTOBS_OUTLIER_DIV
/// of its observations (`stats.outliers`). One observation 6-8 sigma off among 30 good ones
/// leaves chi2 / dof near 3, below the INCONSISTENT bound, and pulls a FITTED tilt; hence
/// also the rule below (`stats.gross`): its scale is that of the OTHER residuals (the
/// externally studentised residual), so the outlier cannot hide by inflating it.
#define SL_TILTOBS_OUTLIER_MIN_N 8U
#define SL_TILTOBS_OUTLIER_DIV 8U
/// A FITTED fit with at least SL_TILTOBS_OUTLIER_MIN_N observations loses its worst one when
/// that one's squared residual in sigmas exceeds SL_TILTOBS_GROSS_Z2 (4 sigma) times the
/// chi-square scale of the others, max(1, (chi2 - z^2) / (dof - 1)), within the same bound
/// of drops; the next call fits the ring again and looks for another. The residuals are the
/// DELETED ones, z^2 / (1 - h) with h = w e' M^-1 e the observation's leverage (M the
/// weighted bearing moments; 1 - h held at 1/16 at least): what the observation's residual
/// would be were it left out of the fit, so chi2 - z^2 / (1 - h) is exactly the others'
/// chi-square; the worst observation is the one with the largest. An observation at an end
/// of the pass's bearings pulls the fit towards itself and hid its own residual (one far
/// bound 3 % long among 11 at 3 m/s: a FITTED direction 19 deg off at 5.9 deg of sigma).
/// An AMBIGUOUS fit loses it only when the worst observation is gross under BOTH its
/// readings (as measured and as the fold's mirror, or its only one when it is not
/// mirrorable), each against the same scale:
/// an observation whose one reading fits while the other does not may be the very one that
/// tells the two hypotheses apart (dropping it could make a wrong reading FITTED), but one
/// that fits neither reading tells them apart by nothing more than the scale it inflates,
/// which is what keeps the fit AMBIGUOUS (noise-free `sl-eval driveby`: an abeam far bound
/// read 4 bins short, alpha 4.8 deg low, 5.8 sigma, at 3 m/s; `unit_tiltobs`,
/// test_a_gross_outlier_in_an_ambiguous_pass_is_dropped).
#define SL_TILTOBS_GROSS_Z2 16U

/// Counters (cumulative; never asserted).
typedef struct sl_tiltobs_stats {
    uint32_t observations;  ///< observations stored
    uint32_t rejected;      ///< VALID targets not stored: union extent saturated or without a
                            ///< VALID alpha, or sl_tilt_obs_make refused (|alpha| >= 80 deg ...)
    uint32_t no_target;     ///< updated confirmed tracks whose target was not found / not VALID
    uint32_t no_ring;       ///< observations of confirmed tracks lost: every ring in use
                            ///< by confirmed tracks
    uint32_t evicted;       ///< provisional rings taken by a confirmed track
    uint32_t unconfirmed_dropped; ///< observations recorded while the track was not
                                  ///< confirmed, dropped (an INCONSISTENT fit)
    uint32_t fits;          ///< sl_tilt_fit calls
    uint32_t resets;        ///< histories cleared because the motion input was missing
    uint32_t unverified;    ///< targets not stored under `verified_only`: bounds the range
                            ///< profile did not check (SL_TARGET_PROFILE / _NO_TAIL unset)
    uint32_t outliers;      ///< observations dropped from INCONSISTENT fits
    uint32_t gross;         ///< observations dropped from FITTED fits (gross outliers)
    uint32_t too_steep;     ///< fits beyond `max_tan_q16`, reported INCONSISTENT
} sl_tiltobs_stats_t;

/// The history of every tracked pole plus the odometry. Caller-owned.
typedef struct sl_tiltobs {
    const sl_board_t *board;   ///< borrowed (radar mounting, geometry tables)
    sl_tilt_params_t prm;      ///< fit parameters from the board
    sl_tilt_odom_t odom;       ///< vehicle origin pose at the end of the last rotation
    sl_tilt_odom_t odom_prev;  ///< ... at its start
    bool moving;               ///< the last rotation had a motion input (poses usable)
    uint8_t rr;                ///< internal: round-robin start of the fits
    uint8_t pending;           ///< rings with an observation not fitted yet
    uint16_t max_tan_q16;      ///< tan of the largest tilt a pole may have, Q16 (0: no bound;
                               ///< the pipeline sets the detector's cfg.max_lean_tan_q16,
                               ///< 30 deg): a fit beyond it is INCONSISTENT (a smear kernel
                               ///< the profile cannot read puts r1 and r2 a metre apart:
                               ///< a 50-bin Gaussian kernel made a FITTED tilt of 45 deg or
                               ///< more at a TiltSigma of 0.4, DANGER for a pole leaning 10
                               ///< away; sl_tiltobs.h, 3.)
    bool verified_only;        ///< store only targets whose bounds the range profile checked
                               ///< (SL_TARGET_PROFILE or _NO_TAIL): set by the pipeline unless
                               ///< the stream is known not to smear (sl_profile_clean), i.e.
                               ///< also from the start of a stream, before any evidence: an
                               ///< unremoved tail in the mask's bounds reads as a lean (a single
                               ///< such observation makes a whole pass INCONSISTENT: the first
                               ///< hit of a track on the sensor-scale drive-by, 12 deg off at
                               ///< a stated 0.4 deg, before the stream had shown its tail)
    sl_tiltobs_stats_t stats;
    sl_tilt_work_t work;       ///< fit scratch
    sl_tiltobs_ring_t ring[SL_CFG_TILT_TRACKS];
} sl_tiltobs_t;

/// A ring's result in the vehicle frame at the current pose.
typedef struct sl_tiltobs_vehicle {
    uint8_t quality;          ///< sl_tilt_quality_t
    int32_t psi_cdeg;         ///< tilt from vertical, 0..9000
    int32_t phi_cdeg;         ///< direction the top leans towards, CCW from forward, 0..35999
    uint16_t psi_sigma_cdeg;
    uint16_t phi_sigma_cdeg;
    int32_t base_x_um;        ///< pole base, x forward of the vehicle origin
    int32_t base_y_um;        ///< y left (saturated to int32)
    int32_t lean_path_cdeg;   ///< tilt towards the vehicle's path: atan of the tilt
                              ///< vector's component along -sign(base_y) y (> 0: the top
                              ///< leans over the path; the sign convention of PoleLean)
    uint16_t lean_path_sigma_cdeg; ///< 1-sigma of lean_path_cdeg: the tilt sigma along t and
                              ///< the direction sigma across it, projected on the path's
                              ///< normal; the tilt sigma (the larger one) when the direction
                              ///< is not determined (phi_sigma_cdeg 18000)
} sl_tiltobs_vehicle_t;

/// Initialise for `board` (borrowed): no history, pose at the origin, heading 0.
/// @return SL_OK, SL_ERR_ARG (NULL). O(sizeof).
sl_err_t sl_tiltobs_init(sl_tiltobs_t *o, const sl_board_t *board);

/// One rotation of ego motion (see the file comment, 1.). `motion_valid` false clears every
/// history (counted in stats.resets when something was held). O(rings).
void sl_tiltobs_advance(sl_tiltobs_t *o, bool motion_valid, int32_t speed_mm_s,
                        int32_t yaw_rate_cdeg_s, uint32_t rotation_us);

/// Record this rotation's observations (file comment, 2.). `tracks`: the
/// tracker's SL_CFG_MAX_TARGETS slots after sl_track_update(); `targets`: the rotation's
/// targets (the ones the tracker was given). Does nothing while not moving. O(see top).
void sl_tiltobs_update(sl_tiltobs_t *o, const sl_track_t *tracks, const sl_target_t *targets,
                       uint32_t n_targets);

/// Fit the rings with new observations (file comment, 3.). O(1) when none is pending;
/// else at most SL_CFG_TILT_FITS_PER_ROTATION sl_tilt_fit() calls.
void sl_tiltobs_fit_pending(sl_tiltobs_t *o);

/// The ring of track `id`, or NULL. O(rings).
const sl_tiltobs_ring_t *sl_tiltobs_find(const sl_tiltobs_t *o, uint16_t id);

/// Result of `r` in the vehicle frame at the current pose (for an AMBIGUOUS fit: its best
/// reading). False (and `out` zeroed) when `r` has no fit yet. Quality other than
/// FITTED/AMBIGUOUS: only `quality` is meaningful. O(1).
bool sl_tiltobs_vehicle(const sl_tiltobs_t *o, const sl_tiltobs_ring_t *r,
                        sl_tiltobs_vehicle_t *out);

/// The other reading of an AMBIGUOUS fit of `r` (sl_tilt_result_t.mirror) in the vehicle
/// frame at the current pose, as sl_tiltobs_vehicle(). False (`out` zeroed but for
/// `quality`) when `r` has no fit or its fit is not AMBIGUOUS. O(1).
bool sl_tiltobs_vehicle_mirror(const sl_tiltobs_t *o, const sl_tiltobs_ring_t *r,
                               sl_tiltobs_vehicle_t *out);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_TILTOBS_H
