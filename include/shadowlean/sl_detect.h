// SPDX-License-Identifier: MIT
/// @file sl_detect.h
/// @brief Pole extraction inside the chassis shadow, corrections of MATH.md s.4, alpha.
///
/// Input: per azimuth, the stable-occupied bit row of the consistency mask (sl_mask.h,
/// layout sl_thresh.h), fed in increasing azimuth order once per rotation. Output: up to
/// `max_targets` targets per rotation, each with its representative azimuth, raw and
/// corrected bounds r1/r2 (micrometres) and the inclination estimate (sl_incline.h).
///
/// ## Stages (all integer; units in the names)
/// 1. **Runs** (per azimuth `az`). A run is a maximal set of consecutive occupied bins;
///    runs separated by at most `cfg.gap_bins` free bins are bridged into one run that is
///    marked *broken* (its occupied count is below its extent). A run is considered when
///    its first bin lies in the search window `[near_exclusion_bins, win_bins[az])`, with
///    `win_bins[az] = ceil(S(az) / b)` and `S(az) = sqrt(shadow_um[az]^2 + radar_height_um^2)`
///    the **slant** range of the ground-shadow edge: the radar measures slant range, and the
///    ground at the horizontal shadow radius R lies at slant sqrt(R^2 + H^2), so a pole whose
///    lowest visible point is inside the shadow has r2 < S (not < R). (The board's
///    `shadow_bins` counts horizontal range; it is only used when `shadow_um` is absent.)
///    - Runs entirely inside the near-field band `[0, near_exclusion_bins)` are ignored: the
///      bright leakage band of REAL_SCANS.md s.2 is never reported. A run that contains
///      bins near_exclusion_bins - 1 *and* near_exclusion_bins crosses into the band and is
///      flagged NEAR (its true r1 is hidden in the band).
///    - A run whose last bin is `>= edge_bins[az]` (the first bin whose centre, less the
///      elongation d(S), reaches S) or that reaches the end of the row passed in is flagged
///      SHADOW: its far end is at or beyond the shadow edge, so r2 is the ground or the
///      pole's base, not the -theta ray. The run is followed past the window to its end.
///      d(S) is only a prior there: with the amplitude row of the azimuth
///      (sl_detect_set_amplitude()), a run reaching that edge (but not the end of the row)
///      is SHADOW only when its part beyond the window end `win_bins[az]` (S) does not look
///      like the smear tail of its part inside: not below the inside peak, or not decaying
///      (with the stream's own tail slope s known, sl_detect_set_tail_slope(): longer than
///      ceil((peak - T) / s) bins, the longest tail the inside peak can leave at threshold
///      T; without it: its first half not stronger than its second by >= 1/2 value per bin
///      of separation). Otherwise the run is flagged TAIL_EDGE: its own end may lie inside
///      the shadow, sl_detect_end skips the r2 >= S test for it and the caller decides on
///      the refined r2 (the pipeline: the range profile's r2, else r2 - d(r2)). Without an
///      amplitude row the d(S) rule stays.
/// 2. **Grouping**. A run on azimuth a joins the group (candidate) that has a run on a - 1
///    whose extent overlaps it within `cfg.link_bins` bins; a run touching two groups merges
///    them. Azimuth azimuths-1 links to azimuth 0 at the end of the rotation (wrap).
///    With amplitude rows, runs are graded (the WEAK test of stage 4): a *weak* run (no bin
///    >= T + `cfg.weak_margin` and its peak < its floor + `cfg.weak_contrast`) never joins
///    a group that holds a strong run, and a strong run never joins a group of weak runs
///    only (nor do two such groups merge at the wrap). Weak clutter along the shadow edge
///    (a band of returns just above the threshold) therefore can neither widen a pole's
///    group (WIDE), break its runs' union, nor bridge it to the ground beyond the edge
///    (SHADOW): it forms groups of its own, rejected WEAK. Runs without an amplitude row
///    and runs at the shadow edge (not graded) link to either. Measured on
///    `daemon_clutter_never_hides_a_pole` (sensor effects, 1 m/s, the pole leaning towards
///    the path). A
///    group remembers, per azimuth, the union extent [first, last] and the occupied count
///    of its runs there, for up to SL_CFG_DETECT_MAX_SPAN azimuths (wider: rejected WIDE).
/// 3. **Representative azimuth**: the azimuth of the group with the most occupied bins
///    (the strongest return: for a slender pole, the beam centre); ties go to the azimuth
///    nearest the middle of the group, then to the lower index. Its run gives raw
///    `bin_first`, `bin_last`.
/// 4. **Rejections**, counted per reason in `stats.rejected[]`, first match wins in this
///    order: NEAR, SHADOW (a run flagged), WEAK (a group of weak runs only, stage 2), WIDE,
///    BROKEN, SHADOW (the corrected r2: the corrections are computed only for a group that
///    passed the tests before), then SHORT and RHO:
///    NEAR (any run of the group crosses into the near-field band);
///    SHADOW (any run flagged SHADOW, or the corrected r2 of the representative run is
///    >= S(az): the base is not inside the shadow; the r2 test is left to the caller for a
///    group with a TAIL_EDGE run, stage 1);
///    WIDE (the group spans more azimuths than a pole of `cfg.max_pole_diameter_um` at r1
///    can: allowed = floor((D / r1 [rad] + beam) / step) + 1 + `cfg.width_slack_az`;
///    but see "Leaning across the line of sight" below: with `slant` set, a slender
///    group that a pole leaning across the beam explains is kept, flagged SLANT);
///    BROKEN (the representative run has a gap; while the runs' peaks are measured, i.e.
///    moving with the stream's tail slope known (stage 4), not for as many missed bins as
///    the tail its peak leaves: a smear tail dips below the threshold on a noisy sensor);
///    then the clutter tests (sl_detect_clutter_reason(), after the corrections and alpha):
///    SHORT (the representative run is one bin: a speck of gravel or a noise spike, no
///    extent to measure); RHO (the incline flag is OUT_OF_DOMAIN, or INVALID / AMBIGUOUS
///    and the run AS MEASURED is below the model's minimum rho_amb of that azimuth by more
///    than the quantisation can explain: rho_m < rho_amb - b / r1, b the bin size, rho_m =
///    (r2 + elong_um) / r1, r2 before the board's elongation model d(r2) was subtracted
///    (INVALID: rejected when r1 >= r2 + elong_um). A run of n bins measures (n - 1) b
///    between its bin centres and the true extent is < n b, so a real pole near the fold
///    reads at most b / r1 below rho_amb; smear only lengthens a return, so rho_m bounds the
///    true ratio from above whatever the actual smear, whereas d is a model that can
///    overcorrect by many bins (a smear steeper than tabulated, a board not calibrated) and
///    would push a pole leaning away below the fold or to r2 <= r1; sl_profile then
///    measures its bounds); WEAK (only when amplitude rows were given:
///    sl_detect_set_amplitude()): no run of the group
///    is clearly above its local floor, i.e. for every run its peak power is below
///    threshold + `cfg.weak_margin` AND below floor + `cfg.weak_contrast`, the floor being
///    the mean power of the gap_bins + 1 bins on each side of the run (free bins by
///    construction of a run). A rough verge or gravel just over the threshold in a band of
///    weak returns fails both; a weak pole over a quiet floor passes the second.
/// 4b. **Slots by evidence**. When more targets pass than `max_targets`, the ones with the
///    least evidence are dropped (never the later azimuths): evidence =
///    4 x (occupied bins of the group over all its azimuths) + 16 x (azimuths with a run) +
///    8 x (extent of the representative run in bins), plus SL_DETECT_EVIDENCE_TRACK when
///    the representative azimuth is hinted (sl_detect_hint(): where the caller expects a
///    confirmed track, so an established pole keeps its slot against any amount of clutter)
///    (sl_target_t.evidence). Each drop is counted in `stats.target_overflow`
///    (CandidatesDropped on CAN). Ties keep the earlier.
///    **Leaning across the line of sight** (only while `slant` is set: the pipeline sets it
///    while it has a motion input and fits the 3D tilt, sl_tiltobs.h). A pole whose top
///    leans sideways crosses the azimuths one after the other: every azimuth sees a short
///    piece of it, the pieces step through range, and the group is wider than a vertical
///    pole can be (a 20 deg lean at 3 m: 13-14 azimuths for an allowance of 9-10). Such a
///    group is not WIDE when all of these hold, U = [uf, ul] being its union extent (min
///    first / max last bin over its azimuths) and `allowed` the vertical pole's span above:
///    - own extents: on a smearing sensor every azimuth's run is its piece of the pole plus
///      a smear tail as long as its level allows, so in bits a slanted pole fills its range
///      extent like a wall and the tails' ends (shorter on the beam's weaker edge azimuths)
///      step against the line. Once the stream's tail slope is known
///      (sl_detect_set_tail_slope, self-calibrated by the range profiles or a saved prior;
///      both fixed for a rotation at sl_detect_begin) and amplitude rows come with the runs,
///      each azimuth's entry keeps the highest value of its runs (sl_detect_cand_t.peak)
///      and its own extent ends
///      floor((peak - T) / slope) bins before its last bin (at least its first bin): the
///      longest tail its peak can leave, so the own extent is never longer than the truth.
///      The tests below use own extents (own last bins; u_own = the largest); without a
///      slope or a peak an entry's own extent is its run;
///    - one line: every run whole (no bridged gap) but for as many missed bins as its tail
///      has (last - own last: a smear tail near the threshold dips below it on a noisy
///      sensor; a run records how many bins it missed, not where), and the runs step through
///      range one way (from the first azimuth's run towards the last's), no first bin more
///      than one bin against that direction, no own last bin more than one (a run without a
///      tail) or two (an own extent estimated from the peak and a noisy tail's end) (weak
///      clutter along the shadow edge is broken and wanders, and leaves no tail; a pole
///      merged with it is lost too);
///    - thin: its own bins over all its azimuths are at most (u_own - uf + 1) x allowed,
///      what a vertical pole of the same range extent leaves (a wall, a car side or a hedge
///      fills most of the span on every azimuth and fails, smeared or not: its own runs
///      stay the whole wall's height);
///    - no wider than a lean of at most `cfg.max_lean_tan_q16` can make it: span <=
///      allowed + ceil(w / step), w = (r(ul) sin(theta) + r(uf) max(sin(beta), 0)) x
///      max_lean_tan / r(uf) [rad], the visible height of the pole (its lowest point on the
///      -theta ray at r(ul), its top at most on the +beta ray) turned by the lean, seen
///      from r(uf) (theta, beta of the representative azimuth).
///    The target's bounds are then the union extent (bin_first = uf, bin_last = ul: the
///    nearest and farthest point of the pole, the ranges its in-plane inclination is
///    estimated from; no radius from width, ext_grow 0), its representative azimuth the
///    middle of the ones whose own extent ends on u_own (the pole's lowest visible point,
///    the end a smear tail lengthens), `occupied` that run's bins, and it carries
///    SL_TARGET_SLANT. One
///    rotation measures the lean towards the radar only approximately (the ends of the pole
///    lie off the half-plane of its bearing; second order in the sideways lean), which the
///    3D tilt fit's stated sigmas cover (`sl-eval driveby`). On a smearing sensor the range
///    profile (sl_profile.h) refines its r2 from the rows of that azimuth and its
///    neighbours; r1 stays the mask's. The pipeline sends no PoleLean for a track updated by
///    a SLANT target (that frame is one azimuth's run). `cfg.max_lean_tan_q16` = 0 keeps
///    every wider group WIDE. A SLANT target may start a track: weak clutter cannot, as a
///    group of weak runs is rejected WEAK whatever its shape, and since stage 2 grades the
///    runs it cannot join a pole's group either, so no confirmed track is needed first
///    (`daemon_clutter_never_hides_a_pole`; results: docs/RESULTS.md).
/// 5. **Corrections** (sl_detect_correct(), MATH.md s.4), b = bin_size_um:
///    - raw bounds: r1_raw = bin_first * b (near edge of the first occupied bin),
///      r2_raw = (bin_last + 1) * b (far edge of the last occupied bin);
///    - half-bin (paper Sec. V-A): r1 = r1_raw + b/2, r2 = r2_raw - b/2. Combined, r1 and r2
///      are the CENTRES of the first and last occupied bins (a point target in one bin k
///      gives r1 = r2 = (k + 1/2) b, the mean of a position uniform in the bin: unbiased);
///      bin k is assumed to span [k b, (k + 1) b) as in the board generator;
///    - elongation: r2 -= d(r2), d = piecewise-linear interpolation of the board's table
///      (elong_range_um -> elong_d_um), constant beyond its ends, 0 without a table;
///    - radius R: the board's pole_radius_um when non-zero (flag RADIUS_BOARD); otherwise,
///      when cfg.radius_from_width, from the azimuthal width of the inner edge: az_count
///      here is the number of contiguous azimuths around the representative one whose run
///      reaches into the 3-bin slab [bin_first, bin_first + 2] (a round pole's silhouette
///      lies ~R behind its front; a leaning pole spreads in bearing along its
///      length, so the whole group's width overstates the diameter; docs/DESIGN.md, "Detection"),
///      R = r1 * tan(w / 2) with w = (az_count - 1) * step - beam, set to 0 when the beam's
///      half footprint r1 * beam / 2 exceeds 4 R (the beam cannot resolve the diameter), the smallest arc consistent with az_count
///      azimuth samples less the beam's own spread (small angle; clamped to
///      [0, cfg.max_radius_um]; flags RADIUS_WIDTH and RADIUS_CLAMPED). It is biased low on
///      purpose: a thin pole seen on 2-3 azimuths gets R = 0 rather than a fake radius;
///      the azimuth quantisation (0.9 deg = 47 mm at 3 m) makes it coarse. The nearest return is the pole's front surface, so
///      r1 += R (front surface -> axis). The far end of the return comes from the surface
///      points the beam still covers near the silhouette: with L = r1 * tan(beam / 2) the
///      half-footprint of the beam, the deepest covered surface point lies
///      R - sqrt(max(0, R^2 - L^2)) behind the front, so r2 += sqrt(max(0, R^2 - L^2)).
///      A wide beam (L >= R, the paper's simulation) leaves r2 alone; a narrow one shifts
///      both bounds by ~R (rho unchanged to first order).
/// 6. **Alpha**: sl_incline_estimate(r1, r2, &board->geom[az], sigma_r,
///    board->theta_sigma_cdeg), sigma_r = board->range_sigma_um for both bounds, except
///    r1's with a radius from width (sl_detect_r1_sigma_um; the bounds' sigmas combined by
///    sl_incline_bounds_sigma_um, the target flagged SL_TARGET_COARSE: the same width, so
///    the same error, every rotation); its flag is stored in the target (targets are
///    reported whatever the flag; consumers use `incline_flag`).
///
/// ## Calling sequence (one rotation)
///     sl_detect_begin(&d);
///     for (az = 0; az < azimuths; az++)            // increasing; gaps allowed
///         sl_detect_row(&d, az, occ_row, words);   // e.g. straight after sl_mask_update()
///     n = sl_detect_end(&d);                       // targets in d.targets[0 .. n)
/// or `sl_detect_rotation_from_mask()` which does exactly that from a mask.
///
/// ## Ownership, memory, cost
/// Caller-owned `sl_detect_t`, no allocation; it borrows `board` (static const) until
/// re-init. RAM: sizeof(sl_detect_t) = 4 x SL_CFG_MAX_AZIMUTHS (window tables) +
/// SL_CFG_DETECT_MAX_CANDIDATES x (14 + 7 x SL_CFG_DETECT_MAX_SPAN) + SL_CFG_MAX_TARGETS x
/// sizeof(sl_target_t) (52) + 50 bytes of azimuth hints + 5 x SL_CFG_DETECT_MAX_CANDIDATES + 1
/// (the row's link table) + ~68 bytes (defaults: 9,448 bytes on x86-64).
/// Cost: sl_detect_row O(words up to the shadow edge + runs x open groups), two compares per
/// run and open group (the link table), plus a scan of each run's bins for its peak while
/// `peaks` (moving with a known tail slope, stage 4); an azimuth with nothing occupied in its window
/// exits after one OR per window word (and a walk of the open groups when there are any). Per target at
/// sl_detect_end: one sl_incline_estimate + one isqrt. Measured instruction counts:
/// docs/PERFORMANCE.md, "Core modules".
/// sl_detect_init: one isqrt per azimuth. Not reentrant per instance; no callbacks.
#ifndef SHADOWLEAN_SL_DETECT_H
#define SHADOWLEAN_SL_DETECT_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_config.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_mask.h"
#include "shadowlean/sl_thresh.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Azimuths one group records per-azimuth runs for; a wider group is rejected WIDE.
/// At 0.9 deg per azimuth, 24 covers a 0.3 m pole down to 1.3 m plus a 2 deg beam.
#ifndef SL_CFG_DETECT_MAX_SPAN
#define SL_CFG_DETECT_MAX_SPAN 24
#endif
#if SL_CFG_DETECT_MAX_SPAN < 1 || SL_CFG_DETECT_MAX_SPAN > 255
#error "SL_CFG_DETECT_MAX_SPAN must be in [1, 255]"
#endif

/// Groups open at once within a rotation (runs beyond it are dropped and counted).
#ifndef SL_CFG_DETECT_MAX_CANDIDATES
#define SL_CFG_DETECT_MAX_CANDIDATES 32
#endif
#if SL_CFG_DETECT_MAX_CANDIDATES < 1 || SL_CFG_DETECT_MAX_CANDIDATES > 255
#error "SL_CFG_DETECT_MAX_CANDIDATES must be in [1, 255]"
#endif

/// Evidence bonus of a target on a hinted azimuth (stage 4b).
#define SL_DETECT_EVIDENCE_TRACK 1024U

/// Rejection reasons (index of `sl_detect_stats_t.rejected`).
typedef enum sl_detect_reject {
    SL_DETECT_REJ_NEAR = 0,   ///< a run crosses into the near-field exclusion band
    SL_DETECT_REJ_SHADOW = 1, ///< the return reaches the shadow edge (base not in the shadow)
    SL_DETECT_REJ_WIDE = 2,   ///< too wide in azimuth for a slender pole at its range
    SL_DETECT_REJ_BROKEN = 3, ///< a gap inside the run on the representative azimuth
    SL_DETECT_REJ_SHORT = 4,  ///< the representative run is a single bin (no extent: no rho)
    SL_DETECT_REJ_RHO = 5,    ///< rho outside what the model gives on this azimuth (the
                              ///< run as measured, before d(r2): below the fold by more than
                              ///< one bin, or r1 >= r2; above the domain)
    SL_DETECT_REJ_WEAK = 6,   ///< no run of the group rises clearly above its local floor
                              ///< (needs the amplitude row: sl_detect_set_amplitude)
    SL_DETECT_REJ_COUNT = 7
} sl_detect_reject_t;

/// `sl_target_t.flags`.
#define SL_TARGET_RADIUS_BOARD 0x01U   ///< radius from board->pole_radius_um
#define SL_TARGET_RADIUS_WIDTH 0x02U   ///< radius estimated from the azimuthal width
#define SL_TARGET_RADIUS_CLAMPED 0x04U ///< ... and clamped to cfg.max_radius_um
#define SL_TARGET_ELONG 0x08U          ///< the elongation table was applied (d != 0)
#define SL_TARGET_WRAPS 0x10U          ///< the group crosses azimuth 0
#define SL_TARGET_PROFILE 0x20U        ///< bounds from the range profile (sl_profile.h)
#define SL_TARGET_TAIL_EDGE 0x40U      ///< a run's smear tail crosses the shadow edge: the
                                       ///< caller tests the refined r2 against S (stage 1)
#define SL_TARGET_NO_TAIL 0x80U        ///< the range profile saw the return end in a cliff (no
                                       ///< smear tail): the mask's bounds are its own
#define SL_TARGET_SLANT 0x100U         ///< a slender group wider than a vertical pole, kept as
                                       ///< a pole leaning across the line of sight (stage 4,
                                       ///< "Leaning across the line of sight"): bounds are
                                       ///< the group's union extent
#define SL_TARGET_COARSE 0x200U        ///< a bound the extraction cannot resolve (sl_profile.h,
                                       ///< "Uncertainty of the bounds": the end of a walk
                                       ///< over a smear tail, one rotation's edge, r1 with a
                                       ///< radius from width): sigma includes it, and its
                                       ///< error repeats from rotation to rotation (the
                                       ///< tracker does not average it out)
#define SL_TARGET_CUT 0x400U           ///< the range profile saw the return cut off (falling
                                       ///< ever faster into a cliff: a smear kernel's support
                                       ///< or the beam's edge), or the stream's returns so
                                       ///< (sl_profile.h, "Cut-off returns"): the mask's
                                       ///< bounds, unverified (COARSE); in a stream of them
                                       ///< the 3D-tilt histories are cleared
#define SL_TARGET_RAMP 0x800U          ///< the range profile found a ramp at a bound
                                       ///< (sl_profile.h, "Ramps": a smear kernel's front
                                       ///< part or flattening end the profile cannot tell
                                       ///< from the pole): the bound is anywhere along it,
                                       ///< sigma holds it; a 3D-tilt observation that does
                                       ///< not count towards a fit's minimum (sl_tiltobs.h)
#define SL_TARGET_WALKED 0x1000U       ///< r2 is where the range profile's walk over a smear
                                       ///< tail stopped (sl_profile.h, step 4): known to two
                                       ///< bins (sl_profile_coarse_sigma_um), which the
                                       ///< 3D-tilt observation's sigma holds (sl_tiltobs.h)

/// Detection parameters that are not (yet) board fields.
typedef struct sl_detect_cfg {
    uint32_t max_pole_diameter_um; ///< widest object still called a pole (WIDE test)
    uint32_t max_radius_um;        ///< clamp of the width-estimated radius
    uint16_t beam_width_cdeg;      ///< azimuth spread of a point target's return at the
                                   ///< threshold (sensor beam; simulator cone), 0.01 deg
    uint8_t gap_bins;              ///< free bins bridged inside a run (marked broken)
    uint8_t link_bins;             ///< extent overlap tolerance between adjacent azimuths
    uint8_t width_slack_az;        ///< extra azimuths allowed by the WIDE test
    bool radius_from_width;        ///< estimate R from the width when the board has none
    uint8_t weak_margin;           ///< WEAK test: a peak this far above the threshold is
                                   ///< strong whatever the floor (default 6 counts, ~6 dB
                                   ///< on the sensor's 19.8-counts-per-decade scale)
    uint8_t weak_contrast;         ///< WEAK test: or this far above the local floor
                                   ///< (default 20 counts, ~10x in amplitude)
    uint16_t max_lean_tan_q16;     ///< WIDE test while `union_ext`: tan of the largest lean
                                   ///< across the line of sight a slender group may show
                                   ///< (Q16; default tan 30 deg = 37,837; 0 = none)
} sl_detect_cfg_t;

/// Defaults: D_max 0.3 m, R clamp 0.15 m, beam 1.8 deg (CTS350-X), gap 2 bins, link 1 bin,
/// slack 1 azimuth, radius from width on, weak margin 6, weak contrast 20, sideways lean up
/// to 30 deg.
void sl_detect_cfg_default(sl_detect_cfg_t *cfg);

/// One detected target (one rotation). Plain value.
typedef struct sl_target {
    uint16_t az;            ///< representative azimuth index (0 .. azimuths-1)
    uint16_t az_first;      ///< first azimuth of the group (clockwise; > az when wrapping)
    uint16_t az_count;      ///< group width in azimuths
    uint16_t bin_first;     ///< first occupied bin of the representative run
    uint16_t bin_last;      ///< last occupied bin of the representative run
    uint16_t flags;         ///< SL_TARGET_*
    uint32_t r1_raw_um;     ///< bin_first * b
    uint32_t r2_raw_um;     ///< (bin_last + 1) * b
    uint32_t r1_um;         ///< corrected inner bound (half-bin, radius)
    uint32_t r2_um;         ///< corrected outer bound (half-bin, elongation, radius)
    uint32_t radius_um;     ///< radius used (0 = none)
    int32_t elong_um;       ///< d(r2) subtracted from r2
    uint32_t shadow_slant_um; ///< S(az): slant range of the ground-shadow edge
    int32_t alpha_cdeg;     ///< inclination, 0.01 deg, > 0 = top towards the radar (VALID)
    uint16_t sigma_cdeg;    ///< 1-sigma of alpha, 0.01 deg (VALID)
    uint8_t incline_flag;   ///< sl_incline_flag_t
    uint8_t incline_branch; ///< sl_incline_branch_t
    uint8_t occupied;       ///< occupied bins in the representative run (saturating)
    uint8_t ext_grow;       ///< the group's union extent (min first / max last bin over all
                            ///< its azimuths) beyond the representative run, in bins: low
                            ///< nibble before bin_first, high nibble after bin_last, each
                            ///< saturating at SL_TARGET_EXT_SAT (3D tilt, sl_tiltobs.h);
                            ///< 0 unless sl_detect_t.union_ext
    uint16_t evidence;      ///< slot priority (stage 4b), saturating
} sl_target_t;

/// sl_target_t.ext_grow: a nibble at this value means "this many bins or more".
#define SL_TARGET_EXT_SAT 15U

/// Counters (cumulative since init; never asserted).
typedef struct sl_detect_stats {
    uint32_t rotations;        ///< sl_detect_end() calls
    uint32_t rows;             ///< rows accepted
    uint32_t runs;             ///< runs started inside the search window
    uint32_t groups;           ///< groups closed (targets + rejected)
    uint32_t targets;          ///< targets reported
    uint32_t rejected[SL_DETECT_REJ_COUNT]; ///< groups rejected, by first reason
    uint32_t span_overflow;    ///< groups wider than SL_CFG_DETECT_MAX_SPAN (also WIDE)
    uint32_t cand_overflow;    ///< runs dropped: no free group slot
    uint32_t target_overflow;  ///< accepted targets dropped: more than max_targets (the
                               ///< least evidence; stage 4b)
    uint32_t order_errors;     ///< rows ignored: azimuth out of range or not increasing
} sl_detect_stats_t;

/// Per-azimuth summary of a group (internal).
typedef struct sl_detect_azrun {
    uint16_t first; ///< union extent of the group's runs on this azimuth
    uint16_t last;
    uint16_t count; ///< occupied bins (0 = no run on this azimuth)
} sl_detect_azrun_t;

/// A group being built (internal).
typedef struct sl_detect_cand {
    uint16_t az_first;  ///< first azimuth (feed order; wrap merges append past azimuths-1)
    uint16_t az_last;   ///< last azimuth with a run (unwrapped)
    uint16_t last_lo, last_hi; ///< extent on az_last
    uint16_t prev_lo, prev_hi; ///< extent on az_last - 1 (lo > hi: none)
    uint8_t state;      ///< 0 free, 1 open, 2 closed (waiting for the wrap merge)
    uint8_t flags;      ///< internal NEAR / SHADOW / SPAN / WRAPS bits
    sl_detect_azrun_t run[SL_CFG_DETECT_MAX_SPAN]; ///< azimuths az_first .. az_last (the
                        ///< entries beyond the span hold stale data: never read)
    uint8_t peak[SL_CFG_DETECT_MAX_SPAN]; ///< per entry of run[]: the highest amplitude
                        ///< value of its runs (0: no amplitude row), measured and read only
                        ///< while sl_detect_t.peaks (stage 4's own extents); stale otherwise
} sl_detect_cand_t;

/// The groups the current row's runs may join, with their extents on the azimuth before
/// (internal scratch of sl_detect_row, kept here rather than on its stack frame, which the
/// finalisation of the groups it closes sits on top of).
typedef struct sl_detect_links {
    uint16_t lo[SL_CFG_DETECT_MAX_CANDIDATES];     ///< first bin on the azimuth before
    uint16_t hi_tol[SL_CFG_DETECT_MAX_CANDIDATES]; ///< last bin there + cfg.link_bins
    uint8_t slot[SL_CFG_DETECT_MAX_CANDIDATES];    ///< index in cand[]
    uint8_t n;                                     ///< entries in use
} sl_detect_links_t;

/// The detector. Caller-owned; fields read-only to the application.
typedef struct sl_detect {
    const sl_board_t *board;
    sl_detect_cfg_t cfg;
    uint16_t win_bins[SL_CFG_MAX_AZIMUTHS];  ///< runs must start below this bin
    uint16_t edge_bins[SL_CFG_MAX_AZIMUTHS]; ///< a run reaching this bin touches the edge
    uint32_t step_bam;      ///< 2^32 / azimuths
    uint32_t beam_bam;      ///< cfg.beam_width_cdeg as bam32
    uint16_t azimuths;
    uint16_t bins;          ///< board->roi_bins
    uint16_t near_bins;     ///< board->near_exclusion_bins
    uint8_t max_targets;    ///< min(board->max_targets or SL_CFG_MAX_TARGETS, SL_CFG_MAX_TARGETS)
    uint8_t n_targets;      ///< targets of the last completed rotation
    int32_t last_az;        ///< last row's azimuth this rotation (-1: none yet)
    uint16_t n_open;        ///< groups in state "open" (skips the per-row close scan)
    uint32_t open_bits[(SL_CFG_DETECT_MAX_CANDIDATES + 31) / 32]; ///< open groups (bitmap)
    sl_detect_cand_t cand[SL_CFG_DETECT_MAX_CANDIDATES];
    sl_detect_links_t links; ///< scratch of sl_detect_row
    sl_target_t targets[SL_CFG_MAX_TARGETS];
    uint32_t hint_bits[(SL_CFG_MAX_AZIMUTHS + 31) / 32]; ///< hinted azimuths (stage 4b)
    const uint8_t *amp;     ///< amplitude row for the next sl_detect_row (borrowed) or NULL
    uint16_t amp_bins;      ///< its length
    uint8_t amp_threshold;  ///< the threshold it was cut at
    uint16_t tail_slope_q8; ///< self-calibrated smear tail, 1/256 value per bin (0: unknown)
    bool union_ext;         ///< fill sl_target_t.ext_grow (else 0): set by the application
                            ///< before a rotation's rows (the pipeline: while a motion
                            ///< input is present, for the 3D tilt); O(span) per target
    bool slant;             ///< keep slender groups wider than a pole as SLANT targets
                            ///< (stage 4): set by the application before a rotation's rows
                            ///< (the pipeline: while a motion input is present)
    bool peaks;             ///< this rotation measures the runs' peaks (stage 4, own
                            ///< extents): slant and a tail slope at sl_detect_begin
    sl_detect_stats_t stats;
} sl_detect_t;

/// Initialise for a board (borrowed until re-init). `cfg` NULL = defaults (copied).
/// @return SL_OK; SL_ERR_ARG when a pointer is NULL, the board lacks shadow tables
/// (shadow_um and shadow_bins both NULL), has bin_size_um 0, azimuths outside
/// 1..SL_CFG_MAX_AZIMUTHS or roi_bins outside 1..SL_CFG_ROI_BINS.
/// Cost: O(azimuths) with one isqrt and one d(r) lookup each.
sl_err_t sl_detect_init(sl_detect_t *d, const sl_board_t *board, const sl_detect_cfg_t *cfg);

/// Start a rotation: drops the previous rotation's targets and groups. O(candidates).
void sl_detect_begin(sl_detect_t *d);

/// Feed the stable-occupied row of azimuth `az` (`words` words, layout sl_thresh.h;
/// borrowed for the call). Rows must come in increasing azimuth order; a missing azimuth
/// simply breaks adjacency. Only the first `words` words are read (bins beyond are treated
/// as unknown: a run reaching the end of the row is flagged SHADOW).
/// @return SL_OK; SL_ERR_RANGE (az >= azimuths, or az not above the previous row's):
/// counted in `stats.order_errors`, row ignored.
sl_err_t sl_detect_row(sl_detect_t *d, uint16_t az, const uint32_t *occ, uint32_t words);

/// Close the rotation: wrap merge (azimuth azimuths-1 with 0), representative azimuth,
/// rejections, corrections and alpha for every remaining group.
/// @return the number of targets in `d->targets` (0..max_targets), in the order their
/// groups closed (increasing last azimuth; wrapping groups last) as long as they fit; once
/// the slots are full a stronger target takes the slot of the weakest (stage 4b). They
/// stay valid until the next sl_detect_begin().
sl_ssize_t sl_detect_end(sl_detect_t *d);

/// begin + one row per azimuth from `mask` (held rows of stale azimuths included; none for
/// azimuths without history) + end. Reads only the words up to the furthest edge bin.
/// @return as sl_detect_end(). Cost: O(azimuths x words used x mask planes) + the above.
sl_ssize_t sl_detect_rotation_from_mask(sl_detect_t *d, const sl_mask_t *mask);

/// Bins detection reads at most: max over azimuths of edge_bins + 1, clamped to roi_bins.
/// Threshold and mask only these (sl_mask_init(bins = this, rounded up to 32)) when nothing
/// else needs the far range: it cuts those two stages ~3x on paper-sim (160 of 512 bins).
/// O(azimuths).
uint16_t sl_detect_bins_needed(const sl_detect_t *d);

/// The power row (8-bit, `bins` values, thresholded at `threshold`) of the azimuth passed
/// to the NEXT sl_detect_row() call, for the WEAK test; borrowed until that call returns,
/// then forgotten (rows fed without one, e.g. held rows, are not tested). O(1).
void sl_detect_set_amplitude(sl_detect_t *d, const uint8_t *power, uint16_t bins,
                             uint8_t threshold);

/// The stream's smear tail slope (1/256 value per bin per frame, e.g. sl_profile_t.slope_q8;
/// 0 = unknown: the board's d(S) decides SHADOW at the edge, stage 1). Kept until changed. O(1).
void sl_detect_set_tail_slope(sl_detect_t *d, uint16_t slope_q8);

/// Clear every hint (stage 4b). Hints stay until cleared (sl_detect_begin keeps them).
/// O(azimuths / 32).
void sl_detect_hints_clear(sl_detect_t *d);

/// Hint azimuths `az - half_width .. az + half_width` (circular): a target whose
/// representative azimuth is hinted gets SL_DETECT_EVIDENCE_TRACK more evidence. Out of
/// range `az` is ignored. O(half_width).
void sl_detect_hint(sl_detect_t *d, uint16_t az, uint16_t half_width);

/// Clutter tests of stage 4 (SHORT, RHO) on a finished target `t` (bin_first/bin_last,
/// r1_um, r2_um, elong_um, incline flag and rho of r1_um/r2_um set) on azimuth `t->az`:
/// the rejection reason, or -1 when the
/// target may take a slot. Pure; O(1) (one 64-bit division).
int sl_detect_clutter_reason(const sl_board_t *board, const sl_target_t *t, uint32_t rho_q28);

/// Evidence of a target (stage 4b) from the group's total occupied bins, its azimuths with
/// a run and the representative run's extent in bins. Pure, O(1), saturating at 65535.
uint16_t sl_detect_evidence(uint32_t occupied_total, uint32_t az_with_run, uint32_t extent_bins);

/// Stage 5 alone (MATH.md s.4) for a run `bin_first..bin_last` on azimuth `az`, with
/// `az_count` the azimuths the radius estimate sees (sl_detect_end passes the column at the
/// inner edge, see stage 5). Fills r1_raw_um, r2_raw_um, r1_um, r2_um, radius_um, elong_um
/// and the RADIUS_* / ELONG flags of `t` (other fields untouched). `cfg` NULL = defaults.
/// `az` is not used yet (kept for per-azimuth beam or range-offset tables). Pure;
/// O(elong points) plus one isqrt when a radius applies.
void sl_detect_correct(const sl_board_t *board, const sl_detect_cfg_t *cfg, uint16_t az,
                       uint16_t bin_first, uint16_t bin_last, uint16_t az_count,
                       sl_target_t *t);

/// Sigma of r1 (um) from `base_um`, the sigma of the edge itself: with a radius estimated
/// from the azimuthal width (SL_TARGET_RADIUS_WIDTH, radius_um > 0), sqrt(base^2 + R^2 / 3).
/// The column at the inner edge holds the diameter and whatever of the beam's skirt the
/// return's strength lifts above the threshold, which the beam width at that level (not a
/// board field) would separate: the correction r1 += R is uncertain by its own size
/// (uniform within +-R). Pure; one isqrt.
uint32_t sl_detect_r1_sigma_um(const sl_target_t *t, uint32_t base_um);

/// Inner bound (um) of the group's union extent: r1 less ext_grow's bins before the
/// representative run (a saturated nibble counts as SL_TARGET_EXT_SAT bins) and a radius
/// estimated from the azimuthal width (SL_TARGET_RADIUS_WIDTH: on a pole leaning across the
/// line of sight the width holds the lean's own spread in bearing); a board radius stays.
/// 0 when that would not be positive. `bin_um`: the bin size ext_grow counts in. Pure, O(1).
uint32_t sl_detect_union_r1_um(const sl_target_t *t, uint32_t bin_um);

/// The board's elongation d(r) in micrometres (piecewise linear over elong_range_um ->
/// elong_d_um, constant beyond the ends, 0 with no table; truncated toward zero, <= 1 um).
/// O(elong_points).
int32_t sl_detect_elong_um(const sl_board_t *board, uint32_t r_um);

/// Slant range of the ground-shadow edge on azimuth `az`: sqrt(shadow_um^2 + H^2), from
/// `shadow_um` (or, without it, (shadow_bins + 1) * b as the horizontal radius). O(isqrt).
uint32_t sl_detect_shadow_slant_um(const sl_board_t *board, uint16_t az);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_DETECT_H
