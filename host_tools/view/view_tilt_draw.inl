// SPDX-License-Identifier: MIT
// view_tilt_draw.inl: draw_tilt_marks (view_tilt.h).
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace slv {

template <class ToPx>
void draw_tilt_marks(cv::Mat &img, const std::vector<TiltMark> &marks, double radar_x_m,
                     double radar_y_m, ToPx to_px)
{
    const cv::Scalar kFit(0, 140, 255);    // orange: FITTED
    const cv::Scalar kAmb(160, 160, 160);  // grey: AMBIGUOUS (direction not trusted)
    for (const TiltMark &m : marks) {
        const cv::Scalar c = m.quality == 0 ? kFit : kAmb;
        const double bx = m.base_x_m - radar_x_m, by = m.base_y_m - radar_y_m;
        const double L = 4.0 * std::tan(m.psi_deg * M_PI / 180.0); // top of a 4 m pole
        const double ph = m.phi_deg * M_PI / 180.0;
        const cv::Point2d p0 = to_px(bx, by), p1 = to_px(bx + L * std::cos(ph), by + L * std::sin(ph));
        const cv::Point a(static_cast<int>(std::lround(p0.x)), static_cast<int>(std::lround(p0.y)));
        const cv::Point b(static_cast<int>(std::lround(p1.x)), static_cast<int>(std::lround(p1.y)));
        cv::circle(img, a, 5, cv::Scalar(0, 0, 0), cv::FILLED, cv::LINE_AA);
        cv::circle(img, a, 4, c, cv::FILLED, cv::LINE_AA);
        cv::arrowedLine(img, a, b, c, 2, cv::LINE_AA, 0, 0.25);
        char t[64];
        std::snprintf(t, sizeof t, "%d: psi %.1f dir %.0f%s", m.id, m.psi_deg, m.phi_deg,
                      m.quality == 0 ? "" : " ambiguous");
        cv::putText(img, t, a + cv::Point(8, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3,
                    cv::LINE_AA);
        cv::putText(img, t, a + cv::Point(8, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45, c, 1, cv::LINE_AA);
    }
}

} // namespace slv
