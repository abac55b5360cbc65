// SPDX-License-Identifier: MIT
/// @file geom.h
/// @brief The estimator's geometry entry (sl_incline_geom_t) of an opening angle theta and an
/// upper emission bound beta, in degrees: the one implementation that the board tables
/// (sl-tables, through sl::make_geom) and a vehicle's calibration file (calib_file.c) share,
/// so a calibrated azimuth can never differ from a board's.
///
/// Every field is its exact value (computed in double from theta and beta in radians)
/// rounded ONCE to nearest, ties away from zero (llround):
///   cos/sin of theta, beta, theta+beta  -> Q30 (x 2^30)
///   rho_amb = 1/cos((theta+beta)/2), rho_seam = 1/cos(theta+beta) -> UQ4.28 (x 2^28),
///       saturated to UINT32_MAX when >= 16 or when the cosine is <= 0
///   theta, beta -> bam32 (x 2^32/360, two's complement for negative angles)
/// The caller checks the angles (finite, |angle| <= 180 deg); the core decides whether an
/// entry is in its supported domain (sl_incline_geom_ok()).
///
/// Host/port only (double, libm); the core takes the entries as data. Pure, reentrant.
/// Depends on the core's headers only, not on a core library: sl-tables links it without
/// the board tables it generates.
#ifndef SHADOWLEAN_PORT_GEOM_H
#define SHADOWLEAN_PORT_GEOM_H

#include "shadowlean/sl_incline.h"

#ifdef __cplusplus
extern "C" {
#endif

/// The geometry entry of theta, beta (degrees).
sl_incline_geom_t slp_geom_make(double theta_deg, double beta_deg);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_GEOM_H
