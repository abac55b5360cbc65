// SPDX-License-Identifier: MIT
// view_draw.h: drawing helpers shared by sl-view and sl-calib (OpenCV, BGR 8-bit images).
//
// Panels:
//  - PolarAxes: a polar radar image, range (m) to the right, azimuth index downwards
//    (0 at the top), with range ticks and azimuth ticks in degrees (vehicle frame).
//  - CartAxes: a top view centred on the radar, vehicle forward up, left to the left;
//    a point at slant range r on vehicle-frame azimuth a (deg, clockwise from forward) is at
//    (cx + r sin a, cy - r cos a) pixels / scale. Radar images carry no elevation, so the
//    top view places returns at their slant range (as every radar viewer does).
//  - PlotAxes: a plain x/y line plot with ticks and grid.
// Text is drawn with a dark outline so it reads on any background.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace sl {

// Colours (BGR), named by role so every picture uses the same code.
namespace col {
const cv::Scalar kBoardShadow(0, 215, 255);   ///< board's theoretical shadow edge: amber
const cv::Scalar kCalibShadow(255, 80, 255);  ///< calibrated shadow edge: magenta
const cv::Scalar kNearField(255, 160, 60);    ///< near-field exclusion: blue
const cv::Scalar kChassis(255, 255, 255);     ///< chassis outline: white
const cv::Scalar kMask(60, 220, 60);          ///< consistency mask: green
const cv::Scalar kDetect(40, 40, 255);        ///< detections: red
const cv::Scalar kTruth(255, 255, 0);         ///< ground truth: cyan
const cv::Scalar kUnusable(60, 60, 200);      ///< unusable sectors: dark red
const cv::Scalar kText(240, 240, 240);
const cv::Scalar kGrid(90, 90, 90);
} // namespace col

/// Text with a dark outline. `scale` is OpenCV's font scale (0.5 ~ 11 px high).
void draw_text(cv::Mat &img, const std::string &s, cv::Point org, double scale = 0.5,
               const cv::Scalar &c = col::kText, int thickness = 1);

/// Grey image of 8-bit power with a display stretch: v -> 255 * min(1, v / vmax)^gamma.
cv::Mat power_to_grey(const cv::Mat &power, double vmax, double gamma = 0.7);

/// Robust display maximum: the q-quantile of the non-zero values (at least 10).
double display_max(const cv::Mat &power, double q = 0.995);

struct PolarAxes {
    cv::Rect rect;              ///< image area inside the canvas
    int azimuths = 400;
    double range_max_m = 10;    ///< right edge
    double yaw_deg = 0;         ///< vehicle-frame azimuth of index 0 (board radar_yaw_deg)
    cv::Point2d px(double az_index, double range_m) const;
    /// Draws `grey` (azimuths x bins, bin size b) into rect, then ticks and labels.
    void draw_image(cv::Mat &canvas, const cv::Mat &bgr_polar, double bin_m) const;
    void draw_axes(cv::Mat &canvas) const;
    /// A per-azimuth range curve (NaN breaks the line).
    void curve(cv::Mat &canvas, const std::vector<double> &range_m, const cv::Scalar &c,
               int thickness = 2, bool dashed = false) const;
};

struct CartAxes {
    cv::Rect rect;
    double roi_m = 10;          ///< half-width shown (metres)
    cv::Point2d centre() const;
    double scale() const;       ///< pixels per metre
    /// Vehicle frame (x forward, y left, metres, relative to the radar) -> pixels.
    cv::Point2d px_xy(double x_fwd_m, double y_left_m) const;
    /// Slant range r on vehicle azimuth a (deg clockwise from forward) -> pixels.
    cv::Point2d px_ra(double r_m, double az_vehicle_deg) const;
    /// Resamples a polar BGR image (azimuths x bins, bin size b, index 0 at yaw_deg) into
    /// the rect (nearest azimuth, linear in range).
    void draw_image(cv::Mat &canvas, const cv::Mat &bgr_polar, double bin_m, double yaw_deg) const;
    void draw_axes(cv::Mat &canvas) const;
    /// A closed curve of per-azimuth ranges (index i at yaw + 360 i / n); NaN breaks it.
    void curve(cv::Mat &canvas, const std::vector<double> &range_m, double yaw_deg,
               const cv::Scalar &c, int thickness = 2, bool dashed = false) const;
    /// Scale bar of `len_m` metres in the lower-left corner.
    void scale_bar(cv::Mat &canvas, double len_m) const;
};

struct LegendItem {
    cv::Scalar colour;
    std::string label;
    int style = 0;              ///< 0 line, 1 dashed line, 2 filled box, 3 box outline, 4 cross
};
/// Legend box at `org` (top-left); returns its height.
int draw_legend(cv::Mat &img, const std::vector<LegendItem> &items, cv::Point org,
                int width = 300);

struct PlotAxes {
    cv::Rect rect;
    double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
    cv::Point2d px(double x, double y) const;
    void draw(cv::Mat &canvas, double xstep, double ystep, const std::string &xlabel,
              const std::string &ylabel) const;
    /// Line through (x[i], y[i]); NaN breaks it.
    void line(cv::Mat &canvas, const std::vector<double> &x, const std::vector<double> &y,
              const cv::Scalar &c, int thickness = 2) const;
    void dots(cv::Mat &canvas, const std::vector<double> &x, const std::vector<double> &y,
              const cv::Scalar &c, int radius = 2) const;
    /// Vertical band [xa, xb] shaded with `c` at opacity `a`.
    void band(cv::Mat &canvas, double xa, double xb, const cv::Scalar &c, double a) const;
};

} // namespace sl
