/// @file sl_incline.h
/// @brief Inclination estimator (MATH.md s.2-3): (r1, r2, per-azimuth geometry) -> alpha.
///
/// FIRST DRAFT of the table-entry type only; the estimator API is added below it.
#ifndef SHADOWLEAN_SL_INCLINE_H
#define SHADOWLEAN_SL_INCLINE_H

#include <stdint.h>

#include "shadowlean/sl_fx.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Precomputed geometry of one azimuth (one entry of a board's theta table). Written by the
/// host generator (`sl-tables`, or `sl_geom_make()` in host code), rounded once to nearest.
/// theta = opening angle of the chassis shadow (depression of the grazing ray), beta =
/// upper emission bound (elevation). Read-only to the core.
typedef struct sl_incline_geom {
    sl_q30_t cos_theta_q30;    ///< cos(theta)
    sl_q30_t sin_theta_q30;    ///< sin(theta)
    sl_q30_t cos_beta_q30;     ///< cos(beta)
    sl_q30_t sin_beta_q30;     ///< sin(beta)
    sl_q30_t cos_tb_q30;       ///< cos(theta + beta)
    sl_q30_t sin_tb_q30;       ///< sin(theta + beta)
    sl_uq4_28_t rho_amb_q28;   ///< 1 / cos((theta + beta) / 2): below it, ambiguous
    sl_uq4_28_t rho_seam_q28;  ///< 1 / cos(theta + beta): branch seam (alpha = beta)
    sl_bam32_t theta_bam32;    ///< theta as a binary angle
    sl_bam32_t beta_bam32;     ///< beta as a binary angle (two's complement if negative)
} sl_incline_geom_t;

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_INCLINE_H
