// SPDX-License-Identifier: MIT
// calib_shadow.h: the chassis shadow measured from many rotations (sl-calib shadow).
//
// Per azimuth the rotations (and +-az_half_window neighbouring azimuths) are averaged into a
// mean range profile of the 8-bit power: `raw` (no range smoothing) and p (boxcar of
// +-range_smooth_bins bins). Bin k spans [k b, (k + 1) b), its centre is (k + 1/2) b.
//
//  - near-field band: the brightest bin of p up to near_search_m is the band's peak P; the
//    band ends (`near_end_m`) where p falls through F + 0.5 (P - F) (half fall, interpolated).
//    Its stability in time (`near_cv`) is the median over the band's bins of std/mean across
//    rotations.
//  - dark core: F = min p over [band peak, search_max_m] (`core_level`); `core_m` is the first
//    bin after the band that starts min_core_m of bins within 15 % of (P - F) of F. The noise
//    sigma of `raw` over the next 0.5 m (robust: MAD of first differences / 0.6745 / sqrt 2)
//    sets the rise level d0 = max(min_ground_contrast, 4 sigma) (`rise_level`).
//  - inner edge (`inner_edge_m`): walking inwards from the core, where p rises above
//    F + max(min_ground_contrast, 0.1 (P - F)): the band's tail meets the floor.
//  - ground start (`ground_start_m`, SLANT range S): the first bin after the core whose raw
//    level reaches F + d0 and starts a confirmed rise (>= 90 % of the next confirm_m of p
//    stays >= F + d0 / 2); S is that bin's centre (a partly lit bin counts, as the half-bin
//    rule of the targets). The window's foot is then refined on the azimuth's own mean
//    profile within +-refine_bins (first bin >= f1 + d1 followed by one >= f1 + d1 / 2, f1
//    and d1 from that profile's dark core): the window alone returns the EARLIEST foot of
//    its azimuths, biased short where S changes fast with azimuth. A rise that falls back to the floor is a return inside the ring:
//    skipped, its level remembered. `ground_level` G = max of p over ground_window_m after
//    the foot; `ground_half_m` = where p crosses F + 0.5 (G - F) (half rise, as REAL_SCANS
//    s.2 uses). theta uses S, or the half rise with edge_half_rise.
//  - theta(az) = atan(H / R) with the horizontal radius R = sqrt(S^2 - H^2) of the slant
//    ground start S (the radar measures slant range): theta = asin(H / S).
//
// Unusable azimuths (never given a theta; `reason` says why):
//  - "no dark ring": P - F < min_ring_contrast, or the band never falls to the core level;
//  - "no ground edge": no confirmed rise after the core within search_max_m, or
//    G - F < min_ground_contrast (the platform occludes the sector, or no road return);
//  - "bright return inside the ring": a skipped rise, or a bin of the single-azimuth profile
//    between the first dark bin past the inner edge and the foot, more than bright_min
//    (single azimuth: single_az_factor x bright_min) above F: a platform self-return or an
//    object standing in the ring;
//  - "ground start within the radar height": S <= H (no real angle);
//  - "steeper than the beam's lower bound": theta > max_theta_deg (the board's lower emission
//    bound plus a margin: ground that close is not lit, so the rise is not the ground's);
//  - "outlier": theta differs from the median of the usable azimuths within
//    +-outlier_half_window by more than outlier_deg.
// A sector is a maximal run of consecutive unusable azimuths (wrapping at 0).
//
// Cost: O(azimuths x (2 w + 1) x rotations x bins); 400 x 5 x 11 x 512 is ~11 M adds.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace sl {

struct ShadowCalibOptions {
    double radar_height_m = 0;     ///< H (board)
    double bin_size_m = 0;         ///< b (capture or board)
    int az_half_window = 2;        ///< azimuths averaged on each side
    int range_smooth_bins = 1;     ///< +- bins of the boxcar on the profile
    double near_search_m = 2.5;    ///< the band's peak is searched in [b, this]
    double search_max_m = 10.0;    ///< core and ground are searched up to this slant range
    double ground_window_m = 1.0;  ///< window after the foot for the ground level G
    double min_core_m = 0.2;       ///< the core is the first run this long of dark bins
    int refine_bins = 6;           ///< per-azimuth refinement of the foot (0 = off)
    double confirm_m = 0.8;        ///< a rise must stay up this long to be the ground
    bool edge_half_rise = false;   ///< theta from the half rise instead of the foot
    double min_ring_contrast = 6;  ///< P - F, power units
    double min_ground_contrast = 3;///< G - F, power units
    double bright_min = 8;         ///< bright return inside the ring: > F + this
    double single_az_factor = 1.5; ///< single-azimuth profile: > F + this x bright_min
    double max_theta_deg = 38;     ///< the board's lower emission bound + 3 deg (sl-calib)
    int outlier_half_window = 10;  ///< azimuths each side for the outlier test
    double outlier_deg = 4.0;      ///< |theta - local median| above this: outlier
};

struct ShadowAz {
    int az = 0;
    bool usable = false;
    std::string reason;            ///< empty when usable
    double near_peak_level = 0, near_end_m = 0, near_cv = 0;
    double inner_edge_m = 0, core_m = 0, core_level = 0;
    double rise_level = 0;         ///< d0
    double ground_start_m = 0;     ///< slant range S theta is computed from (foot or half)
    double ground_foot_m = 0;      ///< slant range of the foot (NaN when not found)
    double ground_half_m = 0;      ///< slant range of the half rise (NaN when not found)
    double ground_level = 0;
    double ground_radius_m = 0;    ///< horizontal R = sqrt(S^2 - H^2)
    double theta_deg = 0;          ///< NaN unless usable
    double theta_raw_deg = 0;      ///< from S whenever S > H (also for unusable azimuths)
    double bright_inside_m = 0;    ///< range of the strongest return inside the ring
    double bright_level = 0;       ///< its level above F (power units)
};

struct ShadowSector {
    int az_first = 0, az_count = 0; ///< consecutive unusable azimuths (may wrap)
    std::string reason;             ///< most frequent reason in the sector
};

struct ShadowCalib {
    ShadowCalibOptions opt;
    int frames = 0, azimuths = 0, bins = 0;
    cv::Mat mean;                  ///< CV_32F azimuths x bins, mean over rotations (no window)
    cv::Mat profile;               ///< CV_32F azimuths x bins, windowed + smoothed profile
    std::vector<ShadowAz> az;
    std::vector<ShadowSector> unusable;
    int usable_count = 0;
};

/// The estimator's input, accumulated one rotation at a time (memory: four values per
/// azimuth and bin, whatever the number of rotations): per (azimuth, bin) the sum over
/// rotations, and for the band's stability the sum and sum of squares of the
/// `az_half_window` window's mean of each rotation.
class ShadowAccumulator {
public:
    ShadowAccumulator(int azimuths, int bins, int az_half_window);
    /// One rotation (CV_8U, azimuths x bins); `valid[a]` (empty = all valid) excludes rows.
    void add(const cv::Mat &frame, const std::vector<uint8_t> &valid);
    int frames() const { return frames_; }
    /// The estimator on what was added; `bins` > 0 uses only the first `bins` columns.
    /// Throws std::invalid_argument like calibrate_shadow.
    ShadowCalib estimate(const ShadowCalibOptions &opt, int bins = 0) const;

private:
    int A_, K_, w_, frames_ = 0;
    std::vector<double> sum_;
    std::vector<int> cnt_;
    std::vector<double> wm_, wm2_;
    std::vector<int> wn_;
};

/// Runs the estimator on `frames` (CV_8U, all azimuths x bins, same shape). `valid[f][a]`
/// (optional: empty = all valid) excludes missing rows. Throws std::invalid_argument on
/// inconsistent input (no frames, shapes differ, H or b not positive).
ShadowCalib calibrate_shadow(const std::vector<cv::Mat> &frames,
                             const std::vector<std::vector<uint8_t>> &valid,
                             const ShadowCalibOptions &opt);

/// The "az:deg" theta table and its companions as an INI fragment (format in
/// host_tools/calib/README.md): section [calib], keys board, source, frames, radar_height_m,
/// bin_size_m, azimuths, theta_table, ground_start_m, near_end_m, unusable.
/// `board_theta_deg` (per azimuth, may be empty) adds board_theta_table for comparison.
std::string shadow_calib_ini(const ShadowCalib &c, const std::string &board,
                             const std::string &source,
                             const std::vector<double> &board_theta_deg);

/// A calibrated shadow read back from such a fragment (sl-view --calib).
struct ShadowCalibFile {
    int azimuths = 0;
    double radar_height_m = 0, bin_size_m = 0;
    std::vector<double> theta_deg;      ///< per azimuth, NaN = unusable / absent
    std::vector<double> ground_start_m; ///< per azimuth slant range, NaN = absent
    std::vector<double> near_end_m;     ///< per azimuth, NaN = absent
};
/// Parses the fragment (inih). false + err on I/O or format problems.
bool read_shadow_calib(const std::string &path, ShadowCalibFile &out, std::string &err);

} // namespace sl
