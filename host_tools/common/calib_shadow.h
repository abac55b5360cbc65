// calib_shadow.h: the chassis shadow measured from many rotations (sl-calib shadow).
//
// Per azimuth the rotations (and +-az_half_window neighbouring azimuths) are averaged into a
// mean range profile p(k) of the 8-bit power, smoothed over +-range_smooth_bins bins. On it:
//
//  - near-field band: the brightest bin up to near_search_m is the band's peak P; the band
//    ends (`near_end_m`) where p falls through F + 0.5 (P - F) (half fall). Its stability in
//    time is the median over the band's bins of std/mean across rotations (`near_cv`).
//  - dark core: F = min p over [band peak, search_max_m] (`core_level`); `core_m` is the
//    first bin after the band that comes within 15 % of (P - F) of F (the ring's first dark
//    bin, not the global argmin: a return splitting the ring leaves its inner half as core).
//  - inner edge (`inner_edge_m`): walking inwards from the core, the last bin whose p is
//    above F + max(min_ground_contrast, 0.1 (P - F)): where the band's tail meets the floor.
//  - ground start (`ground_start_m`, SLANT range): G = the ground_ref_quantile of p over
//    [core, core + ground_window_m] (`ground_level`); the first upward crossing of
//    L = F + edge_fraction (G - F) after the core, interpolated linearly between bin centres
//    (bin k spans [k b, (k + 1) b), centre (k + 1/2) b). A crossing that does not stay above
//    F + 0.5 (L - F) for persist_m is an isolated return inside the ring: recorded
//    (`bright_inside_m`), the search continues beyond it.
//  - theta(az) = atan(H / R) with the horizontal radius R = sqrt(S^2 - H^2) of the slant
//    ground start S (the radar measures slant range): theta = asin(H / S).
//
// Unusable azimuths (never given a theta; `reason` says why):
//  - "no dark ring": P - F < min_ring_contrast (the band never falls to a floor);
//  - "no ground edge": no persistent rise after the core within search_max_m, or
//    G - F < min_ground_contrast (platform occludes the sector, or no road return);
//  - "bright return inside the ring": on the windowed OR the single-azimuth profile, a bin
//    between the inner edge and the ground start exceeds F + bright_fraction (G - F) and is
//    separated from the band by dark bins (a platform self-return, or an object in the ring);
//  - "ground start within the radar height": S <= H (no real angle);
//  - "outlier": theta differs from the median of the usable azimuths within
//    +-outlier_half_window by more than outlier_deg.
// A sector is a maximal run of consecutive unusable azimuths (wrapping at 0).
//
// Cost: O(azimuths x (2 w + 1) x rotations x bins); 400 x 5 x 11 x 230 is ~5 M adds.
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
    double ground_window_m = 2.0;  ///< window after the core for the ground level G
    double ground_ref_quantile = 0.75;
    double edge_fraction = 0.5;    ///< L = F + edge_fraction (G - F)
    double persist_m = 0.3;        ///< a rise must stay up this long to be the ground
    double min_ring_contrast = 6;  ///< P - F, power units
    double min_ground_contrast = 3;///< G - F, power units
    double bright_fraction = 1.0;  ///< bright return inside the ring: p > F + this (G - F)
    double bright_min = 8;         ///< ... and p > F + this (power units)
    int outlier_half_window = 10;  ///< azimuths each side for the outlier test
    double outlier_deg = 4.0;      ///< |theta - local median| above this: outlier
};

struct ShadowAz {
    int az = 0;
    bool usable = false;
    std::string reason;            ///< empty when usable
    double near_peak_level = 0, near_end_m = 0, near_cv = 0;
    double inner_edge_m = 0, core_m = 0, core_level = 0;
    double ground_start_m = 0;     ///< slant range S (NaN when not found)
    double ground_level = 0;
    double ground_radius_m = 0;    ///< horizontal R = sqrt(S^2 - H^2)
    double theta_deg = 0;          ///< NaN unless usable
    double theta_raw_deg = 0;      ///< from S whenever S > H (also for unusable azimuths)
    double bright_inside_m = 0;    ///< range of the offending return (0: none)
    double bright_level = 0;
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
