// SPDX-License-Identifier: MIT
/// @file sl_profile.h
/// @brief Range profiles beside the bit mask: amplitude kept where a pole is, smear-aware
/// bounds from it (docs/DESIGN.md, "Range extraction").
///
/// The threshold + n-frame AND of the mask keeps one bit per bin, so r2 is where the smear
/// tail crosses the threshold, and the tail's length depends on the level the pole leaves
/// at its last own bin (compression: short returns read long). This module keeps, for a few
/// azimuths that show something inside the shadow, the SUM of the 8-bit rows over the
/// rotations (a bounded per-azimuth accumulator) and extracts the bounds from it with a tail
/// model fitted on the profile itself, so no board constant has to be right.
///
/// ## Accumulation (sl_profile_row, once per azimuth row, any order)
/// - A *slot* watches one azimuth: `sum[k]` = sum over `frames` rows of `power[bin0 + k]`,
///   k < SL_CFG_PROFILE_BINS (8-bit values, so up to 257 rows fit a uint16; at
///   `cfg.max_frames` the sums and the count are halved: an exponential forgetting that
///   keeps the mean and bounds the memory).
/// - An azimuth without a slot claims a free one when this row has an occupied bit (the
///   per-frame threshold bits) in the search window `[near, win)` (the detector's window:
///   the shadow). `bin0 = max(0, first occupied bin - cfg.lead_bins)`.
/// - Evidence alone can fill every slot (a wide return, clutter), so once targets exist,
///   sl_profile_assign() gives each target's representative azimuth a slot, taking it from
///   an azimuth that is no target's when none is free.
/// - sl_profile_end_rotation(): slots whose azimuth showed no bit in the window for more
///   than `cfg.max_idle` rotations are freed; with `reset` (the vehicle moved: the caller
///   passes n_eff < n) every slot is cleared and freed, so a profile never mixes positions.
///
/// ## While moving (one rotation, neighbouring azimuths)
/// A moving pole is at another range and azimuth every rotation, so rotations cannot be
/// summed. Instead, after each rotation the caller reserves, for every track, the azimuths
/// where it is expected next (sl_profile_reserve: its static-object prediction +-2; +-4
/// for a pole leaning across the line of sight while slots are free). Evidence claims
/// only the slots left free after that, and only for a row whose first run in the window
/// ends two bins or more before the window's end (the ground at the shadow edge, and a wide
/// return that reaches it, never qualify): a pole's first sightings, which no track
/// expects yet, are refined too (their walked far bound carries the two-bin sigma of
/// sl_tiltobs.h, SL_TARGET_WALKED). A target whose own slot holds fewer than `cfg.min_frames` rows is refined from
/// the sum of this rotation's rows of its azimuth and its two
/// neighbours when they belong to its detection group (adjacent azimuths, 0.9 deg apart,
/// lie inside one beam width, 1.8 deg: the same pole at the same ranges, each with its own
/// speckle), over the bins all of them cover: three rows, `stats.spatial`. Not a neighbour
/// whose return ends more than 2 bins from the target's (a row's end: its last bin within
/// T/4 values of its own highest): an oblique pole ends 5-7 bins apart on neighbouring
/// azimuths, and its tail laid over the target's own bins reads as the target's tail
/// (`stats.misaligned`). One row left (no neighbour in the group, or none
/// ending where it ends) is too few to walk a tail over or calibrate on (FEW_FRAMES),
/// except a return that ends in a cliff no smear tail makes (the step after it falls by
/// more than two of the steepest plausible slopes) and is not cut off: NO_TAIL with the
/// mask's bounds, and evidence that the stream is clean (`clean_n`), as summed rows'
/// cliffs are. One row cut off (mostly the beam's edge on an oblique pole) is no evidence
/// either way: FEW_FRAMES. Only to remove a
/// smear tail: when that sum ends in a cliff (no tail) the mask's bounds are kept (an
/// oblique pole spans other ranges on the neighbours), counted NO_TAIL. Limits: the walk
/// (step 4) tolerates noise at the rounding level plus the step noise measured from the
/// rows' disagreement; with +-2 values of independent noise on every bin of each row and no
/// such measure (sl_profile_extract) it stops a few bins into the tail (`unit_profile`), and
/// a noise the rows share (the same scatterers in overlapping beams) is not measured. With the
/// default 12 slots two tracks are watched in full while moving (5 azimuths each; confirmed
/// tracks first), the others partly or not (`stats.reserve_full`).
///
/// ## Extraction (sl_profile_extract, pure; S = sum, F = frames, T = threshold)
/// 1. r1: the first bin at or after `hint - 3` (the mask's first bin) with S >= F T.
/// 2. The run above F T from there (gaps up to 2 bins bridged) must end inside the profile
///    (else TAIL_CUT); e = its last bin with S >= F (T + T/4) (below, the noise floor
///    flattens the tail).
/// 3. Tail slope, self-fitted: integer least squares over the (up to) 8 bins ending at e,
///    s in 1/256 value per bin per frame; plausible in [0.5, 24] values/bin over >= 4 bins,
///    else the running calibration (below) is used, else NO_TAIL.
///    No tail: when the step after the run's last bin above F T falls by more than 2 F s
///    (a cliff, not a smear tail), r2 is that last bin and there is no walk; but not when
///    that bin lies at or beyond the shadow edge (`cliff_end`): a pole's own return ends
///    inside the shadow (else it is rejected as SHADOW), so a drop there ends a smear tail
///    (where it meets the floor, or where the smear's support ends) and the walk decides.
///    Nor after a tail: when the self fit ran over all 8 bins and its slope is within the
///    calibration's +-30 % gate of the calibrated slope, the run falls like this stream's
///    smear tail, and a drop at its end (one rotation's rows near the floor can fall by three
///    slopes in one step) is where that tail meets the floor: the walk decides.
/// 4. Walk back from e while the bin before decays into this one like a tail:
///    S[j-1] - S[j] >= F (s_loc - s_loc / 6) (a bin is the pole's own when it decays by
///    clearly less than the local tail slope). A shallower step is still tail when it is
///    short of s_loc by less than one value and it and the step after it (already walked)
///    fall by at least 2 s_loc - 1 value (8-bit values of a static scene are not dithered:
///    that is the rounding bound), or, while s_loc is still the first fit, when the step
///    before it and both together fall like the tail (a knee between two smear
///    components), or when the fall over the (up to) 3 steps that end in it is that of as
///    many tail steps, less one value (a difference of two bins: as noisy as one step, three
///    times its signal; one bin read high or low by speckle the rows share no longer ends
///    the walk, while own bins before the step, flat or the leading edge, fall by far
///    less). s_loc is the slope fitted on the 6 tail bins nearest to the walk
///    (j .. j + 5) once there are 6, so a tail that steepens towards the pole is followed.
///    The walk starts from the slope of the 4 bins ending at e when the whole fit (the
///    first, or the refit below, over 5 or more bins) is steeper than it by a quarter and a
///    value per bin: such a tail (convex in the log: a power law, or a fast component
///    under a slow one) bends within the fit window, and against the fit's slope its
///    shallower far steps read as the pole's own (r2 4-9 bins long,
///    `test_profile_a_tail_that_steepens_towards_the_pole`).
///    The bin where the walk stops is the last own bin: r2. When the first fit window
///    reached into the pole's own bins (a short tail), the fit is repeated on the tail the
///    walk found (>= 4 bins) and the walk done again.
///    Noisy rows (one rotation's rows of neighbouring azimuths, moving): every step test and
///    the cliff test of step 3 are widened by two sigmas of one step of the sum, less the
///    value of rounding already allowed, measured from how much the rows' steps disagree
///    behind the sum's brightest bin (the rows hold the same tail; a row's beam gain is an
///    offset): sl_profile_extract_noisy. On the sensor's value scale (0.5 dB per value) a
///    tail at the threshold is only ~20 dB above an exponential noise floor and its steps
///    scatter by a value or two; summed rotations of a static scene are not widened.
/// 4'. A walk that stops at or beyond the shadow edge stopped on the smear, not on the pole
///    (a pole's own return ends inside the shadow): typically where a kernel of finite
///    support ends while its tail is still strong, the tail's last bins bend down and the
///    first fit over them is too steep. The walk restarts from the bin before the stop with a
///    fit ending there, when that fit falls like a smear tail (1/2 .. 3/2 of the calibrated
///    slope, or of the first walk's fit before any calibration): a pole whose own bins reach
///    beyond the edge falls there slowly, stays beyond and is rejected (SHADOW). At most 8
///    restarts, counted in `retried`.
/// 5. Result in bins (relative to bin0): i1, i2, the slope used and where it came from.
/// 6. Sub-bin far edge, only when the return ends in a cliff (no smear tail to separate):
///    r2 = the start of the last own bin + its lit fraction (sl_profile_fill_q16 of that
///    bin against the own bin before it) instead of the bin's centre. With a tail the last
///    own bin's power is mixed with the smear of the bins before it and the whole-bin
///    centre is kept (not done: the fill after removing the fitted tail).
///    Sub-bin leading edge, also only on a cliff and with three whole bins after the first
///    (sl_profile_lead_edge): along a straight pole the range grows as the square of the
///    distance from the foot of its line, so the pole's length per unit range is
///    ~ 1 / sqrt(r - foot); the lit part starts at the foot (estimator branch 2) or, on
///    branch 1, r1 (1 - cos(alpha - beta)) past it (the top end on the +beta ray). The first
///    bin's lit fraction follows from its power over the second's; the third bin checks
///    the model, and a shape it does not explain (a flat box, a bright scatterer, clipping)
///    keeps the first bin's centre (`stats.lead_kept`). The pole's radius, which rounds the
///    foot's peak, is what the models leave out (`sim_static_sweep`; figures in
///    docs/RESULTS.md). Not on smeared returns: a ratio of two noisy bins through a convex
///    model is biased by their variance, which makes the estimate depend on n under
///    per-frame speckle (docs/DESIGN.md).
/// The value scale (log of power) only enters through the ratio 1/6 and T/4; nothing depends
/// on the simulator's kernel, the board's d(r) or n.
///
/// ## Uncertainty of the bounds (sigma of alpha)
/// The board's `range_sigma_um` is a bound's quantisation (b / sqrt(12) for a bin of b) and
/// holds for an edge the profile resolves: a cliff, a leading edge summed over rotations.
/// Two edges are known to two bins only, sigma b / sqrt(3) (uniform over two bins; the
/// larger of the two is used):
/// - r2 at the end of a walk over a smear tail: the walk takes a bin as tail while its own
///   power adds less than about one sixth of the local slope to the tail's (7 % of the
///   tail's power at 3.3 values per bin), and a pole's last, partly lit bins return less
///   than that under the accumulated smear of its bright bins. The pole ends in the last own
///   bin or in the next; which one, no rule without a model of the smear can say. The error
///   is one-sided and repeats on every rotation (measured short by 15-105 mm on the
///   simulated benches, by up to 60 mm while driving).
/// - r1 and r2 from one rotation's rows of neighbouring azimuths (moving): the edge bins
///   carry one rotation's speckle, so a partly lit edge bin is above the threshold on one
///   rotation and below it on the next, and the pole is anywhere within the azimuth's beam.
/// r1's sigma also holds a radius from width (sl_detect_r1_sigma_um: the correction is
/// uncertain by its own size).
/// Unverified bounds. In a stream not known to be clean (SL_PROFILE_CAL_SMEAR_N self-fits or
/// a prior: it smears; a stream of cut-off returns, below; before SL_PROFILE_CAL_SMEAR_N
/// returns were seen to end in a cliff that does not cut them off, with fewer self-fits:
/// nothing known yet, as at the start of every stream; sl_profile_clean), a target the
/// profile could not check (no slot, too few rows, a cliff in one rotation's rows, any other
/// fallback) keeps the mask's r2, the threshold crossing of a
/// tail shortened by the board's d(r): a prior, not a measurement. Its r2 is then known only
/// to lie between r1 and that end (sigma: the extent / sqrt(12), at least d and a bin), it is
/// flagged COARSE, and no warning level rises on it
/// (sl_track.h: levels rise only at a filtered sigma <= max_sigma). Alpha is unchanged; its
/// sigma also holds the alpha at the interval's other end (r2 one bin past r1, or the fold),
/// uniform between: where alpha is flat in r2 the linearised sigma says nothing of it.
/// Ramps. The exponential tail the walk removes is one smear shape. A kernel with a front
/// part (RadaRays' triangular kernel starts 35 % of its width before the target) makes the
/// leading edge a ramp, and a kernel of finite support (linear in power) ends its tail in
/// a cliff after a slow decline, which step 3 reads as a return without smear, or which
/// the walk (when the drop is beyond the shadow edge) leaves where the tail flattens. One
/// profile cannot tell such a tail from the pole's own bins, so the alpha stays and its
/// sigma holds the alpha at the ramps' other ends (the edge uniform along the ramp: the
/// difference / sqrt(3), added in quadrature; the fold when the bounds there give no valid
/// estimate). A ramp counts from 3 bins (two are the coarse sigma's already), in steps of
/// at least one value per bin:
/// - r1, on branch 1 (leaning towards the radar: r1 is the top end, nearest the foot of
///   the perpendicular, where a pole's own return is strongest and falls from): the bins
///   over which the profile keeps rising after r1. (On branch 2 a rise to the foot is the
///   pole's own.)
/// - r2, in a stream known to smear (`slope_q8` != 0: a tail slope self-fitted or given)
///   or on a target with a ramp at r1: the bins over which the profile falls into a cliff
///   read as r2; or into the end of a walk, when that ramp falls faster in its half nearer
///   r2 (by half a value per bin: a tail flattening towards the pole; a pole's own power
///   falls fastest right after its brightest point), and then over every bin where the
///   profile does not rise into r2 (a kernel linear in power falls by less than a value
///   per bin near the pole: flat after rounding). Whether or not a drop ends the run: a
///   weaker, longer smear component (or a weaker part of the pole) can carry the run past
///   the kernel's end, and the walk then removes only that. A stream without smear (the noise-free demo) keeps the board's sigma
///   on its cliffs.
/// Counted in `stats.ramps`, flagged SL_TARGET_COARSE. On the paper's bench with a 20-bin
/// triangular kernel the ramps' sigma keeps every level down (poles of -10 to +10 deg;
/// `daemon_triangular_smear_never_a_false_warning`). Exponential and two-component tails
/// that fade into the floor have no such ramp.
/// Cut-off returns. The log of a power that reaches zero falls ever faster: a kernel of
/// finite support (RadaRays' is linear in power) ends every return in a cliff after bins
/// that fall faster and faster, and so does a slanted pole's run where it leaves the beam.
/// A cliff is such a cut when the bins before its last (a partly lit bin) fall for 3 or more
/// steps of at least a value per bin and faster, by half a value per bin, in the half nearer
/// the cliff (a pole's own return, brightest at its foot or top, falls fastest right after
/// it: the noise-free demo's and bench_eight_poles' never so). The target keeps the mask's
/// bounds, unverified whatever the stream (NO_TAIL | CUT, COARSE; `stats.cut_ends`).
/// Until the stream is known clean, a cut-off cliff also takes back one clean one (`clean_n`):
/// a stream becomes clean on SL_PROFILE_CAL_SMEAR_N more clean cliffs than cut-off ones (a
/// kernel's end under noise passes the cut test only now and then, and a stream taken for
/// clean would send its next cliffs, the mask's bounds, as verified). Once clean, only `cut_n` undoes it.
/// `cut_n` counts cut-off cliffs less the others (0..255); from SL_PROFILE_CAL_SMEAR_N on
/// (sl_profile_cut) the stream's returns are cut off: its smear is no tail the walk can
/// remove (what it would take for a tail may be the kernel's own shape), so every target
/// of the profile keeps the mask's bounds, unverified; the stream is not clean; and the
/// pipeline clears the 3D-tilt histories (no range bound of such a stream is an
/// observation, and what they hold from before it was known is suspect). A walk's tail is
/// no such evidence (a short tail after flatter own bins falls faster near its end too),
/// and a cut-off cliff alone does not make a stream so (the beam cuts some returns of a
/// slanted pole; the 3D fit's union extent does not depend on one azimuth's cut).
/// Held on `driveby_realistic.ini` with 20- and 35-bin triangular kernels on both value
/// scales (`daemon_triangular_smear_never_a_false_warning`: no LeanWarning above the true
/// level); exponential streams, the demo and the Oxford scans show no cut.
/// Limitation: the first rotations of such a stream, before SL_PROFILE_CAL_SMEAR_N net
/// cut-off cliffs, can send a PoleLean frame beyond 4 LeanSigma (a 35-bin kernel without a
/// front part: a walk whose tail fit straddles a 20-value drop into a weak part of the
/// return, whose first steps fall by less than a value). And a slanted pole approaching in
/// a noise-free stream is cut by the beam on several rotations in a row, which the count
/// cannot tell from a kernel (the stream counts as cut for a few rotations).
/// The two sigmas combine as sigma_rho^2 = (s2^2 + rho^2 s1^2) / r1^2 into the one sigma
/// sl_incline_estimate() takes (sl_incline_bounds_sigma_um), and such a target is flagged
/// SL_TARGET_COARSE: its error repeats from rotation to rotation, so the tracker does not
/// let its fused variance fall below the measurement's (sl_track.h, "Filter"). Alpha is
/// unchanged; only its sigma (PoleLean's LeanSigma) and the tracker's weights change.
///
/// ## Front part: a kernel's rise before the target
/// A smear kernel with a front part (power before the target: a range response with a
/// leading skirt, RadaRays' kernels, an exponential tail behind a linear rise) makes every
/// return climb over the front's length before the pole, and r1, the first bin above the
/// threshold, then lies that many bins early (100-180 mm for a 4-bin linear front on a
/// return 60 values above the threshold, enough to turn a drive-by's 3D fit).
/// The rise of a return is its steps of at least one value per bin (per frame of the sum)
/// from its first bin above the threshold on (ramp_bins), the longer of its own azimuth's
/// row's (one rotation's rows of an oblique pole may start at other ranges, which breaks the
/// sum's rise) and the sum's (less noise to break a rise's shallow steps).
/// Where a pole's own return hardly rises: on estimator branch 2 (leaning away) r1 is the
/// foot of the perpendicular from the radar to the pole's line, a range minimum inside the
/// lit segment, where the pole's length per unit range is singular: its own return climbs
/// over its partly lit first bin, the smear of its first bins accumulating over the next
/// (1-2 bins, more on a thick trunk whose round front spreads the foot) and noise. On
/// branch 1 r1 is the top end on the +beta ray, at the elevation beam's edge, and the own
/// return climbs with the beam's gain (3-6 bins on the sensor's value scale, measured on
/// the realistic drive-by without a front).
/// Nor where the pole leans across the line of sight: each azimuth then holds another piece
/// of it at other ranges, and the azimuth beam's pattern weighs the slanted piece so that a
/// row's own return rises too (2-4 bins on the leaning-away returns of poles leaning along
/// the path, measured without a front); its neighbouring rows start at other ranges.
/// So the stream's front is learned from branch 2 only, like the tail slope: a walked
/// extraction (a tail was removed: a stream without smear, whose returns end in cliffs,
/// never learns a front), not SLANT, reading branch 2, whose own row's brightest of its
/// first 8 bins is at least T/2 above the threshold (a weaker return shows less of its
/// front), and whose neighbouring azimuths in the group (at least one, watched) start within
/// a bin of its own row (a kernel's front is the same on every row), adds its rise to
/// `lead_n`, once per slot (a static sum is one return however often it is extracted; while
/// moving every rotation's rows are new), the counts halved at SL_PROFILE_LEAD_KEEP. From SL_PROFILE_LEAD_MIN samples on (`cfg.prior_front_bins`
/// before) the front is known when 7 of 8 of them rise by 3 bins or more, as `front_bins` =
/// the smallest rise held by an eighth of them (a low quantile: a front shows on every
/// return, while noise and a pole's own geometry lengthen only some rises); once known it is
/// lost only when half rise by a bin at most. Measured on the realistic drive-by (branch-2
/// rises counted, median; shadowleand's exit log prints them): 3.3 dB/bin and power-law
/// tails 1-2 on both value scales, trunks of 10-15 cm radius 1-2, single poles leaning along
/// the path 2 (3 on the sensor's value scale, where a slow tail's accumulated smear
/// lengthens them; their rises, 1-5 bins, put an eighth at 2: hence 7 of 8, not half), a
/// 4-bin linear front 4 (none below 4 in an eighth); a 2-bin front 2, so it is not learned
/// (its rises are those of a pole without one). A stream taken for one with a front by
/// mistake keeps its truth within its sigma: r1 then moves by at most half the span its
/// sigma holds.
/// With a front known, every walked target's r1 (both branches, not SLANT) moves to the
/// middle of its first min(front_bins, its rise) bins (`stats.front_skipped`), and its
/// sigma holds the alpha at their ends (uniform: a long own return's accumulated smear and
/// a partly lit bin rise too, so where the pole starts within the rise no rule here can
/// say; COARSE, no RAMP); what rise is left still widens it ("Ramps"). A slot reserved
/// while moving (sl_profile_reserve) starts front_bins earlier than the track's r1 would
/// have it. When the front becomes known `front_news` is set and the pipeline clears the
/// 3D-tilt histories, as for a cut-off stream: their observations were taken with r1 up
/// to the front's length early. A slot claimed on evidence while moving (a first sighting
/// no track expects: clutter, a pole's far edge) teaches nothing: such a rise would teach a
/// front mid-pass, move r1 and clear the 3D-tilt histories. Not done: fronts of 1-2 bins (the harder bench's one-bin
/// skirt at -6 dB), which no rise tells from a partly lit bin and the smear its first bins
/// accumulate; the front of a SLANT target's union r1; a static scene's handful of poles
/// never reach SL_PROFILE_LEAD_MIN (there only a prior applies).

/// ## Online calibration (D3)
/// `slope_q8`: exponential mean (weight 1/8) of the self-fitted slopes of accepted
/// extractions, each gated to +-30 % of the current value once 4 fits are in
/// (`stats.cal_rejected` counts the others). It is the fallback for short tails only, and
/// detection's tail bound (sl_detect_set_tail_slope: the shadow edge, the own extent of a
/// pole leaning across the beam). It starts at `cfg.prior_slope_q8` when the application
/// saved one (a fresh start otherwise waits for the first upright target's self-fit).
///
/// `r2_offset_um`: the walk's end, corrected from upright poles. Where
/// a walk over a smear tail stops is not where the pole ends: its last, partly lit bins hide
/// under the smear of its bright ones (r2 short), and what the stream's r1 reads (a pole's
/// front surface, a front skirt, a partly lit first bin) is not the axis either. Those
/// errors depend on the sensor's range response and the poles more than on the lean, so the
/// stream measures them where the truth is known without being told: on upright poles. For
/// an upright pole r2 = r1 / cos(theta) (the foot of the perpendicular at the radar's height
/// and the shadow ray); its residual r2 - r1 / cos(theta) is the bounds' error as the
/// estimator sees it (it reads the ratio r2 / r1). Every target whose r2 ends a walk over
/// rotations summed (a static scene), not SLANT, without a ramp at a bound, and whose
/// residual lies within one bin either way is such a sample (one degree of lean moves the
/// residual by half a bin at 2.4 m, by most of a bin at 4 m, so the gate keeps poles within
/// one to two degrees of upright; the mean assumes the stream's near-upright poles lean as
/// often one way as the other), counted in a histogram of 16 cells of an eighth of a bin
/// over [-1, +1) bin (`resid_n`, halved at SL_PROFILE_RESID_KEEP), once per slot (a static
/// sum is one return however often it is extracted; a pole whose slot is freed after
/// `max_idle` rotations without evidence and claimed again counts again, so a parked
/// vehicle's flickering pole can weigh more than one). From SL_PROFILE_RESID_MIN samples on
/// (`cfg.prior_r2_offset_um` before) every such walked r2 moves by minus their mean:
/// `r2_offset_um`, applied within one bin either way (a stream whose near-upright poles all
/// lean one way by a degree reads them upright; no calibration moves r2 by more than a bin).
/// The mean, not the median: a walk's end is bimodal (the pole's last own bin or the one
/// before it), and what reads the bounds averages them (the tracker's fusion, a bench's
/// mean), so the mean residual is what biases it. Its sigma is unchanged (the walk's two
/// bins). Not moved: returns that end in a cliff (their edges are the board's range sigma),
/// a walk that took every bin after the first for tail (r2 = r1, INVALID), and
/// one rotation's rows of neighbouring azimuths (moving): their walk runs on noisier sums
/// with widened tests, and what they feed, the 3D fit's union extent (max r2 over the
/// group's azimuths), has a residual of its own which the representative's does not measure
/// (applied there, it biases the realistic drive-by's observations on the magnitude scale;
/// not done: a residual of the union extent). `stats.resid_samples`; shadowleand's exit log prints the offset for
/// `--r2-offset`.
///
/// ## Ownership, memory, cost
/// Caller-owned `sl_profile_t`, no allocation. RAM: SL_CFG_MAX_AZIMUTHS bytes + slots x
/// (2 x SL_CFG_PROFILE_BINS + 10) + 2 x SL_CFG_PROFILE_BINS (the neighbours' sum) + ~70 B
/// (2,304 B with the defaults on x86-64); with SL_CFG_FIT also 8 x SL_CFG_PROFILE_BINS
/// (the fit's powers) + sizeof(sl_rfit_ws_t).
/// sl_profile_row: an unwatched azimuth costs one table read and a scan of the window's
/// words for the first occupied bit; a watched one SL_CFG_PROFILE_BINS additions.
/// sl_profile_extract: O(bins) with a 6- or 8-point integer fit per walked bin, 64-bit
/// divisions (measured cost: docs/PERFORMANCE.md, "Core modules"). Not reentrant per
/// instance.
#ifndef SHADOWLEAN_SL_PROFILE_H
#define SHADOWLEAN_SL_PROFILE_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_config.h"
#include "shadowlean/sl_detect.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_response.h"
#include "shadowlean/sl_rfit.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Azimuths watched at once (slots).
#ifndef SL_CFG_PROFILE_SLOTS
#define SL_CFG_PROFILE_SLOTS 12
#endif
#if SL_CFG_PROFILE_SLOTS < 1 || SL_CFG_PROFILE_SLOTS > 254
#error "SL_CFG_PROFILE_SLOTS must be in [1, 254]"
#endif

/// Bins per watched profile (from the slot's bin0).
#ifndef SL_CFG_PROFILE_BINS
#define SL_CFG_PROFILE_BINS 64
#endif
#if SL_CFG_PROFILE_BINS < 16 || SL_CFG_PROFILE_BINS > 1024
#error "SL_CFG_PROFILE_BINS must be in [16, 1024]"
#endif

#define SL_PROFILE_NONE 0xFFU

/// Why an extraction fell back to the mask's bounds (`sl_profile_stats_t.fallback`).
typedef enum sl_profile_fail {
    SL_PROFILE_OK = 0,
    SL_PROFILE_NO_SLOT = 1,   ///< the azimuth is not watched (or has no frame yet)
    SL_PROFILE_LEAD_CUT = 2,  ///< the run starts before the profile (no leading edge)
    SL_PROFILE_NO_RUN = 3,    ///< nothing above the threshold near the mask's first bin
    SL_PROFILE_TAIL_CUT = 4,  ///< the run reaches the profile's end
    SL_PROFILE_NO_TAIL = 5,   ///< no plausible tail slope (self fit or calibration)
    SL_PROFILE_FEW_FRAMES = 6, ///< fewer than cfg.min_frames rows summed (moving: reset)
    SL_PROFILE_FAIL_COUNT = 7
} sl_profile_fail_t;

/// Accepted self-fitted tail slopes (`cal_n`) from which the stream counts as smearing: its
/// mask bounds then carry a tail (sl_tiltobs_t.verified_only; from the start with a
/// cfg.prior_slope_q8). Returns seen to end in a cliff (`clean_n`) from which, with fewer
/// fits, it counts as clean (sl_profile_clean).
#define SL_PROFILE_CAL_SMEAR_N 4U

/// Rises counted for the front part ("Front part"): L = 0 .. SL_PROFILE_LEAD_HIST - 1 (longer
/// rises count as the longest).
#define SL_PROFILE_LEAD_HIST 8U
/// Samples from which the stream's own front replaces cfg.prior_front_bins.
#define SL_PROFILE_LEAD_MIN 8U
/// Samples at which the counts are halved (recent returns count).
#define SL_PROFILE_LEAD_KEEP 32U

/// Cells of the walk-end residual histogram ("Online calibration"): an eighth of a bin each
/// over [-1, +1) bin.
#define SL_PROFILE_RESID_CELLS 16U
/// Samples from which the stream's own residual replaces cfg.prior_r2_offset_um.
#define SL_PROFILE_RESID_MIN 8U
/// Samples at which the residual counts are halved.
#define SL_PROFILE_RESID_KEEP 64U
/// Largest |cfg.prior_r2_offset_um| accepted (a larger one is no bin's): 100 mm.
#define SL_PROFILE_R2_OFFSET_MAX_UM 100000

/// Where the slope of an extraction came from.
#define SL_PROFILE_SLOPE_FIT 1U ///< self-fitted on this profile
#define SL_PROFILE_SLOPE_CAL 2U ///< the running calibration (tail too short to fit)
#define SL_PROFILE_SLOPE_CLIFF 3U ///< no tail: the return ends in a cliff, r2 = its last bin

typedef struct sl_profile_cfg {
    uint16_t max_frames; ///< halve the sums at this many frames (2..257, default 128)
    uint8_t lead_bins;   ///< bins kept before the first occupied bin at claim (default 6)
    uint8_t max_idle;    ///< rotations without evidence before a slot is freed (default 4)
    uint8_t min_frames;  ///< rows a profile needs before it replaces the mask's bounds
                         ///< (default 2: one row carries one rotation's speckle in full and
                         ///< is no better than the mask; while moving the sums are reset
                         ///< every rotation and the rows of neighbouring azimuths count)
    uint16_t prior_slope_q8; ///< tail slope to start from, 1/256 value per bin (default 0:
                             ///< none): this sensor's calibrated slope_q8 saved from an
                             ///< earlier run by the application. Used until the first
                             ///< self-fit replaces it (cal_n stays 0 until then: no gate
                             ///< against it). A prior says the sensor smears: the stream is
                             ///< never taken as clean (sl_profile_clean), so unchecked bounds
                             ///< stay unverified and out of the tilt history
                             ///< (sl_tiltobs_t.verified_only). 0 or 128..6144 (0.5..24 values
                             ///< per bin).
    uint8_t prior_front_bins; ///< front part to start from, bins (default 0: none): the
                              ///< `front_bins` an earlier run learned ("Front part"), used
                              ///< until the stream has SL_PROFILE_LEAD_MIN samples of its own.
                              ///< 0 or 2..SL_PROFILE_LEAD_HIST - 1.
    int32_t prior_r2_offset_um; ///< walk-end correction of r2 to start from, um (default
                                ///< 0: none): the `r2_offset_um` an earlier run learned
                                ///< ("Online calibration"), used until the stream has
                                ///< SL_PROFILE_RESID_MIN samples of its own; applied within
                                ///< one bin either way. |value| <= SL_PROFILE_R2_OFFSET_MAX_UM.
} sl_profile_cfg_t;

void sl_profile_cfg_default(sl_profile_cfg_t *cfg);

typedef struct sl_profile_slot {
    uint16_t sum[SL_CFG_PROFILE_BINS]; ///< sum of power[bin0 + k] over `frames` rows
    uint16_t az;
    uint16_t bin0;
    uint16_t frames;
    uint8_t idle;  ///< rotations without an occupied bit in the window
    uint8_t seen;  ///< an occupied bit in the window this rotation
    uint8_t live;
    uint8_t lead_seen; ///< this slot's rise counted for the front part (once per sum), or
                       ///< not to be: claimed on evidence while moving
    uint8_t resid_seen; ///< this slot's walk-end residual counted (once per sum)
#if SL_CFG_FIT
    uint16_t fit_frames; ///< rows in the sum at its last fit (0: none; halved with the sum)
    uint8_t fit_quality; ///< that fit's sl_rfit_quality_t
    int32_t fit_a_q8, fit_b_q8; ///< its bounds, bins Q8 from bin0
    uint32_t fit_sa_q8, fit_sb_q8; ///< their sigmas, bins Q8
    int32_t fit_corr_q15; ///< their correlation
    uint32_t sq[SL_CFG_PROFILE_BINS]; ///< sum of the squared values (halved with `sum`): how
                                      ///< much of the speckle changes from row to row
#endif
} sl_profile_slot_t;

/// Result of one extraction (bins relative to the slot's bin0).
typedef struct sl_profile_bounds {
    uint16_t i1;        ///< first bin of the pole (leading edge)
    uint16_t i2;        ///< last own bin (tail removed)
    uint16_t e;         ///< last bin of the tail used for the fit
    uint16_t slope_q8;  ///< tail slope used, 1/256 value per bin (per frame)
    uint8_t slope_src;  ///< SL_PROFILE_SLOPE_*
    uint8_t fail;       ///< sl_profile_fail_t (SL_PROFILE_OK: the fields above are valid)
    uint8_t end_drop;   ///< 1: the step after the run's last bin falls by more than two
                        ///< slopes (a cliff, or a smear tail whose kernel ends there)
    uint8_t retried;    ///< walks restarted after a stop at or beyond the shadow edge (4')
} sl_profile_bounds_t;

typedef struct sl_profile_stats {
    uint32_t claims;        ///< slots claimed
    uint32_t claim_full;    ///< azimuths with evidence but no free slot
    uint32_t released;      ///< slots freed after max_idle
    uint32_t resets;        ///< sl_profile_end_rotation with reset
    uint32_t extracted;     ///< targets refined from a profile
    uint32_t fallback[SL_PROFILE_FAIL_COUNT]; ///< targets left with the mask's bounds, by reason
    uint32_t assigned;      ///< slots given to targets' azimuths (sl_profile_assign)
    uint32_t stolen;        ///< ... taken from an azimuth that was no target's
    uint32_t assign_full;   ///< targets left without a slot (every slot watches a target)
    uint32_t cal_accepted;  ///< self-fitted slopes taken into the calibration
    uint32_t cal_rejected;  ///< ... refused by the +-30 % gate
    uint32_t ramps;         ///< targets whose sigma holds a ramp ("Uncertainty of the bounds")
    uint32_t lead_kept;     ///< cliff-ended targets whose leading edge kept the first
                            ///< bin's centre (sl_profile_lead_edge: the shape fits no model)
    uint32_t spatial;       ///< targets refined from one rotation's rows of neighbouring
                            ///< azimuths (too few rotations summed: moving)
    uint32_t misaligned;    ///< ... neighbouring rows left out of such a sum: their return
                            ///< ends more than 2 bins from the target's (an oblique pole)
    uint32_t reserved;      ///< slots reserved where a track is expected (sl_profile_reserve)
    uint32_t reserve_full;  ///< ... azimuths left unwatched: no free slot
    uint32_t cut_ends;      ///< cliffs the return falls ever faster into (cut off by a
                            ///< kernel's support or the beam, not ended: "Cut-off returns")
    uint32_t front_skipped; ///< targets whose r1 moved past the stream's front part
    uint32_t resid_samples; ///< upright-pole residuals counted ("Online calibration")
    uint32_t fits;          ///< sl_profile_refine_fit: fits run
    uint32_t fits_reused;   ///< ... targets given their slot's last fit (its sum grew by
                            ///< less than a quarter since)
    uint32_t fits_kept;     ///< ... refits without bounds or sigmas: the slot's last fit kept
    uint32_t fits_flat;     ///< ... answers from the flat density (it explained the samples
                            ///< better than the slender target's)
    uint32_t fit_quality[4]; ///< ... by sl_rfit_quality_t
} sl_profile_stats_t;

typedef struct sl_profile {
    sl_profile_cfg_t cfg;
    uint16_t azimuths;
    uint16_t near_bins;
    uint16_t slope_q8;      ///< calibrated tail slope (0: none yet)
    uint16_t cal_n;         ///< fits taken into slope_q8 (saturating)
    uint16_t n_live;        ///< slots in use
    uint8_t moving;         ///< the last sl_profile_end_rotation had `reset`: claims on
                            ///< evidence only for runs ending clear of the window's end
    uint8_t clean_n;        ///< returns seen to end in a cliff that does not cut them off,
                            ///< less cut-off ones until there are SL_PROFILE_CAL_SMEAR_N
                            ///< ("Cut-off returns"; saturating at 255): with
                            ///< SL_PROFILE_CAL_SMEAR_N of them and fewer self-fits, a stream
                            ///< known not to smear ("Unverified bounds")
    uint8_t cut_n;          ///< cut-off returns less returns ending otherwise in a cliff
                            ///< (0..255): from SL_PROFILE_CAL_SMEAR_N on, a stream whose
                            ///< smear no tail model describes ("Cut-off returns")
    uint8_t front_bins;     ///< the stream's front part, bins (0: none; "Front part")
    uint8_t front_news;     ///< set when the front became known (the bounds before it
                            ///< are suspect); the pipeline clears it
    uint8_t lead_n[SL_PROFILE_LEAD_HIST]; ///< rises of branch-2 returns by length ("Front part")
    uint8_t resid_n[SL_PROFILE_RESID_CELLS]; ///< walk-end residuals of upright poles by cell
                                             ///< ("Online calibration")
    int32_t r2_offset_um;   ///< added to every walked r2 ("Online calibration"; the prior
                            ///< until SL_PROFILE_RESID_MIN samples, then the stream's own)
    uint8_t slot_of[SL_CFG_MAX_AZIMUTHS]; ///< slot index per azimuth, SL_PROFILE_NONE
    sl_profile_slot_t slot[SL_CFG_PROFILE_SLOTS];
    uint16_t scratch[SL_CFG_PROFILE_BINS]; ///< neighbours' rows summed (sl_profile_refine)
#if SL_CFG_FIT
    uint32_t fit_y[SL_CFG_PROFILE_BINS];   ///< sl_profile_refine_fit: observed power
    uint32_t fit_f[SL_CFG_PROFILE_BINS];   ///< ... and the background's, per sample
    sl_rfit_ws_t fit_ws;                   ///< ... the fit's work memory
#endif
    sl_profile_stats_t stats;
} sl_profile_t;

/// Initialise (no slot in use). `cfg` NULL = defaults. @return SL_ERR_ARG for NULL `pr`,
/// azimuths 0 or > SL_CFG_MAX_AZIMUTHS, max_frames outside 2..257, a prior_slope_q8 other
/// than 0 outside 128..6144, a prior_front_bins of 1 or SL_PROFILE_LEAD_HIST and more, a
/// |prior_r2_offset_um| above SL_PROFILE_R2_OFFSET_MAX_UM.
sl_err_t sl_profile_init(sl_profile_t *pr, uint16_t azimuths, uint16_t near_bins,
                         const sl_profile_cfg_t *cfg);

/// One azimuth row: `power` (n bins from bin 0, 8-bit), this frame's threshold bits `bits`
/// (layout sl_thresh.h, at least ceil(min(n, win)/32) words) and the detector's search
/// window end `win` for this azimuth. Adds the row to the azimuth's slot, claiming a free one
/// when the row has an occupied bit in [near, win) (while moving: only when the first run
/// there ends two bins or more before `win`; `claim_full` counts only when stopped). Rows of
/// an azimuth out of range are ignored.
void sl_profile_row(sl_profile_t *pr, uint16_t az, const uint8_t *power, uint32_t n,
                    const uint32_t *bits, uint32_t win);

/// End of a rotation: age and free idle slots; `reset` clears every sum (vehicle moving).
void sl_profile_end_rotation(sl_profile_t *pr, bool reset);

/// After a rotation's targets are known: every target's representative azimuth without a
/// slot gets one (a free slot, else one watching an azimuth that is no target's, counted
/// `stolen`; `assign_full` when every slot watches a target), with bin0 = bin_first -
/// lead_bins. Its profile starts with the next row. O(targets x slots).
void sl_profile_assign(sl_profile_t *pr, const sl_target_t *targets, uint32_t n);

/// While moving (after sl_profile_end_rotation with `reset`, which frees every slot): watch
/// the azimuths `az - half .. az + half` (circular) where a track is expected next rotation,
/// with bin0 = `bin_first` - lead_bins, each in a free slot (`reserve_full` counts the ones
/// left out). Evidence claims only what is left free while moving, and never for a run
/// that reaches the shadow edge (the ground there would take every slot in azimuth order).
/// @return the azimuths now watched.
/// O(half x slots).
uint32_t sl_profile_reserve(sl_profile_t *pr, uint16_t az, uint16_t bin_first, uint32_t half);

/// Values of the sensor's log mapping that span the fill table (48 x 0.5 dB = 24 dB, a lit
/// fraction of 0.004: below it the edge bin reads as empty).
#define SL_PROFILE_FILL_VALUES 48U

/// Lit fraction of an edge bin, Q16 (65535 = the whole bin), from its summed value
/// `edge_sum` against `ref_sum`, the summed value of a neighbouring bin the target fills
/// completely, over `frames` rows (pure).
/// Physics: the range bin (43.8 mm on the CTS350-X) is ten times the wavelength (3.9 mm),
/// so the returns of the scatterers along a pole add in power, not in amplitude, and a bin
/// a pole fills for a fraction f of its length returns f times the power of a full bin of
/// the same pole. The sensor's 8-bit output is logarithmic, 0.5 dB per value (Navtech FFT
/// data), so f = 10^(-(ref - edge) / 20) with the values' difference. Table of
/// 10^(-k/20), linear between whole values; an edge at or above the reference is full, one
/// SL_PROFILE_FILL_VALUES or more below it empty. Assumes the pole's power per unit length
/// is about constant over the two bins (not so at a range extremum of the pole, where the
/// length per bin peaks: hence used for r2, not for r1).
uint32_t sl_profile_fill_q16(uint32_t edge_sum, uint32_t ref_sum, uint32_t frames);

/// Lit fraction of the FIRST bin of a return, Q16 (pure), from its summed value against the
/// second bin's, over `frames` rows. Geometry, no constant of the scene: along a straight
/// pole the range grows with the distance s from the foot of its line as r = sqrt(p^2 + s^2),
/// so the pole's length per unit range is ~ 1 / sqrt(r - p). The lit part starts `delta_q16`
/// (bins, Q16) past the foot: 0 when r1 IS the foot (estimator branch 2, a range minimum
/// inside the lit segment), r1 (1 - cos(alpha - beta)) when r1 is the top end on the +beta
/// ray (branch 1). With f the first bin's lit fraction, the bins hold 2 (sqrt(f + d) -
/// sqrt(d)) and 2 (sqrt(1 + f + d) - sqrt(f + d)) (units of sqrt(bin)); f is found from their
/// ratio, measured from the values' difference at 0.5 dB per value (either bin may be the
/// brighter): at the foot in closed form, f = q^2 / (1 + 2 q) (q = f + sqrt(f (1 + f))), else
/// by bisection to 1/256 bin (0.2 mm); full when the ratio reaches f = 1's. From
/// SL_PROFILE_LEAD_END_Q16 on the length per bin is taken as constant (the ratio is f:
/// sl_profile_fill_q16). A pole's radius rounds the foot's peak (its surface spreads the
/// nearest point over R), so a well-filled first bin reads partly filled: r1 then errs
/// towards the far end of its bin by up to ~R. Cost: one 64-bit division at the foot, else
/// 9 ratio evaluations (two 64-bit integer square roots each).
uint32_t sl_profile_lead_fill_q16(uint32_t first_sum, uint32_t second_sum, uint32_t frames,
                                  uint32_t delta_q16);

/// The leading edge from the first three bins' sums `sum3` (pure): `*f_q16` = the first
/// bin's lit fraction (sl_profile_lead_fill_q16 with `delta_q16`). Returns true when the
/// third bin agrees with the same model: its power over the second's within 3 values
/// (1.5 dB) of the model's (sqrt(f + d + 2) - sqrt(f + d + 1)) / (sqrt(f + d + 1) -
/// sqrt(f + d)), or of 1 for an end. The tolerance: one value is the rounding of two 8-bit
/// values; the rest is what the model leaves out (the pole's radius, the elevation pattern):
/// on sim_static_sweep's noise-free returns the third bin sits up to 2.5 values off the
/// model. A return whose shape the line's geometry does not explain gets false and the
/// caller keeps the first bin's centre: a flat box (the foot model then predicts a third
/// bin >= 3.8 values below the second), a bright scatterer on the pole, clipping.
bool sl_profile_lead_edge(const uint16_t *sum3, uint32_t frames, uint32_t delta_q16,
                          uint32_t *f_q16);

/// Offset of the lit part from the foot beyond which the leading edge is taken as an end of
/// constant length per bin (64 bins, Q16).
#define SL_PROFILE_LEAD_END_Q16 (64UL << 16)

/// Whether the stream is known not to smear: SL_PROFILE_CAL_SMEAR_N more returns seen to end
/// in a cliff that does not cut them off than cut-off ones (`clean_n`), fewer accepted
/// self-fits, no prior and not
/// a stream of cut-off returns (sl_profile_cut). False at the start of every
/// stream (nothing known yet) and in a smearing one: bounds the profile did not check are
/// then unverified (sl_profile.h, "Unverified bounds"; sl_tiltobs_t.verified_only). Pure.
bool sl_profile_clean(const sl_profile_t *pr);

/// Whether the stream's returns are cut off ("Cut-off returns"): `cut_n` >=
/// SL_PROFILE_CAL_SMEAR_N, i.e. that many more cut-off cliffs than others seen. Pure.
bool sl_profile_cut(const sl_profile_t *pr);

/// Sigma of a bound known to two bins of `bin_um`: bin_um / sqrt(3), rounded (pure).
uint32_t sl_profile_coarse_sigma_um(uint32_t bin_um);

/// Most rows a profile sum may hold for sl_profile_extract (a slot's max_frames <= 257, three
/// neighbours' rows: <= 771): more is SL_PROFILE_NO_SLOT (the arithmetic is 32-bit).
#define SL_PROFILE_MAX_FRAMES 1023U

/// Smear-aware bounds from a profile (pure; see "Extraction"). `hint` = the mask's first
/// bin relative to the profile start, `cal_slope_q8` the fallback slope (0: none),
/// `cliff_end` the first bin (relative to the profile start) that lies at or beyond the
/// shadow edge: a run whose last bin is there never ends in a cliff (step 3), UINT32_MAX
/// for no limit.
sl_profile_bounds_t sl_profile_extract(const uint16_t *sum, uint32_t n, uint32_t frames,
                                       uint32_t threshold, uint32_t hint, uint32_t cal_slope_q8,
                                       uint32_t cliff_end);

/// sl_profile_extract on sums whose steps are noisy beyond rounding: `tol_q8` (1/256 value x
/// frames) widens every step test of the walk and the cliff test (two sigmas of one step of
/// the sums, less a value; sl_profile_refine measures it while moving from the disagreement
/// of the neighbouring rows' steps). 0: sl_profile_extract.
sl_profile_bounds_t sl_profile_extract_noisy(const uint16_t *sum, uint32_t n, uint32_t frames,
                                             uint32_t threshold, uint32_t hint,
                                             uint32_t cal_slope_q8, uint32_t cliff_end,
                                             uint32_t tol_q8);

/// Refine a detected target with the profile of its azimuth (while moving: this rotation's
/// rows of it and its neighbours, see "While moving"): r1 from the leading edge, r2
/// from the last own bin (half-bin centres, r2 sub-bin when the return ends in a cliff (6.),
/// a walk's end over summed rotations moved by `r2_offset_um` ("Online calibration"), the
/// target's radius terms kept, no d(r)), alpha
/// re-estimated; flag SL_TARGET_PROFILE, `elong_um` = the smear removed (mask r2 centre -
/// profile r2 centre). A pole leaning across the beam (SL_TARGET_SLANT, sl_detect.h stage
/// 4): its azimuth's run is the pole's lowest piece [bin_last - occupied + 1, bin_last], the
/// leading edge searched from there, and only r2 is replaced (r1, the union's first bin,
/// lies on other azimuths). Without a usable profile the target is left as it is (counted
/// by reason). Updates the slope and walk-end calibrations. @return the extraction's
/// sl_profile_fail_t.
uint8_t sl_profile_refine(sl_profile_t *pr, const sl_board_t *board, uint32_t threshold,
                          sl_target_t *t);

/// Refine a detected target with a fit of its return (sl_rfit.h) on the profile of its
/// azimuth (while moving: this rotation's rows of it and its neighbours, as
/// sl_profile_refine): the profile's mean values turned into power through `resp`'s value
/// scale, the background per sample from `resp`'s noise floor (at least the brightest
/// sample times the level of the response's outermost taps, below which the model cannot
/// tell a far sidelobe from the floor), the window the target's run and half the response's
/// support either side, cut at the shadow edge, the pole's return modelled as SL_RFIT_FOOT
/// and as SL_RFIT_UNIFORM convolved with `resp`'s range response, the one with the lower
/// negative log-likelihood taken; independent looks from how much of the speckle
/// of the return's bins changes from row to row (the slot's sums of squares: one look for a
/// frozen draw however many rotations are summed, and for one rotation's rows). A summed fit
/// stands until the sum grows by a quarter; a refit starts from it, and one that gives no
/// bounds or sigmas keeps it. r1 / r2 from the fitted bounds (the detector's radius terms
/// kept), alpha re-estimated with the sigma the fit's covariance gives (the bounds'
/// correlation included); a fit the model does not explain (SL_RFIT_OUT_OF_MODEL) leaves
/// the target with `incline_flag` SL_INCLINE_OUT_OF_DOMAIN (Quality OUT_OF_MODEL on the bus),
/// a fit without signal or sigma keeps the mask's bounds, widened. Flags: SL_TARGET_PROFILE,
/// and SL_TARGET_COARSE for sums over rotations (their errors repeat). @return the
/// sl_profile_fail_t (SL_PROFILE_OK: fitted). Cost: two fits (sl_rfit.h) of at most
/// SL_CFG_PROFILE_BINS samples per target whose slot's sum grew by a quarter, else O(1).
/// With SL_CFG_FIT only.
#if SL_CFG_FIT
uint8_t sl_profile_refine_fit(sl_profile_t *pr, const sl_board_t *board,
                              const sl_response_t *resp, uint32_t threshold, sl_target_t *t);
#endif

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_PROFILE_H
