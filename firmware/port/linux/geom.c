// SPDX-License-Identifier: MIT
// geom.c: the estimator's geometry entry of (theta, beta). See geom.h.
#include "geom.h"

#include <math.h>
#include <stdint.h>

static const double k_pi = 3.14159265358979323846;

// |v| <= 1 here, so llround(v * 2^30) is in [-2^30, 2^30]: fits Q2.30.
static int32_t q30(double v)
{
    return (int32_t)llround(v * 1073741824.0);
}

static uint32_t uq28(double v)
{
    if (!(v > 0.0) || !isfinite(v)) {
        return UINT32_MAX; // 1/cos of an angle >= 90 deg: no finite positive bound
    }
    const double s = v * 268435456.0;
    if (s >= 4294967295.0) {
        return UINT32_MAX;
    }
    return (uint32_t)llround(s);
}

// Modular int64 -> uint32: two's complement for negative angles; 180 deg wraps to -180.
static uint32_t bam(double d)
{
    return (uint32_t)(uint64_t)llround(d / 360.0 * 4294967296.0);
}

sl_incline_geom_t slp_geom_make(double theta_deg, double beta_deg)
{
    const double t = theta_deg * k_pi / 180.0;
    const double b = beta_deg * k_pi / 180.0;
    sl_incline_geom_t g;
    g.cos_theta_q30 = q30(cos(t));
    g.sin_theta_q30 = q30(sin(t));
    g.cos_beta_q30 = q30(cos(b));
    g.sin_beta_q30 = q30(sin(b));
    g.cos_tb_q30 = q30(cos(t + b));
    g.sin_tb_q30 = q30(sin(t + b));
    g.rho_amb_q28 = uq28(1.0 / cos((t + b) / 2.0));
    g.rho_seam_q28 = uq28(1.0 / cos(t + b));
    g.theta_bam32 = bam(theta_deg);
    g.beta_bam32 = bam(beta_deg);
    return g;
}
