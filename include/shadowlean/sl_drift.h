// SPDX-License-Identifier: MIT
/// @file sl_drift.h
/// @brief Drift watch: the live ground-return start against the loaded calibration's theta.
///
/// Sensitivity of alpha to theta is at least 1 (MATH.md s.3): a shifted mount or a loaded
/// vehicle skews every lean by the change of theta. The watch notices it while parked or on
/// open ground: once per rotation it reads ONE azimuth's row (the "watched" azimuth, which
/// walks through all azimuths: index (k x SL_DRIFT_STEP) mod azimuths in rotation k) and
/// finds where the ground clutter starts beyond the shadow; the slant range S of that start
/// gives theta_live (sin(theta_live) = H / S), compared with the board's (the loaded
/// calibration's) theta of that azimuth.
///
/// ## One sample (sl_drift_tail + sl_drift_row, on the watched azimuth only)
/// The row read is two parts joined:
/// - bins [0, bins): the watched azimuth's stable-occupied row (the consistency mask's, as
///   detection reads it, taken at the end of the rotation), which ends at the board's shadow
///   edge (sl_detect_bins_needed(), rounded up to whole words);
/// - bins [bins, bins + SL_DRIFT_EXTRA_BINS): the "tail", thresholded by sl_drift_tail from
///   the watched azimuth's raw FFT message as it passes through the pipeline (the message
///   carries the whole range; the mask and the scan's ROI are not widened). It is that
///   rotation's single row, not a stable one (see "Noise" below). Missing (the row lost, the
///   message shorter than the mask): the mask's part alone, as before (one-sided).
/// With the tail the watch is two-sided: theta growing (the body sinking: a loaded vehicle,
/// a mount tilted down) moves the ground start inwards into the mask's part, theta
/// shrinking (an unloaded vehicle, a mount tilted up, a calibration made loaded) moves it
/// outwards into the tail; about 5 bins per degree at theta 26 deg, 4.38 cm bins, so the 64
/// tail bins cover a shrink of up to ~10 deg on the paper-sim board (beyond the 8 deg
/// outlier bound). Without a tail a shrinking theta gives "no ground" samples.
/// - ground start g = the start of the run of bins >= threshold (gaps of one bin allowed)
///   that reaches the row's last bin (or, with a tail, the one before: a single row may miss
///   its last bin); no such run: no sample ("no ground");
/// - rejected when any two adjacent bins in [near_exclusion_bins, g - 2) are >= threshold
///   (something stands in the shadow on this azimuth: a target, not ground) ("occupied");
/// - theta_live - theta from the slant range of g's centre, S = (g + 1/2) x bin, to first
///   order with the board's trig: (H - S sin(theta)) / (S cos(theta)) (0.02 deg off at a
///   2 deg drift, 0.3 deg at 8);
/// - rejected when |theta_live - theta_board| > SL_DRIFT_OUTLIER_CDEG (a pole at the edge
///   merged with the ground, a kerb, a wall) ("outlier");
/// - else the sample d = theta_live - theta_board (0.01 deg) updates its sector (one of
///   SL_DRIFT_SECTORS equal sectors of the rotation): est += (d - est) / 2 (the first
///   sample sets it).
///
/// ## The estimate (sl_drift_end_rotation, once per rotation)
/// Valid when at least SL_DRIFT_MIN_SECTORS sectors have SL_DRIFT_MIN_SAMPLES samples; the
/// drift is then the median of those sectors' estimates (robust to one sector with a
/// wall or a kerb), else 0 and not valid. THETA_DRIFT is raised when |drift| >
/// SL_DRIFT_FAULT_CDEG (1 deg) in SL_DRIFT_PERSIST consecutive rotations, and cleared when
/// |drift| <= SL_DRIFT_FAULT_CDEG again in as many. Latency after a step change of theta by
/// 2 deg: each sector is sampled every 8th rotation and needs two samples past the step
/// (est = 0.5 then 0.75 of the step: 1.5 deg > 1 deg), so the median moves after ~2 x 8
/// rotations, plus SL_DRIFT_PERSIST: within 32 rotations of the rows changing
/// (tests/core/test_drift.c). In the pipeline the rows are the consistency mask's stable
/// rows, which show newly lit ground n rotations (the window, 16) after it appears: the
/// fault is raised within n + 32 = 48 rotations (12 s at 4 Hz) of the step, in both
/// directions (below).
///
/// The join: the tail is used only when the mask's row is settled at its end (its last two
/// bins stable-occupied or stable-free, sl_drift_row's `free_`). While the window fills,
/// while driving, or where ground flickers at the mask's edge those bins are neither, and a
/// tail joined there would put the ground start at the join whatever the truth; such rows
/// are read without the tail (the one-sided reading, usually "no ground").
/// Noise: a tail bin is one rotation's return, where the mask's bins are consistent over its
/// window. Isolated noise bins in the shadow are not "occupied" (that needs two adjacent
/// bins) and shift g by at most two bins (0.4 deg) when next to the run; a gap of two bins
/// in the tail's ground (weak clutter) cuts the run short (theta_live too small). Both are
/// single samples: each sector's estimate halves their weight at every later sample, and
/// the median over sectors and SL_DRIFT_PERSIST rotations keep a single bad sample off the
/// fault (no k-of-m vote over rotations was needed: the sectors' samples are already 8
/// rotations apart).
/// Latency, both directions: theta growing, the newly lit bins become stable-occupied n
/// rotations (the mask's window, 16) after the step; theta shrinking, the now-dark bins at
/// the mask's end become stable-free (the join) n rotations after it. Then as above:
/// within n + 32 = 48 rotations (12 s at 4 Hz) of the step either way
/// (calib_drift_theta_step_2deg_raises_theta_drift_within_48_rotations: +2 deg;
/// calib_drift_theta_step_minus_2deg_... and _minus_6deg_past_the_mask_...: -2 and -6 deg).
///
/// Units: theta and drift in 0.01 deg (Health.ThetaDrift sends 0.1 deg).
/// Cost: per azimuth one compare in the pipeline (is this the watched azimuth?) and one
/// pointer in the scan's row (the message); per rotation the tail (sl_thresh_u8 over
/// SL_DRIFT_EXTRA_BINS bins, word-wise), one azimuth's stable rows from the mask, the join
/// and O(bins / 32) word operations and one 64-bit division for the sample, O(sectors^2)
/// for the median (the whole pipeline's per-azimuth figures: docs/PERFORMANCE.md, the thumb
/// ctests). RAM: sizeof(sl_drift_t)
/// = 60 B (the tail: 8 B more). No allocation, no float.
/// Limits: two-sided only where the raw message carries SL_DRIFT_EXTRA_BINS bins past the
/// mask (the CTS350-X sends its whole range); needs ground returns above the threshold at the shadow's edge
/// and the mask's window of consistent rows (parked, or slow on open ground); walls, kerbs
/// or parked cars at the shadow's edge are samples too (outliers beyond 8 deg are dropped,
/// and the median over sectors ignores a minority of sectors).
#ifndef SHADOWLEAN_SL_DRIFT_H
#define SHADOWLEAN_SL_DRIFT_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_proto.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SL_DRIFT_SECTORS 8U
#define SL_DRIFT_STEP 53U            ///< watched azimuth step per rotation (coprime with 400)
#define SL_DRIFT_OUTLIER_CDEG 800    ///< samples further than 8 deg off are not ground
#define SL_DRIFT_MIN_SAMPLES 2U      ///< per sector, before the sector counts
#define SL_DRIFT_MIN_SECTORS 5U      ///< sectors needed for an estimate
#define SL_DRIFT_FAULT_CDEG 100      ///< THETA_DRIFT above 1 deg ...
#define SL_DRIFT_PERSIST 8U          ///< ... in this many consecutive rotations
#define SL_DRIFT_EXTRA_BINS 64U      ///< tail bins read past the mask's end (multiple of 32)

typedef struct sl_drift_stats {
    uint32_t samples;     ///< samples used
    uint32_t no_ground;   ///< watched rows without a ground run in range
    uint32_t occupied;    ///< watched rows with something standing in the shadow
    uint32_t outliers;    ///< samples further than SL_DRIFT_OUTLIER_CDEG off
} sl_drift_stats_t;

typedef struct sl_drift {
    uint16_t azimuths;                       ///< the board's
    uint16_t watch_az;                       ///< azimuth sampled this rotation
    int16_t est_cdeg[SL_DRIFT_SECTORS];      ///< per-sector estimate of theta_live - theta
    uint8_t n[SL_DRIFT_SECTORS];             ///< samples per sector (saturating at 255)
    int16_t drift_cdeg;                      ///< the estimate (0 when !valid)
    bool valid;                              ///< enough sectors
    bool fault;                              ///< THETA_DRIFT holds
    uint8_t persist;                         ///< consecutive rotations against `fault`
    uint8_t tail_n;                          ///< tail bins held (0: none this rotation)
    uint16_t tail_from;                      ///< the tail's first bin (the mask's bins)
    uint32_t tail[SL_DRIFT_EXTRA_BINS / 32U]; ///< tail bits, bin tail_from + k = bit k
    sl_drift_stats_t stats;
} sl_drift_t;

/// Reset for `board` (azimuths). O(1).
void sl_drift_init(sl_drift_t *d, const sl_board_t *board);

/// The watched azimuth's raw FFT message (sl_scan_row_t.fft; its azimuth index is the
/// watched one, the caller checks): bins [from, from + SL_DRIFT_EXTRA_BINS) of `f->bin_data`
/// (`f->bins` bins in wire format: 8-bit, or 16-bit little-endian reduced as the scan reduces
/// them: min(v >> pow16_shift, 255)), thresholded (>= threshold) into the tail, which
/// sl_drift_row joins to the mask's row when its `bins` == `from`. Bins past f->bins are not
/// read (fewer tail bins); NULL `f`: no tail. O(SL_DRIFT_EXTRA_BINS). Cleared at the end of
/// the rotation.
void sl_drift_tail(sl_drift_t *d, const sl_proto_fft_t *f, uint16_t from, uint8_t pow16_shift,
                   uint16_t threshold);

/// The watched azimuth's occupied row and (nullable: no tail joined) its stable-free row
/// `free_` (same layout; sl_mask_stable's): `bits` (bin k = bit k % 32 of word k / 32, as
/// sl_thresh_u8 and sl_mask write it), `bins` of them (bin 0 = range 0), bin size `bin_um` (the
/// radar's). Any other azimuth: ignored (the pipeline calls it for d->watch_az only).
/// O(bins / 32) word operations + one 64-bit division.
void sl_drift_row(sl_drift_t *d, const sl_board_t *board, uint16_t az, const uint32_t *bits,
                  const uint32_t *free_, uint16_t bins, uint32_t bin_um);

/// End of a rotation: the estimate, the fault's persistence, the next watched azimuth.
/// O(SL_DRIFT_SECTORS^2).
void sl_drift_end_rotation(sl_drift_t *d);

/// Health.ThetaDrift in 0.01 deg: the estimate, 0 while not valid. O(1).
int16_t sl_drift_cdeg(const sl_drift_t *d);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_DRIFT_H
