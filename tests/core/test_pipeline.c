// SPDX-License-Identifier: MIT
// Unit tests for sl_pipeline.h: the whole core end to end on streams built here with the
// core encoders (sl_proto_encode_*), from a small geometric scene renderer (double
// precision, the oracle) for the paper-sim board. Covers: poles at -10/0/+10 deg, the
// near-field band and ground beyond the shadow never reported, ambiguous poles flagged,
// CAN frames decoding to the targets, missing azimuths / junk / duplicates / a radar restart,
// broken / empty / saturated scans, 16-bit and full-length messages, CAN busy, motion input
// (CAN and setter) and a simulated drive-by.
//
// About the accuracy checks: one rotation of a static scene quantises r1 and r2 to bins,
// which moves alpha by up to ~1 deg at 2.5 m (MATH.md s.3; the paper's Table I std). The
// static tests therefore check two things: (1) the pipeline's alpha equals the oracle's
// estimate from the same quantised bins (half-bin corrected, MATH.md closed form in double)
// within 0.05 deg, for every pole; (2) for poles placed where the quantisation error is
// small (the renderer searches the distance), alpha is within 0.5 deg of the truth. The
// drive-by (moving: the quantisation changes every rotation) checks the mean error.
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_pipeline.h"

/// The default E2E configuration of message SL_CAN_MSG_<m> (the boards under test use it).
#define E2E(m) (&sl_can_e2e_defaults[SL_CAN_MSG_##m])

/// The receiver took the frame as part of its sequence (the first one, or any later step).
static bool e2e_accepted(sl_can_e2e_status_t st)
{
    return st == SL_CAN_E2E_OK || st == SL_CAN_E2E_OK_SOME_LOST || st == SL_CAN_E2E_INITIAL;
}

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static sl_pipeline_t pl; // static, as a firmware holds it
static const sl_board_t *B;

static uint64_t rng_state = 0x243F6A8885A308D3ULL;
static uint32_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 20);
}

// ------------------------------------------------------------------------ geometry oracle

typedef struct seg {
    double r1, r2;       // slant range bounds of the visible segment (m)
    bool base_in_shadow; // the -theta ray hits the pole above the ground
} seg_t;

// A pole crossing radar height at horizontal distance d (m), in-plane inclination alpha
// (> 0: top towards the radar), visible wedge [-theta, +beta] (MATH.md s.2).
static seg_t pole_segment(double d, double alpha_deg, double theta_deg, double beta_deg, double h)
{
    const double a = alpha_deg * DEG, th = theta_deg * DEG, be = beta_deg * DEG;
    const double p = d * cos(a);
    const double r_top = p / cos(be - a), r_bot = p / cos(-th - a);
    double r1 = r_top < r_bot ? r_top : r_bot;
    if (a >= -th && a <= be && p < r1) {
        r1 = p; // the perpendicular foot is inside the wedge
    }
    seg_t s = {r1, r_top > r_bot ? r_top : r_bot, r_bot * sin(th) < h};
    return s;
}

// The MATH.md s.2 inversion. flag: 0 valid, 1 ambiguous.
static double alpha_from_rho(double rho, double theta_deg, double beta_deg, int *flag)
{
    const double th = theta_deg * DEG, be = beta_deg * DEG;
    *flag = 0;
    if (rho < 1.0 / cos((th + be) / 2.0)) {
        *flag = 1;
        return 0.0;
    }
    if (rho >= 1.0 / cos(th + be)) {
        return atan((rho * cos(th) - cos(be)) / (rho * sin(th) + sin(be))) / DEG;
    }
    return (acos(1.0 / rho) - th) / DEG;
}

static double bin_m(void)
{
    return B->bin_size_um * 1e-6;
}

static double theta_deg(uint32_t az)
{
    return B->theta_cdeg[az] / 100.0;
}

// Values (0.5 dB of power each, the sensor's log scale) a bin lit over `fill` of its length
// reads below a full one; the fill the pipeline reads back from that drop.
static int edge_drop(double fill)
{
    return fill <= 0 ? 255 : (int)lround(-20.0 * log10(fill));
}
static double read_fill(int drop)
{
    return drop >= 48 ? 0.0 : pow(10.0, -drop / 20.0);
}

// The first bin's lit fraction for a first-over-second power ratio q when the lit part
// starts dl bins past the foot of the pole's line (sl_profile_lead_fill_q16's model).
static double lead_fill_oracle(double q, double dl)
{
    double lo = 0, hi = 1;
    for (int k = 0; k < 60; k++) {
        const double f = 0.5 * (lo + hi);
        const double g = (sqrt(f + dl) - sqrt(dl)) / (sqrt(f + dl + 1) - sqrt(f + dl));
        if (g <= q) {
            lo = f;
        } else {
            hi = f;
        }
    }
    return 0.5 * (lo + hi);
}

// What the pipeline should estimate from the bins the segment occupies.
static double predicted_alpha(double d, double alpha, uint32_t az, bool profiled, int *flag)
{
    const seg_t s = pole_segment(d, alpha, theta_deg(az), B->beta_up_cdeg / 100.0,
                                 B->radar_height_um * 1e-6);
    const double b = bin_m();
    // Refined from the profile (`profiled`): r2 = the start of the last bin + its lit fraction
    // as the pipeline reads it back from the rendered value (sl_profile_fill_q16); r1 = the
    // first bin's centre, or its lit fraction when the rendered box's flat start fits the
    // leading-edge model (sl_profile_lead_edge, here in double precision). The mask's
    // bounds (`profiled` false): both centres.
    const double i1 = floor(s.r1 / b), i2 = floor(s.r2 / b);
    double r1 = (i1 + 0.5) * b;
    const double r2 = profiled ? i2 * b + read_fill(edge_drop(s.r2 / b - i2)) * b : (i2 + 0.5) * b;
    if (r2 <= r1) {
        *flag = 2;
        return 0;
    }
    const double be = B->beta_up_cdeg / 100.0;
    const double a0 = alpha_from_rho(r2 / r1, theta_deg(az), be, flag);
    if (profiled && *flag == 0 && i2 >= i1 + 3) {
        // the box: first, second and third bins at the same value (q = 1, P3 / P2 = 1)
        const double dl = a0 >= be ? i1 * (1.0 - cos((a0 - be) * DEG)) : 0.0; // bins
        const double f = lead_fill_oracle(1.0, dl);
        const double p3 = (sqrt(f + dl + 2) - sqrt(f + dl + 1)) / (sqrt(f + dl + 1) - sqrt(f + dl));
        if (fabs(20.0 * log10(p3)) <= 3.0) {
            r1 = (i1 + 1.0 - f) * b;
        }
    }
    return alpha_from_rho(r2 / r1, theta_deg(az), be, flag);
}

// A distance in [lo, hi] (1 mm steps) where the quantised estimate lies in [want_lo, want_hi]
// (or is ambiguous when `ambiguous`), closest to the truth.
static double place_pole(double alpha, uint32_t az, double lo, double hi, double want_lo,
                         double want_hi, bool ambiguous)
{
    double best = -1, best_err = 1e9;
    for (double d = lo; d <= hi; d += 0.001) {
        int flag;
        const double e = predicted_alpha(d, alpha, az, true, &flag);
        if (ambiguous) {
            if (flag == 1) {
                return d;
            }
            continue;
        }
        if (flag == 0 && e >= want_lo && e <= want_hi && fabs(e - alpha) < best_err) {
            best = d;
            best_err = fabs(e - alpha);
        }
    }
    assert_true(best > 0);
    return best;
}

// ---------------------------------------------------------------------------- scene

typedef struct tpole {
    uint32_t az;        // centre azimuth
    double d, alpha;    // horizontal distance at radar height (m), inclination (deg)
    int half_width;     // azimuths each side of the centre
    int gap_bin;        // > 0: this bin offset inside the run stays empty (broken return)
} tpole_t;

typedef struct scene {
    tpole_t p[8];
    int np;
    bool near_band, ground, noise, flicker;
    int empty_rot, saturated_rot, short_rot; // -1: none
    uint32_t pow_shift16;                    // 16-bit streams: value << this
} scene_t;

static void scene_defaults(scene_t *s)
{
    memset(s, 0, sizeof *s);
    s->near_band = s->ground = s->noise = s->flicker = true;
    s->empty_rot = s->saturated_rot = s->short_rot = -1;
}

static uint32_t ground_first_bin(uint32_t az)
{
    const double h = B->radar_height_um * 1e-6, r = B->shadow_um[az] * 1e-6;
    return (uint32_t)ceil(sqrt(h * h + r * r) / bin_m());
}

static void draw_pole(uint8_t *row, uint32_t bins, double d, double alpha, uint32_t az, int gap)
{
    const seg_t s = pole_segment(d, alpha, theta_deg(az), B->beta_up_cdeg / 100.0,
                                 B->radar_height_um * 1e-6);
    uint32_t first = (uint32_t)floor(s.r1 / bin_m()), last = (uint32_t)floor(s.r2 / bin_m());
    if (!s.base_in_shadow) {
        last = ground_first_bin(az); // the base stands on lit ground: the return joins it
    }
    for (uint32_t k = first; k <= last && k < bins; k++) {
        if (gap > 0 && k == first + (uint32_t)gap) {
            continue;
        }
        row[k] = 200;
    }
    if (s.base_in_shadow && last > first && last < bins && (gap <= 0 || last != first + (uint32_t)gap)) {
        // the last bin lit over part of its length returns that part of a full bin's power
        const int drop = edge_drop(s.r2 / bin_m() - floor(s.r2 / bin_m()));
        row[last] = (uint8_t)(drop >= 160 ? 40 : 200 - drop);
    }
}

static void render_static(const scene_t *s, int rot, uint32_t az, uint8_t *row, uint32_t bins)
{
    for (uint32_t k = 0; k < bins; k++) {
        row[k] = s->noise ? (uint8_t)(rnd() & 31U) : 0U; // below the threshold (40)
    }
    if (s->near_band) {
        for (uint32_t k = 0; k < 36 && k < bins; k++) {
            row[k] = 120; // REAL_SCANS.md s.2 leakage band, inside [0, near_exclusion_bins)
        }
    }
    if (s->ground) {
        for (uint32_t k = ground_first_bin(az); k < bins; k++) {
            row[k] = (uint8_t)(60 + (rnd() & 15U)); // lit ground beyond the shadow edge
        }
    }
    for (int i = 0; i < s->np; i++) {
        const tpole_t *p = &s->p[i];
        const int da = (int)az - (int)p->az;
        if (da >= -p->half_width && da <= p->half_width) {
            draw_pole(row, bins, p->d, p->alpha, az, p->gap_bin);
        }
    }
    if (s->flicker && az == 300 && (rot % 2) == 1) {
        for (uint32_t k = 90; k < 96; k++) {
            row[k] = 150; // a transient inside the shadow: never stable
        }
    }
    if (rot == s->empty_rot) {
        memset(row, 0, bins);
    }
    if (rot == s->saturated_rot) {
        memset(row, 255, bins);
    }
}

// ---------------------------------------------------------------------------- streams

typedef struct stream {
    uint8_t *buf;
    size_t n, cap;
    size_t rot_end[128]; // offset after the last message of rotation r
    int rots;
    uint16_t sweep;
    uint32_t msg;        // FFT messages written (timestamps)
    size_t cut_at;       // > 0: the connection dies here (feed_stream calls finish)
} stream_t;

static void st_init(stream_t *st, size_t cap)
{
    memset(st, 0, sizeof *st);
    st->buf = malloc(cap);
    assert_non_null(st->buf);
    st->cap = cap;
}

static void st_free(stream_t *st)
{
    free(st->buf);
    memset(st, 0, sizeof *st);
}

static void st_config(stream_t *st, uint16_t azimuths, uint16_t bins)
{
    const sl_proto_config_t c = {.azimuths = azimuths, .bin_size_100um = 438,
                                 .range_bins = bins, .encoder_size = 5600,
                                 .rotation_mhz = 4000, .packet_rate = 1600,
                                 .has_data_width = true, .data_width = 1};
    const sl_ssize_t k = sl_proto_encode_config(st->buf + st->n, st->cap - st->n, &c,
                                                (sl_bytes_t){NULL, 0});
    assert_true(k > 0);
    st->n += (size_t)k;
}

static void st_junk(stream_t *st, size_t len)
{
    for (size_t i = 0; i < len; i++) {
        // Junk with partial signatures in it.
        st->buf[st->n++] = (rnd() % 4U == 0U) ? sl_proto_signature[rnd() % 6U] : (uint8_t)rnd();
    }
}

static uint64_t msg_time_us(uint32_t k)
{
    return 1700000000ULL * 1000000ULL + (uint64_t)k * 625U; // 1600 azimuths/s
}

static void st_fft(stream_t *st, uint32_t az, const uint8_t *row, uint32_t bins, int bpb,
                   uint32_t shift16)
{
    const uint64_t t = msg_time_us(st->msg++);
    const sl_proto_fft_t f = {.sweep_counter = st->sweep++, .azimuth_ticks = (uint16_t)(az * 14U),
                              .seconds = (uint32_t)(t / 1000000U),
                              .split_ns = (uint32_t)(t % 1000000U) * 1000U, .bins = bins};
    sl_ssize_t k;
    if (bpb == 1) {
        k = sl_proto_encode_fft8(st->buf + st->n, st->cap - st->n, &f, row);
    } else {
        static uint16_t w[4096];
        for (uint32_t i = 0; i < bins; i++) {
            w[i] = (uint16_t)(((uint32_t)row[i] << shift16) | (rnd() & ((1U << shift16) - 1U)));
        }
        k = sl_proto_encode_fft16(st->buf + st->n, st->cap - st->n, &f, w);
    }
    assert_true(k > 0);
    st->n += (size_t)k;
}

typedef void (*row_fn)(void *ctx, int rot, uint32_t az, uint64_t t_us, uint8_t *row, uint32_t bins);

typedef struct sopt {
    int rotations;
    uint32_t bins;
    int bpb;
    uint32_t shift16;
    int drop_per_1000;   // random azimuth messages lost
    int junk_per_1000;   // junk inserted before a message
    int dup_per_1000;    // a message sent twice
    int swap_per_1000;   // two consecutive messages swapped (late arrival)
    int burst_rot;       // rotation with a burst of lost azimuths (-1: none)
    uint32_t burst_az, burst_len;
    int restart_rot;     // radar restart before this rotation (-1: none)
} sopt_t;

static sopt_t sopt_defaults(void)
{
    sopt_t o = {.rotations = 20, .bins = 400, .bpb = 1, .shift16 = 8, .burst_rot = -1,
                .restart_rot = -1};
    return o;
}

static void build(stream_t *st, const sopt_t *o, row_fn fn, void *ctx)
{
    static uint8_t row[4096], row2[4096];
    st_config(st, 400, (uint16_t)o->bins);
    for (int r = 0; r < o->rotations; r++) {
        if (r == o->restart_rot) {
            // The radar restarts: the connection dies mid-message, a new stream begins with
            // a Configuration and fresh sweep counters.
            st_fft(st, 0, row, o->bins, o->bpb, o->shift16);
            st->n -= 100;
            st->cut_at = st->n;
            st_config(st, 400, (uint16_t)o->bins);
            st->sweep = 0;
        }
        for (uint32_t a = 0; a < 400; a++) {
            const uint64_t t = msg_time_us(st->msg);
            fn(ctx, r, a, t, row, o->bins);
            const bool burst = r == o->burst_rot && a >= o->burst_az && a < o->burst_az + o->burst_len;
            if (burst || (int)(rnd() % 1000U) < o->drop_per_1000) {
                st->msg++;
                st->sweep++;
                continue;
            }
            if ((int)(rnd() % 1000U) < o->junk_per_1000) {
                st_junk(st, 1 + rnd() % 60U);
            }
            if (a + 1U < 400U && (int)(rnd() % 1000U) < o->swap_per_1000) {
                // Send a + 1 first, then a (late).
                const uint64_t t2 = msg_time_us(st->msg + 1U);
                fn(ctx, r, a + 1U, t2, row2, o->bins);
                const uint32_t m0 = st->msg;
                const uint16_t s0 = st->sweep;
                st->msg = m0 + 1U;
                st->sweep = (uint16_t)(s0 + 1U);
                st_fft(st, a + 1U, row2, o->bins, o->bpb, o->shift16);
                st->msg = m0;
                st->sweep = s0;
                st_fft(st, a, row, o->bins, o->bpb, o->shift16);
                st->msg++;
                st->sweep++;
                a++;
                continue;
            }
            st_fft(st, a, row, o->bins, o->bpb, o->shift16);
            if ((int)(rnd() % 1000U) < o->dup_per_1000) {
                st->msg--;
                st->sweep--;
                st_fft(st, a, row, o->bins, o->bpb, o->shift16);
            }
        }
        st->rot_end[r] = st->n;
        st->rots = r + 1;
    }
}

static void render_static_fn(void *ctx, int rot, uint32_t az, uint64_t t, uint8_t *row,
                             uint32_t bins)
{
    (void)t;
    render_static(ctx, rot, az, row, bins);
}

// ---------------------------------------------------------------------------- port

#define MAXROT 64
#define MAXTG 8
typedef struct rec {
    int rotations;
    int nt[MAXROT];
    sl_target_t tg[MAXROT][MAXTG];
    uint8_t frames_eff[MAXROT];
    uint16_t missing[MAXROT];
    uint8_t level[MAXROT];
    sl_can_frame_t *can;
    int ncan, capcan;
    int can_rot[8192]; // rotation each frame was sent in
    int busy_every, calls, busy;
} rec_t;
static rec_t rec;

static sl_err_t port_can_tx(void *ctx, const sl_can_frame_t *f)
{
    rec_t *r = ctx;
    r->calls++;
    if (r->busy_every > 0 && r->calls % r->busy_every == 0) {
        r->busy++;
        return SL_ERR_BUSY;
    }
    if (r->ncan < r->capcan) {
        r->can_rot[r->ncan] = r->rotations - 1;
        r->can[r->ncan++] = *f;
    }
    return SL_OK;
}

static void port_on_rotation(void *ctx, const sl_pipeline_rotation_t *x)
{
    rec_t *r = ctx;
    assert_int_equal(x->rotation, (uint32_t)r->rotations);
    if (r->rotations < MAXROT) {
        const int k = r->rotations;
        r->nt[k] = x->n_targets;
        for (int i = 0; i < x->n_targets && i < MAXTG; i++) {
            r->tg[k][i] = x->targets[i];
        }
        r->frames_eff[k] = x->frames_eff;
        r->missing[k] = x->missing;
        r->level[k] = x->level;
    }
    r->rotations++;
}

static void rec_reset(int busy_every)
{
    free(rec.can);
    memset(&rec, 0, sizeof rec);
    rec.capcan = 8192;
    rec.can = calloc((size_t)rec.capcan, sizeof *rec.can);
    rec.busy_every = busy_every;
}

static sl_pipeline_cfg_t cfg_for(const sl_board_t *b)
{
    sl_pipeline_cfg_t c;
    sl_pipeline_cfg_default(&c, b);
    c.port.can_tx = port_can_tx;
    c.port.on_rotation = port_on_rotation;
    c.port.ctx = &rec;
    return c;
}

// Feed rotation by rotation (now_us = rotation start), in chunks of `chunk` bytes (0: random
// sizes 1..5000), then finish. At `cut_at` the connection dies: finish (when
// `finish_at_cut`, as the daemon does on a disconnect) or nothing (the decoder resyncs).
static bool finish_at_cut = true;
static void feed_stream(const stream_t *st, size_t chunk, uint64_t seed)
{
    uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 7;
    size_t i = 0;
    for (int r = 0; r < st->rots; r++) {
        const uint64_t now = 1000000U + (uint64_t)r * 250000U;
        while (i < st->rot_end[r]) {
            size_t k = chunk;
            if (k == 0) {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                k = 1 + (size_t)(s % 5000U);
            }
            if (k > st->rot_end[r] - i) {
                k = st->rot_end[r] - i;
            }
            if (st->cut_at > i && st->cut_at - i < k) {
                k = st->cut_at - i;
            }
            assert_int_equal(sl_pipeline_feed(&pl, st->buf + i, k, now), SL_OK);
            i += k;
            if (i == st->cut_at && finish_at_cut) {
                assert_int_equal(sl_pipeline_finish(&pl, now), SL_OK);
            }
        }
    }
    assert_int_equal(sl_pipeline_finish(&pl, 1000000U + (uint64_t)st->rots * 250000U), SL_OK);
}

// ---------------------------------------------------------------------------- the scene

// Poles at -10 / 0 / +10 deg placed where one rotation's quantisation error is small, an
// ambiguous pole at the fold (-13 deg), a pole standing outside the shadow, and the rest.
static scene_t g_scene;
static void make_scene(scene_t *s)
{
    scene_defaults(s);
    s->p[0] = (tpole_t){60, place_pole(-10, 60, 2.2, 3.2, -10.4, -9.6, false), -10, 1, 0};
    s->p[1] = (tpole_t){160, place_pole(0, 160, 2.2, 3.2, -0.4, 0.4, false), 0, 1, 0};
    s->p[2] = (tpole_t){260, place_pole(10, 260, 2.2, 3.2, 10.0, 10.4, false), 10, 1, 0};
    s->p[3] = (tpole_t){330, place_pole(-13, 330, 2.2, 3.2, 0, 0, true), -13, 1, 0};
    s->p[4] = (tpole_t){110, 5.6, 0, 1, 0}; // base on lit ground beyond the shadow edge
    s->np = 5;
}


// Targets of rotation k are exactly the three valid poles and the ambiguous one. The
// representative azimuth may be a neighbour of the pole's centre when a row of the centre
// was lost early on (it then became stable one rotation later).
static const tpole_t *pole_near(const scene_t *s, uint32_t az)
{
    for (int i = 0; i < s->np; i++) {
        if (labs((long)s->p[i].az - (long)az) <= s->p[i].half_width) {
            return &s->p[i];
        }
    }
    return NULL;
}

static void check_targets(const scene_t *s, int k)
{
    assert_int_equal(rec.nt[k], 4);
    int seen = 0;
    for (int i = 0; i < rec.nt[k]; i++) {
        const sl_target_t *t = &rec.tg[k][i];
        const tpole_t *p = pole_near(s, t->az);
        if (p == NULL || p->az == 110 || p->gap_bin != 0) {
            fail_msg("rotation %d: unexpected target at azimuth %u bins %u..%u", k, t->az,
                     t->bin_first, t->bin_last);
        }
        assert_true(t->bin_first >= B->near_exclusion_bins);
        int flag;
        const double pred =
            predicted_alpha(p->d, p->alpha, t->az, (t->flags & SL_TARGET_PROFILE) != 0U, &flag);
        if (p->alpha == -13) {
            assert_int_equal(flag, 1);
            assert_int_equal(t->incline_flag, SL_INCLINE_AMBIGUOUS);
            assert_int_equal(t->alpha_cdeg, 0); // flagged, never given a number
            seen |= 8;
            continue;
        }
        assert_int_equal(t->incline_flag, SL_INCLINE_VALID);
        const double got = t->alpha_cdeg / 100.0;
        if (fabs(got - pred) > 0.05 || fabs(got - p->alpha) > 0.5) {
            fail_msg("rotation %d az %u: alpha %.2f, oracle from the bins %.3f, truth %.1f", k,
                     t->az, got, pred, p->alpha);
        }
        seen |= p->alpha < 0 ? 1 : p->alpha == 0 ? 2 : 4;
    }
    assert_int_equal(seen, 15);
}

static stream_t g_static; // the static scene, 24 rotations, built once
static void ensure_static_stream(void)
{
    if (g_static.buf != NULL) {
        return;
    }
    make_scene(&g_scene);
    sopt_t o = sopt_defaults();
    o.rotations = 24;
    st_init(&g_static, 24U * 400U * (40U + o.bins) + 4096U);
    build(&g_static, &o, render_static_fn, &g_scene);
}

static int setup(void **state)
{
    (void)state;
    B = sl_board_find("paper-sim");
    return B == NULL ? -1 : 0;
}

// ---------------------------------------------------------------------------- tests

static void test_pipeline_detects_poles_at_minus10_0_plus10_deg_after_n_rotations(void **state)
{
    (void)state;
    ensure_static_stream();
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    assert_int_equal(pl.mask_bins, 160); // 135 bins needed on paper-sim, whole words
    feed_stream(&g_static, 65536, 0);
    assert_int_equal(rec.rotations, 24);
    const int n = B->mask_frames;
    for (int k = 0; k < 24; k++) {
        if (k < n - 1) {
            assert_int_equal(rec.nt[k], 0); // nothing is stable before n rotations
        } else {
            check_targets(&g_scene, k);
        }
        assert_int_equal(rec.frames_eff[k], n); // no motion input: the board's n
    }
    // Near band, ground, the pole outside the shadow and the transient: never targets
    // (check_targets fails on any target not at a scene pole; the lit-ground pole at
    // azimuth 110 is a scene pole, so check it explicitly).
    for (int k = 0; k < 24; k++) {
        for (int i = 0; i < rec.nt[k]; i++) {
            assert_true(rec.tg[k][i].az != 110 && rec.tg[k][i].az != 300);
        }
    }
    // Noise-free returns end in cliffs: no bound is coarse, sigma is the board's.
    for (int k = 0; k < 24; k++) {
        for (int i = 0; i < rec.nt[k]; i++) {
            assert_int_equal(rec.tg[k][i].flags & SL_TARGET_COARSE, 0);
        }
    }
    assert_true(pl.detect.stats.rejected[SL_DETECT_REJ_SHADOW] > 0);
    assert_int_equal(pl.proto.stats.resyncs, 0);
    assert_int_equal(pl.stats.azimuths, 24 * 400);
    assert_int_equal(pl.stats.azimuths_missing, 0);
}

// Decoded CAN frames against the targets and the tracker (E2E sequence, values, levels).
static void test_pipeline_can_frames_decode_to_the_targets(void **state)
{
    (void)state;
    ensure_static_stream();
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
    feed_stream(&g_static, 1448, 0);
    assert_int_equal(rec.rotations, 24);
    sl_can_e2e_rx_t rx[4];
    for (int i = 0; i < 4; i++) {
        sl_can_e2e_rx_init(&rx[i], SL_CAN_COUNTER_MODULO - 1U);
    }
    int pole_frames[MAXROT] = {0}, statuses = 0, warnings = 0, healths = 0, planes = 0;
    (void)planes;
    const int n = B->mask_frames, confirm = c.confirm_hits;
    for (int i = 0; i < rec.ncan; i++) {
        const sl_can_frame_t *f = &rec.can[i];
        const int k = rec.can_rot[i];
        if (f->id == B->can_id_pole_lean) {
            assert_true(e2e_accepted(sl_can_e2e_check(&rx[0], E2E(POLE_LEAN), f)));
            sl_can_pole_lean_t m;
            assert_int_equal(sl_can_decode_pole_lean(f, E2E(POLE_LEAN), &m), SL_OK);
            pole_frames[k]++;
            // The target of this rotation at that azimuth (0.2 deg LSB, az step 0.9 deg).
            const sl_target_t *t = NULL;
            for (int j = 0; j < rec.nt[k]; j++) {
                if (labs((long)rec.tg[k][j].az * 90 - (long)m.azimuth_cdeg) <= 20) {
                    t = &rec.tg[k][j];
                }
            }
            assert_non_null(t);
            // Ranges are rounded once (um -> 0.02 m): within half an LSB (10 mm).
            assert_true(labs((long)t->r1_um - (long)m.range_inner_um) <= 10000);
            assert_true(labs((long)t->r2_um - (long)m.range_outer_um) <= 10000);
            if (t->incline_flag == SL_INCLINE_VALID) {
                // Identical measurements every rotation: the filtered lean is the measurement.
                assert_int_equal(m.quality, SL_CAN_QUALITY_FILTERED);
                assert_true(labs((long)m.lean_cdeg - (long)t->alpha_cdeg) <= 5);
                assert_true(m.lean_sigma_cdeg > 0 && m.lean_sigma_cdeg <= 200);
            } else {
                assert_int_equal(m.quality, SL_CAN_QUALITY_AMBIGUOUS);
                assert_int_equal(m.lean_cdeg, 0);
            }
            assert_false(m.clamped);
        } else if (f->id == B->can_id_lean_warning) {
            assert_true(e2e_accepted(sl_can_e2e_check(&rx[1], E2E(LEAN_WARNING), f)));
            sl_can_lean_warning_t w;
            assert_int_equal(sl_can_decode_lean_warning(f, E2E(LEAN_WARNING), &w), SL_OK);
            warnings++;
            if (k < n - 1 + confirm - 1) {
                assert_false(w.has_target); // no confirmed track yet
                assert_int_equal(w.level, SL_CAN_LEVEL_NONE);
            } else if (k >= n - 1 + confirm + 2) {
                // The +10 deg pole (estimate >= 10.0 deg): DANGER after `confirm` updates.
                assert_true(w.has_target);
                assert_int_equal(w.level, SL_CAN_LEVEL_DANGER);
                assert_true(labs((long)w.azimuth_cdeg - 260L * 90L) <= 10);
                assert_true(w.lean_cdeg >= 1000 && w.lean_cdeg <= 1050);
                assert_int_equal(w.quality, SL_CAN_QUALITY_FILTERED);
                assert_int_equal(rec.level[k], SL_WARN_DANGER);
            }
        } else if (f->id == B->can_id_status) {
            assert_true(e2e_accepted(sl_can_e2e_check(&rx[2], E2E(STATUS), f)));
            sl_can_status_t st;
            assert_int_equal(sl_can_decode_status(f, E2E(STATUS), &st), SL_OK);
            statuses++;
            assert_int_equal(st.link_state, SL_CAN_LINK_STREAMING);
            assert_int_equal(st.rotations, (uint32_t)k + 1U);
            assert_int_equal(st.azimuths_missing, 0);
            assert_int_equal(st.decoder_resyncs, 0);
            assert_int_equal(st.can_dropped, 0);
        } else if (f->id == B->can_id_health) {
            assert_true(e2e_accepted(sl_can_e2e_check(&rx[3], E2E(HEALTH), f)));
            sl_can_health_t h;
            assert_int_equal(sl_can_decode_health(f, E2E(HEALTH), &h), SL_OK);
            healths++;
            assert_int_equal(h.fault, 0); // a clean stream raises no fault
            assert_int_equal(h.reconnects, 0);
            assert_int_equal(h.candidates_dropped, 0);
#if SL_CFG_GROUND
        } else if (f->id == B->can_id_ground_plane) {
            // One per rotation with the ground on (the default), before its Status.
            sl_can_ground_plane_t g;
            assert_int_equal(sl_can_decode_ground_plane(f, E2E(GROUND_PLANE), &g), SL_OK);
            assert_int_equal(g.counter, (unsigned)planes % SL_CAN_COUNTER_MODULO);
            assert_int_equal(statuses, planes);
            assert_true(g.quality <= SL_CAN_GROUND_GOOD);
            planes++;
        } else if (f->id == B->can_id_ground_hazard) {
            sl_can_ground_hazard_t h;
            assert_int_equal(sl_can_decode_ground_hazard(f, E2E(GROUND_HAZARD), &h), SL_OK);
            assert_true(h.kind == SL_CAN_GROUND_DROP || h.kind == SL_CAN_GROUND_STEP);
            assert_int_equal(statuses + 1, planes); // after its rotation's GroundPlane
#endif
        } else {
            fail_msg("frame with unexpected id 0x%x", (unsigned)f->id);
        }
    }
#if SL_CFG_GROUND
    assert_int_equal(planes, 24);
#endif
    assert_int_equal(healths, 24);
    assert_int_equal(statuses, 24);
    assert_int_equal(warnings, 24);
    for (int k = 0; k < 24; k++) {
        // PoleLean for the 4 tracks once confirmed (hits >= confirm), none before.
        assert_int_equal(pole_frames[k], k >= n - 1 + confirm - 1 ? 4 : 0);
    }
    for (int i = 0; i < 3; i++) {
        assert_int_equal(rx[i].stats.status[SL_CAN_E2E_OK_SOME_LOST], 0);
        assert_int_equal(rx[i].stats.crc_errors, 0);
    }
    assert_int_equal(pl.stats.can_dropped, 0);
    assert_int_equal(pl.stats.can_frames, rec.ncan);
}

#if !SL_CFG_GROUND
// The firmware configuration has no ground: GroundPlane and GroundHazard keep their names,
// Data IDs and the board's ids (a DBC of the host configuration describes the same bus),
// without a signal table; mode 11C stays refused for them (their layout has signals in
// bits 12..15). test_pipeline_can_frames_decode_to_the_targets fails on any frame of theirs.
static void test_pipeline_fw_ground_messages_keep_their_identity_only(void **state)
{
    (void)state;
    const sl_can_message_desc_t *gp = sl_can_layout(SL_CAN_MSG_GROUND_PLANE);
    const sl_can_message_desc_t *gh = sl_can_layout(SL_CAN_MSG_GROUND_HAZARD);
    assert_string_equal(gp->name, "GroundPlane");
    assert_string_equal(gh->name, "GroundHazard");
    assert_int_equal(gp->data_id, SL_CAN_DATA_ID_GROUND_PLANE);
    assert_int_equal(gp->n_signals, 0);
    assert_null(gh->signals);
    sl_can_ids_t ids;
    sl_can_ids_from_board(&ids, B);
    assert_int_equal(ids.id[SL_CAN_MSG_GROUND_PLANE], B->can_id_ground_plane);
    sl_can_tx_t tx;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_OK);
    ids.e2e[SL_CAN_MSG_GROUND_HAZARD].mode = SL_CAN_E2E_MODE_NIBBLE;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
}
#endif

// Lost azimuths (random and a burst over the 0 deg pole), junk bytes with partial
// signatures, duplicated and swapped messages, and a radar restart (cut mid-message,
// new Configuration, sweep counters from 0), fed in random chunks.
static void test_pipeline_survives_missing_azimuths_junk_duplicates_and_a_radar_restart(void **state)
{
    (void)state;
    scene_t s;
    make_scene(&s);
    sopt_t o = sopt_defaults();
    o.rotations = 34;
    o.drop_per_1000 = 20;
    o.junk_per_1000 = 25;
    o.dup_per_1000 = 10;
    o.swap_per_1000 = 10;
    o.burst_rot = 18;
    o.burst_az = 158;
    o.burst_len = 5;
    o.restart_rot = 24;
    stream_t st;
    st_init(&st, (size_t)o.rotations * 400U * (120U + o.bins) + 65536U);
    build(&st, &o, render_static_fn, &s);
    for (uint64_t seed = 0; seed < 3; seed++) {
        finish_at_cut = seed != 2; // seed 2: no EOF, the decoder swallows and resyncs
        rec_reset(0);
        const sl_pipeline_cfg_t c = cfg_for(B);
        assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
        feed_stream(&st, seed == 0 ? 65536 : 0, seed);
        // The restart (finish at the cut) completes the rotation before it early (flush);
        // the rotation count is unchanged.
        assert_int_equal(rec.rotations, o.rotations);
        assert_true(pl.proto.stats.resyncs > 0);
        assert_true(pl.stats.azimuths_missing > 0);
        assert_true(pl.scan.stats.duplicates > 0);
        assert_true(pl.scan.stats.out_of_order > 0);
        // With the EOF the new stream's Configuration is seen (a restart); without it the
        // cut message swallows it and the decoder resyncs on the next FFT message.
        if (pl.stats.restarts != (seed != 2 ? 1U : 0U) ||
            pl.proto.stats.configuration != (seed != 2 ? 2U : 1U)) {
            fail_msg("seed %u: restarts %u, configurations %u", (unsigned)seed,
                     pl.stats.restarts, pl.proto.stats.configuration);
        }
        int with_targets = 0;
        for (int k = 0; k < rec.rotations && k < MAXROT; k++) {
            for (int i = 0; i < rec.nt[k]; i++) {
                const sl_target_t *t = &rec.tg[k][i];
                const tpole_t *p = pole_near(&s, t->az);
                if (p == NULL || p->az == 110) {
                    fail_msg("seed %u rotation %d: spurious target az %u bins %u..%u",
                             (unsigned)seed, k, t->az, t->bin_first, t->bin_last);
                }
            }
            if (k >= 18 && k < 34) {
                // Missing rows are held by the mask: the poles stay (burst over pole 0 incl.).
                check_targets(&s, k);
                with_targets++;
            }
        }
        assert_int_equal(with_targets, 16);
        assert_int_equal(pl.proto.stats.truncated, seed != 2 ? 1 : 0);
    }
    finish_at_cut = true;
    st_free(&st);
}

// Broken returns (a gap) are rejected; an empty and a saturated rotation produce nothing
// and restart the consistency window; short (contoured) rows are zero-filled.
static void empty_sat_fn(void *ctx, int rot, uint32_t az, uint64_t t, uint8_t *row, uint32_t bins)
{
    (void)t;
    render_static(ctx, rot, az, row, bins);
}

static void test_pipeline_handles_broken_empty_and_saturated_scans(void **state)
{
    (void)state;
    scene_t s;
    make_scene(&s);
    s.p[4] = (tpole_t){200, 2.6, 5, 1, 3}; // a broken return (one empty bin inside)
    s.empty_rot = 20;
    s.saturated_rot = 21;
    sopt_t o = sopt_defaults();
    o.rotations = 40;
    stream_t st;
    st_init(&st, (size_t)o.rotations * 400U * (40U + o.bins) + 65536U);
    build(&st, &o, empty_sat_fn, &s);
    // A malformed FFT message (payload shorter than its fixed part) in the middle.
    uint8_t bad[22 + 10];
    assert_int_equal(sl_proto_encode_header(bad, sizeof bad, SL_PROTO_ID_FFT_DATA, 10), 22);
    memset(bad + 22, 0, 10);
    memmove(st.buf + st.rot_end[5] + sizeof bad, st.buf + st.rot_end[5], st.n - st.rot_end[5]);
    memcpy(st.buf + st.rot_end[5], bad, sizeof bad);
    st.n += sizeof bad;
    for (int r = 5; r < st.rots; r++) {
        st.rot_end[r] += sizeof bad;
    }
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    feed_stream(&st, 65536, 0);
    assert_int_equal(rec.rotations, 40);
    assert_int_equal(pl.scan.stats.malformed, 1);
    for (int k = 0; k < 40; k++) {
        // The pole bins are occupied in the saturated rotation 21 and after it: their run
        // restarts at 21, so they are stable again at 21 + 15 (free bins at 22 + 15).
        if ((k >= 15 && k < 20) || k >= 21 + 15) {
            check_targets(&s, k); // the broken pole at 200 is not among them
        } else if (rec.nt[k] != 0) {
            fail_msg("rotation %d: %d targets, first at az %u", k, rec.nt[k], rec.tg[k][0].az);
        }
    }
    assert_true(pl.detect.stats.rejected[SL_DETECT_REJ_BROKEN] > 0);
    st_free(&st);
}

// The same scene as 16-bit power (id 31) and as contoured short rows gives the same targets.
static void test_pipeline_16_bit_stream_gives_the_same_targets(void **state)
{
    (void)state;
    scene_t s;
    make_scene(&s);
    sopt_t o = sopt_defaults();
    o.bpb = 2;
    o.shift16 = 8;
    o.bins = 150; // shorter than the 160 masked bins: every row is short and zero-filled
    s.ground = false; // (the ground starts at bin 135, within 150: keep it simple)
    stream_t st;
    st_init(&st, (size_t)o.rotations * 400U * (40U + 2U * o.bins) + 65536U);
    build(&st, &o, render_static_fn, &s);
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    feed_stream(&st, 0, 3);
    assert_int_equal(rec.rotations, 20);
    for (int k = 15; k < 20; k++) {
        check_targets(&s, k);
    }
    assert_int_equal(pl.scan.stats.wide_azimuths, 20 * 400);
    assert_int_equal(pl.scan.stats.short_azimuths, 20 * 400);
    st_free(&st);
}

// Whole CTS350-X messages (3768 bins, 3.8 KB): truncated by the decoder, never rejected.
static void test_pipeline_truncates_full_length_messages_instead_of_rejecting_them(void **state)
{
    (void)state;
    scene_t s;
    make_scene(&s);
    sopt_t o = sopt_defaults();
    o.bins = 3768;
    o.rotations = 6;
    stream_t st;
    st_init(&st, (size_t)o.rotations * 400U * (40U + o.bins) + 65536U);
    build(&st, &o, render_static_fn, &s);
    rec_reset(0);
    sl_pipeline_cfg_t c = cfg_for(B);
    c.mask_frames = 4;
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    feed_stream(&st, 0, 5);
    assert_int_equal(rec.rotations, 6);
    for (int k = 3; k < 6; k++) {
        check_targets(&s, k);
    }
    assert_int_equal(pl.proto.stats.cut, 6 * 400);
    assert_int_equal(pl.proto.stats.too_big, 0);
    assert_int_equal(pl.proto.stats.bytes_skipped, 0);
    st_free(&st);
}

// can_tx returning SL_ERR_BUSY: counted as drops, reported in the Status frames, never stuck.
static void test_pipeline_counts_busy_can_frames_as_drops(void **state)
{
    (void)state;
    ensure_static_stream();
    rec_reset(4);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    feed_stream(&g_static, 65536, 0);
    assert_int_equal(rec.rotations, 24);
    assert_true(rec.busy > 10);
    assert_int_equal(pl.stats.can_dropped, (uint32_t)rec.busy);
    assert_int_equal(pl.stats.can_frames, (uint32_t)rec.ncan);
    assert_int_equal(rec.calls, rec.ncan + rec.busy);
    uint32_t last = 0;
    int statuses = 0;
    for (int i = 0; i < rec.ncan; i++) {
        if (rec.can[i].id == B->can_id_status) {
            sl_can_status_t st;
            assert_int_equal(sl_can_decode_status(&rec.can[i], E2E(STATUS), &st), SL_OK);
            assert_true(st.can_dropped >= last);
            last = st.can_dropped;
            statuses++;
        }
    }
    assert_true(statuses > 0 && last > 0);
}

// Status frames sent between rotations (sl_pipeline_send_status, the daemon's idle Status)
// share the rotations' E2E counter: the sequence has no jump and no repeat across both
// kinds (and across the modulo-15 wrap), and every frame carries the counters of its time.
static void test_pipeline_idle_status_frames_continue_the_e2e_sequence(void **state)
{
    (void)state;
    ensure_static_stream();
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_send_status(NULL, 0), SL_ERR_ARG);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    // Idle Status before any data: CONNECTING, all counters 0.
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_CONNECTING);
    assert_int_equal(sl_pipeline_send_status(&pl, 500000U), SL_OK);
    assert_int_equal(rec.ncan, 2); // Status, then Health
    assert_int_equal(rec.can[1].id, B->can_id_health);
    sl_can_status_t st;
    assert_int_equal(sl_can_decode_status(&rec.can[0], E2E(STATUS), &st), SL_OK);
    assert_int_equal(rec.can[0].id, B->can_id_status);
    assert_int_equal(st.link_state, SL_CAN_LINK_CONNECTING);
    assert_int_equal(st.rotations, 0);
    assert_int_equal(st.counter, 0);
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
    int idle = 1;
    size_t i = 0;
    for (int r = 0; r < g_static.rots; r++) {
        const uint64_t now = 1000000U + (uint64_t)r * 250000U;
        assert_int_equal(sl_pipeline_feed(&pl, g_static.buf + i, g_static.rot_end[r] - i, now),
                         SL_OK);
        i = g_static.rot_end[r];
        // One idle Status after every third rotation, two after every fifth.
        const int k = (r % 3 == 2 ? 1 : 0) + (r % 5 == 4 ? 2 : 0);
        for (int j = 0; j < k; j++) {
            if (r == 10) {
                sl_pipeline_set_link_state(&pl, SL_CAN_LINK_SILENT);
            }
            const int before = rec.ncan;
            assert_int_equal(sl_pipeline_send_status(&pl, now + 1000U), SL_OK);
            assert_int_equal(rec.ncan, before + 2);
            assert_int_equal(sl_can_decode_status(&rec.can[before], E2E(STATUS), &st), SL_OK);
            assert_int_equal(st.rotations, pl.stats.rotations);
            assert_int_equal(st.azimuths_missing, pl.stats.azimuths_missing);
            assert_int_equal(st.decoder_resyncs, pl.proto.stats.resyncs);
            assert_int_equal(st.can_dropped, 0);
            assert_int_equal(st.link_state, r == 10 ? SL_CAN_LINK_SILENT : SL_CAN_LINK_STREAMING);
            assert_false(st.saturated);
            idle++;
            if (r == 10) {
                sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
            }
        }
    }
    assert_int_equal(sl_pipeline_finish(&pl, 99000000U), SL_OK);
    assert_int_equal(rec.rotations, 24);
    sl_can_e2e_rx_t rx;
    sl_can_e2e_rx_init(&rx, SL_CAN_COUNTER_MODULO - 1U);
    int statuses = 0;
    uint32_t last_rot = 0;
    for (int j = 0; j < rec.ncan; j++) {
        if (rec.can[j].id != B->can_id_status) {
            continue;
        }
        assert_true(e2e_accepted(sl_can_e2e_check(&rx, E2E(STATUS), &rec.can[j])));
        assert_int_equal(sl_can_decode_status(&rec.can[j], E2E(STATUS), &st), SL_OK);
        assert_int_equal(st.counter, (uint8_t)(statuses % 15));
        assert_true(st.rotations >= last_rot);
        last_rot = st.rotations;
        statuses++;
    }
    assert_int_equal(statuses, 24 + idle);
    assert_true(statuses > 30); // wrapped modulo 15 twice
    assert_int_equal(rx.stats.status[SL_CAN_E2E_OK_SOME_LOST], 0);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_REPEATED], 0);
    assert_int_equal(last_rot, 24);
    assert_int_equal(pl.stats.can_frames, (uint32_t)rec.ncan);
    // A refused idle Status (and its Health) is a drop like any other frame, reported by
    // the next one.
    rec.busy_every = 1;
    rec.calls = 0;
    assert_int_equal(sl_pipeline_send_status(&pl, 99100000U), SL_OK);
    assert_int_equal(pl.stats.can_dropped, 2); // the Status and the Health frame
    rec.busy_every = 0;
    const int before = rec.ncan;
    assert_int_equal(sl_pipeline_send_status(&pl, 99200000U), SL_OK);
    assert_int_equal(sl_can_decode_status(&rec.can[before], E2E(STATUS), &st), SL_OK);
    assert_int_equal(st.can_dropped, 2);
    sl_can_health_t h;
    assert_int_equal(sl_can_decode_health(&rec.can[before + 1], E2E(HEALTH), &h), SL_OK);
    assert_true((h.fault & SL_CAN_FAULT_CAN_OUTPUT_ERRORS) != 0U);
    assert_true(e2e_accepted(sl_can_e2e_check(&rx, E2E(STATUS), &rec.can[before])));
    assert_int_equal(rx.stats.lost_frames, 1); // the refused frame used its counter value
}

// Drops the port noticed after can_tx accepted the frames: added (saturating) and carried
// by the next Status frame, together with can_tx refusals.
static void test_pipeline_adds_port_drops_saturating_into_the_next_status(void **state)
{
    (void)state;
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    sl_can_status_t st;
    sl_pipeline_add_can_dropped(&pl, 0);
    sl_pipeline_add_can_dropped(&pl, 7);
    assert_int_equal(pl.stats.can_dropped, 7);
    assert_int_equal(sl_pipeline_send_status(&pl, 1000U), SL_OK);
    assert_int_equal(sl_can_decode_status(&rec.can[0], E2E(STATUS), &st), SL_OK);
    assert_int_equal(st.can_dropped, 7);
    assert_false(st.saturated);
    // A refusal adds one per frame (Status and its Health).
    rec.busy_every = 1;
    assert_int_equal(sl_pipeline_send_status(&pl, 2000U), SL_OK);
    rec.busy_every = 0;
    assert_int_equal(pl.stats.can_dropped, 9); // Status and Health refused
    sl_pipeline_add_can_dropped(&pl, 299); // 308: above the 8-bit field
    assert_int_equal(sl_pipeline_send_status(&pl, 3000U), SL_OK);
    assert_int_equal(sl_can_decode_status(&rec.can[2], E2E(STATUS), &st), SL_OK);
    assert_int_equal(st.can_dropped, 255);
    assert_true(st.saturated);
    // The 32-bit total saturates instead of wrapping to a small number.
    sl_pipeline_add_can_dropped(&pl, UINT32_MAX - 310U); // 308 + that = UINT32_MAX - 2
    assert_int_equal(pl.stats.can_dropped, UINT32_MAX - 2U);
    sl_pipeline_add_can_dropped(&pl, 5);
    assert_int_equal(pl.stats.can_dropped, UINT32_MAX);
    sl_pipeline_add_can_dropped(&pl, UINT32_MAX);
    assert_int_equal(pl.stats.can_dropped, UINT32_MAX);
    assert_int_equal(sl_pipeline_send_status(&pl, 4000U), SL_OK);
    assert_int_equal(sl_can_decode_status(&rec.can[4], E2E(STATUS), &st), SL_OK);
    assert_int_equal(st.can_dropped, 255);
    assert_true(st.saturated);
}

// n_eff = clamp(floor(D / (v T + r_max |w| T)) + 1, min, n), integer arithmetic.
static void test_pipeline_window_follows_speed_and_yaw(void **state)
{
    (void)state;
    const uint32_t T = 250000, D = 43800, R = 6000000;
    assert_int_equal(sl_pipeline_window(16, 1, 0, 0, T, D, R), 16);
    assert_int_equal(sl_pipeline_window(16, 1, 10, 0, T, D, R), 16);     // 2.5 mm/rot: 18 -> 16
    assert_int_equal(sl_pipeline_window(16, 1, 50, 0, T, D, R), 4);      // 12.5 mm: 3.5 + 1
    assert_int_equal(sl_pipeline_window(16, 1, -100, 0, T, D, R), 2);    // reversing: |v|
    assert_int_equal(sl_pipeline_window(16, 1, 175, 0, T, D, R), 2);     // 43.75 mm: 1 + 1
    assert_int_equal(sl_pipeline_window(16, 1, 176, 0, T, D, R), 1);
    assert_int_equal(sl_pipeline_window(16, 1, 1500, 0, T, D, R), 1);
    assert_int_equal(sl_pipeline_window(16, 3, 1500, 0, T, D, R), 3);    // floor
    assert_int_equal(sl_pipeline_window(4, 8, 1500, 0, T, D, R), 4);     // floor > n
    // Yaw 0.1 deg/s: 0.025 deg/rot = 436 urad at 6 m = 2.62 mm -> 16 + 1 -> 16 (clamped).
    assert_int_equal(sl_pipeline_window(16, 1, 0, 10, T, D, R), 16);
    // Yaw 1 deg/s: 4363 urad -> 26.2 mm -> 43.8 / 26.2 = 1 + 1 = 2.
    assert_int_equal(sl_pipeline_window(16, 1, 0, -100, T, D, R), 2);
    assert_int_equal(sl_pipeline_window(16, 1, 0, 1000, T, D, R), 1);
    assert_int_equal(sl_pipeline_window(16, 1, INT32_MIN, INT32_MIN, UINT32_MAX, D, R), 1);
    // Against a double reference over a grid.
    for (int32_t v = 0; v <= 400; v += 7) {
        for (int32_t w = 0; w <= 300; w += 13) {
            const double disp = ceil(v * (double)T / 1000.0) +
                                ceil(R * ceil(w * (double)T * 355.0 / (113.0 * 18000.0)) / 1e6);
            int want = disp == 0 ? 16 : (int)floor(D / disp) + 1;
            want = want > 16 ? 16 : want < 1 ? 1 : want;
            assert_int_equal(sl_pipeline_window(16, 1, v, w, T, D, R), want);
        }
    }
}

static sl_can_frame_t motion_frame(sl_can_tx_t *tx, int32_t speed, int32_t yaw)
{
    const sl_can_vehicle_motion_t m = {.speed_mm_s = speed, .yaw_rate_cdeg_s = yaw,
                                       .speed_valid = true, .yaw_rate_valid = true};
    sl_can_frame_t f;
    assert_int_equal(sl_can_encode_vehicle_motion(tx, &m, &f), SL_OK);
    return f;
}

// VehicleMotion over CAN (E2E-checked) and the direct setter set the window per rotation;
// stale motion falls back to the board's n; stopping restores n without losing history.
static void test_pipeline_takes_motion_from_can_and_the_setter(void **state)
{
    (void)state;
    ensure_static_stream();
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    sl_can_ids_t ids;
    sl_can_ids_from_board(&ids, B);
    sl_can_tx_t vtx;
    assert_int_equal(sl_can_tx_init(&vtx, &ids), SL_OK);
    size_t i = 0;
    for (int r = 0; r < g_static.rots; r++) {
        const uint64_t now = 1000000U + (uint64_t)r * 250000U;
        if (r == 2) {
            // The first frame only synchronises the E2E sequence (its value is not used);
            // the next one, a bus cycle later, continues it and is used.
            sl_can_frame_t f = motion_frame(&vtx, 3000, 0);
            assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now - 20000U), SL_OK);
            assert_int_equal(pl.motion_rx.e2e.stats.status[SL_CAN_E2E_INITIAL], 1);
            f = motion_frame(&vtx, 50, 0); // 5 cm/s: n_eff 4
            assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_OK);
            f.data[3] ^= 1U; // corrupted: rejected by the CRC
            assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_ERR_MALFORMED);
            f = motion_frame(&vtx, 50, 0);
            f.id = 0x123; // another id: ignored
            assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_ERR_ARG);
        }
        if (r == 3) {
            sl_can_frame_t f = motion_frame(&vtx, 50, 0);
            assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_OK);
        }
        if (r == 5) {
            sl_pipeline_set_motion(&pl, 3000, true, 0, false, now); // 3 m/s: n_eff 1
        }
        if (r == 6) {
            sl_pipeline_set_motion(&pl, 0, true, 0, true, now); // stopped: n
        }
        // r >= 7: no fresh input; the setter's value ages out after 500 ms (r >= 9).
        const uint64_t feed_now = now + 1000U;
        assert_int_equal(sl_pipeline_feed(&pl, g_static.buf + i, g_static.rot_end[r] - i, feed_now),
                         SL_OK);
        i = g_static.rot_end[r];
    }
    assert_int_equal(sl_pipeline_finish(&pl, 99000000U), SL_OK);
    // frames_eff of rotation r is chosen when its first row arrives, i.e. during the feed of
    // rotation r's bytes (the config + row 0 of rotation 0 come in feed 0).
    static const uint8_t want[10] = {16, 16, 4, 4, 4, 1, 16, 16, 16, 16};
    for (int k = 0; k < 10; k++) {
        assert_int_equal(rec.frames_eff[k], want[k]);
    }
    assert_int_equal(pl.stats.motion_accepted, 3);   // CAN frames only (one synchronising)
    assert_int_equal(pl.stats.motion_set_calls, 2);  // the two setter calls
    assert_int_equal(pl.stats.motion_rejected, 1);
    assert_int_equal(pl.motion_rx.stats.other_ids, 1);
    // A shorter window during rotations 2..5 does not lose history: the static poles are
    // stable again at n (16 equal rows) with no extra delay.
    check_targets(&g_scene, 15);
    // n_eff 1 at rotation 5 (3 m/s): every occupied run counts, including the transient
    // at azimuth 300 (odd rotations): the limit of single-frame detection while moving.
    assert_int_equal(rec.nt[5], 5);
    assert_int_equal(rec.nt[4], 4);
}

/// The Fault of the Health frame (after its Status) the pipeline sends at `now`.
static uint16_t health_fault(uint64_t now)
{
    assert_int_equal(sl_pipeline_send_status(&pl, now), SL_OK);
    sl_can_health_t h;
    assert_int_equal(sl_can_decode_health(&rec.can[rec.ncan - 1], E2E(HEALTH), &h), SL_OK);
    return h.fault;
}

// Health reports VehicleMotion frames the E2E check rejected (MOTION_E2E) in the Health
// frame after them, and only there: a repetition, a jump beyond the board's max delta
// counter and a corrupted CRC each set the bit; frames in sequence do not.
static void test_pipeline_reports_motion_e2e_rejections_on_health(void **state)
{
    (void)state;
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    sl_can_ids_t ids;
    sl_can_ids_from_board(&ids, B);
    sl_can_tx_t vtx;
    assert_int_equal(sl_can_tx_init(&vtx, &ids), SL_OK);
    assert_int_equal(pl.motion_rx.e2e.max_delta_counter, B->can_max_delta_counter_motion);
    uint64_t now = 1000000U;
    sl_can_frame_t f = motion_frame(&vtx, 50, 0);
    assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_OK); // INITIAL
    now += 20000U;
    f = motion_frame(&vtx, 50, 0);
    assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_OK); // OK
    assert_int_equal(health_fault(now) & SL_CAN_FAULT_MOTION_E2E, 0);
    assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now + 1000U), SL_ERR_STATE); // REPEATED
    assert_int_equal(health_fault(now) & SL_CAN_FAULT_MOTION_E2E, SL_CAN_FAULT_MOTION_E2E);
    now += 20000U;
    f = motion_frame(&vtx, 50, 0);
    assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_OK); // OK
    assert_int_equal(health_fault(now) & SL_CAN_FAULT_MOTION_E2E, 0);
    for (unsigned k = 0; k < B->can_max_delta_counter_motion; k++) {
        (void)motion_frame(&vtx, 50, 0); // lost on the bus
    }
    now += 20000U;
    f = motion_frame(&vtx, 50, 0);
    assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_ERR_STATE); // WRONG_SEQUENCE
    assert_int_equal(health_fault(now) & SL_CAN_FAULT_MOTION_E2E, SL_CAN_FAULT_MOTION_E2E);
    now += 20000U;
    f = motion_frame(&vtx, 50, 0);
    f.data[0] ^= 0x5AU;
    assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_ERR_MALFORMED); // ERROR
    assert_int_equal(health_fault(now) & SL_CAN_FAULT_MOTION_E2E, SL_CAN_FAULT_MOTION_E2E);
    assert_int_equal(health_fault(now) & SL_CAN_FAULT_MOTION_E2E, 0);
    const uint32_t *n = pl.motion_rx.e2e.stats.status;
    assert_int_equal(n[SL_CAN_E2E_REPEATED] + n[SL_CAN_E2E_WRONG_SEQUENCE] + n[SL_CAN_E2E_ERROR], 3);
    assert_int_equal(pl.stats.motion_rejected, 3);
}

// ---------------------------------------------------------------------------- drive-by

// The vehicle drives along +y (forward) at `v` m/s; a pole stands 2.8 m to the right,
// leaning 10 deg towards the path. Each azimuth message is rendered at its own time: the
// pole's azimuth (clockwise from forward = encoder zero on paper-sim), distance and in-plane
// inclination alpha = atan2(sin(psi) x / d, cos(psi)) change along the pass.
typedef struct drive {
    double v, x, psi_deg, y0;
    uint64_t t0_us;
    bool noise;
} drive_t;

static void drive_pose(const drive_t *dv, uint64_t t_us, double *az_idx, double *d, double *alpha)
{
    const double yv = dv->y0 + dv->v * (double)(t_us - dv->t0_us) * 1e-6;
    const double fwd = 0.0 - yv, right = dv->x;
    *d = sqrt(fwd * fwd + right * right);
    double az = atan2(right, fwd) / DEG; // clockwise from forward
    if (az < 0) {
        az += 360;
    }
    *az_idx = az / 0.9;
    const double psi = dv->psi_deg * DEG;
    *alpha = atan2(sin(psi) * right / *d, cos(psi)) / DEG;
}

static void drive_fn(void *ctx, int rot, uint32_t az, uint64_t t, uint8_t *row, uint32_t bins)
{
    const drive_t *dv = ctx;
    for (uint32_t k = 0; k < bins; k++) {
        row[k] = dv->noise ? (uint8_t)(rnd() & 31U) : 0U;
    }
    for (uint32_t k = 0; k < 36 && k < bins; k++) {
        row[k] = 120;
    }
    for (uint32_t k = ground_first_bin(az); k < bins; k++) {
        row[k] = (uint8_t)(60 + (rnd() & 15U));
    }
    // The beam passes the pole once per rotation: its 3-azimuth window is centred on the
    // pole's azimuth at that moment (fixed within the rotation: a slender pole's return is
    // 3 azimuths wide, so the width-based radius estimate stays 0).
    double ai, d, alpha;
    drive_pose(dv, msg_time_us((uint32_t)rot * 400U), &ai, &d, &alpha);
    drive_pose(dv, msg_time_us((uint32_t)rot * 400U + (uint32_t)lround(ai)), &ai, &d, &alpha);
    const long centre = lround(ai);
    drive_pose(dv, t, &ai, &d, &alpha);
    if (labs((long)az - centre) <= 1) {
        draw_pole(row, bins, d, alpha, az, 0);
    }
}

typedef struct drive_result {
    int detections;      // rotations with a target at the pole
    int valid;           // ... with a valid alpha
    double mean_err, max_err;
    int spurious;        // targets away from the pole
    int first_rot;       // first rotation with a detection (-1: none)
    int confirmed_frames; // PoleLean frames sent
    int profiled;        // valid targets refined from the range profile (one rotation's
                         // rows of neighbouring azimuths while moving)
} drive_result_t;

static drive_result_t run_drive(double v, bool motion, bool via_can, int drop_per_1000)
{
    drive_t dv = {.v = v, .x = 2.8, .psi_deg = 10, .y0 = -6.0, .t0_us = msg_time_us(0),
                  .noise = true};
    const int rots = (int)ceil(12.0 / v / 0.25); // 12 m of travel
    sopt_t o = sopt_defaults();
    o.rotations = rots < 120 ? rots : 120;
    o.drop_per_1000 = drop_per_1000;
    stream_t st;
    st_init(&st, (size_t)o.rotations * 400U * (40U + o.bins) + 65536U);
    build(&st, &o, drive_fn, &dv);
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    sl_can_ids_t ids;
    sl_can_ids_from_board(&ids, B);
    sl_can_tx_t vtx;
    assert_int_equal(sl_can_tx_init(&vtx, &ids), SL_OK);
    size_t i = 0;
    for (int r = 0; r < st.rots; r++) {
        const uint64_t now = 1000000U + (uint64_t)r * 250000U;
        if (motion && via_can) {
            const sl_can_frame_t f = motion_frame(&vtx, (int32_t)lround(v * 1000), 0);
            assert_int_equal(sl_pipeline_on_can_rx(&pl, &f, now), SL_OK);
        } else if (motion) {
            sl_pipeline_set_motion(&pl, (int32_t)lround(v * 1000), true, 0, true, now);
        }
        assert_int_equal(sl_pipeline_feed(&pl, st.buf + i, st.rot_end[r] - i, now + 1000U), SL_OK);
        i = st.rot_end[r];
    }
    assert_int_equal(sl_pipeline_finish(&pl, 1000000U + (uint64_t)st.rots * 250000U), SL_OK);
    drive_result_t res = {0, 0, 0, 0, 0, -1, 0, 0};
    double sum = 0;
    for (int k = 0; k < rec.rotations && k < MAXROT; k++) {
        for (int j = 0; j < rec.nt[k]; j++) {
            const sl_target_t *t = &rec.tg[k][j];
            // Truth at the time the representative azimuth was swept: message k*400 + az.
            double ai, d, alpha;
            drive_pose(&dv, msg_time_us((uint32_t)k * 400U + t->az), &ai, &d, &alpha);
            if (fabs(ai - t->az) > 2.0) {
                res.spurious++;
                continue;
            }
            res.detections++;
            if (res.first_rot < 0) {
                res.first_rot = k;
            }
            if (t->incline_flag != SL_INCLINE_VALID) {
                continue;
            }
            int flag;
            const bool prof = (t->flags & SL_TARGET_PROFILE) != 0U;
            res.profiled += prof ? 1 : 0;
            const double pred = predicted_alpha(d, alpha, t->az, prof, &flag);
            const double got = t->alpha_cdeg / 100.0;
            if (flag == 0 && fabs(got - pred) > 0.05) {
                fail_msg("drive-by rotation %d az %u: alpha %.2f, oracle from the bins %.3f "
                         "(bins %u..%u, az_count %u, radius %u um, r1 %u r2 %u, d %.3f)", k,
                         t->az, got, pred, t->bin_first, t->bin_last, t->az_count,
                         t->radius_um, t->r1_um, t->r2_um, d);
            }
            res.valid++;
            sum += got - alpha;
            if (fabs(got - alpha) > res.max_err) {
                res.max_err = fabs(got - alpha);
            }
        }
    }
    res.mean_err = res.valid > 0 ? sum / res.valid : 0;
    for (int j = 0; j < rec.ncan; j++) {
        if (rec.can[j].id == B->can_id_pole_lean) {
            res.confirmed_frames++;
        }
    }
    st_free(&st);
    return res;
}

static void test_pipeline_drive_by_detects_the_pole_only_with_motion_input(void **state)
{
    (void)state;
    static const double speeds[] = {1.0, 2.0, 3.0};
    for (size_t s = 0; s < 3; s++) {
        const double v = speeds[s];
        const drive_result_t with = run_drive(v, true, s != 1, s == 2 ? 30 : 0);
        const drive_result_t without = run_drive(v, false, false, 0);
        // The pole is inside the shadow for ~7 m of the 12 m pass.
        const int inside = (int)(7.0 / v / 0.25);
        if (with.valid < inside / 2 || fabs(with.mean_err) > 0.5 || with.max_err > 3.0 ||
            with.spurious != 0 || with.confirmed_frames < 3) {
            fail_msg("v = %.1f m/s with motion: %d detections (%d valid, expected ~%d), mean "
                     "error %.3f deg, max %.2f, spurious %d, PoleLean frames %d",
                     v, with.detections, with.valid, inside, with.mean_err, with.max_err,
                     with.spurious, with.confirmed_frames);
        }
        // Without motion input the fixed n = 16 window never sees the moving return stable.
        if (without.detections != 0 || without.confirmed_frames != 0) {
            fail_msg("v = %.1f m/s without motion: %d detections, first at rotation %d", v,
                     without.detections, without.first_rot);
        }
        printf("drive-by %.1f m/s: %d rotations with the pole (%d valid), mean alpha error "
               "%+.3f deg, max %.2f deg, %d PoleLean frames, %d from the profile; without "
               "motion input: %d\n",
               v, with.detections, with.valid, with.mean_err, with.max_err,
               with.confirmed_frames, with.profiled, without.detections);
    }
}

// ---------------------------------------------------------------------------- init checks

// Slot overflow (issue 18): 20 static returns that pass every rejection test (6 bins, one
// azimuth each, a valid rho) at the LOWEST azimuths, then two poles at higher azimuths: 22
// targets for the board's 16 slots every rotation. The poles keep their slots (evidence, not
// azimuth order) and are sent as PoleLean; the drops are counted on CAN: Health's
// CandidatesDropped grows by 6 per rotation and its Fault has TARGET_SLOTS_OVERFLOW.
static void overflow_fn(void *ctx, int rot, uint32_t az, uint64_t t, uint8_t *row, uint32_t bins)
{
    (void)t;
    render_static(ctx, rot, az, row, bins);
    if (az >= 10U && az < 90U && (az - 10U) % 4U == 0U) {
        for (uint32_t k = 110; k <= 115 && k < bins; k++) {
            row[k] = 90;
        }
    }
}

// Smear tails across the shadow edge (sl_detect.h stage 1, TAIL_EDGE): a pole at azimuth
// 100 whose own bins end 3 bins inside the edge, with a tail falling 3 values per bin that
// reaches 20 bins past it, is kept (the d(S) rule alone, which paper-sim has as d = 0,
// rejects it SHADOW), with its r2 from the profile inside the shadow; a pole at azimuth 200
// whose own bins (falling 1 value per bin) end 2 bins BEYOND the edge, followed by the same
// tail, passes the run-level tail rule but is rejected SHADOW on its refined r2.
static uint32_t g_edge_bin;
static int edge_level(uint32_t k, uint32_t k1, uint32_t k2, int own0, int own_step)
{
    if (k < k1) {
        return 0;
    }
    const int last_own = own0 - own_step * (int)(k2 - k1);
    if (k <= k2) {
        return own0 - own_step * (int)(k - k1);
    }
    return last_own - 3 * (int)(k - k2);
}

static void edge_fn(void *ctx, int rot, uint32_t az, uint64_t t, uint8_t *row, uint32_t bins)
{
    (void)ctx;
    (void)rot;
    (void)t;
    memset(row, 0, bins);
    const uint32_t e = g_edge_bin;
    for (uint32_t k = 0; k < bins; k++) {
        int v = 0;
        if (az >= 99U && az <= 101U) {
            v = edge_level(k, e - 12U, e - 4U, 110, 0); // own end inside the window
        } else if (az >= 199U && az <= 201U) {
            v = edge_level(k, e - 10U, e + 2U, 110, 1); // own end beyond the edge
        }
        row[k] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
    }
}

static void test_pipeline_smear_tail_across_the_shadow_edge(void **state)
{
    (void)state;
    g_edge_bin = ground_first_bin(100); // the window end: first bin at or beyond S
    assert_int_equal(ground_first_bin(200), g_edge_bin);
    stream_t st;
    st_init(&st, 24u << 20);
    sopt_t o = sopt_defaults();
    o.rotations = 20;
    build(&st, &o, edge_fn, NULL);
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    feed_stream(&st, 65536, 0);
    st_free(&st);
    assert_int_equal(rec.rotations, 20);
    const int first = B->mask_frames - 1;
    for (int k = first; k < 20; k++) {
        assert_int_equal(rec.nt[k], 1);
        const sl_target_t *t = &rec.tg[k][0];
        assert_true(t->az >= 99U && t->az <= 101U);
        assert_true((t->flags & SL_TARGET_TAIL_EDGE) != 0U);
        if (k > first) { // the profile has >= 2 rows from the second rotation on
            assert_true((t->flags & SL_TARGET_PROFILE) != 0U);
            assert_int_equal(t->r2_um, (uint32_t)(((2ULL * (g_edge_bin - 4U) + 1U) * B->bin_size_um + 1U) / 2U));
            assert_true(t->r2_um < t->shadow_slant_um);
            // r2 ends a walk over the smear tail: known to two bins (sl_profile.h,
            // "Uncertainty of the bounds"); r1, summed over rotations, to the board's sigma.
            assert_true((t->flags & SL_TARGET_COARSE) != 0U);
            const uint32_t s2 = sl_profile_coarse_sigma_um(B->bin_size_um);
            assert_true(s2 > B->range_sigma_um);
            const uint32_t sr = sl_incline_bounds_sigma_um(t->r1_um, t->r2_um, B->range_sigma_um, s2);
            const sl_incline_result_t two = sl_incline_estimate(
                t->r1_um, t->r2_um, &B->geom[t->az], sr, B->theta_sigma_cdeg);
            const sl_incline_result_t one = sl_incline_estimate(
                t->r1_um, t->r2_um, &B->geom[t->az], B->range_sigma_um, B->theta_sigma_cdeg);
            assert_int_equal(t->incline_flag, SL_INCLINE_VALID);
            assert_int_equal(t->alpha_cdeg, one.alpha_cdeg); // the value is not changed
            assert_int_equal(t->sigma_cdeg, two.sigma_cdeg);
            assert_true(two.sigma_cdeg > one.sigma_cdeg + one.sigma_cdeg / 2U);
        }
    }
    // The pole beyond the edge: rejected SHADOW every rotation from the first.
    assert_true(pl.detect.stats.rejected[SL_DETECT_REJ_SHADOW] >= (uint32_t)(20 - first));
    assert_true(pl.prof.stats.extracted >= (uint32_t)(20 - first - 1));
}

// A board whose d(S) overcorrects (0.5 m on paper-sim's geometry) and steep tails (10
// values per bin) that end before the d(S) edge: detection alone keeps the pole whose own
// bins end 2 bins beyond the shadow edge (r2 - d is inside); the profile's own r2 rejects
// it SHADOW, while the pole whose own bins end inside stays, with its own r2.
static int g_edge_tail_step = 3;
static void edge_steep_fn(void *ctx, int rot, uint32_t az, uint64_t t, uint8_t *row,
                          uint32_t bins)
{
    (void)ctx;
    (void)rot;
    (void)t;
    memset(row, 0, bins);
    const uint32_t e = g_edge_bin;
    for (uint32_t k = 0; k < bins; k++) {
        int v = 0;
        const uint32_t k1 = az >= 199U && az <= 201U ? e - 10U : e - 12U;
        const uint32_t k2 = az >= 199U && az <= 201U ? e + 2U : e - 4U;
        if ((az >= 99U && az <= 101U) || (az >= 199U && az <= 201U)) {
            if (k >= k1 && k <= k2) {
                v = 110 - (int)(k - k1);
            } else if (k > k2) {
                v = 110 - (int)(k2 - k1) - g_edge_tail_step * (int)(k - k2);
            }
        }
        row[k] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
    }
}

static sl_board_t g_board_d;
static void test_pipeline_overcorrecting_d_does_not_let_a_base_beyond_the_edge_through(void **state)
{
    (void)state;
    g_board_d = *B;
    g_board_d.elong_points = 1;
    g_board_d.elong_range_um[0] = 5000000U;
    g_board_d.elong_d_um[0] = 500000; // 0.5 m: 11.4 bins
    g_edge_bin = ground_first_bin(100);
    g_edge_tail_step = 10;
    stream_t st;
    st_init(&st, 24u << 20);
    sopt_t o = sopt_defaults();
    o.rotations = 20;
    build(&st, &o, edge_steep_fn, NULL);
    const int first = B->mask_frames - 1;
    // Without range profiles, detection's r2 - d keeps both poles.
    rec_reset(0);
    sl_pipeline_cfg_t c = cfg_for(&g_board_d);
    c.profile = false;
    assert_int_equal(sl_pipeline_init(&pl, &g_board_d, &c), SL_OK);
    feed_stream(&st, 65536, 0);
    for (int k = first; k < 20; k++) {
        assert_int_equal(rec.nt[k], 2);
    }
    // With them (the default), the profile's own r2 decides.
    rec_reset(0);
    c = cfg_for(&g_board_d);
    assert_int_equal(sl_pipeline_init(&pl, &g_board_d, &c), SL_OK);
    feed_stream(&st, 65536, 0);
    st_free(&st);
    for (int k = first; k < 20; k++) {
        assert_int_equal(rec.nt[k], 1);
        const sl_target_t *t = &rec.tg[k][0];
        assert_true(t->az >= 99U && t->az <= 101U);
        assert_true((t->flags & SL_TARGET_PROFILE) != 0U);
        assert_int_equal(t->flags & SL_TARGET_TAIL_EDGE, 0);
        assert_int_equal(t->r2_um, (uint32_t)(((2ULL * (g_edge_bin - 4U) + 1U) * B->bin_size_um + 1U) / 2U));
    }
    assert_int_equal(pl.detect.stats.rejected[SL_DETECT_REJ_SHADOW], (uint32_t)(20 - first));
}

static void test_pipeline_slot_overflow_keeps_the_poles_and_is_counted_on_can(void **state)
{
    (void)state;
    scene_t sc;
    scene_defaults(&sc);
    sc.flicker = false;
    sc.p[0] = (tpole_t){300, 3.0, 0.0, 2, 0};
    sc.p[1] = (tpole_t){350, 3.1, 10.0, 2, 0};
    sc.np = 2;
    stream_t st;
    st_init(&st, 24u << 20);
    sopt_t o = sopt_defaults();
    o.rotations = 20;
    build(&st, &o, overflow_fn, &sc);
    rec_reset(0);
    const sl_pipeline_cfg_t c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    assert_int_equal(B->max_targets, 16);
    feed_stream(&st, 65536, 0);
    st_free(&st);
    assert_int_equal(rec.rotations, 20);
    const int first = B->mask_frames - 1; // first rotation with stable returns
    for (int k = first; k < 20; k++) {
        assert_int_equal(rec.nt[k], 16);
    }
    assert_int_equal(pl.detect.stats.target_overflow, (uint32_t)(6 * (20 - first)));
    // The last rotation's targets include both poles.
    const sl_target_t *tg = pl.detect.targets;
    int poles = 0;
    for (int i = 0; i < pl.detect.n_targets; i++) {
        poles += (tg[i].az >= 298 && tg[i].az <= 302) || (tg[i].az >= 348 && tg[i].az <= 352);
    }
    assert_int_equal(pl.detect.n_targets, 16);
    assert_int_equal(poles, 2);
    // CAN: PoleLean at both poles in the last rotation; Health after every Status.
    bool seen300 = false, seen350 = false;
    int n_health = 0, n_status = 0;
    sl_can_health_t last_h;
    memset(&last_h, 0, sizeof last_h);
    sl_can_e2e_rx_t rxh;
    sl_can_e2e_rx_init(&rxh, SL_CAN_COUNTER_MODULO - 1U);
    for (int i = 0; i < rec.ncan; i++) {
        const sl_can_frame_t *f = &rec.can[i];
        if (f->id == B->can_id_status) {
            n_status++;
            assert_true(i + 1 < rec.ncan);
            assert_int_equal(rec.can[i + 1].id, B->can_id_health);
        } else if (f->id == B->can_id_health) {
            n_health++;
            assert_true(e2e_accepted(sl_can_e2e_check(&rxh, E2E(HEALTH), f)));
            assert_int_equal(sl_can_decode_health(f, E2E(HEALTH), &last_h), SL_OK);
            const int k = rec.can_rot[i];
            const bool overflow = k >= first;
            assert_int_equal((last_h.fault & SL_CAN_FAULT_TARGET_SLOTS_OVERFLOW) != 0, overflow);
            assert_int_equal(last_h.candidates_dropped, overflow ? (uint32_t)(6 * (k - first + 1)) : 0U);
        } else if (f->id == B->can_id_pole_lean && rec.can_rot[i] == 19) {
            sl_can_pole_lean_t pl_f;
            assert_int_equal(sl_can_decode_pole_lean(f, E2E(POLE_LEAN), &pl_f), SL_OK);
            const int32_t az = pl_f.azimuth_cdeg - B->radar_yaw_cdeg;
            seen300 |= az >= 26800 && az <= 27200;
            seen350 |= az >= 31300 && az <= 31700;
        }
    }
    assert_true(n_status >= 20);
    assert_int_equal(n_health, n_status);
    assert_true(seen300 && seen350);
    assert_int_equal(last_h.candidates_dropped, 6 * (20 - first));
}

static void test_pipeline_rejects_boards_that_need_more_mask_bins(void **state)
{
    (void)state;
    // paper-sim with a 3x larger ground shadow: detection then reads ~400 bins.
    static sl_board_t big;
    static uint32_t shadow[400];
    big = *B;
    for (int a = 0; a < 400; a++) {
        shadow[a] = B->shadow_um[a] * 3U;
    }
    big.shadow_um = shadow;
    sl_pipeline_cfg_t c = cfg_for(&big);
    static sl_detect_t det;
    assert_int_equal(sl_detect_init(&det, &big, NULL), SL_OK);
    const uint32_t need = ((uint32_t)sl_detect_bins_needed(&det) + 31U) & ~31U;
    assert_true(need > 320 && need <= 512);
    const sl_err_t e = sl_pipeline_init(&pl, &big, &c);
    if (need > SL_CFG_MASK_BINS) { // firmware configuration (test_pipeline_fw)
        assert_int_equal(e, SL_ERR_RANGE);
        assert_int_equal(pl.reason, SL_PIPELINE_MASK_BINS);
        assert_non_null(pl.last_err_msg);
        assert_non_null(strstr(pl.last_err_msg, "SL_CFG_MASK_BINS"));
        assert_int_equal(sl_pipeline_feed(&pl, (const uint8_t *)"x", 1, 0), SL_ERR_ARG);
    } else {
        assert_int_equal(e, SL_OK);
        assert_int_equal(pl.mask_bins, need);
    }
    // Bad arguments.
    assert_int_equal(sl_pipeline_init(NULL, B, &c), SL_ERR_ARG);
    assert_int_equal(sl_pipeline_init(&pl, NULL, &c), SL_ERR_ARG);
    c = cfg_for(B);
    c.mask_frames = SL_CFG_MASK_FRAMES_MAX + 1;
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_ERR_RANGE);
    assert_int_equal(pl.reason, SL_PIPELINE_MASK_FRAMES);
    c = cfg_for(B);
    c.pow16_shift = 16;
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_ERR_ARG);
    // A radar whose configuration does not match the board: rows dropped, counted.
    assert_int_equal(sl_pipeline_init(&pl, B, NULL), SL_OK);
    stream_t st;
    st_init(&st, 400U * 500U * 3U);
    st_config(&st, 360, 400);
    static uint8_t row[400];
    memset(row, 200, sizeof row);
    for (uint32_t a = 0; a < 400; a++) {
        st_fft(&st, a, row, 400, 1, 8);
    }
    st_config(&st, 400, 400); // the radar is reconfigured to the board's geometry
    for (int r = 0; r < 2; r++) {
        for (uint32_t a = 0; a < 400; a++) {
            st_fft(&st, a, row, 400, 1, 8);
        }
    }
    rec_reset(0);
    c = cfg_for(B);
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
    assert_int_equal(sl_pipeline_feed(&pl, st.buf, st.n, 0), SL_OK);
    assert_int_equal(sl_pipeline_finish(&pl, 0), SL_OK);
    assert_int_equal(pl.stats.geometry_rejected, 1);
    assert_int_equal(pl.stats.rows_dropped, 400);
    assert_int_equal(pl.stats.azimuths, 800);
    assert_int_equal(pl.last_err, SL_ERR_RANGE);
    assert_non_null(pl.last_err_msg);
    st_free(&st);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pipeline_detects_poles_at_minus10_0_plus10_deg_after_n_rotations),
        cmocka_unit_test(test_pipeline_can_frames_decode_to_the_targets),
#if !SL_CFG_GROUND
        cmocka_unit_test(test_pipeline_fw_ground_messages_keep_their_identity_only),
#endif
        cmocka_unit_test(test_pipeline_survives_missing_azimuths_junk_duplicates_and_a_radar_restart),
        cmocka_unit_test(test_pipeline_handles_broken_empty_and_saturated_scans),
        cmocka_unit_test(test_pipeline_16_bit_stream_gives_the_same_targets),
        cmocka_unit_test(test_pipeline_truncates_full_length_messages_instead_of_rejecting_them),
        cmocka_unit_test(test_pipeline_counts_busy_can_frames_as_drops),
        cmocka_unit_test(test_pipeline_idle_status_frames_continue_the_e2e_sequence),
        cmocka_unit_test(test_pipeline_adds_port_drops_saturating_into_the_next_status),
        cmocka_unit_test(test_pipeline_window_follows_speed_and_yaw),
        cmocka_unit_test(test_pipeline_reports_motion_e2e_rejections_on_health),
        cmocka_unit_test(test_pipeline_takes_motion_from_can_and_the_setter),
        cmocka_unit_test(test_pipeline_drive_by_detects_the_pole_only_with_motion_input),
        cmocka_unit_test(test_pipeline_rejects_boards_that_need_more_mask_bins),
        cmocka_unit_test(test_pipeline_slot_overflow_keeps_the_poles_and_is_counted_on_can),
        cmocka_unit_test(test_pipeline_smear_tail_across_the_shadow_edge),
        cmocka_unit_test(test_pipeline_overcorrecting_d_does_not_let_a_base_beyond_the_edge_through),
    };
    const int rc = cmocka_run_group_tests(tests, setup, NULL);
    st_free(&g_static);
    free(rec.can);
    return rc;
}
