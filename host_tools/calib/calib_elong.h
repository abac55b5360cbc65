// SPDX-License-Identifier: MIT
// calib_elong.h: the elongation bias d (MATH.md s.4, paper Sec. V-B "Calibration of d")
// measured from a target at known distances (sl-calib elongation). Host only.
//
// One *position* is a set of consecutive rotations of one capture during which the target
// stands still relative to the radar (a static capture is one position; a simulated pass
// at 1 cm per rotation is one position per rotation). Per position:
//   1. each rotation's rows are thresholded (sl_thresh_u8, board threshold) and fed to the
//      core's consistency mask (sl_mask) with n = min(mask_frames, rotations of the position);
//      the stable-occupied rows after the position's last rotation are what the module sees;
//   2. on the azimuths allowed by the truth (+-az_search around its azimuth, or all), every
//      run of occupied bins (gaps <= gap_bins bridged, as sl_detect) that starts at or beyond
//      the near-field exclusion is a candidate; the target is the candidate whose first bin
//      is nearest the true r1 (within r1_tolerance_m), ties to the most occupied bins;
//      among the target's azimuths the one with the most occupied bins is kept
//      (sl_detect's representative azimuth);
//   3. half-bin bounds as the core (sl_detect_correct): r1 = (first + 1/2) b,
//      r2 = (last + 1/2) b; d = r2 - r2_true; also r1 - r1_true (should be ~0).
// The table is keyed by the observed half-bin r2, the value sl_detect_elong_um() looks d up
// with (the paper's table is keyed by target distance; MATH.md s.4).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "view_frames.h"

namespace sl {

struct ElongTruth {
    int rot_first = 0, rot_last = 0; ///< sl_scan frame numbers (inclusive)
    int az = -1;                     ///< azimuth index of the target, -1 = search all
    double r1_true_m = 0, r2_true_m = 0;
    std::string label;
};

struct ElongOptions {
    int threshold = 40;
    int mask_frames = 16;
    int near_exclusion_bins = 0;
    int gap_bins = 2;
    int az_search = 3;
    double r1_tolerance_m = 0.3;
};

struct ElongMeasurement {
    std::string capture, label;
    int rot_first = 0, rot_last = 0, frames_used = 0, mask_n = 0;
    bool found = false;
    std::string why;                 ///< when not found
    int az = -1, bin_first = 0, bin_last = 0, az_count = 0;
    double r1_true_m = 0, r2_true_m = 0, r1_m = 0, r2_m = 0;
    double d_m = 0, d_r1_m = 0;
};

/// The positions of one capture measured as its rotations stream by (sl::for_each_frame),
/// in memory that does not grow with the capture: while a position's rotations arrive it
/// holds one consistency mask (and, until it has mask_frames rotations, so that n is known,
/// the thresholded rows of those rotations: ~26 KB each); once they are past, only the stable
/// rows of the azimuths it searches. Rotations must come in stream order.
class ElongStream {
public:
    /// `opt`: threshold, mask_frames and az_search are used while streaming.
    ElongStream(const std::vector<ElongTruth> &positions, const ElongOptions &opt);
    ~ElongStream();
    ElongStream(const ElongStream &) = delete;
    ElongStream &operator=(const ElongStream &) = delete;

    /// One decoded rotation (not cropped: for_each_frame's frames).
    void add(const RadarFrame &f, int azimuths);
    /// After the last rotation: one measurement per position, in the order given. `fs`: the
    /// capture's FrameSet at the end (source, bin size, roi_bins = the crop); `opt` as
    /// measure_elongation's (near_exclusion_bins from that bin size).
    std::vector<ElongMeasurement> finish(const FrameSet &fs, const ElongOptions &opt);

private:
    struct Pos;
    void start_mask(Pos &p, int n);
    void close(Pos &p);
    static ElongMeasurement measure(const Pos &p, const FrameSet &fs, const ElongOptions &opt);

    std::vector<std::unique_ptr<Pos>> pos_;
    ElongOptions opt_;
    int azimuths_ = 0, bins_ = 0;
    std::vector<uint32_t> bits_; ///< the rotation being added, thresholded (azimuths x SL_ROI_WORDS)
};

/// Measures one position in `fs` (frames whose `rotation` is in [t.rot_first, t.rot_last]);
/// an ElongStream over the frames held in `fs`.
ElongMeasurement measure_elongation(const FrameSet &fs, const ElongTruth &t,
                                    const ElongOptions &opt);

struct ElongTablePoint {
    double r_m = 0, d_m = 0, std_m = 0, r_min_m = 0, r_max_m = 0;
    int n = 0;
};

struct ElongTable {
    std::vector<ElongTablePoint> points; ///< ascending r
    int n = 0;
    double mean_m = 0, std_m = 0;   ///< over all positions
    double slope = 0, intercept_m = 0, resid_std_m = 0; ///< d = intercept + slope r2
    double mean_d_r1_m = 0;
};

/// Groups the found measurements into `points` groups of (nearly) equal count by observed
/// r2 (0 = automatic: one per ~12 positions, 1..8) and fits d = a + b r2 by least squares.
ElongTable fit_elongation(const std::vector<ElongMeasurement> &m, int points);

/// "elongation = r:d, r:d, ..." (ranges 2 decimals, d 3 decimals, metres), the board key.
std::string elongation_line(const ElongTable &t);

} // namespace sl
