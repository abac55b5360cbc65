// SPDX-License-Identifier: MIT
// fuzz_tilt: libFuzzer entry point for the 3D tilt history and fit (sl_tiltobs.h, sl_tilt.h).
//
// The fit is fixed-point arithmetic on 64-bit intermediates over whatever the detector and
// the tracker hand it; a drive-by no simulator here renders (a pole anywhere within 60 m,
// bounds off by any amount, tracks that appear, vanish or restart under a new id, motion at
// any speed and yaw rate, a rotation period of 0 to 1 s) must never overflow (undefined
// behaviour under UBSan), crash, or report an out-of-range result.
//
// Input (read front to back; missing bytes read as 0):
//   header  u8: bit 0 board (paper-sim / robotcar-leaf), bit 1 verified_only, bits 2-3
//           max_tan_q16 (0, 30 deg, 5 deg, 89 deg); u8 poles (% 5), per pole i8 x, i8 y
//           (base, 0.1 m), u8 psi (0.25 deg), u8 phi (1.5 deg).
//   rotation (repeated until the input ends)
//           u8 op: bit 0 motion valid; the byte with bit 0 cleared, signed: yaw rate, deg/s
//           i8 speed (0.05 m/s), u8 rotation period (4 ms)
//           per pole: u8 bit 0 seen, bit 1 confirmed, bits 2-4 evidence, bit 5 a new track
//           id, bit 6 the track's bounds not its target's, bit 7 a gross error (r2 0.2 m
//           long; unseen: the track is gone); i8 r1 error (1 mm); i8 r2 error (4 mm); u8
//           bits 0-1 group width - 1, bits 2-3 union extent (both nibbles), bits 4-7 azimuth
//           error (signed); u8 flags: bits 0-5 RAMP, RADIUS_WIDTH, PROFILE, NO_TAIL, SLANT,
//           COARSE, bits 4-5 also the elongation (-20..40 mm), bits 6-7 the radius (50 mm;
//           both set: the target's own alpha AMBIGUOUS).
// A pole is seen from the moving vehicle on the azimuth of its bearing with the in-plane
// inclination and r1 / r2 of the model (tests/support/tilt_model.h, as test_tiltobs.c
// draws them), then the bytes perturb it: so the fuzzer reaches FITTED and AMBIGUOUS fits,
// outlier drops and the fold as well as nonsense.
//
// Invariants after every rotation: every ring's count <= its capacity, head < capacity, a
// free ring empty, `pending` = the rings with `fresh` set, a ring's drops within its bound;
// every result in range (quality an sl_tilt_quality_t; FITTED/AMBIGUOUS: n_obs within
// [SL_TILT_MIN_OBS, count], psi 0..9000 cdeg, phi 0..35999, and the vehicle-frame view's
// psi, phi, direction sigma and path lean in range; AMBIGUOUS: the other reading the same,
// with a reading of the fold other than the best's; any other quality: no other reading).
//
// The same file builds two ways (as fuzz_proto.c):
//  - -DSL_FUZZ_LIBFUZZER -fsanitize=fuzzer: the `fuzz_tilt` libFuzzer binary;
//  - without: `fuzz_tilt_replay [--random N [--write DIR]] [file|dir]...`: every file given
//    plus N pseudo-random drive-bys from a fixed seed (the `fuzz_tilt_random` ctest; --write
//    keeps them as files, the libFuzzer run's seeds).
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_tiltobs.h"

#include "../../support/tilt_model.h"

extern const sl_board_t sl_board_paper_sim;
extern const sl_board_t sl_board_robotcar_leaf;

#define CHECK(c)                                                                             \
    do {                                                                                     \
        if (!(c)) {                                                                          \
            fprintf(stderr, "fuzz_tilt: invariant failed: %s (%s:%d)\n", #c, __FILE__,       \
                    __LINE__);                                                               \
            abort();                                                                         \
        }                                                                                    \
    } while (0)

typedef struct reader {
    const uint8_t *p;
    size_t n;
} reader_t;

static uint8_t u8(reader_t *r)
{
    if (r->n == 0U) {
        return 0U;
    }
    r->n--;
    return *r->p++;
}

static int8_t i8(reader_t *r) { return (int8_t)u8(r); }

typedef struct pole {
    double bx, by, psi, phi; // base (odometry frame, m), tilt and direction (deg)
} pole_t;

// The pole's target as the detector would report it from the radar at (rx, ry) heading
// `yaw` (rad): false when it is not in front of the radar's shadow at all.
static bool see(const sl_board_t *b, double rx, double ry, double yaw, const pole_t *p,
                sl_target_t *g)
{
    const double H = b->radar_height_um * 1e-6;
    const double tt = tan(sl_tm_rad(p->psi));
    const double tx = tt * cos(sl_tm_rad(p->phi)), ty = tt * sin(sl_tm_rad(p->phi));
    const double qx = p->bx + H * tx, qy = p->by + H * ty;
    const double d0 = hypot(qx - rx, qy - ry);
    if (d0 < 0.5 || d0 > 60.0) {
        return false;
    }
    const double cw =
        -(sl_tm_deg(atan2(qy - ry, qx - rx)) - sl_tm_deg(yaw)) - b->radar_yaw_cdeg / 100.0;
    const double rel = fmod(fmod(cw, 360.0) + 720.0, 360.0);
    const int az = (int)floor(rel / (360.0 / b->azimuths) + 0.5) % b->azimuths;
    sl_tm_target(b, az, d0, atan2(qy - ry, qx - rx), tx, ty, g);
    return true;
}

static int32_t clamp_i32(int64_t v)
{
    return v > INT32_MAX ? INT32_MAX : (v < INT32_MIN ? INT32_MIN : (int32_t)v);
}

static void check_state(const sl_tiltobs_t *o)
{
    uint32_t fresh = 0U;
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; i++) {
        const sl_tiltobs_ring_t *r = &o->ring[i];
        CHECK(r->count <= (uint32_t)SL_CFG_TILT_OBS_PER_TRACK);
        CHECK(r->head < (uint32_t)SL_CFG_TILT_OBS_PER_TRACK);
        if (r->track_id == 0U) {
            CHECK(r->count == 0U && r->fresh == 0U);
            continue;
        }
        fresh += r->fresh != 0U ? 1U : 0U;
        CHECK((uint32_t)r->dropped <= (uint32_t)SL_CFG_TILT_OBS_PER_TRACK / SL_TILTOBS_OUTLIER_DIV + 1U);
        sl_tiltobs_vehicle_t v;
        const bool have = sl_tiltobs_vehicle(o, r, &v);
        CHECK(have == (r->fitted != 0U));
        if (!have) {
            continue;
        }
        CHECK(r->res.quality <= (uint8_t)SL_TILT_INCONSISTENT);
        CHECK(v.quality == r->res.quality);
        if (v.quality == (uint8_t)SL_TILT_FITTED || v.quality == (uint8_t)SL_TILT_AMBIGUOUS) {
            CHECK(r->res.n_obs >= SL_TILT_MIN_OBS && r->res.n_obs <= r->count);
            CHECK(r->res.psi_cdeg >= 0 && r->res.psi_cdeg <= 9000);
            CHECK(r->res.phi_cdeg >= 0 && r->res.phi_cdeg < 36000);
            CHECK(v.psi_cdeg >= 0 && v.psi_cdeg <= 9000);
            CHECK(v.phi_cdeg >= 0 && v.phi_cdeg < 36000);
            CHECK(v.phi_sigma_cdeg <= 18000U);
            CHECK(v.lean_path_cdeg >= -9000 && v.lean_path_cdeg <= 9000);
        }
        sl_tiltobs_vehicle_t m;
        const bool other = sl_tiltobs_vehicle_mirror(o, r, &m);
        CHECK(other == (v.quality == (uint8_t)SL_TILT_AMBIGUOUS));
        if (other) {
            const sl_tilt_reading_t *mr = &r->res.mirror;
            CHECK(mr->psi_cdeg >= 0 && mr->psi_cdeg <= 9000);
            CHECK(mr->phi_cdeg >= 0 && mr->phi_cdeg < 36000);
            CHECK(m.psi_cdeg == mr->psi_cdeg && m.phi_cdeg >= 0 && m.phi_cdeg < 36000);
            CHECK(m.phi_sigma_cdeg <= 18000U);
            CHECK(m.lean_path_cdeg >= -9000 && m.lean_path_cdeg <= 9000);
            CHECK(r->res.mirror_mask != r->res.mirrored_mask);
        } else {
            CHECK(r->res.mirror_mask == 0U && r->res.mirror.tx_q24 == 0 && r->res.mirror.ty_q24 == 0);
        }
    }
    CHECK(fresh == o->pending);
}

// What the inputs reached (the replay prints it: a run that never fits proves little).
static unsigned long g_obs, g_fits, g_fitted, g_ambiguous, g_drops, g_gross;

static void run_one(const uint8_t *data, size_t size)
{
    static sl_tiltobs_t o; // ~7 KB: not on the stack
    static sl_track_t tracks[SL_CFG_MAX_TARGETS];
    reader_t rd = {data, size};
    const uint8_t hdr = u8(&rd);
    const sl_board_t *b = (hdr & 1U) != 0U ? &sl_board_robotcar_leaf : &sl_board_paper_sim;
    CHECK(sl_tiltobs_init(&o, b) == SL_OK);
    static const uint16_t k_max_tan[4] = {0U, 37837U, 5734U, 65535U};
    o.verified_only = (hdr & 2U) != 0U;
    o.max_tan_q16 = k_max_tan[(hdr >> 2) & 3U];
    memset(tracks, 0, sizeof tracks);
    pole_t poles[4];
    const uint32_t np = u8(&rd) % 5U;
    for (uint32_t i = 0; i < np; i++) {
        poles[i].bx = i8(&rd) * 0.1;
        poles[i].by = i8(&rd) * 0.1;
        poles[i].psi = u8(&rd) / 4.0;
        poles[i].phi = u8(&rd) * 1.5;
    }
    double x = 0.0, y = 0.0, yaw = 0.0; // vehicle pose (double: what the fuzzer's world is)
    for (uint32_t rot = 0; rd.n > 0U && rot < 4096U; rot++) {
        const uint8_t op = u8(&rd);
        const bool moving = (op & 1U) != 0U;
        const int32_t yaw_cdeg_s = (int32_t)(int8_t)(op & 0xFEU) * 100; // +-256 deg/s
        const int32_t speed_mm_s = (int32_t)i8(&rd) * 50;              // +-6.4 m/s
        const uint32_t dt_us = (uint32_t)u8(&rd) * 4000U;              // 0..1.02 s
        sl_tiltobs_advance(&o, moving, speed_mm_s, yaw_cdeg_s, dt_us);
        const double dt = dt_us * 1e-6;
        const double ym = yaw + sl_tm_rad(yaw_cdeg_s / 100.0) * dt / 2.0;
        x += speed_mm_s * 1e-3 * dt * cos(ym);
        y += speed_mm_s * 1e-3 * dt * sin(ym);
        yaw += sl_tm_rad(yaw_cdeg_s / 100.0) * dt;
        sl_target_t g[4];
        uint32_t ng = 0U;
        for (uint32_t i = 0; i < (uint32_t)SL_CFG_MAX_TARGETS; i++) {
            tracks[i].updated = 0U;
        }
        for (uint32_t i = 0; i < np; i++) {
            const uint8_t tb = u8(&rd);
            const int8_t e1 = i8(&rd);
            const int8_t e2 = i8(&rd);
            const uint8_t ea = u8(&rd);
            const uint8_t fl = u8(&rd);
            sl_track_t *t = &tracks[i];
            if ((tb & 1U) == 0U || !see(b, x, y, yaw, &poles[i], &g[ng])) {
                if ((tb & 0x80U) != 0U) {
                    t->live = 0U; // the track is gone
                }
                continue;
            }
            sl_target_t *q = &g[ng];
            const int64_t gross = (tb & 0x80U) != 0U ? 200000 : 0; // a bound 0.2 m off
            q->r1_um = (uint32_t)clamp_i32((int64_t)q->r1_um + e1 * 1000);
            q->r2_um = (uint32_t)clamp_i32((int64_t)q->r2_um + e2 * 4000 + gross);
            const int32_t daz = (int32_t)(int8_t)(ea & 0xF0U) / 16; // -8..7 azimuths
            q->az = (uint16_t)(((int32_t)q->az + daz + b->azimuths) % b->azimuths);
            q->az_first = q->az;
            q->az_count = (uint16_t)(1U + (ea & 3U));
            q->ext_grow = (uint8_t)((ea & 0x0CU) != 0U ? ((ea & 0x0CU) >> 2) * 0x11U : 0U);
            q->flags = (uint16_t)(((fl & 1U) != 0U ? SL_TARGET_RAMP : 0U) |
                                  ((fl & 2U) != 0U ? SL_TARGET_RADIUS_WIDTH : 0U) |
                                  ((fl & 4U) != 0U ? SL_TARGET_PROFILE : 0U) |
                                  ((fl & 8U) != 0U ? SL_TARGET_NO_TAIL : 0U) |
                                  ((fl & 16U) != 0U ? SL_TARGET_SLANT : 0U) |
                                  ((fl & 32U) != 0U ? SL_TARGET_COARSE : 0U));
            q->radius_um = (fl & 2U) != 0U ? (uint32_t)(fl >> 6) * 50000U : 0U;
            if ((fl & 0xC0U) == 0xC0U) {
                q->incline_flag = (uint8_t)SL_INCLINE_AMBIGUOUS;
            }
            const uint32_t bin = b->bin_size_um;
            q->bin_first = (uint16_t)(q->r1_um / bin < 65535U ? q->r1_um / bin : 65535U);
            q->bin_last = (uint16_t)(q->r2_um / bin < 65535U ? q->r2_um / bin : 65535U);
            q->r1_raw_um = (uint32_t)q->bin_first * bin;
            q->r2_raw_um = ((uint32_t)q->bin_last + 1U) * bin;
            q->elong_um = (int32_t)((fl >> 4) & 3U) * 20000 - 20000;
            // the tracker's slot for it
            t->live = 1U;
            t->updated = 1U;
            t->evidence = (uint8_t)((tb >> 2) & 7U);
            t->confirmed = (uint8_t)((tb & 2U) != 0U ? 1U : 0U);
            t->id = (uint16_t)(i + 1U + ((tb & 0x20U) != 0U ? 8U : 0U)); // unique per slot
            t->az = q->az;
            t->r1_um = q->r1_um + ((tb & 0x40U) != 0U ? 1U : 0U);
            t->r2_um = q->r2_um;
            ng++;
        }
        sl_tiltobs_update(&o, tracks, g, ng);
        sl_tiltobs_fit_pending(&o);
        check_state(&o);
    }
    // Whatever is still pending is fitted within a bounded number of calls.
    for (uint32_t k = 0; k < 64U && o.pending != 0U; k++) {
        sl_tiltobs_fit_pending(&o);
        check_state(&o);
    }
    g_obs += o.stats.observations;
    g_fits += o.stats.fits;
    g_drops += o.stats.outliers;
    g_gross += o.stats.gross;
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; i++) {
        g_fitted += o.ring[i].fitted != 0U && o.ring[i].res.quality == (uint8_t)SL_TILT_FITTED;
        g_ambiguous += o.ring[i].fitted != 0U && o.ring[i].res.quality == (uint8_t)SL_TILT_AMBIGUOUS;
    }
}

#ifdef SL_FUZZ_LIBFUZZER
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    run_one(data, size);
    return 0;
}
#else
#include "replay_files.h"

static unsigned long g_inputs;

static int run_file(const char *path, const char *name, unsigned long index)
{
    (void)name;
    (void)index;
    static uint8_t buf[1U << 16];
    size_t n = 0;
    if (replay_read("fuzz_tilt_replay", path, buf, sizeof buf, &n) != 0) {
        return 1;
    }
    run_one(buf, n);
    g_inputs++;
    return 0;
}

// Pseudo-random drive-bys: one to four poles within 2-5 m of a straight or curved path, a
// plausible motion, and perturbation bytes drawn from a fixed generator (xorshift64*).
static uint64_t g_rng = 0x9E3779B97F4A7C15ULL;
static uint8_t rnd(void)
{
    return replay_rnd(&g_rng);
}

static void run_random(unsigned long n, const char *write_dir)
{
    static uint8_t buf[4096];
    for (unsigned long k = 0; k < n; k++) {
        size_t len = 0;
        buf[len++] = rnd();
        const uint8_t np = (uint8_t)(1U + rnd() % 4U);
        buf[len++] = np;
        for (uint8_t i = 0; i < np; i++) {
            buf[len++] = (uint8_t)(int8_t)(20 + (int)(rnd() % 100U)); // x 2..12 m
            const int side = (rnd() & 1U) != 0U ? 1 : -1;
            buf[len++] = (uint8_t)(int8_t)(side * (20 + (int)(rnd() % 30U))); // y 2..5 m
            buf[len++] = rnd() % 100U; // psi 0..25 deg
            buf[len++] = rnd();        // phi
        }
        const bool wild = (k % 4U) == 3U; // every fourth input: unconstrained bytes
        const uint8_t yaw = (uint8_t)((rnd() % 8U) << 1);
        const uint8_t v = (uint8_t)(10U + rnd() % 60U); // 0.5..3.5 m/s
        while (len + 3U + 5U * np < sizeof buf && len < 1200U) {
            buf[len++] = wild ? rnd() : (uint8_t)(1U | ((rnd() % 16U) == 0U ? yaw : 0U));
            buf[len++] = wild ? rnd() : v;
            buf[len++] = wild ? rnd() : 62U; // 248 ms
            for (uint8_t i = 0; i < np; i++) {
                const uint8_t tb = rnd();
                buf[len++] = wild ? tb : (uint8_t)(1U | 2U | (5U << 2) | (tb & 0xE0U & ((rnd() % 8U) == 0U ? 0xFFU : 0U)));
                buf[len++] = wild ? rnd() : (uint8_t)(int8_t)((int)(rnd() % 21U) - 10);
                buf[len++] = wild ? rnd() : (uint8_t)(int8_t)((int)(rnd() % 7U) - 3);
                buf[len++] = wild ? rnd() : (uint8_t)(rnd() & 0x0FU);
                buf[len++] = wild ? rnd() : (uint8_t)(rnd() & 0x3FU);
            }
        }
        if (write_dir != NULL) { // keep it as a libFuzzer run's seed
            replay_write(write_dir, k, buf, len);
        }
        run_one(buf, len);
        g_inputs++;
    }
}

int main(int argc, char **argv)
{
    replay_args_t a;
    if (replay_args(argc, argv, "fuzz_tilt_replay", run_file, &a) != 0) {
        return 1;
    }
    const unsigned long files = a.files;
    const int bad = a.bad;
    run_random(a.random_n, a.write_dir);
    printf("fuzz_tilt_replay: %lu inputs (%lu files), all invariants held; %lu observations, "
           "%lu fits, rings ending FITTED %lu / AMBIGUOUS %lu, drops %lu inconsistent + %lu gross\n",
           g_inputs, files, g_obs, g_fits, g_fitted, g_ambiguous, g_drops, g_gross);
    return bad;
}
#endif
