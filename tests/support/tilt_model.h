// SPDX-License-Identifier: MIT
// tilt_model.h: the target a straight pole makes on one azimuth in the in-plane model
// (MATH.md s.2, sl_incline.h), as the 3D-tilt tests draw their drive-bys (test_tiltobs.c,
// fuzz/fuzz_tilt.c). Double precision: tests only, never the core.
#ifndef SL_TEST_TILT_MODEL_H
#define SL_TEST_TILT_MODEL_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_detect.h"
#include "shadowlean/sl_incline.h"

#define SL_TM_PI 3.14159265358979323846

// Degrees to radians and back, as (x pi) / 180 and (x 180) / pi: the drive-bys' digests
// (test_tiltobs.c) depend on every rounding.
static inline double sl_tm_rad(double d) { return d * SL_TM_PI / 180.0; }
static inline double sl_tm_deg(double r) { return r * 180.0 / SL_TM_PI; }

// The board's opening angle theta on azimuth `az`, degrees.
static inline double sl_tm_theta_deg(const sl_board_t *b, int az)
{
    return b->geom[az].theta_bam32 * 360.0 / 4294967296.0;
}

// The target of a pole with tilt vector (tx, ty) whose point at radar height lies `d0`
// metres from the radar at bearing `a_true` (rad, odometry frame), seen on azimuth `az`:
// the in-plane inclination alpha = atan(-(t . e)), read as the estimator would (folded to
// beta - theta - alpha beyond the fold), r1 from the in-plane geometry (the foot of the
// perpendicular, or the top end on the +beta ray on branch 1) and r2 = r1 rho from the
// model for the alpha as read: branch 1 rho = cos(a - b) / cos(a + t), branch 2
// rho = 1 / cos(a + t). One azimuth wide, sigma 0.5 deg, VALID.
static inline void sl_tm_target(const sl_board_t *b, int az, double d0, double a_true,
                                double tx, double ty, sl_target_t *g)
{
    const double theta = sl_tm_theta_deg(b, az);
    const double beta = (double)(int32_t)b->geom[az].beta_bam32 * 360.0 / 4294967296.0;
    const double alpha = sl_tm_deg(atan(-(tx * cos(a_true) + ty * sin(a_true))));
    const double foot = d0 * cos(sl_tm_rad(alpha));
    const double r1 = (alpha >= beta) ? foot / cos(sl_tm_rad(beta - alpha)) : foot;
    const double fold = (beta - theta) / 2.0;
    const double read = (alpha < fold) ? beta - theta - alpha : alpha;
    const double rho = (read >= beta) ? cos(sl_tm_rad(read - beta)) / cos(sl_tm_rad(read + theta))
                                      : 1.0 / cos(sl_tm_rad(read + theta));
    memset(g, 0, sizeof *g);
    g->az = (uint16_t)az;
    g->az_first = (uint16_t)az;
    g->az_count = 1U;
    g->r1_um = (uint32_t)llround(r1 * 1e6);
    g->r2_um = (uint32_t)llround(r1 * rho * 1e6);
    g->alpha_cdeg = (int32_t)llround(read * 100.0);
    g->sigma_cdeg = 50U;
    g->incline_flag = (uint8_t)SL_INCLINE_VALID;
    g->incline_branch = (uint8_t)((read >= beta) ? SL_INCLINE_BRANCH_1 : SL_INCLINE_BRANCH_2);
}

#endif // SL_TEST_TILT_MODEL_H
