// SPDX-License-Identifier: MIT
/// @file sl_track.h
/// @brief Targets over rotations: association, filtered alpha, warning level with hysteresis.
///
/// Once per rotation the caller hands over that rotation's targets (sl_detect.h) and the
/// time (`now_us`, microseconds, monotonic; the core never reads a clock).
///
/// ## Association
/// A target may continue a live track when both gates hold: circular azimuth distance
/// `<= cfg.az_gate` azimuths and `|r1 - track r1| <= cfg.range_gate_um`, both measured from
/// the track's predicted position (see "Static-object prediction" below; the last position
/// itself when the vehicle stands still), the azimuth distance to the target's detection
/// group (az_first .. az_first + az_count - 1, 0 when the prediction falls inside it: the
/// representative of a pole leaning across the line of sight moves within its 10-15
/// azimuths, 11 off the prediction on a 1 m/s drive-by, beyond the gate; groups at one range
/// do not overlap). Pairs are taken
/// greedily by increasing normalised distance (|d az| / az_gate + |d r1| / range_gate), ties
/// by the azimuth distance to the representative, each
/// track and target at most once (global nearest neighbour). Unmatched targets open new
/// tracks while slots are free (`stats.full` otherwise). Tracks not matched for longer than
/// `board->track_timeout_us` are dropped (0: dropped at the first update without a match).
/// The gates are for a (nearly) static scene. While the vehicle moves, the caller widens them
/// by the ego displacement per rotation (`sl_track_set_motion()`): the range gate by `d`,
/// the azimuth gate, per track, by the angle `d` subtends at the track's r1 plus the yaw
/// per rotation (no prediction: a static point moves by at most that much between
/// rotations, in any direction).
///
/// ## Static-object prediction and confirmation (clutter never confirms)
/// Everything shadowlean reports stands still on the ground, so before associating, each
/// live track's position is predicted for a static object under the ego motion of one
/// rotation (sl_track_predict_static()): with b the track's bearing from the vehicle's
/// forward axis (azimuth + board->radar_yaw_cdeg, clockwise) and d the displacement, the
/// point (r cos b, r sin b) becomes (r cos b - d, r sin b): r' = |.|, b' = atan2 (integer
/// sin/cos, error < 0.2 %; yaw is not predicted, only tolerated). The gates above are
/// centred on this prediction instead of the last position. A track then accumulates
/// `evidence`: +1 for an association whose residual from the prediction is within
/// `cfg.consist_az` azimuths (+ the yaw per rotation; measured to the target's detection
/// group, az_first .. az_first + az_count - 1, 0 when the prediction falls inside it: the
/// representative azimuth of a pole leaning across the line of sight moves within its
/// 10-15 azimuths as the vehicle passes) and `cfg.consist_range_um` (measured, likewise, to
/// the target's range extent: from its group's union inner bound, r1 less ext_grow's bins
/// before the representative run and a radius from width, to r2; 0 inside it: the nearest
/// point of such a pole is the union's inner bound on a rotation that reads it SLANT and the
/// representative run's first bin, 0.2-0.35 m further, on one that does not, while the
/// static point the track followed stays on the pole, inside its extent), capped at
/// `cfg.confirm_min + 2`; an association outside that tolerance resets it to 1 (the track
/// jumped: what it followed does not move like a static object); a rotation without an
/// association takes 1 off and moves the track's az / r1 to the prediction (dead reckoning,
/// so a pole missed for a rotation is still predicted where it is).
/// `confirmed` = evidence >= `cfg.confirm_min` (default 3, i.e.
/// three rotations whose range AND bearing follow the ego motion). Scattered clutter at
/// every azimuth associates now and then (the gates are wide while moving) but almost never
/// where a static object would be, three times running, so its tracks never confirm. The
/// pipeline sends PoleLean only for confirmed tracks.
///
/// ## Filter (1-D Kalman, fixed point)
/// State alpha in 1/256 cdeg (Q8 cdeg), variance P in cdeg^2 (uint32). Only targets with
/// `incline_flag == SL_INCLINE_VALID` update it; other flags refresh the track's position
/// and time only. Per valid measurement z (cdeg) with sigma_z = max(target sigma,
/// cfg.min_sigma_cdeg):
///
///     first:   alpha = z, P = sigma_z^2
///     else:    P += q^2 (q = cfg.q_cdeg, the random walk allowed per update)
///              K = P / (P + sigma_z^2)              (Q16, one 64-bit division)
///              alpha += K (z - alpha);  P = (1 - K) P   (round half up via sl_fx)
///              repeat:  P = max(P, sigma_z^2) when the target's corrected r1 and r2 equal
///                       the previous valid measurement's (a static scene quantised the
///                       same way every rotation is one measurement, not many: variance
///                       floor while the bins repeat, docs/DESIGN.md, "Tracking"); the same
///                       floor for a target flagged SL_TARGET_COARSE (a bound known to
///                       two bins, whose error repeats on every rotation: sl_profile.h,
///                       "Uncertainty of the bounds")
///     restart: the track's first measurement refined from a range profile
///              (SL_TARGET_PROFILE, sl_profile.h) is taken as the first (alpha = z,
///              P = sigma_z^2): the mask's bounds before it are whole bins shortened by the
///              smear's compression, errors that repeat rotation after rotation (a bias, not
///              noise the filter could average out), and the profile measures the same
///              return without them. Later mask-only measurements (the profile unusable on
///              a rotation) are fused as usual.
///
/// `alpha_cdeg` and `sigma_cdeg` (= isqrt(P)) are the reported values.
///
/// ## Warning level
/// raw level of a filtered alpha a: DANGER when a >= board->danger_lean_cdeg (leaning
/// towards the vehicle; alpha > 0 = top towards the radar), else CAUTION when
/// `cfg.caution_abs ? |a| : a` >= board->caution_lean_cdeg (the board header defines
/// CAUTION on |lean|; set caution_abs = false for "towards only"), else NONE. A board
/// threshold <= 0 disables its level.
/// - Raising: `cfg.confirm` consecutive valid updates with a raw level above the current one
///   and the filtered sigma <= `cfg.max_sigma_cdeg`; the level becomes the raw level of the
///   last of them.
/// - Lowering: immediately, to the raw level computed with every threshold lowered by
///   `cfg.hysteresis_cdeg` (so a lean hovering at a threshold does not toggle).
/// - Non-valid measurements leave the level unchanged (and do not count as confirmations
///   nor break a confirmation streak).
///
/// ## Ownership, memory, cost
/// Caller-owned `sl_tracker_t`; borrows `board` until re-init. RAM: SL_CFG_MAX_TARGETS x
/// sizeof(sl_track_t) (64 bytes) + 88 bytes (defaults: 2,136 bytes on x86-64). Cost per update:
/// O(tracks x targets x min(tracks, targets)) gate tests (worst case 32^3 = 32k simple
/// steps; a few hundred instructions for a handful of poles) + one 64-bit division and one
/// isqrt per valid measurement. Not reentrant per instance.
#ifndef SHADOWLEAN_SL_TRACK_H
#define SHADOWLEAN_SL_TRACK_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_config.h"
#include "shadowlean/sl_detect.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Warning level of a track.
typedef enum sl_warn_level {
    SL_WARN_NONE = 0,
    SL_WARN_CAUTION = 1,
    SL_WARN_DANGER = 2,
} sl_warn_level_t;

/// Tracking parameters that are not board fields.
typedef struct sl_track_cfg {
    uint32_t range_gate_um;    ///< max |d r1| to associate (default 0.3 m)
    uint16_t az_gate;          ///< max circular azimuth distance (default 3)
    uint16_t q_cdeg;           ///< process noise per valid update (default 20 = 0.2 deg)
    uint16_t min_sigma_cdeg;   ///< floor of a measurement's sigma (default 50)
    uint16_t max_sigma_cdeg;   ///< levels are raised only at filtered sigma <= this (300)
    uint16_t hysteresis_cdeg;  ///< lowering margin below each threshold (default 100 = 1 deg)
    uint8_t confirm;           ///< consecutive valid updates needed to raise (default 3)
    bool caution_abs;          ///< CAUTION on |alpha| (default true, as sl_board.h says)
    uint32_t consist_range_um; ///< distance of the predicted r1 from the target's range
                               ///< extent (union inner bound .. r2) of a consistent update
                               ///< (default 0.2 m: +-1 bin of quantisation on each side
                               ///< plus the width-based radius correction's jitter)
    uint16_t consist_az;       ///< |az - predicted az| of a consistent update, azimuths
                               ///< (default 3: the representative azimuth of a 2 deg beam
                               ///< return moves by up to half its 4-8 azimuths)
    uint8_t confirm_min;       ///< evidence needed for `confirmed` (default 3)
} sl_track_cfg_t;

/// Defaults as listed on each field.
void sl_track_cfg_default(sl_track_cfg_t *cfg);

/// One track. Fields read-only to the application.
typedef struct sl_track {
    uint64_t first_seen_us;  ///< time of the target that opened it
    uint64_t last_seen_us;   ///< time of the last associated target
    uint32_t r1_um;          ///< last target's corrected r1
    uint32_t r2_um;          ///< last target's corrected r2
    int32_t alpha_q8;        ///< filter state, 1/256 cdeg
    uint32_t var_cdeg2;      ///< filter variance, cdeg^2 (0 = no valid measurement yet)
    int32_t alpha_cdeg;      ///< filtered alpha, 0.01 deg (valid when valid_hits > 0)
    uint16_t sigma_cdeg;     ///< filtered 1-sigma, 0.01 deg (valid when valid_hits > 0)
    uint16_t id;             ///< non-zero, unique among live tracks
    uint16_t az;             ///< last target's representative azimuth
    uint16_t hits;           ///< targets associated (saturating)
    uint16_t valid_hits;     ///< valid alpha measurements (saturating)
    uint8_t level;           ///< sl_warn_level_t
    uint8_t streak;          ///< consecutive valid updates above the current level
    uint8_t last_flag;       ///< incline flag of the last associated target
    uint8_t live;            ///< 1 = slot in use
    uint8_t updated;         ///< 1 = matched by the last sl_track_update()
    uint8_t evidence;        ///< consistent static-object updates (see "confirmation")
    uint8_t confirmed;       ///< 1 = evidence >= cfg.confirm_min
    uint8_t last_slant;      ///< 1 = the last associated target was SL_TARGET_SLANT (a pole
                             ///< leaning across the beam: no one azimuth holds its run)
    uint16_t pred_az;        ///< internal: predicted azimuth for this update
    uint8_t profiled;        ///< 1 = a valid measurement came from a range profile
                             ///< (SL_TARGET_PROFILE); the first one restarts the filter
    uint32_t pred_r1_um;     ///< internal: predicted r1 for this update
} sl_track_t;

/// Counters (cumulative; never asserted).
typedef struct sl_track_stats {
    uint32_t updates;        ///< sl_track_update() calls
    uint32_t associated;     ///< target -> existing track matches
    uint32_t created;        ///< tracks opened
    uint32_t dropped;        ///< tracks dropped after the timeout
    uint32_t full;           ///< targets without a track: no free slot
    uint32_t level_changes;  ///< warning level transitions (any direction)
    uint32_t time_backwards; ///< now_us earlier than a track's last_seen_us (treated as 0 s)
    uint32_t inconsistent;   ///< associations off the static prediction (evidence reset)
    uint32_t confirmations;  ///< tracks that became confirmed
} sl_track_stats_t;

/// The tracker. Caller-owned; fields read-only to the application.
typedef struct sl_tracker {
    const sl_board_t *board;
    sl_track_cfg_t cfg;
    uint16_t next_id;
    uint16_t live;           ///< live tracks
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    sl_track_stats_t stats;
    uint32_t motion_um;      ///< ego displacement per update (sl_track_set_motion), um
    uint32_t motion_yaw_bam; ///< |yaw| per update, bam32 (2^32 = one turn)
    bool motion_reverse;     ///< the displacement is backwards (sl_track_set_reverse)
} sl_tracker_t;

/// Initialise (no tracks). `cfg` NULL = defaults (copied). Borrows `board`.
/// @return SL_OK; SL_ERR_ARG for NULL tracker/board, board azimuths 0, az_gate 0 or
/// range_gate_um 0.
sl_err_t sl_track_init(sl_tracker_t *tr, const sl_board_t *board, const sl_track_cfg_t *cfg);

/// Feed one rotation's targets (`n` of them, borrowed for the call; NULL allowed when n is
/// 0) at time `now_us`: associate, filter, update levels, open and drop tracks.
void sl_track_update(sl_tracker_t *tr, const sl_target_t *targets, uint32_t n,
                     uint64_t now_us);

/// Ego motion between consecutive updates, for the gates (see "Association"): translation
/// `disp_um` (>= 0) and |yaw| `yaw_bam32` (2^32 = one turn). Stays in effect until changed;
/// 0, 0 = static. O(1).
void sl_track_set_motion(sl_tracker_t *tr, uint32_t disp_um, uint32_t yaw_bam32);

/// Direction of the displacement given to sl_track_set_motion(): true = the vehicle
/// reverses (the static-object prediction moves the other way). Default false. O(1).
void sl_track_set_reverse(sl_tracker_t *tr, bool reverse);

/// Where a static object seen at azimuth index `az`, range `r_um` is expected after the ego
/// displacement `disp_um` forward (a negative displacement: pass the reverse flag through
/// sl_track_set_reverse(); this pure function takes `disp_um` forward only) (see "Static-object prediction"); r and d are clamped to
/// 2^30 um (1 km). Pure; O(1) (one isqrt, one atan2, two divisions).
void sl_track_predict_static(const sl_board_t *board, uint16_t az, uint32_t r_um,
                             uint32_t disp_um, uint16_t *az_out, uint32_t *r_out);

/// The azimuth gate of track `t` under the current motion (cfg.az_gate + the yaw per update
/// + the angle the displacement subtends at the track's r1), in azimuths, saturated at
/// 65535. O(1).
uint16_t sl_track_gate_az(const sl_tracker_t *tr, const sl_track_t *t);

/// Highest warning level over live tracks (SL_WARN_NONE when none). O(tracks).
sl_warn_level_t sl_track_max_level(const sl_tracker_t *tr);

/// Live track by id, or NULL. O(tracks).
const sl_track_t *sl_track_find(const sl_tracker_t *tr, uint16_t id);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_TRACK_H
