// SPDX-License-Identifier: MIT
// view_draw.cpp: see view_draw.h.
#include "view_draw.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sl {
namespace {
constexpr double kPi = 3.14159265358979323846;

std::string num(double v, int prec)
{
    char b[32];
    std::snprintf(b, sizeof b, "%.*f", prec, v);
    return b;
}

void dashed_line(cv::Mat &img, cv::Point2d a, cv::Point2d b, const cv::Scalar &c, int t)
{
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int n = std::max(1, static_cast<int>(len / 6));
    for (int i = 0; i < n; i += 2) {
        const double f0 = static_cast<double>(i) / n, f1 = std::min(1.0, (i + 1.0) / n);
        cv::line(img, a + f0 * (b - a), a + f1 * (b - a), c, t, cv::LINE_AA);
    }
}
} // namespace

void draw_text(cv::Mat &img, const std::string &s, cv::Point org, double scale,
               const cv::Scalar &c, int thickness)
{
    cv::putText(img, s, org, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0),
                thickness + 2, cv::LINE_AA);
    cv::putText(img, s, org, cv::FONT_HERSHEY_SIMPLEX, scale, c, thickness, cv::LINE_AA);
}

cv::Mat power_to_grey(const cv::Mat &power, double vmax, double gamma)
{
    cv::Mat f;
    power.convertTo(f, CV_32F, 1.0 / std::max(1.0, vmax));
    cv::min(f, 1.0, f);
    cv::max(f, 0.0, f);
    cv::pow(f, gamma, f);
    cv::Mat g;
    f.convertTo(g, CV_8U, 255.0);
    cv::Mat bgr;
    cv::cvtColor(g, bgr, cv::COLOR_GRAY2BGR);
    return bgr;
}

double display_max(const cv::Mat &power, double q)
{
    std::vector<float> v;
    cv::Mat f;
    power.convertTo(f, CV_32F);
    for (int r = 0; r < f.rows; r++) {
        const float *p = f.ptr<float>(r);
        for (int k = 0; k < f.cols; k++) {
            if (p[k] > 0) {
                v.push_back(p[k]);
            }
        }
    }
    if (v.empty()) {
        return 10;
    }
    const size_t i = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1)));
    std::nth_element(v.begin(), v.begin() + static_cast<long>(i), v.end());
    return std::max(10.0, static_cast<double>(v[i]));
}

// ---------------------------------------------------------------------------- PolarAxes
cv::Point2d PolarAxes::px(double az_index, double range_m) const
{
    return {rect.x + range_m / range_max_m * rect.width,
            rect.y + az_index / azimuths * rect.height};
}

void PolarAxes::draw_image(cv::Mat &canvas, const cv::Mat &bgr_polar, double bin_m) const
{
    const int bins = std::min(bgr_polar.cols,
                              std::max(1, static_cast<int>(std::ceil(range_max_m / bin_m))));
    cv::Mat roi = bgr_polar(cv::Rect(0, 0, bins, bgr_polar.rows));
    // Exact placement: bin k spans [k b, (k + 1) b) -> x in rect.
    const int wpx = static_cast<int>(std::lround(bins * bin_m / range_max_m * rect.width));
    cv::Mat scaled;
    cv::resize(roi, scaled, cv::Size(std::max(1, wpx), rect.height), 0, 0, cv::INTER_NEAREST);
    const int w = std::min(scaled.cols, rect.width);
    scaled(cv::Rect(0, 0, w, rect.height)).copyTo(canvas(cv::Rect(rect.x, rect.y, w, rect.height)));
}

void PolarAxes::draw_axes(cv::Mat &canvas) const
{
    cv::rectangle(canvas, rect, col::kGrid, 1);
    const double step = range_max_m > 12 ? 2.0 : 1.0;
    for (double r = 0; r <= range_max_m + 1e-9; r += step) {
        const cv::Point2d a = px(0, r);
        cv::line(canvas, a, cv::Point2d(a.x, rect.y + rect.height + 5), col::kGrid, 1);
        draw_text(canvas, num(r, 0), cv::Point(static_cast<int>(a.x) - 5, rect.y + rect.height + 20),
                  0.45);
    }
    draw_text(canvas, "slant range (m)", cv::Point(rect.x + rect.width / 2 - 60, rect.y + rect.height + 40), 0.5);
    for (int deg = 0; deg <= 360; deg += 45) {
        const double idx = std::fmod((deg - yaw_deg) + 720.0, 360.0) / 360.0 * azimuths;
        const cv::Point2d a = px(deg == 360 ? azimuths : idx, 0);
        cv::line(canvas, cv::Point2d(rect.x - 5, a.y), a, col::kGrid, 1);
        draw_text(canvas, std::to_string(deg), cv::Point(rect.x - 40, static_cast<int>(a.y) + 5), 0.45);
    }
}

void PolarAxes::curve(cv::Mat &canvas, const std::vector<double> &range_m, const cv::Scalar &c,
                      int thickness, bool dashed) const
{
    const int n = static_cast<int>(range_m.size());
    for (int i = 0; i < n; i++) {
        if (!std::isfinite(range_m[i]) || range_m[i] > range_max_m) {
            continue;
        }
        // Each azimuth row spans [i, i + 1): a vertical segment, joined to the next row.
        const cv::Point2d a = px(i, range_m[i]), b = px(i + 1, range_m[i]);
        if (dashed && (i % 4) >= 2) {
            continue;
        }
        cv::line(canvas, a, b, c, thickness, cv::LINE_AA);
        const int j = i + 1;
        if (j < n && std::isfinite(range_m[j]) && range_m[j] <= range_max_m && !dashed) {
            cv::line(canvas, b, px(j, range_m[j]), c, thickness, cv::LINE_AA);
        }
    }
}

// ----------------------------------------------------------------------------- CartAxes
cv::Point2d CartAxes::centre() const
{
    return {rect.x + rect.width / 2.0, rect.y + rect.height / 2.0};
}

double CartAxes::scale() const { return std::min(rect.width, rect.height) / (2.0 * roi_m); }

cv::Point2d CartAxes::px_xy(double x_fwd_m, double y_left_m) const
{
    const cv::Point2d c = centre();
    return {c.x - y_left_m * scale(), c.y - x_fwd_m * scale()};
}

cv::Point2d CartAxes::px_ra(double r_m, double az_vehicle_deg) const
{
    const double a = az_vehicle_deg * kPi / 180.0;
    return px_xy(r_m * std::cos(a), -r_m * std::sin(a));
}

void CartAxes::draw_image(cv::Mat &canvas, const cv::Mat &bgr_polar, double bin_m,
                          double yaw_deg) const
{
    const int n = bgr_polar.rows;
    cv::Mat padded;
    cv::vconcat(bgr_polar, bgr_polar.row(0), padded); // row n = row 0 (wrap)
    cv::Mat mx(rect.height, rect.width, CV_32F), my(rect.height, rect.width, CV_32F);
    const cv::Point2d c = centre();
    const double s = scale();
    for (int v = 0; v < rect.height; v++) {
        float *px_ = mx.ptr<float>(v), *py_ = my.ptr<float>(v);
        for (int u = 0; u < rect.width; u++) {
            const double xf = (c.y - (rect.y + v + 0.5)) / s;
            const double yl = (c.x - (rect.x + u + 0.5)) / s;
            const double r = std::hypot(xf, yl);
            double a = std::atan2(-yl, xf) * 180.0 / kPi - yaw_deg;
            a = std::fmod(a + 720.0, 360.0);
            px_[u] = static_cast<float>(r / bin_m - 0.5);
            py_[u] = static_cast<float>(a / 360.0 * n);
        }
    }
    cv::Mat out;
    cv::remap(padded, out, mx, my, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0));
    out.copyTo(canvas(rect));
}

void CartAxes::draw_axes(cv::Mat &canvas) const
{
    cv::rectangle(canvas, rect, col::kGrid, 1);
    const cv::Point2d c = centre();
    const double step = roi_m > 12 ? 5.0 : (roi_m > 6 ? 2.0 : 1.0);
    cv::Mat layer = canvas(rect); // circles clipped to the panel
    const cv::Point2d off(rect.x, rect.y);
    for (double r = step; r <= roi_m * 1.42; r += step) {
        cv::circle(layer, c - off, static_cast<int>(r * scale()), col::kGrid, 1, cv::LINE_AA);
        const cv::Point2d t = px_ra(r, 135);
        if (t.x < rect.x + rect.width - 40 && t.y < rect.y + rect.height - 10) {
            draw_text(canvas, num(r, 0) + " m", cv::Point(static_cast<int>(t.x) + 3, static_cast<int>(t.y)), 0.4,
                      cv::Scalar(170, 170, 170));
        }
    }
    (void)layer;
    draw_text(canvas, "forward", cv::Point(static_cast<int>(c.x) - 30, rect.y + 18), 0.5);
}

void CartAxes::curve(cv::Mat &canvas, const std::vector<double> &range_m, double yaw_deg,
                     const cv::Scalar &c, int thickness, bool dashed) const
{
    const int n = static_cast<int>(range_m.size());
    cv::Mat sub = canvas(rect);
    const cv::Point2d off(rect.x, rect.y);
    for (int i = 0; i < n; i++) {
        const int j = (i + 1) % n;
        if (!std::isfinite(range_m[i]) || !std::isfinite(range_m[j])) {
            continue;
        }
        if (dashed && (i % 4) >= 2) {
            continue;
        }
        const double ai = yaw_deg + 360.0 * i / n, aj = yaw_deg + 360.0 * (i + 1) / n;
        cv::line(sub, px_ra(range_m[i], ai) - off, px_ra(range_m[j], aj) - off, c, thickness,
                 cv::LINE_AA);
    }
}

void CartAxes::scale_bar(cv::Mat &canvas, double len_m) const
{
    const cv::Point a(rect.x + 20, rect.y + rect.height - 25);
    const cv::Point b(a.x + static_cast<int>(len_m * scale()), a.y);
    cv::rectangle(canvas, cv::Rect(a.x - 6, a.y - 22, b.x - a.x + 12, 34), cv::Scalar(0, 0, 0),
                  cv::FILLED);
    cv::line(canvas, a, b, col::kText, 3);
    cv::line(canvas, a + cv::Point(0, -6), a + cv::Point(0, 6), col::kText, 2);
    cv::line(canvas, b + cv::Point(0, -6), b + cv::Point(0, 6), col::kText, 2);
    draw_text(canvas, num(len_m, len_m < 1 ? 1 : 0) + " m", cv::Point((a.x + b.x) / 2 - 12, a.y - 8), 0.45);
}

// ------------------------------------------------------------------------------- legend
int draw_legend(cv::Mat &img, const std::vector<LegendItem> &items, cv::Point org, int width)
{
    const int row = 22, h = static_cast<int>(items.size()) * row + 10;
    cv::Mat roi = img(cv::Rect(org.x, org.y, std::min(width, img.cols - org.x),
                               std::min(h, img.rows - org.y)));
    cv::Mat dark(roi.size(), roi.type(), cv::Scalar(20, 20, 20));
    cv::addWeighted(roi, 0.25, dark, 0.75, 0, roi);
    cv::rectangle(img, cv::Rect(org.x, org.y, roi.cols, roi.rows), col::kGrid, 1);
    for (size_t i = 0; i < items.size(); i++) {
        const int y = org.y + 16 + static_cast<int>(i) * row;
        const cv::Point a(org.x + 8, y - 4), b(org.x + 38, y - 4);
        const auto &it = items[i];
        switch (it.style) {
        case 1:
            dashed_line(img, a, b, it.colour, 2);
            break;
        case 2:
            cv::rectangle(img, cv::Rect(a.x, y - 11, 30, 12), it.colour, cv::FILLED);
            break;
        case 3:
            cv::rectangle(img, cv::Rect(a.x + 5, y - 11, 20, 12), it.colour, 2);
            break;
        case 4:
            cv::drawMarker(img, cv::Point((a.x + b.x) / 2, y - 5), it.colour, cv::MARKER_CROSS, 12, 2);
            break;
        default:
            cv::line(img, a, b, it.colour, 2, cv::LINE_AA);
        }
        draw_text(img, it.label, cv::Point(org.x + 46, y), 0.45);
    }
    return h;
}

// ----------------------------------------------------------------------------- PlotAxes
cv::Point2d PlotAxes::px(double x, double y) const
{
    return {rect.x + (x - x0) / (x1 - x0) * rect.width,
            rect.y + rect.height - (y - y0) / (y1 - y0) * rect.height};
}

void PlotAxes::draw(cv::Mat &canvas, double xstep, double ystep, const std::string &xlabel,
                    const std::string &ylabel) const
{
    for (double x = std::ceil(x0 / xstep) * xstep; x <= x1 + 1e-9; x += xstep) {
        const cv::Point2d a = px(x, y0), b = px(x, y1);
        cv::line(canvas, a, b, col::kGrid, 1);
        draw_text(canvas, num(x, xstep < 0.1 ? 2 : (xstep < 1 ? 1 : 0)), cv::Point(static_cast<int>(a.x) - 10, static_cast<int>(a.y) + 18), 0.45);
    }
    for (double y = std::ceil(y0 / ystep) * ystep; y <= y1 + 1e-9; y += ystep) {
        const cv::Point2d a = px(x0, y), b = px(x1, y);
        cv::line(canvas, a, b, col::kGrid, 1);
        draw_text(canvas, num(y, ystep < 0.1 ? 2 : (ystep < 1 ? 1 : 0)), cv::Point(rect.x - 42, static_cast<int>(a.y) + 5), 0.45);
    }
    cv::rectangle(canvas, rect, cv::Scalar(160, 160, 160), 1);
    draw_text(canvas, xlabel, cv::Point(rect.x + rect.width / 2 - 80, rect.y + rect.height + 38), 0.5);
    draw_text(canvas, ylabel, cv::Point(rect.x, rect.y - 10), 0.5);
}

void PlotAxes::line(cv::Mat &canvas, const std::vector<double> &x, const std::vector<double> &y,
                    const cv::Scalar &c, int thickness) const
{
    for (size_t i = 0; i + 1 < x.size() && i + 1 < y.size(); i++) {
        if (std::isfinite(y[i]) && std::isfinite(y[i + 1]) && std::isfinite(x[i]) &&
            std::isfinite(x[i + 1])) {
            cv::line(canvas, px(x[i], y[i]), px(x[i + 1], y[i + 1]), c, thickness, cv::LINE_AA);
        }
    }
}

void PlotAxes::dots(cv::Mat &canvas, const std::vector<double> &x, const std::vector<double> &y,
                    const cv::Scalar &c, int radius) const
{
    for (size_t i = 0; i < x.size() && i < y.size(); i++) {
        if (std::isfinite(x[i]) && std::isfinite(y[i]) && y[i] >= y0 && y[i] <= y1) {
            cv::circle(canvas, px(x[i], y[i]), radius, c, cv::FILLED, cv::LINE_AA);
        }
    }
}

void PlotAxes::band(cv::Mat &canvas, double xa, double xb, const cv::Scalar &c, double a) const
{
    const cv::Point2d p0 = px(std::max(x0, xa), y1), p1 = px(std::min(x1, xb), y0);
    cv::Rect r(cv::Point(static_cast<int>(p0.x), static_cast<int>(p0.y)),
               cv::Point(static_cast<int>(std::ceil(p1.x)), static_cast<int>(p1.y)));
    r &= cv::Rect(0, 0, canvas.cols, canvas.rows);
    if (r.area() <= 0) {
        return;
    }
    cv::Mat roi = canvas(r);
    cv::Mat fill(roi.size(), roi.type(), c);
    cv::addWeighted(roi, 1 - a, fill, a, 0, roi);
}

} // namespace sl
