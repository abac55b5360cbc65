// SPDX-License-Identifier: MIT
// Unit tests for sl_tiltobs.h: per-track observation rings, odometry, per-rotation fits and
// the vehicle-frame result, on the paper-sim board.
//
// Drive-bys are generated here in double precision, independently of the module: the vehicle
// starts at the odometry origin heading +x and moves at v with yaw rate w (4 rotations per
// second); a pole P(z) = B + z t; on each rotation the pole is seen on the azimuth cell of
// its bearing from the radar AT THE TIME that azimuth is swept (pose interpolated inside the
// rotation, as a spinning radar sees it), with alpha = atan(-(t . e)) read as the estimator
// would (folded to beta - theta - alpha beyond the fold) and r1 from the in-plane geometry.
// The module receives these as tracker slots and targets, exactly as the pipeline hands them.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_tiltobs.h"
#include "shadowlean/sl_profile.h"

#include "../support/tilt_model.h"

static const double PI = 3.14159265358979323846;
static double rad(double d) { return d * PI / 180.0; }
static double deg(double r) { return r * 180.0 / PI; }
static double wrap180(double d)
{
    while (d > 180.0) d -= 360.0;
    while (d <= -180.0) d += 360.0;
    return d;
}

static sl_tiltobs_t obs;

// FNV-1a digest of every vehicle-frame result the sweeps check (fixed point only: the same
// on every target). From x86-64; aarch64 and s390x must match (bit-identical arithmetic).
// The host and firmware capacities keep different numbers of observations, so two values.
#if SL_CFG_TILT_OBS_PER_TRACK == 32
#define RESULTS_DIGEST 0x40a1d09b31c367e5ULL
#else
#define RESULTS_DIGEST_FW 0xb25d99ad5b86a2bbULL
#endif
static uint64_t digest = 14695981039346656037ULL;
static void digest_i32(int32_t v)
{
    for (int i = 0; i < 4; ++i) {
        digest ^= (uint8_t)((uint32_t)v >> (8 * i));
        digest *= 1099511628211ULL;
    }
}

typedef struct pole {
    double bx, by, psi, phi; // base (odometry frame, m), tilt, direction (deg, odometry frame)
} pole_t;

typedef struct drive {
    double v, w;             // m/s, deg/s
    double x, y, yaw;        // pose (rad), start of the current rotation
} drive_t;

static const sl_board_t *board(void)
{
    const sl_board_t *b = sl_board_find("paper-sim");
    assert_non_null(b);
    return b;
}

// Pose at time s (seconds) after the rotation start (midpoint rule over the exact arc).
static void pose_at(const drive_t *d, double s, double *x, double *y, double *yaw)
{
    const double ym = d->yaw + rad(d->w) * s / 2;
    *x = d->x + d->v * s * cos(ym);
    *y = d->y + d->v * s * sin(ym);
    *yaw = d->yaw + rad(d->w) * s;
}

// The target pole `p` makes on this rotation; false when it is not in the shadow ring.
static bool see(const sl_board_t *b, const drive_t *d, const pole_t *p, sl_target_t *g)
{
    const double H = b->radar_height_um * 1e-6, T = 0.25;
    const double tt = tan(rad(p->psi));
    const double tx = tt * cos(rad(p->phi)), ty = tt * sin(rad(p->phi));
    const double qx = p->bx + H * tx, qy = p->by + H * ty;
    const int N = b->azimuths;
    int az = 0;
    double x = d->x, y = d->y, yaw = d->yaw, s = 0;
    for (int it = 0; it < 3; ++it) { // the azimuth and the time it is swept agree
        pose_at(d, s, &x, &y, &yaw);
        const double rx = x + b->radar_x_um * 1e-6 * cos(yaw) - b->radar_y_um * 1e-6 * sin(yaw);
        const double ry = y + b->radar_x_um * 1e-6 * sin(yaw) + b->radar_y_um * 1e-6 * cos(yaw);
        const double cw = -(deg(atan2(qy - ry, qx - rx)) - deg(yaw)) - b->radar_yaw_cdeg / 100.0;
        const double rel = fmod(cw + 720.0, 360.0);
        az = (int)floor(rel / (360.0 / N) + 0.5) % N;
        s = T * az / N;
    }
    pose_at(d, s, &x, &y, &yaw);
    const double rx = x + b->radar_x_um * 1e-6 * cos(yaw) - b->radar_y_um * 1e-6 * sin(yaw);
    const double ry = y + b->radar_x_um * 1e-6 * sin(yaw) + b->radar_y_um * 1e-6 * cos(yaw);
    const double d0 = hypot(qx - rx, qy - ry);
    if (d0 < 1.3 || hypot(p->bx - rx, p->by - ry) > H / tan(rad(sl_tm_theta_deg(b, az)))) {
        return false;
    }
    sl_tm_target(b, az, d0, atan2(qy - ry, qx - rx), tx, ty, g);
    return true;
}

// Bad far bounds injected into the first pole's targets: on the rotations where it is seen
// for the k-th time with k % corrupt_every == corrupt_phase (corrupt_every 0: none).
static int corrupt_every, corrupt_phase;
// ... read that much long (0: 8 %).
static double corrupt_scale;

// Sightings a track needs before it is confirmed (the tracker's evidence, one per sighting;
// 0 or 1: confirmed from the first); reset_at > 0: on its reset_at-th sighting the track's
// evidence restarts at 1 (an association inconsistent with a static object), so it is
// unconfirmed again for confirm_at - 1 sightings; corrupt_unconfirmed: the first pole's
// targets read wrong (r2 8 % long) whenever its track is not confirmed.
static int confirm_at, reset_at, corrupt_unconfirmed;

// Observations held that were recorded while the track was not confirmed.
static unsigned held_unconfirmed(const sl_tiltobs_ring_t *r)
{
    unsigned n = 0;
    for (unsigned k = 0; k < r->count; ++k) {
        n += (r->obs[k].mark & SL_TILT_OBS_UNCONFIRMED) != 0U;
    }
    return n;
}

// Runs a drive-by of `n` poles (one track each, ids 1..n) for `rotations`; returns the
// rotations on which at least one pole was seen.
static int drive_by(const pole_t *p, int n, double v, double w, int rotations, sl_track_t *tracks)
{
    const sl_board_t *b = board();
    assert_int_equal(sl_tiltobs_init(&obs, b), SL_OK);
    memset(tracks, 0, sizeof(sl_track_t) * SL_CFG_MAX_TARGETS);
    drive_t d = {v, w, 0, 0, 0};
    int seen = 0;
    int sightings[8] = {0};
    for (int k = 0; k < rotations; ++k) {
        sl_tiltobs_advance(&obs, true, (int32_t)llround(v * 1000), (int32_t)llround(w * 100), 250000U);
        sl_target_t g[8];
        uint32_t ng = 0;
        for (int i = 0; i < n; ++i) {
            sl_track_t *t = &tracks[i];
            t->updated = 0U;
            if (see(b, &d, &p[i], &g[ng])) {
                t->live = 1U;
                sightings[i < 8 ? i : 7]++;
                t->evidence = (uint8_t)(t->evidence < 5U ? t->evidence + 1U : 5U);
                if (reset_at > 0 && sightings[i < 8 ? i : 7] == reset_at) {
                    t->evidence = 1U;
                }
                t->confirmed = (uint8_t)(t->evidence >= confirm_at ? 1U : 0U);
                t->updated = 1U;
                if (i == 0 && corrupt_unconfirmed && t->confirmed == 0U) {
                    g[ng].r2_um = (uint32_t)llround(g[ng].r2_um * 1.08); // as corrupt_every
                }
                t->id = (uint16_t)(i + 1);
                t->az = g[ng].az;
                t->r1_um = g[ng].r1_um;
                t->r2_um = g[ng].r2_um;
                ng++;
            }
        }
        seen += ng > 0U ? 1 : 0;
        if (ng > 0U && corrupt_every > 0 && seen % corrupt_every == corrupt_phase) {
            // a far bound read long by 8 % (a smear tail of ~5 bins left in it): alpha
            // ~15 deg high, 30 of its sigmas (the outliers of `sl-eval driveby --realistic`)
            g[0].r2_um = (uint32_t)llround(g[0].r2_um * (corrupt_scale > 0.0 ? corrupt_scale : 1.08));
            tracks[0].r2_um = g[0].r2_um; // the track holds its target's bounds
        }
        sl_tiltobs_update(&obs, tracks, g, ng);
        sl_tiltobs_fit_pending(&obs);
        double x, y, yaw;
        pose_at(&d, 0.25, &x, &y, &yaw);
        d.x = x;
        d.y = y;
        d.yaw = yaw;
    }
    return seen;
}

// The vehicle-frame truth at the end of the drive.
static void truth(const pole_t *p, double v, double w, int rotations, double *phi_v,
                  double *bx_v, double *by_v)
{
    drive_t d = {v, w, 0, 0, 0};
    for (int k = 0; k < rotations; ++k) {
        double x, y, yaw;
        pose_at(&d, 0.25, &x, &y, &yaw);
        d.x = x;
        d.y = y;
        d.yaw = yaw;
    }
    *phi_v = wrap180(p->phi - deg(d.yaw));
    const double dx = p->bx - d.x, dy = p->by - d.y;
    *bx_v = dx * cos(d.yaw) + dy * sin(d.yaw);
    *by_v = -dx * sin(d.yaw) + dy * cos(d.yaw);
}

// The fold test with the firmware's 16-observation rings: AMBIGUOUS (right answer, flagged)
// is accepted for at most three of its four poles (the ring then holds only the half pass
// after the pole, 14 degrees of freedom: the mirror's chi-square must exceed the best's by
// t^2 = 13.2, not 9, sl_tilt.h; the value must still be within the bounds). The alpha sigmas are the model's for the
// union bounds (0.6-1.2 deg near the fold on paper-sim), no longer a fixed 0.5 deg.
static int ambiguous_ok;
static int ambiguous_seen;

static void check_pole(const pole_t *p, double v, double w, int rotations, uint16_t id,
                       double psi_tol, double phi_tol)
{
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, id);
    assert_non_null(r);
    sl_tiltobs_vehicle_t out;
    assert_true(sl_tiltobs_vehicle(&obs, r, &out));
    double phi_v, bx, by;
    truth(p, v, w, rotations, &phi_v, &bx, &by);
    digest_i32(out.psi_cdeg);
    digest_i32(out.phi_cdeg);
    digest_i32(out.base_x_um);
    digest_i32(out.base_y_um);
    digest_i32(out.lean_path_cdeg);
    digest_i32(out.psi_sigma_cdeg);
    digest_i32(out.phi_sigma_cdeg);
    digest_i32(out.lean_path_sigma_cdeg);
    const double e_psi = out.psi_cdeg / 100.0 - p->psi;
    const double e_phi = wrap180(out.phi_cdeg / 100.0 - phi_v);
    const double e_b = hypot(out.base_x_um * 1e-6 - bx, out.base_y_um * 1e-6 - by);
    // lean towards the path (y = 0 of the vehicle frame)
    const double tyv = tan(rad(p->psi)) * sin(rad(phi_v));
    const double lean = deg(atan(by >= 0 ? -tyv : tyv));
    printf("pole (%.1f, %.1f) psi %.1f phi %.0f: n %u q %u psi %+.2f phi %+.1f base %.3f m "
           "lean %.2f (truth %.2f)\n",
           p->bx, p->by, p->psi, p->phi, r->count, out.quality, e_psi, e_phi, e_b,
           out.lean_path_cdeg / 100.0, lean);
    if (ambiguous_ok && out.quality == SL_TILT_AMBIGUOUS) {
        ambiguous_seen++;
    } else {
        assert_int_equal(out.quality, SL_TILT_FITTED);
    }
    assert_true(fabs(e_psi) <= psi_tol);
    assert_true(fabs(e_phi) <= phi_tol);
    assert_true(e_b <= 0.15);
    assert_true(fabs(out.lean_path_cdeg / 100.0 - lean) <= psi_tol + 0.5);
    // what goes on CAN holds the truth within 3 of its stated sigmas (issue #12)
    if (out.quality == SL_TILT_FITTED) {
        assert_true(fabs(e_psi) <= 3.0 * out.psi_sigma_cdeg / 100.0);
        assert_true(out.phi_sigma_cdeg >= 18000U || fabs(e_phi) <= 3.0 * out.phi_sigma_cdeg / 100.0);
        assert_true(fabs(out.lean_path_cdeg / 100.0 - lean) <= 3.0 * out.lean_path_sigma_cdeg / 100.0);
    }
}

// ---------------------------------------------------------------------------------------

static void test_straight_drive_bys_both_sides_all_directions(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    int checked = 0;
    for (int side = -1; side <= 1; side += 2) {
        for (double phi = 0; phi < 360; phi += 45) {
            for (double v = 1.0; v <= 3.0; v += 2.0) {
                const pole_t p = {v * 4.0, side * 3.0, 8.0, phi};
                const int rot = 32; // 8 s: the pole is passed half way
                drive_by(&p, 1, v, 0.0, rot, tracks);
                check_pole(&p, v, 0.0, rot, 1, 1.0, 10.0);
                checked++;
            }
        }
    }
    assert_int_equal(checked, 32);
    assert_true(obs.stats.fits > 0U);
}

// Beyond the fold ((beta - theta) / 2 = -13 deg on paper-sim) every single rotation reads the
// mirror image; the drive-by must still give the true direction.
static void test_leaning_away_beyond_the_fold(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    ambiguous_ok = SL_CFG_TILT_OBS_PER_TRACK < 32;
    ambiguous_seen = 0;
    for (int side = -1; side <= 1; side += 2) {
        for (double psi = 16.0; psi <= 20.0; psi += 4.0) {
            const pole_t p = {4.0, side * 3.0, psi, side > 0 ? 80.0 : 290.0}; // away from the path
            drive_by(&p, 1, 1.0, 0.0, 32, tracks);
            check_pole(&p, 1.0, 0.0, 32, 1, 1.0, 10.0);
        }
    }
    ambiguous_ok = 0;
    assert_true(ambiguous_seen <= 3);
}

static void test_curved_path_10_deg_per_second(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p[2] = {{3.0, 3.0, 10.0, 200.0}, {5.0, -2.5, 12.0, 60.0}};
    drive_by(p, 2, 1.5, 10.0, 24, tracks);
    check_pole(&p[0], 1.5, 10.0, 24, 1, 1.0, 10.0);
    check_pole(&p[1], 1.5, 10.0, 24, 2, 1.0, 10.0);
}

// One gross outlier in a pass (a far bound with a smear tail left in it: the profile could
// not clean that rotation) makes the fit INCONSISTENT; the ring drops the observation with
// the largest residual in sigmas and fits again: FITTED within the bounds. A pole that
// reads wrong on every fourth rotation (not a straight pole's alpha(y)) loses at most one
// in eight of its observations and stays INCONSISTENT.
static void test_one_outlier_is_dropped_a_bent_pole_stays_inconsistent(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p = {4.0, 3.0, 10.0, 200.0};
    corrupt_every = 1000;
    corrupt_phase = 6; // the 6th rotation it is seen on
    drive_by(&p, 1, 1.0, 0.0, 32, tracks);
    assert_true(obs.stats.outliers >= 1U);
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 1);
    assert_non_null(r);
    assert_true(r->dropped >= 1U && r->dropped <= r->count / SL_TILTOBS_OUTLIER_DIV + 1U);
    check_pole(&p, 1.0, 0.0, 32, 1, 1.0, 10.0);
    // every fourth observation wrong: never more than one in eight dropped
    corrupt_every = 4;
    corrupt_phase = 1;
    drive_by(&p, 1, 1.0, 0.0, 32, tracks);
    r = sl_tiltobs_find(&obs, 1);
    assert_non_null(r);
    sl_tiltobs_vehicle_t out;
    assert_true(sl_tiltobs_vehicle(&obs, r, &out));
    printf("bent: n %u dropped %u quality %u\n", r->count, r->dropped, out.quality);
    assert_true((uint32_t)r->dropped * SL_TILTOBS_OUTLIER_DIV <= (uint32_t)r->count + r->dropped);
    assert_int_equal(out.quality, SL_TILT_INCONSISTENT);
    corrupt_every = 0;
}

// drive_by() of pole `p` (track 1) with one far bound read 3 % long on its `phase`-th
// sighting; its ring and the vehicle-frame result in `out`.
static const sl_tiltobs_ring_t *drive_corrupted(const pole_t *p, double v, int rotations,
                                                int phase, sl_track_t *tracks,
                                                sl_tiltobs_vehicle_t *out)
{
    corrupt_every = 1000;
    corrupt_phase = phase;
    corrupt_scale = 1.03;
    drive_by(p, 1, v, 0.0, rotations, tracks);
    corrupt_every = 0;
    corrupt_scale = 0.0;
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 1);
    assert_non_null(r);
    assert_true(sl_tiltobs_vehicle(&obs, r, out));
    return r;
}

// A wrong observation that does not make the fit INCONSISTENT: a far bound 3 % long (alpha
// 3-4 deg high, 7-8 of its 0.5 deg sigmas) among 16-32 good ones leaves chi2 / dof near 3,
// so the fit stood FITTED and was pulled by it (0.4 deg of tilt and 1-2 deg of direction
// here, more with fewer observations). Its residual against the scale of the others is far
// beyond 4 sigma: it is dropped and the fit is the clean pass's. Clean passes drop nothing
// (the sweeps above and the reference pass here: stats.gross 0).
static void test_a_gross_outlier_in_a_fitted_pass_is_dropped(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p = {4.0, 3.0, 5.0, 135.0};
    drive_by(&p, 1, 1.0, 0.0, 32, tracks);
    assert_int_equal(obs.stats.gross, 0U);
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 1);
    assert_non_null(r);
    sl_tiltobs_vehicle_t clean;
    assert_true(sl_tiltobs_vehicle(&obs, r, &clean));
    assert_int_equal(clean.quality, SL_TILT_FITTED);
    sl_tiltobs_vehicle_t out;
    // late in the pass: the firmware's 16-observation ring still holds it
    r = drive_corrupted(&p, 1.0, 32, 26, tracks, &out);
    printf("gross: dropped %u (stats %u, inconsistent-path %u) psi %.2f (clean %.2f) phi %.1f (%.1f)\n",
           r->dropped, obs.stats.gross, obs.stats.outliers, out.psi_cdeg / 100.0,
           clean.psi_cdeg / 100.0, out.phi_cdeg / 100.0, clean.phi_cdeg / 100.0);
    assert_int_equal(obs.stats.gross, 1U);
    assert_int_equal(obs.stats.outliers, 0U);
    assert_int_equal(r->dropped, 1U);
    assert_int_equal(out.quality, SL_TILT_FITTED);
    assert_true(abs(out.psi_cdeg - clean.psi_cdeg) <= 5);
    assert_true(abs(out.phi_cdeg - clean.phi_cdeg) <= 50);
    check_pole(&p, 1.0, 0.0, 32, 1, 1.0, 10.0);
}

// An AMBIGUOUS fit loses its worst observation when that one is gross under BOTH its
// readings, and the worst is the one with the largest DELETED residual, z^2 / (1 - h) with
// h its leverage (sl_tiltobs.h, "Outlier rejection"): one far bound read 3 % long in a 3 m/s
// pass of a pole leaning away beyond the fold (12-20 deg; 11 observations, the clean pass
// FITTED), on each of the first ten sightings in turn. At the ends of the pass's bearings it
// pulls the fit towards itself and hid its own residual (a FITTED direction 19 deg off at
// 5.9 deg of sigma); elsewhere it inflates the residuals' scale until the mirror fits within
// the margin (AMBIGUOUS). Now where it goes, the pass is as the clean one (FITTED, or
// AMBIGUOUS with its values where the dropped bound was the one that told the readings
// apart); no FITTED result differs from the clean one. (Before the leverage 15 of the 30
// passes dropped it, before AMBIGUOUS fits dropped anything 9; now 28.)
static void test_a_gross_outlier_in_an_ambiguous_pass_is_dropped(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    int dropped = 0, fitted = 0;
    for (int ps = 12; ps <= 20; ps += 4) {
        const pole_t p = {4.0, 3.0, (double)ps, 90.0}; // 3 m left, leaning away (left)
        drive_by(&p, 1, 3.0, 0.0, 16, tracks);
        const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 1);
        assert_non_null(r);
        sl_tiltobs_vehicle_t clean;
        assert_true(sl_tiltobs_vehicle(&obs, r, &clean));
        assert_int_equal(clean.quality, SL_TILT_FITTED);
        assert_int_equal(r->count, 11U);
        assert_int_equal(r->dropped, 0U);
        for (int ph = 1; ph <= 10; ++ph) {
            sl_tiltobs_vehicle_t out;
            r = drive_corrupted(&p, 3.0, 16, ph, tracks, &out); // the ph-th sighting
            assert_int_equal(obs.stats.outliers, 0U);
            const bool same = abs(out.psi_cdeg - clean.psi_cdeg) <= 5 &&
                              abs(out.phi_cdeg - clean.phi_cdeg) <= 50;
            if (r->dropped != 0U) {
                dropped++;
                assert_int_equal(r->dropped, 1U);
                assert_int_equal(obs.stats.gross, 1U);
                assert_true(out.quality == SL_TILT_FITTED || out.quality == SL_TILT_AMBIGUOUS);
                assert_true(same);
            }
            if (out.quality == SL_TILT_FITTED) {
                fitted++;
                assert_true(same);
            }
        }
    }
    printf("passes with a gross outlier: %d of 30 dropped it, %d FITTED\n", dropped, fitted);
    assert_true(dropped >= 25); // 28 (15 before the leverage, 9 before AMBIGUOUS fits)
}

// Runs after the three sweeps above (cmocka runs the tests in order).
static void test_results_digest_is_target_independent(void **state)
{
    (void)state;
    printf("results digest 0x%016llx\n", (unsigned long long)digest);
#if SL_CFG_TILT_OBS_PER_TRACK == 32
    assert_true(digest == RESULTS_DIGEST);
#else
    assert_true(digest == RESULTS_DIGEST_FW);
#endif
}

static void test_fits_are_bounded_per_rotation(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p[3] = {{3.0, 3.0, 8.0, 0.0}, {3.5, -3.0, 8.0, 90.0}, {4.0, 2.5, 8.0, 180.0}};
    drive_by(p, 3, 0.5, 0.0, 1, tracks);
    const uint32_t obs1 = obs.stats.observations;
    assert_int_equal(obs1, 3U);
    assert_int_equal(obs.stats.fits, (uint32_t)(SL_CFG_TILT_FITS_PER_ROTATION < 3 ? SL_CFG_TILT_FITS_PER_ROTATION : 3));
    // Over two more rotations every ring is fitted (round robin), never more than the bound.
    sl_target_t g[3];
    const uint32_t f0 = obs.stats.fits;
    sl_tiltobs_update(&obs, tracks, g, 0U); // nothing new
    sl_tiltobs_fit_pending(&obs);           // the ring left over is fitted
    assert_int_equal(obs.pending, 0U);
    assert_true(obs.stats.fits - f0 <= (uint32_t)SL_CFG_TILT_FITS_PER_ROTATION);
    for (uint16_t id = 1; id <= 3; ++id) {
        const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, id);
        assert_non_null(r);
        assert_int_equal(r->fitted, 1U);
        sl_tiltobs_vehicle_t out;
        assert_true(sl_tiltobs_vehicle(&obs, r, &out));
        assert_int_equal(out.quality, SL_TILT_TOO_FEW); // one observation each
    }
}

static void test_lost_motion_and_lost_tracks_clear_history(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p = {3.0, 3.0, 8.0, 0.0};
    drive_by(&p, 1, 1.0, 0.0, 12, tracks);
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 1U);
    assert_non_null(r);
    assert_true(r->count >= 5U);
    // A rotation without motion: the odometry has a hole, the history goes.
    sl_tiltobs_advance(&obs, false, 0, 0, 250000U);
    assert_null(sl_tiltobs_find(&obs, 1U));
    assert_int_equal(obs.stats.resets, 1U);
    assert_int_equal(obs.pending, 0U);
    const uint32_t before = obs.stats.observations;
    sl_tiltobs_update(&obs, tracks, NULL, 0U);
    assert_int_equal(obs.stats.observations, before);
    // Motion again: a new history; then the track dies and its ring is freed.
    drive_by(&p, 1, 1.0, 0.0, 8, tracks);
    assert_non_null(sl_tiltobs_find(&obs, 1U));
    tracks[0].live = 0U;
    sl_tiltobs_advance(&obs, true, 1000, 0, 250000U);
    sl_tiltobs_update(&obs, tracks, NULL, 0U);
    assert_null(sl_tiltobs_find(&obs, 1U));
}

static void test_more_tracks_than_rings_are_counted(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    pole_t p[SL_CFG_TILT_TRACKS + 2];
    for (int i = 0; i < SL_CFG_TILT_TRACKS + 2; ++i) {
        p[i].bx = 2.0 + 0.3 * i;
        p[i].by = (i % 2) ? 3.0 : -3.0;
        p[i].psi = 5.0;
        p[i].phi = 0.0;
    }
    // drive_by handles up to 8 targets per rotation
    const int n = SL_CFG_TILT_TRACKS + 2 <= 8 ? SL_CFG_TILT_TRACKS + 2 : 8;
    drive_by(p, n, 0.5, 0.0, 2, tracks);
    int rings = 0;
    for (uint16_t id = 1; id <= (uint16_t)n; ++id) rings += sl_tiltobs_find(&obs, id) != NULL;
    assert_int_equal(rings, n < SL_CFG_TILT_TRACKS ? n : SL_CFG_TILT_TRACKS);
    if (n > SL_CFG_TILT_TRACKS) assert_true(obs.stats.no_ring > 0U);
}

// Target `g` as the one detection of confirmed track 3 (its bounds): one observation,
// stored in track 3's ring, which is returned.
static const sl_tiltobs_ring_t *observe_one(const sl_target_t *g)
{
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    memset(tracks, 0, sizeof tracks);
    tracks[0] = (sl_track_t){.live = 1, .updated = 1, .confirmed = 1, .id = 3, .az = g->az,
                             .r1_um = g->r1_um, .r2_um = g->r2_um};
    const uint32_t before = obs.stats.observations;
    sl_tiltobs_update(&obs, tracks, g, 1U);
    assert_int_equal(obs.stats.observations, before + 1U);
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 3U);
    assert_non_null(r);
    return r;
}

// The observation is the group's union extent (ext_grow) with the representative's
// corrections, at the group's centre azimuth; a width-estimated radius is taken out of both
// bounds, the elongation re-evaluated at the union's far end.
static void test_union_extent_is_observed(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    const int64_t bin = b->bin_size_um;
    assert_int_equal(sl_tiltobs_init(&obs, b), SL_OK);
    sl_tiltobs_advance(&obs, true, 1000, 0, 250000U);
    const uint16_t first = 70U, last = 79U; // representative run, bins
    const int64_t hb1 = ((2 * first + 1) * bin + 1) / 2, hb2 = ((2 * last + 1) * bin + 1) / 2;
    sl_target_t g;
    memset(&g, 0, sizeof g);
    g.az = 100; g.az_first = 97; g.az_count = 6; // centre 99.5
    g.bin_first = first; g.bin_last = last;
    g.r2_raw_um = (uint32_t)((last + 1) * bin);
    g.radius_um = 40000U;
    g.elong_um = sl_detect_elong_um(b, (uint32_t)hb2);
    g.flags = SL_TARGET_RADIUS_WIDTH;
    g.r1_um = (uint32_t)(hb1 + 40000);
    g.r2_um = (uint32_t)(hb2 - g.elong_um + 25000);
    g.ext_grow = (uint8_t)(2U | (3U << 4));
    g.incline_flag = SL_INCLINE_VALID;
    const sl_tiltobs_ring_t *r = observe_one(&g);
    const int64_t u1 = hb1 - 2 * bin;
    const int64_t u2 = hb2 + 3 * bin - sl_detect_elong_um(b, (uint32_t)(hb2 + 3 * bin));
    assert_int_equal(r->obs[0].r1_um, (uint32_t)u1);
    // alpha of the union bounds at the centre azimuth (geometry of azimuth 100 after rounding)
    const sl_incline_result_t inc = sl_incline_estimate((uint32_t)u1, (uint32_t)u2, &b->geom[100],
                                                        b->range_sigma_um, b->theta_sigma_cdeg);
    assert_int_equal(inc.flag, SL_INCLINE_VALID);
    const double tan_want = tan(inc.alpha_bam32 * (2.0 * PI / 4294967296.0));
    assert_true(fabs(r->obs[0].tan_q12 / 4096.0 - tan_want) <= 1.0 / 4096.0);
    // the bearing is the centre's (99.5 azimuths clockwise of forward, plus the radar's yaw)
    const double want = -rad(99.5 * 360.0 / b->azimuths + b->radar_yaw_cdeg / 100.0);
    assert_true(fabs(atan2(r->obs[0].sin_a_q15, r->obs[0].cos_a_q15) -
                     atan2(sin(want), cos(want))) <= 0.002);
}

// A ramp at a bound (SL_TARGET_RAMP) is stored, marked SL_TILT_OBS_RAMP.
static void test_ramps_are_observed_marked(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    const int64_t bin = b->bin_size_um;
    for (int ramp = 0; ramp < 2; ++ramp) {
        assert_int_equal(sl_tiltobs_init(&obs, b), SL_OK);
        obs.verified_only = true;
        sl_tiltobs_advance(&obs, true, 1000, 0, 250000U);
        sl_target_t g;
        memset(&g, 0, sizeof g);
        g.az = 100;
        g.bin_first = 70U;
        g.bin_last = 79U;
        g.r1_um = (uint32_t)(70 * bin + bin / 2);
        g.r2_um = (uint32_t)(80 * bin);
        g.r2_raw_um = g.r2_um;
        g.incline_flag = SL_INCLINE_VALID;
        g.flags = (uint16_t)(SL_TARGET_PROFILE | (ramp ? SL_TARGET_RAMP : 0U));
        const sl_tiltobs_ring_t *r = observe_one(&g);
        assert_int_equal(r->obs[0].mark, ramp ? SL_TILT_OBS_RAMP : 0U);
    }
}

// A far bound at the end of a walk over a smear tail (SL_TARGET_WALKED) is known to two bins
// (sl_profile_coarse_sigma_um): the observation's sigma of tan(alpha) holds it, the inner
// bound keeps the board's; without the flag both bounds have the board's sigma.
static void test_a_walked_far_bound_is_observed_with_its_sigma(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    const int64_t bin = b->bin_size_um;
    uint16_t sig[2] = {0U, 0U};
    for (int walked = 0; walked < 2; ++walked) {
        assert_int_equal(sl_tiltobs_init(&obs, b), SL_OK);
        sl_tiltobs_advance(&obs, true, 1000, 0, 250000U);
        sl_target_t g;
        memset(&g, 0, sizeof g);
        g.az = 100;
        g.bin_first = 70U;
        g.bin_last = 79U;
        g.r1_um = (uint32_t)(70 * bin + bin / 2);
        g.r2_um = (uint32_t)(80 * bin);
        g.r2_raw_um = g.r2_um;
        g.incline_flag = SL_INCLINE_VALID;
        g.flags = (uint16_t)(SL_TARGET_PROFILE | (walked ? SL_TARGET_WALKED : 0U));
        const sl_tiltobs_ring_t *r = observe_one(&g);
        const uint32_t coarse = sl_profile_coarse_sigma_um(b->bin_size_um);
        const uint32_t sr = walked ? sl_incline_bounds_sigma_um(g.r1_um, g.r2_um,
                                                                b->range_sigma_um, coarse)
                                   : b->range_sigma_um;
        const sl_incline_result_t inc = sl_incline_estimate(g.r1_um, g.r2_um, &b->geom[100], sr,
                                                            b->theta_sigma_cdeg);
        assert_int_equal(inc.flag, SL_INCLINE_VALID);
        sl_tilt_obs_t want;
        assert_true(sl_tilt_obs_make(&want, 0, 0, 0U, g.r1_um, inc.alpha_bam32, inc.sigma_cdeg,
                                     inc.branch, &b->geom[100]));
        assert_int_equal(r->obs[0].sigma_q16, want.sigma_q16);
        assert_int_equal(r->obs[0].tan_q12, want.tan_q12);
        sig[walked] = r->obs[0].sigma_q16;
    }
    // r2 of two bins (sigma b / sqrt(3), twice the board's b / sqrt(12)) on a far bound 10 bins
    // past r1: the sigma of tan(alpha) grows by about half (733 -> 1,099 in Q16)
    assert_true((uint32_t)sig[1] * 5U > (uint32_t)sig[0] * 7U);
}

// A 1 m/s drive-by of one pole of `psi` deg (3 m out, leaning along +x) over 16 rotations,
// FITTED; its ring.
static sl_tiltobs_ring_t *fitted_ring(double psi)
{
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p = {3.0, 3.0, psi, 0.0};
    drive_by(&p, 1, 1.0, 0.0, 16, tracks);
    sl_tiltobs_ring_t *r = (sl_tiltobs_ring_t *)sl_tiltobs_find(&obs, 1U);
    assert_non_null(r);
    assert_int_equal(r->res.quality, SL_TILT_FITTED);
    return r;
}

// Fits ring `r` again (as after a new observation).
static void refit(sl_tiltobs_ring_t *r)
{
    r->fresh = 1U;
    obs.pending++;
    sl_tiltobs_fit_pending(&obs);
}

// A fit beyond the largest tilt a pole may have (max_tan_q16, the detector's largest lean in
// the pipeline) is INCONSISTENT, with its values; within it, FITTED as without a bound.
static void test_fits_beyond_the_largest_tilt_are_inconsistent(void **state)
{
    (void)state;
    sl_tiltobs_ring_t *r = fitted_ring(12.0);
    const sl_tilt_result_t fitted = r->res;
    const uint16_t bounds[] = {11556U /* tan 10 deg */, 37837U /* tan 30 deg */};
    for (int i = 0; i < 2; ++i) {
        obs.max_tan_q16 = bounds[i];
        refit(r);
        assert_int_equal(r->res.quality, i == 0 ? SL_TILT_INCONSISTENT : SL_TILT_FITTED);
        assert_int_equal(r->res.psi_cdeg, fitted.psi_cdeg);
    }
    assert_int_equal(obs.stats.too_steep, 1U);
}

// Observations with a ramp at a bound stay in the fit but do not make its minimum: a pass
// whose observations are all ramps but SL_TILT_MIN_OBS - 1 is TOO_FEW; with one more without
// a ramp (SL_TILT_MIN_OBS) FITTED, with the values of the unmarked pass (the ramps are in
// the fit either way).
static void test_ramps_do_not_make_a_fit(void **state)
{
    (void)state;
    sl_tiltobs_ring_t *r = fitted_ring(8.0);
    assert_true(r->count >= 10U);
    const sl_tilt_result_t fitted = r->res;
    for (uint32_t keep = SL_TILT_MIN_OBS - 1U; keep <= SL_TILT_MIN_OBS; keep++) {
        for (uint32_t k = 0; k < r->count; k++) {
            r->obs[k].mark = (uint8_t)(k < keep ? 0U : SL_TILT_OBS_RAMP);
        }
        refit(r);
        if (keep < SL_TILT_MIN_OBS) {
            assert_int_equal(r->res.quality, SL_TILT_TOO_FEW);
        } else {
            assert_int_equal(r->res.quality, SL_TILT_FITTED);
            assert_int_equal(r->res.psi_cdeg, fitted.psi_cdeg);
        }
    }
}

static void test_degenerate_inputs(void **state)
{
    (void)state;
    assert_int_equal(sl_tiltobs_init(NULL, board()), SL_ERR_ARG);
    assert_int_equal(sl_tiltobs_init(&obs, NULL), SL_ERR_ARG);
    assert_int_equal(sl_tiltobs_init(&obs, board()), SL_OK);
    sl_tiltobs_vehicle_t out;
    assert_false(sl_tiltobs_vehicle(&obs, NULL, &out));
    assert_null(sl_tiltobs_find(&obs, 0U));
    // Not moving: nothing recorded.
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    memset(tracks, 0, sizeof tracks);
    sl_target_t g;
    memset(&g, 0, sizeof g);
    g.az = 100; g.r1_um = 3000000; g.r2_um = 3500000; g.incline_flag = SL_INCLINE_VALID;
    tracks[0] = (sl_track_t){.live = 1, .updated = 1, .confirmed = 1, .id = 7, .az = 100,
                             .r1_um = 3000000, .r2_um = 3500000};
    sl_tiltobs_update(&obs, tracks, &g, 1U);
    assert_int_equal(obs.stats.observations, 0U);
    // Moving, but the target is not VALID: counted, nothing stored.
    sl_tiltobs_advance(&obs, true, 1000, 0, 250000U);
    g.incline_flag = SL_INCLINE_AMBIGUOUS;
    sl_tiltobs_update(&obs, tracks, &g, 1U);
    assert_int_equal(obs.stats.observations, 0U);
    assert_int_equal(obs.stats.no_target, 1U);
    sl_tiltobs_fit_pending(&obs); // nothing pending: no fit
    assert_int_equal(obs.stats.fits, 0U);
    // The group's union extent is unknown (a nibble of ext_grow saturated): refused, counted.
    g.incline_flag = SL_INCLINE_VALID;
    g.ext_grow = (uint8_t)SL_TARGET_EXT_SAT;
    sl_tiltobs_update(&obs, tracks, &g, 1U);
    assert_int_equal(obs.stats.rejected, 1U);
    g.ext_grow = (uint8_t)(SL_TARGET_EXT_SAT << 4);
    sl_tiltobs_update(&obs, tracks, &g, 1U);
    assert_int_equal(obs.stats.rejected, 2U);
    // The union bounds give no valid alpha (r2 below r1 here): refused, counted.
    g.ext_grow = 0U;
    g.r2_um = 2900000;
    tracks[0].r2_um = 2900000;
    sl_tiltobs_update(&obs, tracks, &g, 1U);
    assert_int_equal(obs.stats.rejected, 3U);
    assert_int_equal(obs.stats.observations, 0U);
}

// An AMBIGUOUS fit's other reading in the vehicle frame is what its best reading would be
// were the fit that reading (the same rotation to the current pose, the same path lean); a
// fit that is not AMBIGUOUS has none.
static void test_an_ambiguous_fit_gives_its_other_reading(void **state)
{
    (void)state;
    assert_int_equal(sl_tiltobs_init(&obs, board()), SL_OK);
    for (int k = 0; k < 7; ++k) sl_tiltobs_advance(&obs, true, 2000, 1500, 250000U); // turning
    sl_tiltobs_ring_t *r = &obs.ring[0];
    r->track_id = 3;
    r->fitted = 1;
    r->anchor_x_um = 1500000;
    r->anchor_y_um = -700000;
    sl_tilt_result_t *res = &r->res;
    res->quality = SL_TILT_AMBIGUOUS;
    res->tx_q24 = -2000000; res->ty_q24 = 1400000; res->psi_cdeg = 820; res->phi_cdeg = 14500;
    res->psi_sigma_cdeg = 40; res->phi_sigma_cdeg = 700;
    res->base_x_um = 4000000; res->base_y_um = 2500000;
    const sl_tilt_reading_t m = {5200000, 3900000, 2110, 3686, 75, 900, 4100000, 2450000};
    res->mirror = m;
    sl_tiltobs_vehicle_t best, other, as_best;
    assert_true(sl_tiltobs_vehicle(&obs, r, &best));
    assert_true(sl_tiltobs_vehicle_mirror(&obs, r, &other));
    assert_int_equal(best.quality, SL_TILT_AMBIGUOUS);
    assert_int_equal(other.quality, SL_TILT_AMBIGUOUS);
    assert_int_not_equal(best.phi_cdeg, other.phi_cdeg);
    // the same ring fitted as the other reading
    const sl_tilt_result_t kept = *res;
    res->quality = SL_TILT_FITTED;
    res->tx_q24 = m.tx_q24; res->ty_q24 = m.ty_q24; res->psi_cdeg = m.psi_cdeg;
    res->phi_cdeg = m.phi_cdeg; res->psi_sigma_cdeg = m.psi_sigma_cdeg;
    res->phi_sigma_cdeg = m.phi_sigma_cdeg; res->base_x_um = m.base_x_um;
    res->base_y_um = m.base_y_um;
    assert_true(sl_tiltobs_vehicle(&obs, r, &as_best));
    as_best.quality = SL_TILT_AMBIGUOUS;
    assert_memory_equal(&as_best, &other, sizeof other);
    // FITTED: no other reading
    sl_tiltobs_vehicle_t none;
    assert_false(sl_tiltobs_vehicle_mirror(&obs, r, &none));
    assert_int_equal(none.quality, SL_TILT_FITTED);
    assert_int_equal(none.psi_cdeg, 0);
    *res = kept;
    res->quality = SL_TILT_INCONSISTENT;
    assert_false(sl_tiltobs_vehicle_mirror(&obs, r, &none));
    assert_false(sl_tiltobs_vehicle_mirror(&obs, NULL, &none));
}

// Before its track is confirmed a pole's observations go into a provisional ring: never
// fitted nor reported; at confirmation the ring is fitted with all of them (a fast pass
// keeps its first rotations). Same result as a track confirmed from its first sighting.
static void test_observations_before_confirmation_are_kept(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p = {4.0, 3.0, 10.0, 200.0};
    confirm_at = 3;
    // Two rotations with the pole seen: a provisional ring, no fit, nothing to report.
    int seen = drive_by(&p, 1, 3.0, 0.0, 1, tracks);
    for (int k = 1; seen < 2 && k < 40; ++k) {
        seen = drive_by(&p, 1, 3.0, 0.0, k + 1, tracks);
    }
    assert_int_equal(seen, 2);
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 1U);
    assert_non_null(r);
    assert_int_equal(r->provisional, 1U);
    assert_int_equal(r->count, 2U);
    assert_int_equal(held_unconfirmed(r), 2U);
    assert_int_equal(obs.stats.fits, 0U);
    assert_int_equal(obs.pending, 0U);
    sl_tiltobs_vehicle_t out;
    assert_false(sl_tiltobs_vehicle(&obs, r, &out)); // never fitted: no PoleTilt
    // The whole pass at 3 m/s: every sighting kept, FITTED within the bounds.
    const int rotations = 32;
    seen = drive_by(&p, 1, 3.0, 0.0, rotations, tracks);
    r = sl_tiltobs_find(&obs, 1U);
    assert_non_null(r);
    assert_int_equal(r->provisional, 0U);
    assert_int_equal(r->count, (unsigned)(seen < SL_CFG_TILT_OBS_PER_TRACK ? seen : SL_CFG_TILT_OBS_PER_TRACK));
    assert_true(sl_tiltobs_vehicle(&obs, r, &out));
    const int32_t psi_late = out.psi_cdeg;
    check_pole(&p, 3.0, 0.0, rotations, 1, 1.0, 10.0);
    // Confirmed from the first sighting: the same observations, the same fit.
    confirm_at = 0;
    drive_by(&p, 1, 3.0, 0.0, rotations, tracks);
    assert_true(sl_tiltobs_vehicle(&obs, sl_tiltobs_find(&obs, 1U), &out));
    assert_int_equal(out.psi_cdeg, psi_late);
}

// Observations from before the track's confirmation that disagree with the rest (the
// pole's first rotations read wrong) make the fit INCONSISTENT: they are dropped and the fit
// is redone. A track that loses its confirmation later records nothing until confirmed
// again. A provisional ring restarts when its track does (evidence back to 1), and a
// confirmed track that finds no free ring takes a provisional one.
static void test_early_observations_yield_and_restart(void **state)
{
    (void)state;
    sl_track_t tracks[SL_CFG_MAX_TARGETS];
    const pole_t p = {4.0, 3.0, 10.0, 200.0};
    confirm_at = 3;
    corrupt_unconfirmed = 1;
    drive_by(&p, 1, 3.0, 0.0, 32, tracks);
    assert_int_equal(obs.stats.unconfirmed_dropped, 2U);
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&obs, 1U);
    assert_non_null(r);
    assert_int_equal(held_unconfirmed(r), 0U);
    assert_int_equal(r->dropped, 0U); // not counted as outliers
    check_pole(&p, 3.0, 0.0, 32, 1, 1.0, 10.0);
    // Confirmation lost on the 5th sighting (unconfirmed on the 5th and 6th): a history begun
    // under confirmation records nothing until the track is confirmed again.
    corrupt_unconfirmed = 1; // (those two read wrong, the first two too)
    reset_at = 5;
    const int seen = drive_by(&p, 1, 3.0, 0.0, 32, tracks);
    r = sl_tiltobs_find(&obs, 1U);
    assert_non_null(r);
    assert_int_equal(obs.stats.unconfirmed_dropped, 2U);
    assert_int_equal(r->count, (unsigned)seen - 4U);
    assert_int_equal(held_unconfirmed(r), 0U);
    check_pole(&p, 3.0, 0.0, 32, 1, 1.0, 10.0);
    corrupt_unconfirmed = 0;
    reset_at = 0;

    // Restart: a provisional ring whose track's evidence falls back to 1 is emptied.
    sl_target_t g[1];
    drive_t d = {0, 0, 0, 0, 0};
    assert_int_equal(sl_tiltobs_init(&obs, board()), SL_OK);
    memset(tracks, 0, sizeof(sl_track_t) * SL_CFG_MAX_TARGETS);
    const pole_t q = {0.5, 2.5, 8.0, 90.0};
    assert_true(see(board(), &d, &q, &g[0]));
    sl_track_t *t = &tracks[0];
    t->live = 1U;
    t->updated = 1U;
    t->id = 7U;
    t->az = g[0].az;
    t->r1_um = g[0].r1_um;
    t->r2_um = g[0].r2_um;
    for (uint8_t ev = 1U; ev <= 2U; ++ev) {
        t->evidence = ev;
        sl_tiltobs_advance(&obs, true, 0, 0, 250000U);
        sl_tiltobs_update(&obs, tracks, g, 1U);
    }
    r = sl_tiltobs_find(&obs, 7U);
    assert_non_null(r);
    assert_int_equal(r->count, 2U);
    t->evidence = 1U; // an inconsistent association: the tracker restarted its evidence
    sl_tiltobs_advance(&obs, true, 0, 0, 250000U);
    sl_tiltobs_update(&obs, tracks, g, 1U);
    r = sl_tiltobs_find(&obs, 7U);
    assert_non_null(r);
    assert_int_equal(r->count, 1U);
    assert_int_equal(r->provisional, 1U);

    // Every ring held by an unconfirmed track: a confirmed one takes one of them.
    for (uint32_t i = 1; i < (uint32_t)SL_CFG_TILT_TRACKS; ++i) {
        tracks[i] = *t;
        tracks[i].id = (uint16_t)(7U + i);
    }
    sl_target_t gg[SL_CFG_TILT_TRACKS + 1];
    for (uint32_t i = 0; i <= (uint32_t)SL_CFG_TILT_TRACKS; ++i) {
        gg[i] = g[0];
    }
    sl_tiltobs_advance(&obs, true, 0, 0, 250000U);
    sl_tiltobs_update(&obs, tracks, gg, SL_CFG_TILT_TRACKS);
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; ++i) {
        assert_non_null(sl_tiltobs_find(&obs, (uint16_t)(7U + i)));
    }
    tracks[SL_CFG_TILT_TRACKS] = *t;
    tracks[SL_CFG_TILT_TRACKS].id = 99U;
    tracks[SL_CFG_TILT_TRACKS].confirmed = 1U;
    tracks[SL_CFG_TILT_TRACKS].evidence = 3U;
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; ++i) {
        tracks[i].updated = 0U; // only the confirmed one this rotation
    }
    const uint32_t no_ring = obs.stats.no_ring;
    sl_tiltobs_advance(&obs, true, 0, 0, 250000U);
    sl_tiltobs_update(&obs, tracks, gg, SL_CFG_TILT_TRACKS + 1U);
    r = sl_tiltobs_find(&obs, 99U);
    assert_non_null(r);
    assert_int_equal(r->provisional, 0U);
    assert_int_equal(obs.stats.evicted, 1U);
    assert_int_equal(obs.stats.no_ring, no_ring);
    // ... while an unconfirmed track never takes a ring from another (nor is counted)
    tracks[SL_CFG_TILT_TRACKS].updated = 0U;
    tracks[SL_CFG_TILT_TRACKS + 1] = *t;
    tracks[SL_CFG_TILT_TRACKS + 1].id = 100U;
    sl_target_t g3[SL_CFG_TILT_TRACKS + 2];
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS + 2U; ++i) {
        g3[i] = g[0];
    }
    sl_tiltobs_advance(&obs, true, 0, 0, 250000U);
    sl_tiltobs_update(&obs, tracks, g3, SL_CFG_TILT_TRACKS + 2U);
    assert_null(sl_tiltobs_find(&obs, 100U));
    assert_int_equal(obs.stats.evicted, 1U);
    assert_int_equal(obs.stats.no_ring, no_ring);
    confirm_at = 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_straight_drive_bys_both_sides_all_directions),
        cmocka_unit_test(test_leaning_away_beyond_the_fold),
        cmocka_unit_test(test_curved_path_10_deg_per_second),
        cmocka_unit_test(test_results_digest_is_target_independent),
        cmocka_unit_test(test_one_outlier_is_dropped_a_bent_pole_stays_inconsistent),
        cmocka_unit_test(test_a_gross_outlier_in_a_fitted_pass_is_dropped),
        cmocka_unit_test(test_a_gross_outlier_in_an_ambiguous_pass_is_dropped),
        cmocka_unit_test(test_fits_are_bounded_per_rotation),
        cmocka_unit_test(test_lost_motion_and_lost_tracks_clear_history),
        cmocka_unit_test(test_more_tracks_than_rings_are_counted),
        cmocka_unit_test(test_union_extent_is_observed),
        cmocka_unit_test(test_ramps_are_observed_marked),
        cmocka_unit_test(test_a_walked_far_bound_is_observed_with_its_sigma),
        cmocka_unit_test(test_fits_beyond_the_largest_tilt_are_inconsistent),
        cmocka_unit_test(test_ramps_do_not_make_a_fit),
        cmocka_unit_test(test_degenerate_inputs),
        cmocka_unit_test(test_an_ambiguous_fit_gives_its_other_reading),
        cmocka_unit_test(test_observations_before_confirmation_are_kept),
        cmocka_unit_test(test_early_observations_yield_and_restart),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
