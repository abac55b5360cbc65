// SPDX-License-Identifier: MIT
// sl_geom.cpp: see sl_geom.h.
#include "sl_geom.h"

#include "geom.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sl {
namespace {

constexpr double kPi = 3.14159265358979323846;

double rad(double deg) { return deg * kPi / 180.0; }
double deg(double r) { return r * 180.0 / kPi; }

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
    return slp_geom_make(theta_deg, beta_deg);
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
