// SPDX-License-Identifier: MIT
// sl_geom.cpp: see sl_geom.h.
#include "sl_geom.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sl {
namespace {

constexpr double kPi = 3.14159265358979323846;

double rad(double deg) { return deg * kPi / 180.0; }
double deg(double r) { return r * 180.0 / kPi; }

int32_t q30(double v)
{
    // |v| <= 1 here, so llround(v * 2^30) is in [-2^30, 2^30]: fits Q2.30.
    return static_cast<int32_t>(std::llround(v * 1073741824.0));
}

uint32_t uq28(double v)
{
    if (!(v > 0.0) || !std::isfinite(v)) {
        return UINT32_MAX; // 1/cos of an angle >= 90 deg: no finite positive bound
    }
    const double s = v * 268435456.0;
    if (s >= 4294967295.0) {
        return UINT32_MAX;
    }
    return static_cast<uint32_t>(std::llround(s));
}

uint32_t bam(double d)
{
    // Modular int64 -> uint32: two's complement for negative angles; 180 deg wraps to -180.
    return static_cast<uint32_t>(static_cast<uint64_t>(std::llround(d / 360.0 * 4294967296.0)));
}

void check_angle(double d, const char *what)
{
    if (!std::isfinite(d) || std::fabs(d) > 180.0) {
        throw std::domain_error(std::string("sl::make_geom: ") + what + " = " +
                                std::to_string(d) + " deg is not a finite angle in [-180, 180]");
    }
}

bool in_domain(double theta_deg, double beta_deg)
{
    const double w = theta_deg + beta_deg;
    return theta_deg >= SL_INCLINE_THETA_MIN_CDEG / 100.0 &&
           theta_deg <= SL_INCLINE_THETA_MAX_CDEG / 100.0 &&
           beta_deg >= SL_INCLINE_BETA_MIN_CDEG / 100.0 &&
           beta_deg <= SL_INCLINE_BETA_MAX_CDEG / 100.0 && w >= SL_INCLINE_WEDGE_MIN_CDEG / 100.0 &&
           w <= SL_INCLINE_WEDGE_MAX_CDEG / 100.0;
}

struct Eval {
    int flag = SL_INCLINE_INVALID;
    int branch = 0;
    double rho = 0, t = 0, b = 0;
};

Eval classify(double r1, double r2, double theta_deg, double beta_deg)
{
    Eval e;
    if (!std::isfinite(r1) || !std::isfinite(r2) || !std::isfinite(theta_deg) ||
        !std::isfinite(beta_deg)) {
        return e;
    }
    if (!in_domain(theta_deg, beta_deg)) {
        e.flag = SL_INCLINE_OUT_OF_DOMAIN;
        return e;
    }
    if (!(r1 > 0.0) || !(r1 < r2)) {
        return e;
    }
    e.rho = r2 / r1;
    e.t = rad(theta_deg);
    e.b = rad(beta_deg);
    if (e.rho > 10.0) {
        e.flag = SL_INCLINE_OUT_OF_DOMAIN;
    } else if (e.rho < 1.0 / std::cos((e.t + e.b) / 2.0)) {
        e.flag = SL_INCLINE_AMBIGUOUS;
    } else {
        e.flag = SL_INCLINE_VALID;
        e.branch = (e.rho >= 1.0 / std::cos(e.t + e.b)) ? 1 : 2;
    }
    return e;
}

} // namespace

sl_incline_geom_t make_geom(double theta_deg, double beta_deg)
{
    check_angle(theta_deg, "theta");
    check_angle(beta_deg, "beta");
    const double t = rad(theta_deg);
    const double b = rad(beta_deg);
    sl_incline_geom_t g{};
    g.cos_theta_q30 = q30(std::cos(t));
    g.sin_theta_q30 = q30(std::sin(t));
    g.cos_beta_q30 = q30(std::cos(b));
    g.sin_beta_q30 = q30(std::sin(b));
    g.cos_tb_q30 = q30(std::cos(t + b));
    g.sin_tb_q30 = q30(std::sin(t + b));
    g.rho_amb_q28 = uq28(1.0 / std::cos((t + b) / 2.0));
    g.rho_seam_q28 = uq28(1.0 / std::cos(t + b));
    g.theta_bam32 = bam(theta_deg);
    g.beta_bam32 = bam(beta_deg);
    return g;
}

double alpha_oracle_deg(double r1, double r2, double theta_deg, double beta_deg, int *flag,
                        int *branch)
{
    const Eval e = classify(r1, r2, theta_deg, beta_deg);
    if (flag) {
        *flag = e.flag;
    }
    if (branch) {
        *branch = e.branch;
    }
    if (e.flag != SL_INCLINE_VALID) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    if (e.branch == 1) {
        return deg(std::atan2(e.rho * std::cos(e.t) - std::cos(e.b),
                              e.rho * std::sin(e.t) + std::sin(e.b)));
    }
    return deg(std::acos(1.0 / e.rho) - e.t);
}

double sigma_oracle_deg(double r1, double r2, double theta_deg, double beta_deg,
                        double sigma_r, double sigma_theta_deg, int *flag)
{
    const Eval e = classify(r1, r2, theta_deg, beta_deg);
    if (flag) {
        *flag = e.flag;
    }
    if (e.flag != SL_INCLINE_VALID) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    const double rho = e.rho;
    double da_drho;
    double da_dtheta;
    if (e.branch == 1) {
        const double c = std::cos(e.t + e.b);
        const double q = rho * rho - 2.0 * rho * c + 1.0;
        da_drho = std::sin(e.t + e.b) / q;
        da_dtheta = -rho * (rho - c) / q;
    } else {
        da_drho = 1.0 / (rho * std::sqrt(rho * rho - 1.0));
        da_dtheta = -1.0;
    }
    const double s_rho = (sigma_r / r1) * std::sqrt(1.0 + rho * rho);
    const double a = da_drho * s_rho;
    const double c = da_dtheta * rad(sigma_theta_deg);
    return deg(std::sqrt(a * a + c * c));
}

} // namespace sl
