// SPDX-License-Identifier: MIT
// sl_geom.h: the host's single code path from (theta, beta) in degrees to the core's
// integer geometry entry (sl_incline_geom_t), and double-precision oracles of the
// inclination estimator (MATH.md s.2-3). Used by the board table generator (sl-tables) and
// by sl-alpha, so a board table and the CLI can never disagree. Host-only (C++17, libm).
#pragma once

#include <cstdint>

#include "shadowlean/sl_incline.h"

namespace sl {

/// The geometry entry of one azimuth: slp_geom_make() (firmware/port/linux/geom.h, the one
/// implementation, shared with a vehicle's calibration file) after checking the angles.
/// Any finite angle in [-180, 180] degrees gives an entry (the core decides whether it is in
/// its supported domain, sl_incline_geom_ok()); NaN/inf or |angle| > 180 throw
/// std::domain_error. Pure, thread-safe.
sl_incline_geom_t make_geom(double theta_deg, double beta_deg);

/// The inclination (degrees, > 0 = top towards the radar) for bounds r1 < r2 (any unit) by
/// MATH.md s.2 in double precision, with the exact bounds (no rounding anywhere). `*flag`
/// (if not null) receives an sl_incline_flag_t value with the core's rules and limits:
/// INVALID when !(0 < r1 < r2) or a value is not finite; OUT_OF_DOMAIN when the geometry is
/// outside SL_INCLINE_* limits or r2/r1 > 10; AMBIGUOUS when r2/r1 < 1/cos((theta+beta)/2);
/// VALID otherwise. Returns NaN unless VALID. `*branch` (if not null) receives 1 or 2 (0
/// unless VALID).
double alpha_oracle_deg(double r1, double r2, double theta_deg, double beta_deg, int *flag,
                        int *branch = nullptr);

/// First-order 1-sigma uncertainty of alpha (degrees), MATH.md s.3 generalised to beta:
/// sigma_rho = (sigma_r / r1) sqrt(1 + rho^2) (sigma_r in the unit of r1, r2);
/// sigma_alpha = sqrt((d alpha/d rho sigma_rho)^2 + (d alpha/d theta sigma_theta)^2) with
/// branch 1: d/d rho = sin(t+b)/Q, d/d theta = -rho (rho - cos(t+b))/Q, Q = rho^2 -
/// 2 rho cos(t+b) + 1; branch 2: d/d rho = 1/(rho sqrt(rho^2-1)), d/d theta = -1.
/// `*flag` as alpha_oracle_deg; NaN unless VALID.
double sigma_oracle_deg(double r1, double r2, double theta_deg, double beta_deg,
                        double sigma_r, double sigma_theta_deg, int *flag);

} // namespace sl
