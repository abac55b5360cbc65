// SPDX-License-Identifier: MIT
/// @file sl_ground.h
/// @brief The ground from the shadow's edge: where the ground return starts around the
/// vehicle gives the vehicle's attitude over the ground (height, pitch, roll) and, where one
/// sector departs from that plane, the terrain (DROP: lower, STEP: higher).
///
/// ## Geometry (one model of the ring, shared with the drift watch)
/// The ray over the chassis edge of azimuth `az` leaves the radar at depression theta(az)
/// (the board's table, vehicle frame). Where it meets the ground, the ground return starts:
/// slant range s. In the vehicle frame (ISO 8855: x forward, y left, z up; origin at the
/// radar) that point is at
///     rho = s cos(theta),  x = rho cos(phi),  y = -rho sin(phi),  d = s sin(theta)
/// (phi the azimuth in the vehicle frame, clockwise from forward; d the depth of the point
/// below the radar). A ground plane below the radar is d = h + a x + b y, so every sector
/// is one linear equation in (h, a, b) and the weighted least-squares fit over the ring is
/// exact for a plane (no small-angle step): h the depth of the plane below the radar along
/// the vehicle's z (the radar's height above the plane is h / sqrt(1 + a^2 + b^2)),
/// pitch = atan(-a) (nose DOWN positive, ISO: the ground ahead nearer below the
/// radar), roll = atan(b) (right side DOWN positive, ISO: the ground on the left further
/// below). The residual of a sector, d - (h + a x + b y), is the ground's height below
/// the plane there: > 0 lower (a ditch, a drop-off), < 0 higher (a kerb, a bank, a step).
///
/// What each change explains (sl_drift.h reads the same edges, one azimuth per rotation):
/// - the body sinking or rising uniformly (load): every s scales alike: h changes, the
///   residuals and theta do not. The drift watch, which takes h = the board's height,
///   reads the same rows as a uniform theta change; the two are told apart by h: when
///   |h - board height| is within the fit's sigma the drift watch's reading is a theta
///   change (the mount, the calibration), else a height change (load, suspension);
/// - the vehicle pitching or rolling on its suspension, or standing on a slope: a first
///   harmonic of s over the azimuth: pitch and roll. A radar mount tilted on the vehicle
///   changes theta in exactly that pattern and is read as attitude (the ring alone cannot
///   tell them apart: a mount that moved is the drift watch's, parked on level ground);
/// - one sector's edge moving alone (the others on their plane): terrain, that sector's
///   residual.
/// The edges are the board's geometry read backwards: a wrong theta(az) table is a
/// residual pattern that is the same on every rotation and every ground.
///
/// ## One sample (sl_ground_row, `reads` azimuths per sector per rotation)
/// Sector k (SL_CFG_GROUND_SECTORS equal sectors of the rotation, len(k) azimuths) reads,
/// in rotation n, the azimuths first(k) + n mod s + j s, s = len(k) / reads, j = 0 ..
/// reads - 1: spread over the sector (independent speckle), and over the rotations every
/// azimuth of it. The
/// row is the raw message's 8-bit values (the whole range: the edge may lie past the
/// masked bins). Around the expected edge e0 = H / sin(theta) / bin (the board's flat
/// ground):
/// 1. coarse start c: from e0, back through the run of bins >= `threshold` it stands in
///    (single-bin gaps allowed), or on to the first two adjacent bins >= `threshold`,
///    within [e0 - search_in_bins, e0 + search_out_bins); none: "no ground"; a run from
///    the window's start on: "bad edge";
/// 2. occupied: two adjacent bins >= threshold in [near_exclusion, c - m) (a target stands
///    in the shadow on this azimuth; m below): the sector is skipped this rotation;
/// 3. the edge with sub-bin precision, as the half-power point of the ground's step
///    through the range response: with powers y (sl_vscale_power) over
///    [c - m, c + m) (m = `margin_bins`, the response's half extent: the CTS350-X's
///    -20 dB point is 10 bins), the floor f the mean power of the `floor_bins` bins before
///    it and the ground's level A the mean power of the `plateau_bins` bins after it,
///        e = (c + m) - sum_k (y_k - f) / (A - f)
///    (a step of height A - f convolved with any symmetric response integrates to
///    (A - f)(c + m - e) over the window: the area estimator, exact at the half-power
///    point and far less sensitive to speckle than a threshold crossing), less the
///    with the ground's level falling past the edge as (e / r)^n (`decay_pow`; flat
///    ground: the depressions one bin spans fall as r^-2 and the grazing angle's shading
///    as r^-1, n = 3; the beam's elevation pattern changes it): the level at the edge is
///    the plateau's over (e / kc)^n (kc its centre) and the window integrates
///    L - n L^2 / (2 e) of it (L = c + m - e). n is learned from the stream: the
///    plateaus' halves summed over SL_GROUND_DECAY_SAMPLES samples (a running window),
///    n = log2(P1 / P2) / log2(k2 / k1); `decay_pow` until the first window is in;
///    once more with c = round(e) when that moved c by more than 3 bins (within 3 bins the
///    response's mass beyond the window's ends moves e by < 0.03 bin). Powers relative
///    to the window's largest value (a 64-entry table on the LOG2 scale: values more than
///    10 octaves below count 0). Rejected ("bad edge") when fewer than half the plateau's
///    bins are >= threshold (not ground), A <= 2 f (no contrast) or e leaves the window;
/// 4. the sector's estimate: an exponentially weighted mean of its samples over
///    min(`avg_rotations`, the rotations the vehicle needs to move `avg_dist_um`) rotations'
///    samples,
///    each weighted by its ground level A - f (sum (A - f) e = sum ((A - f)(c + m) - S):
///    the mean carries no bias from a noisy level, which 1 / (A - f) of one sample has),
///    and the mean square deviation of the samples from it: the sector's sigma is the
///    observed scatter of its samples (speckle, clutter, the vehicle's own motion) shrunk
///    towards a prior (half the response's half-power width, 4 bins, with
///    SL_GROUND_PRIOR_WEIGHT samples' weight: a few samples' scatter is often far below
///    the truth), over the samples averaged, never below `sigma_min_q8`.
///
/// ## The plane and the hazards (sl_ground_end_rotation)
/// - the gate: sectors off the previous rotation's plane by more than half the smaller
///   threshold and 2 sigma (with its variance and the process noise SL_GROUND_Q_*) stay
///   out of the fit (a drop-off coming into the ring ahead is terrain, not pitch); fewer
///   than SL_GROUND_MIN_SECTORS left: no gate;
/// - sectors with an estimate no older than `stale_rotations` enter a weighted fit (weight
///   1 / sigma_d^2, sigma_d = sigma_s sin(theta)); at least SL_GROUND_MIN_SECTORS, covering
///   three quadrants of the vehicle, else no plane (quality NONE);
/// - robust: sectors with a hazard, confirmed or being voted for, stay out (while
///   SL_GROUND_MIN_SECTORS others remain); the sectors whose residual exceeds half the smaller threshold and 2 sigma
///   leave the fit and it is solved again, twice (a drop-off over the front arc would
///   otherwise read partly as pitch); the residuals of every sector are then taken
///   against that plane;
/// - sigmas: the fit's covariance (integer WLS), scaled by sqrt(chi2 / dof) when the
///   scatter about the plane exceeds what the sectors' sigmas explain;
/// - the plane filtered over rotations: each parameter of the fit fused with the previous
///   rotation's plus the process noise (inverse-variance weights); a fit more than 4
///   sigma off it restarts the filter (the attitude really changed);
/// - quality: GOOD when every sigma is within `good_sigma_*`, COARSE otherwise; NONE
///   without a plane. A number the module cannot stand behind is sent COARSE or NONE;
/// - DROP / STEP per sector: the residual beyond `drop_um` (lower) or `step_um` (higher)
///   and beyond 4 sigma (sigma of the sector and of the plane there; 32 sectors decide
///   about 460,000 times an hour at 4 Hz: 3 sigma would raise hundreds) in `confirm`
///   consecutive rotations raises it (votes only once the sector's scatter holds
///   `avg_rotations` x `reads` samples); within 2/3 of the threshold on its side in `confirm`
///   samples, or no sample for `stale_rotations`, clears it (hysteresis);
/// - distance: each hazard carries the point where the ground at the plane's level ends
///   along its sector (vehicle frame) and its horizontal distance from the radar: the ray
///   over the chassis edge meets the plane at rho = h / (tan(theta) - the plane's slope
///   along the sector); the ground's end crossed that ring between the sector's last
///   rotation whose samples were on the plane on average (within a quarter of the
///   threshold on their side: a plane still following the edge halves the step) and the
///   next one, one rotation's travel later: at the vote that opens the
///   hazard the ring's point moved back by the forward travel since that rotation, less
///   half a step (odometry, sl_ground_set_motion; straight motion), then back by the
///   travel while it holds. Parked: the ring's point (the edge is inside the ring). Noise
///   beyond a quarter of the threshold in such a rotation's mean dates it earlier: the
///   point then errs near. `front_um` (radar to the vehicle's front along x) is for the caller's
///   distance to the front (x - front_um).
///
/// ## Units, numbers, cost, RAM
/// Heights, ranges: mm (int32) and um in the sector state; edges: bins Q8; slopes Q16;
/// angles 0.01 deg. Integer only (64-bit sums and divisions); bit-identical on every
/// target. sl_ground_row: the coarse walk (a few bins), the occupied test (word-wise on
/// the pipeline's thresholded row), 2 margin + plateau + floor table reads (twice at
/// most), a few 64-bit divisions, one sine/cosine, two base-2 logarithms; the pipeline
/// calls it for SL_CFG_GROUND_SECTORS x `reads` rows per rotation. sl_ground_end_rotation:
/// O(sectors) passes (the gate, up to three fits, the residuals), 2 x 2 solves, O(64)
/// division steps per variance. RAM: sizeof(sl_ground_t), 2,000 B with 32 sectors (52 B
/// each). Stack: sl_ground_end_rotation holds three per-sector arrays (10 B per sector).
/// Compiled in with SL_CFG_GROUND (sl_config.h: the host configuration); without it the
/// types remain and the functions are not defined.
/// Errors: bad rows are counted in `stats` (no ground, occupied, bad edge, short) and cost
/// the sector that rotation's sample; a rotation without a plane sends quality NONE.
/// Limits: a plane is only fitted where the ground returns above the threshold at the
/// shadow's edge on three quadrants; frozen speckle (a parked vehicle, a static scene)
/// leaves each sector a fixed error that only the other azimuths of the sector average;
/// vertical faces (a wall, a parked car) at the edge read as STEP.
#ifndef SHADOWLEAN_SL_GROUND_H
#define SHADOWLEAN_SL_GROUND_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_response.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Sectors of the ring (equal shares of the rotation).
#ifndef SL_CFG_GROUND_SECTORS
#define SL_CFG_GROUND_SECTORS 32
#endif
#if SL_CFG_GROUND_SECTORS < 8 || SL_CFG_GROUND_SECTORS > 64
#error "SL_CFG_GROUND_SECTORS must be in [8, 64]"
#endif
/// Entries of the value -> power table (values below the window's largest).
#define SL_GROUND_LUT 64U
/// Samples per window of the decay's learning.
#define SL_GROUND_DECAY_SAMPLES 256U
/// Weight of the prior sigma in a sector's scatter, in samples.
#define SL_GROUND_PRIOR_WEIGHT 4U
/// Rows read per sector and rotation by default.
#ifndef SL_CFG_GROUND_READS
#define SL_CFG_GROUND_READS 4U
#endif
/// Process noise of the plane per rotation: slope (tan 0.25 deg)^2 in Q32, depth (10 mm)^2
/// in (1/16 mm)^2 (1 deg/s and 40 mm/s at 4 Hz: a body on its suspension).
#define SL_GROUND_Q_SLOPE 81700U
#define SL_GROUND_Q_H 25600U
/// Sectors needed for a plane.
#define SL_GROUND_MIN_SECTORS 6U

/// Plane quality (GroundPlane.Quality).
typedef enum sl_ground_quality {
    SL_GROUND_NONE = 0,   ///< no plane: too few sectors (no number to use)
    SL_GROUND_COARSE = 1, ///< a plane, sigmas beyond the cfg's good limits
    SL_GROUND_GOOD = 2,   ///< a plane within the good limits
} sl_ground_quality_t;

/// Hazard kind of a sector (GroundHazard.Kind).
typedef enum sl_ground_kind {
    SL_GROUND_FLAT = 0, ///< nothing confirmed
    SL_GROUND_DROP = 1, ///< ground lower than the plane
    SL_GROUND_STEP = 2, ///< ground higher than the plane
} sl_ground_kind_t;

typedef struct sl_ground_cfg {
    sl_vscale_t scale;        ///< 8-bit value -> power (default SL_VSCALE_CTS350X)
    uint16_t threshold;       ///< ground bins: value >= this (default: the board's)
    uint8_t margin_bins;      ///< response half extent m (default 10, CTS350-X -20 dB)
    uint8_t plateau_bins;     ///< bins of ground level after the window (default 32)
    uint8_t floor_bins;       ///< bins of floor before the window (default 8)
    uint8_t search_in_bins;   ///< coarse search before e0 (default 32)
    uint8_t search_out_bins;  ///< ... and after it (default 48)
    uint8_t reads;            ///< rows read per sector and rotation (1..8; default
                              ///< SL_CFG_GROUND_READS, 4)
    uint8_t avg_rotations;    ///< rotations averaged per sector at most (default 8)
    uint32_t avg_dist_um;     ///< ... and while moving, over this distance (default 0.75 m)
    uint16_t sigma_min_q8;    ///< floor of a sector's sigma, bins Q8 (default 0.1 bin = 26)
    uint8_t decay_pow;        ///< the ground's level falls as range^-n past the edge: n until
                              ///< learned (0..4; default 3: flat ground, step 3 below)
    uint8_t stale_rotations;  ///< a sector's estimate is used this long (default 8)
    uint8_t confirm;          ///< samples to raise / clear a hazard (default 3)
    uint32_t drop_um;         ///< DROP: ground lower than the plane by more (default 0.15 m)
    uint32_t step_um;         ///< STEP: ground higher than the plane by more (default 0.08 m)
    uint16_t good_sigma_mm;   ///< GOOD: sigma(h) within this (default 20 mm)
    uint16_t good_sigma_cdeg; ///< ... and sigma(pitch), sigma(roll) within this (30 = 0.3 deg)
    int32_t front_um;         ///< radar to the vehicle's front along x (default 0)
} sl_ground_cfg_t;

/// One sector's state (read-only to the application).
typedef struct sl_ground_sector {
    int32_t x_um;          ///< averaged ground point at the edge: forward of the radar
    int32_t y_um;          ///< ... left of the radar
    int32_t d_um;          ///< ... depth below the radar
    uint32_t var_q;        ///< mean square deviation of d's samples, (10 um)^2
    uint32_t wsum;         ///< the samples' levels summed (exponentially weighted)
    int32_t resid_mm;      ///< ground below the plane (> 0 lower), last fit
    int32_t hx_um, hy_um;  ///< hazard: where the ground at the plane's level ends along
                           ///< the sector, vehicle frame, moved back by the travel since
    int32_t dist_um;       ///< ... its horizontal distance from the radar (see above)
    uint16_t sigma_mm;     ///< the residual's sigma (sector and plane), last fit; computed
                           ///< beyond 2/3 of the threshold or while a hazard holds (else 0)
    uint16_t since_mm;     ///< forward travel since the last rotation whose samples were
                           ///< on the plane on average
    uint8_t n;             ///< samples in the mean (<= the rotations averaged x reads)
    uint8_t nv;            ///< samples in the scatter (<= avg_rotations x reads)
    uint8_t age;           ///< rotations since the last sample (saturating)
    uint8_t kind;          ///< sl_ground_kind_t confirmed
    uint8_t votes;         ///< consecutive samples against `kind`
    uint8_t vote_kind;     ///< what they vote for
    bool fresh;            ///< a sample this rotation
    bool in_fit;           ///< used by the last plane
    int16_t rot_sum_mm;    ///< this rotation's samples' residuals on the last plane, summed
    uint8_t rot_n;         ///< ... their count
} sl_ground_sector_t;

typedef struct sl_ground_plane {
    uint8_t quality;       ///< sl_ground_quality_t
    uint8_t sectors;       ///< sectors in the fit
    int32_t height_mm;     ///< the radar's height above the plane (perpendicular to it)
    int32_t pitch_cdeg;    ///< nose down > 0 (ISO 8855)
    int32_t roll_cdeg;     ///< right side down > 0 (ISO 8855)
    uint16_t height_sigma_mm;
    uint16_t pitch_sigma_cdeg;
    uint16_t roll_sigma_cdeg;
    int32_t slope_x_q16;   ///< a: depth per forward distance
    int32_t slope_y_q16;   ///< b: depth per left distance
} sl_ground_plane_t;

typedef struct sl_ground_stats {
    uint32_t samples;      ///< edges measured
    uint32_t no_ground;    ///< rows without a ground run in the window
    uint32_t occupied;     ///< rows with a target in the shadow (skipped)
    uint32_t bad_edge;     ///< rows whose edge fit failed (no contrast, out of window)
    uint32_t short_rows;   ///< rows too short for the window
    uint32_t planes;       ///< rotations with a plane
    uint32_t no_plane;     ///< rotations without one
} sl_ground_stats_t;

typedef struct sl_ground {
    sl_ground_cfg_t cfg;
    const sl_board_t *board;     ///< borrowed
    uint32_t bin_um;             ///< bin size in use
    int64_t e0_num;              ///< H / bin x 2^38: e0 (bins Q8) = e0_num / sin_theta_q30
    uint16_t near_bins;          ///< the board's near-field band in bins of bin_um
    uint32_t az_step_bam;        ///< 2^32 / azimuths
    uint32_t yaw_bam;            ///< the board's radar yaw, 2^32 per turn
    uint16_t pow_q16[SL_GROUND_LUT]; ///< LOG2 scale: power of the value i below the largest
    int16_t decay_q8;            ///< the ground's decay exponent n in use, Q8
    uint32_t dec_n;              ///< decay learning: samples in the window
    uint32_t dec_h1, dec_h2;     ///< ... the plateaus' halves' shares summed, Q16
    uint32_t dec_lever;          ///< ... log2 of their centres' ratio summed, Q16
    uint16_t next_az;            ///< next azimuth to read this rotation
    uint8_t next_sector;         ///< its sector (SL_CFG_GROUND_SECTORS: done)
    uint16_t phase;              ///< rotation counter for the azimuth within each sector
    bool moving;                 ///< motion known and non-zero this rotation
    uint32_t step_um;            ///< distance driven in the last rotation
    int32_t step_x_um;           ///< ... its forward component (signed)
    sl_ground_plane_t plane;
    bool prior_ok;               ///< the previous rotation's plane (the prior) holds
    int32_t prior_a_q16, prior_b_q16; ///< its slopes (depth per mm, Q16 of 1/16 mm)
    int32_t prior_h_q4;          ///< its depth at the radar's foot, 1/16 mm
    uint32_t prior_va, prior_vb; ///< its slopes' variances, Q32
    uint32_t prior_vh;           ///< its depth's variance, (1/16 mm)^2
    sl_ground_sector_t sec[SL_CFG_GROUND_SECTORS];
    sl_ground_stats_t stats;
} sl_ground_t;

/// Defaults above for `board` (NULL: threshold 40). O(1).
void sl_ground_cfg_default(sl_ground_cfg_t *cfg, const sl_board_t *board);

/// Init for `board` (borrowed) and `cfg` (copied; NULL: defaults). SL_ERR_ARG for NULL
/// `g`/`board`, a board without azimuths or theta table, or a cfg out of range
/// (margin_bins 0 or > 32, plateau_bins or floor_bins 0 or > 64, avg_rotations 0,
/// reads 0 or > 8, avg_rotations x reads > 255,
/// decay_pow > 4, confirm 0, drop_um or step_um 0 or > 10 m, an invalid scale). O(sectors).
sl_err_t sl_ground_init(sl_ground_t *g, const sl_board_t *board, const sl_ground_cfg_t *cfg);

/// The radar's bin size (a Configuration's; 0 is ignored). O(1).
void sl_ground_set_bin_size(sl_ground_t *g, uint32_t bin_um);

/// The azimuth whose row sl_ground_row wants next (none left this rotation: UINT16_MAX).
/// The caller compares each row's index with it (one compare per row). O(1).
static inline uint16_t sl_ground_want(const sl_ground_t *g)
{
    return g->next_az;
}

/// One row (azimuth `az`, `bins` 8-bit values from range 0; `bits` (nullable) the same
/// row's first `bits_n` bins thresholded at cfg.threshold, bin k = bit k % 32 of word
/// k / 32, as sl_thresh_u8 writes it: the occupied test reads them word-wise). Reads it
/// when `az` is the wanted azimuth; rows past the wanted one (the wanted row was lost)
/// skip to the next sector's. O(window) for a read row, O(1) otherwise. NULL `row`:
/// counted as a short row.
void sl_ground_row(sl_ground_t *g, uint16_t az, const uint8_t *row, uint32_t bins,
                   const uint32_t *bits, uint32_t bits_n);

/// Motion during the rotation now ending (speed mm/s, > 0 forward; rotation period us);
/// `valid` false: unknown (distances are not advanced, averaging as parked). O(1).
void sl_ground_set_motion(sl_ground_t *g, bool valid, int32_t speed_mm_s, uint32_t rotation_us);

/// End of the rotation: the sectors' ages, the plane, the residuals, the hazards, the
/// next rotation's azimuths. O(sectors).
void sl_ground_end_rotation(sl_ground_t *g);

/// Hazard sector with the largest |residual| among the confirmed ones, or -1. O(sectors).
int sl_ground_worst(const sl_ground_t *g);

/// Azimuth of sector k's centre in the vehicle frame, 0.01 deg clockwise from forward
/// (board's radar yaw included), in [0, 36000). O(1).
int32_t sl_ground_sector_cdeg(const sl_ground_t *g, uint32_t k);

/// One edge from a row (the sample of steps 1-3 above, `bits` as for sl_ground_row), for
/// tests and tools: the edge in slant bins Q8 searched around `e0_q8`, or a negative
/// sl_ground_edge_err_t. Reads `g` (its cfg, table, near-field band, decay), changes
/// nothing; `aux` (nullable) gets what the decay's learning reads.
/// O(window).
/// What one edge tells the decay's learning (sl_ground_edge_q8's `aux`).
typedef struct sl_ground_edge_aux {
    uint32_t share1_q16;   ///< the plateau's first half's share of its power, Q16
    uint32_t lever_q16;    ///< log2 of the halves' centres' ratio, Q16 (0: no plateau read)
    uint32_t level;        ///< the ground's level at the edge, the scale's power >> 16 (>= 1)
} sl_ground_edge_aux_t;
typedef enum sl_ground_edge_err {
    SL_GROUND_EDGE_NO_GROUND = -1,
    SL_GROUND_EDGE_OCCUPIED = -2,
    SL_GROUND_EDGE_BAD = -3,
    SL_GROUND_EDGE_SHORT = -4,
} sl_ground_edge_err_t;
int32_t sl_ground_edge_q8(const sl_ground_t *g, const uint8_t *row, uint32_t bins,
                          const uint32_t *bits, uint32_t bits_n, int32_t e0_q8,
                          sl_ground_edge_aux_t *aux);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_GROUND_H
