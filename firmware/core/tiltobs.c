// SPDX-License-Identifier: MIT
/// @file tiltobs.c
/// @brief Per-track observation rings, odometry and the per-rotation tilt fits (sl_tiltobs.h).
#include "shadowlean/sl_tiltobs.h"

#include <string.h>

#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_profile.h"

#include "compiler.h"

#define P2_32 ((int64_t)4294967296LL) // 2^32

// cdeg -> bam32 (two's complement for negative angles), rounded to nearest.
static sl_bam32_t cdeg_to_bam(int32_t cdeg)
{
    const int64_t num = (int64_t)cdeg * P2_32;
    const int64_t q = (num >= 0) ? (num + 18000) / 36000 : -((-num + 18000) / 36000);
    return (sl_bam32_t)(uint32_t)(uint64_t)q;
}

static int32_t sat32(int64_t v)
{
    return sl_fx_sat32(v);
}

sl_err_t sl_tiltobs_init(sl_tiltobs_t *o, const sl_board_t *board)
{
    if (o == NULL || board == NULL) {
        return SL_ERR_ARG;
    }
    memset(o, 0, sizeof *o);
    o->board = board;
    o->prm.radar_height_um = board->radar_height_um;
    sl_q30_t s;
    sl_q30_t c;
    sl_tilt_sincos_q30(cdeg_to_bam(board->beta_up_cdeg), &s, &c);
    o->prm.cos_beta_q30 = c;
    o->prm.sin_beta_q30 = s;
    return SL_OK;
}

static void free_ring(sl_tiltobs_t *o, sl_tiltobs_ring_t *r)
{
    if (r->fresh != 0U && o->pending > 0U) {
        o->pending--;
    }
    memset(r, 0, sizeof *r);
}

static void clear_rings(sl_tiltobs_t *o)
{
    bool any = false;
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; i++) {
        if (o->ring[i].track_id != 0U) {
            any = true;
            free_ring(o, &o->ring[i]);
        }
    }
    if (any) {
        o->stats.resets++;
    }
}

void sl_tiltobs_advance(sl_tiltobs_t *o, bool motion_valid, int32_t speed_mm_s,
                        int32_t yaw_rate_cdeg_s, uint32_t rotation_us)
{
    SL_ASSERT(o != NULL);
    if (!motion_valid) {
        clear_rings(o);
        o->moving = false;
        o->odom_prev = o->odom;
        return;
    }
    o->odom_prev = o->odom;
    const int64_t w = (int64_t)yaw_rate_cdeg_s * 10; // mdeg/s
    sl_tilt_odom_step(&o->odom, speed_mm_s, sat32(w), rotation_us);
    o->moving = true;
}

// The ring of `id`, or NULL.
static sl_tiltobs_ring_t *ring_of(sl_tiltobs_t *o, uint16_t id)
{
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; i++) {
        if (o->ring[i].track_id == id) {
            return &o->ring[i];
        }
    }
    return NULL;
}

const sl_tiltobs_ring_t *sl_tiltobs_find(const sl_tiltobs_t *o, uint16_t id)
{
    SL_ASSERT(o != NULL);
    if (id == 0U) {
        return NULL;
    }
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; i++) {
        if (o->ring[i].track_id == id) {
            return &o->ring[i];
        }
    }
    return NULL;
}

// The target the tracker associated with `t` on this rotation (the tracker copies its
// azimuth and corrected bounds), or NULL.
static const sl_target_t *target_of(const sl_track_t *t, const sl_target_t *targets, uint32_t n)
{
    for (uint32_t j = 0; j < n; j++) {
        const sl_target_t *g = &targets[j];
        if (g->az == t->az && g->r1_um == t->r1_um && g->r2_um == t->r2_um) {
            return g;
        }
    }
    return NULL;
}

// The group's union extent (sl_target_t.ext_grow: min first / max last bin over all its
// azimuths) with the corrections of the representative bounds: r1 moves by whole bins (the
// half-bin and radius terms are constant offsets), r2 too, less the change of the
// elongation d(r2) over the added bins (none after a profile refinement, which dropped d).
// A radius estimated from the group's azimuthal width (RADIUS_WIDTH) is removed from both
// bounds (the inner one: sl_detect_union_r1_um, which the tracker's consistency test reads
// too): on a leaning pole seen at an oblique bearing the width holds the lean's own spread
// in bearing (a 1 cm pole reads as R = 0.15 m, the clamp), which would bias the very
// inclination measured here; a board radius (RADIUS_BOARD) stays. A thick pole without a
// board radius then reads from its front surface (R = 0.1 m at 5 m: ~0.3 deg).
// False when a nibble saturated (extent unknown) or the bounds are not a run.
static bool union_bounds(const sl_board_t *b, const sl_target_t *g, uint32_t *r1, uint32_t *r2)
{
    const uint32_t lo = (uint32_t)g->ext_grow & 15U;
    const uint32_t hi = (uint32_t)g->ext_grow >> 4;
    const uint32_t bin = b->bin_size_um;
    const bool width = (g->flags & SL_TARGET_RADIUS_WIDTH) != 0U;
    const uint32_t in1 = sl_detect_union_r1_um(g, bin); // 0: not positive
    const uint32_t add = hi * bin;
    // The representative's last half-bin centre (sl_detect.h, 5.): (bin_last + 1/2) b.
    const uint32_t r2_hb = g->r2_raw_um - bin / 2U;
    int32_t t2 = 0; // what leaves r2 besides the added bins
    if (hi != 0U && (g->flags & SL_TARGET_PROFILE) == 0U) {
        t2 = sl_detect_elong_um(b, r2_hb + add) - g->elong_um;
    }
    if (width) {
        t2 += (int32_t)(g->r2_um - r2_hb) + g->elong_um;
    }
    const int64_t u2 = (int64_t)g->r2_um + add - t2;
    if (lo >= SL_TARGET_EXT_SAT || hi >= SL_TARGET_EXT_SAT || in1 == 0U || u2 <= (int64_t)in1 ||
        u2 > (int64_t)UINT32_MAX) {
        return false;
    }
    *r1 = in1;
    *r2 = (uint32_t)u2;
    return true;
}

// One observation of target `g` into ring `r`: the group's union extent at the group's
// centre azimuth (a leaning pole spans several azimuths, each holding a part of it; the
// representative run alone reads the lean short, and a constant bias becomes a sideways
// tilt in the fit).
static void observe(sl_tiltobs_t *o, sl_tiltobs_ring_t *r, const sl_target_t *g, bool fit)
{
    const sl_board_t *b = o->board;
    const uint32_t naz = b->azimuths;
    // Group centre in half azimuths (az_first + (az_count - 1) / 2), wrapped.
    // (az_count 0: not from a group; its own azimuth.)
    const uint32_t az2 = g->az_count == 0U
                             ? 2U * (uint32_t)g->az
                             : (2U * (uint32_t)g->az_first + g->az_count - 1U) % (2U * naz);
    const uint32_t azi = ((az2 + 1U) / 2U) % naz;
    uint32_t r1u = 0U;
    uint32_t r2u = 0U;
    sl_incline_result_t inc;
    inc.flag = (uint8_t)SL_INCLINE_INVALID;
    if (union_bounds(b, g, &r1u, &r2u)) {
        // The far bound at the end of a walk over a smear tail is known to two bins
        // (sl_profile.h, "Uncertainty of the bounds"), the union's inner bound (the mask's
        // first bins over the group) to the board's quantisation.
        uint32_t sr = b->range_sigma_um;
        const uint32_t coarse = sl_profile_coarse_sigma_um(b->bin_size_um);
        if ((g->flags & SL_TARGET_WALKED) != 0U && coarse > sr) {
            sr = sl_incline_bounds_sigma_um(r1u, r2u, sr, coarse);
        }
        inc = sl_incline_estimate(r1u, r2u, &b->geom[azi], sr, b->theta_sigma_cdeg);
    }
    if (inc.flag != (uint8_t)SL_INCLINE_VALID) {
        o->stats.rejected++;
        return;
    }
    // Vehicle pose at the group's azimuth: linear between the rotation's start and end.
    const int64_t f_num = (int64_t)az2;
    const int64_t f_den = 2 * (int64_t)naz;
    const int64_t vx = o->odom_prev.x_um + (o->odom.x_um - o->odom_prev.x_um) * f_num / f_den;
    const int64_t vy = o->odom_prev.y_um + (o->odom.y_um - o->odom_prev.y_um) * f_num / f_den;
    const int64_t dyaw = (int64_t)(int32_t)(o->odom.yaw - o->odom_prev.yaw);
    const sl_bam32_t yaw = o->odom_prev.yaw + (sl_bam32_t)(uint32_t)(uint64_t)(dyaw * f_num / f_den);
    sl_q30_t s;
    sl_q30_t c;
    sl_tilt_sincos_q30(yaw, &s, &c);
    const int64_t rx = vx + sl_fx_rshift_round64((int64_t)b->radar_x_um * c - (int64_t)b->radar_y_um * s, 30U);
    const int64_t ry = vy + sl_fx_rshift_round64((int64_t)b->radar_x_um * s + (int64_t)b->radar_y_um * c, 30U);
    // Bearing: clockwise from vehicle forward on the board, counter-clockwise in odometry.
    const sl_bam32_t cw = (sl_bam32_t)(((uint64_t)az2 << 31) / naz) + cdeg_to_bam(b->radar_yaw_cdeg);
    const sl_bam32_t bearing = yaw - cw;
    sl_tilt_obs_t ob;
    if (!sl_tilt_obs_make(&ob, sat32(rx - r->anchor_x_um), sat32(ry - r->anchor_y_um), bearing,
                          r1u, inc.alpha_bam32, inc.sigma_cdeg, inc.branch, &b->geom[azi])) {
        o->stats.rejected++;
        return;
    }
    ob.mark = (uint8_t)((fit ? 0U : SL_TILT_OBS_UNCONFIRMED) |
                        ((g->flags & SL_TARGET_RAMP) != 0U ? SL_TILT_OBS_RAMP : 0U));
    r->obs[r->head] = ob;
    r->head = (uint8_t)((r->head + 1U) % (uint32_t)SL_CFG_TILT_OBS_PER_TRACK);
    if (r->count < (uint8_t)SL_CFG_TILT_OBS_PER_TRACK) {
        r->count++;
    }
    if (fit && r->fresh == 0U) {
        r->fresh = 1U;
        o->pending++;
    }
    o->stats.observations++;
}

// A ring for track `t` (slot i) with no ring yet: a free one; for a confirmed track, else a
// provisional one (the fewest observations, then the lowest index), taken from its
// unconfirmed track. NULL: none.
static sl_tiltobs_ring_t *ring_take(sl_tiltobs_t *o, const sl_track_t *t, uint32_t i)
{
    sl_tiltobs_ring_t *r = ring_of(o, 0U);
    if (r == NULL && t->confirmed != 0U) {
        for (uint32_t k = 0; k < (uint32_t)SL_CFG_TILT_TRACKS; k++) {
            sl_tiltobs_ring_t *q = &o->ring[k];
            if (q->provisional != 0U && (r == NULL || q->count < r->count)) {
                r = q;
            }
        }
        if (r != NULL) {
            free_ring(o, r);
            o->stats.evicted++;
        }
    }
    if (r != NULL) {
        r->track_id = t->id;
        r->slot = (uint8_t)i;
        r->anchor_x_um = o->odom.x_um;
        r->anchor_y_um = o->odom.y_um;
        r->provisional = (uint8_t)(t->confirmed != 0U ? 0U : 1U);
    }
    return r;
}

void sl_tiltobs_update(sl_tiltobs_t *o, const sl_track_t *tracks, const sl_target_t *targets,
                       uint32_t n_targets)
{
    SL_ASSERT(o != NULL && tracks != NULL && (targets != NULL || n_targets == 0U));
    // Rings of tracks that are gone.
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_TILT_TRACKS; i++) {
        sl_tiltobs_ring_t *r = &o->ring[i];
        if (r->track_id != 0U && (r->slot >= (uint32_t)SL_CFG_MAX_TARGETS ||
                                  tracks[r->slot].live == 0U || tracks[r->slot].id != r->track_id)) {
            free_ring(o, r);
        }
    }
    if (!o->moving || o->board->geom == NULL) {
        return;
    }
    for (uint32_t i = 0; i < (uint32_t)SL_CFG_MAX_TARGETS; i++) {
        const sl_track_t *t = &tracks[i];
        if (t->live == 0U || t->updated == 0U) {
            continue;
        }
        const bool confirmed = t->confirmed != 0U;
        sl_tiltobs_ring_t *r = ring_of(o, t->id);
        if (r != NULL && r->provisional == 0U && !confirmed) {
            continue; // a history begun under confirmation records only while confirmed
        }
        if (r != NULL && r->provisional != 0U && !confirmed && t->evidence <= 1U) {
            free_ring(o, r); // the track restarted: what the ring held may be another object
            r = NULL;
        }
        const sl_target_t *g = target_of(t, targets, n_targets);
        if (g == NULL || g->incline_flag != (uint8_t)SL_INCLINE_VALID ||
            g->az >= o->board->azimuths) {
            o->stats.no_target += confirmed ? 1U : 0U;
            continue;
        }
        if (o->verified_only && (g->flags & (SL_TARGET_PROFILE | SL_TARGET_NO_TAIL)) == 0U) {
            o->stats.unverified += confirmed ? 1U : 0U;
            continue;
        }
        if (r == NULL) {
            r = ring_take(o, t, i);
            if (r == NULL) {
                o->stats.no_ring += confirmed ? 1U : 0U;
                continue;
            }
        }
        if (confirmed) {
            r->provisional = 0U;
        }
        observe(o, r, g, confirmed);
    }
}

// |tan(alpha_k) - pred_k| of observation k under the fit `res` (pred = -(t . e_k)), Q24
// (< 2^28): the reading the fit chose for it, or with `other` its other one (the fold's
// mirror when the fit read it as measured, and the reverse). O(1).
static SL_NOINLINE int64_t resid_q24(const sl_tiltobs_ring_t *r, uint32_t k, bool other)
{
    const sl_tilt_obs_t *ob = &r->obs[k];
    const bool mir = (k < 32U && ((r->res.mirrored_mask >> k) & 1U) != 0U) != other;
    const int64_t tan_q24 = (int64_t)(mir ? ob->tan_mirror_q12 : ob->tan_q12) * 4096;
    const int64_t pred_q24 = -(((int64_t)r->res.tx_q24 * ob->cos_a_q15 +
                                (int64_t)r->res.ty_q24 * ob->sin_a_q15) >> 15);
    const int64_t d = tan_q24 - pred_q24;
    return d < 0 ? -d : d;
}

// The square of a residual (Q24) in sigmas (Q16), Q8, saturating.
static uint32_t z2_q8_of(int64_t ad_q24, uint32_t sigma_q16)
{
    const uint64_t z_q8 = (uint64_t)ad_q24 / sigma_q16; // < 2^28
    return (z_q8 >= 0x10000U) ? UINT32_MAX : (uint32_t)((z_q8 * z_q8) >> 8);
}

// Relative weight of observation k, (SL_TILT_SIGMA_MIN_Q16 / sigma_k)^2, Q16 (<= 1).
static uint32_t obs_weight_q16(const sl_tilt_obs_t *ob)
{
    const uint64_t q = ((uint64_t)SL_TILT_SIGMA_MIN_Q16 << 16) / ob->sigma_q16; // <= 2^16
    return (uint32_t)((q * q) >> 16);
}

// The weighted bearing moments M = sum w_k e_k e_k' (Q16) of the ring, for the leverages.
typedef struct lev_ctx {
    int64_t m11, m12, m22, det; // M (Q16), det M (Q32)
} lev_ctx_t;

static SL_NOINLINE void lev_init(const sl_tiltobs_ring_t *r, lev_ctx_t *l)
{
    l->m11 = 0;
    l->m12 = 0;
    l->m22 = 0;
    for (uint32_t k = 0; k < r->count; k++) {
        const sl_tilt_obs_t *ob = &r->obs[k];
        const int64_t w = obs_weight_q16(ob);
        const int64_t c = ob->cos_a_q15, s = ob->sin_a_q15;
        l->m11 += (w * ((c * c) >> 14)) >> 16; // Q16 x Q16 >> 16
        l->m12 += (w * ((c * s) >> 14)) >> 16;
        l->m22 += (w * ((s * s) >> 14)) >> 16;
    }
    l->det = l->m11 * l->m22 - l->m12 * l->m12; // Q32, <= 2^42 for 32 observations
}

// The squared residual in sigmas of observation k (`z2_q8`, Q8) as it would be left out
// of the fit: z^2 / (1 - h_k), h_k = w_k e_k' M^-1 e_k its leverage (an observation at the
// end of the pass's bearings pulls the fit towards itself and hides its own residual: one
// far bound 3 % long among 11 left a FITTED direction 19 deg off at 5.9 deg of sigma).
// 1 - h is held at 1/16 at least. Saturating.
static uint32_t deleted_z2(const sl_tiltobs_ring_t *r, const lev_ctx_t *l, uint32_t k,
                           uint32_t z2_q8)
{
    if (l->det <= 0 || z2_q8 == UINT32_MAX) {
        return z2_q8;
    }
    const sl_tilt_obs_t *ob = &r->obs[k];
    const int64_t c = ob->cos_a_q15, s = ob->sin_a_q15;
    // e' adj(M) e, Q32: (Q30 x Q16) >> 14
    const int64_t quad = ((c * c) * l->m22 - 2 * (c * s) * l->m12 + (s * s) * l->m11) >> 14;
    int64_t h = ((int64_t)obs_weight_q16(ob) * (quad < 0 ? 0 : quad)) / l->det; // Q16
    h = h > 61440 ? 61440 : h;                                             // 1 - h >= 1/16
    const uint64_t z = ((uint64_t)z2_q8 << 16) / (uint64_t)(65536 - h);
    return z >= UINT32_MAX ? UINT32_MAX : (uint32_t)z;
}

// The observation with the largest deleted residual in sigmas under the fit (the reading
// it chose) and its square, Q8 (`z2_q8`, saturating). O(n).
static SL_NOINLINE uint32_t worst_obs(const sl_tiltobs_ring_t *r, const lev_ctx_t *l,
                                      uint32_t *z2_q8)
{
    uint32_t worst = 0;
    uint32_t wz = 0;
    for (uint32_t k = 0; k < r->count; k++) {
        const uint32_t z = deleted_z2(r, l, k, z2_q8_of(resid_q24(r, k, false), r->obs[k].sigma_q16));
        if (z > wz) {
            worst = k;
            wz = z;
        }
    }
    *z2_q8 = wz;
    return worst;
}

static void reverse_obs(sl_tilt_obs_t *a, uint32_t lo, uint32_t hi) // [lo, hi)
{
    for (uint32_t i = lo, j = hi; i + 1U < j; i++, j--) {
        const sl_tilt_obs_t tmp = a[i];
        a[i] = a[j - 1U];
        a[j - 1U] = tmp;
    }
}

// Remove observation k (array index) keeping the others in age order; afterwards the ring
// is in the not-full layout (oldest at 0, head = count). O(capacity). Not inlined: its
// frame stays off the fit's call chain (the Cortex-M0 stack budget).
static SL_NOINLINE void drop_obs(sl_tiltobs_ring_t *r, uint32_t k)
{
    const uint32_t cap = (uint32_t)SL_CFG_TILT_OBS_PER_TRACK;
    const uint32_t n = r->count;
    uint32_t at = k;
    if (n == cap && r->head != 0U) {
        // rotate left by head (oldest first): reverse [0, head), [head, cap), [0, cap)
        const uint32_t h = r->head;
        reverse_obs(r->obs, 0U, h);
        reverse_obs(r->obs, h, cap);
        reverse_obs(r->obs, 0U, cap);
        at = (k + cap - h) % cap;
    }
    for (uint32_t i = at; i + 1U < n; i++) {
        r->obs[i] = r->obs[i + 1U];
    }
    r->count = (uint8_t)(n - 1U);
    r->head = r->count;
}

// Observations held with `bit` of their mark (SL_TILT_OBS_*). O(count).
static uint32_t marked(const sl_tiltobs_ring_t *r, uint32_t bit)
{
    uint32_t n = 0U;
    for (uint32_t k = 0; k < r->count; k++) {
        n += ((uint32_t)r->obs[k].mark & bit) != 0U ? 1U : 0U;
    }
    return n;
}

// Drop them (the others keep their age order); returns how many. O(count^2) at most, on
// the rare INCONSISTENT path. Not inlined (the fit's stack chain).
static SL_NOINLINE uint32_t drop_unconfirmed(sl_tiltobs_ring_t *r)
{
    uint32_t n = 0U;
    uint32_t k = 0U;
    while (k < r->count) {
        if ((r->obs[k].mark & SL_TILT_OBS_UNCONFIRMED) != 0U) {
            drop_obs(r, k); // (normalises the layout: oldest first from here on)
            n++;
            k = 0U;
        } else {
            k++;
        }
    }
    return n;
}

// The worst observation of a fit (its squared deleted residual in sigmas `z2_q8`) is a
// gross outlier: z^2 > SL_TILTOBS_GROSS_Z2 x s^2, s^2 = max(1, (chi2 - z^2) / (dof - 1))
// the chi-square scale of the other observations (dof = n - 2, n >=
// SL_TILTOBS_OUTLIER_MIN_N). In an AMBIGUOUS fit the caller asks it of both readings
// (sl_tiltobs.h). O(1).
static SL_NOINLINE bool gross(const sl_tiltobs_ring_t *r, uint32_t z2_q8)
{
    const uint32_t chi2_q8 = r->res.chi2_q8;
    const uint32_t rest_q8 = chi2_q8 > z2_q8 ? chi2_q8 - z2_q8 : 0U;
    uint32_t s2_q8 = rest_q8 / ((uint32_t)r->count - 3U);
    if (s2_q8 < 256U) {
        s2_q8 = 256U;
    }
    return s2_q8 <= UINT32_MAX / SL_TILTOBS_GROSS_Z2 && z2_q8 > SL_TILTOBS_GROSS_Z2 * s2_q8;
}

// In an AMBIGUOUS fit: observation k's OTHER reading under the same fit, squared in sigmas
// (Q8; UINT32_MAX when it has none, not mirrorable), so that an observation gross under
// both its readings can be told from one whose reading decides between the hypotheses.
static uint32_t other_reading_z2(const sl_tiltobs_ring_t *r, const lev_ctx_t *l, uint32_t k)
{
    return r->obs[k].mirrorable == 0U
               ? UINT32_MAX
               : deleted_z2(r, l, k, z2_q8_of(resid_q24(r, k, true), r->obs[k].sigma_q16));
}

// The observation to drop from the ring's fit (sl_tiltobs.h, "Outlier rejection"): an
// INCONSISTENT fit's worst one, a FITTED fit's when it is gross, an AMBIGUOUS fit's when it
// is gross under both its readings; within the ring's bound of drops. False: none. O(n).
static SL_NOINLINE bool outlier_of(const sl_tiltobs_ring_t *r, uint32_t *w)
{
    const bool incons = r->res.quality == (uint8_t)SL_TILT_INCONSISTENT;
    const bool amb = r->res.quality == (uint8_t)SL_TILT_AMBIGUOUS;
    if (!(incons || amb || r->res.quality == (uint8_t)SL_TILT_FITTED) ||
        r->count < SL_TILTOBS_OUTLIER_MIN_N ||
        (uint32_t)r->dropped + 1U > (uint32_t)r->count / SL_TILTOBS_OUTLIER_DIV) {
        return false;
    }
    uint32_t z2_q8;
    lev_ctx_t lev;
    lev_init(r, &lev);
    *w = worst_obs(r, &lev, &z2_q8);
    return incons || (gross(r, z2_q8) && (!amb || gross(r, other_reading_z2(r, &lev, *w))));
}

// A result (FITTED or AMBIGUOUS) stands on SL_TILT_MIN_OBS observations without a ramp at a
// bound, else it is TOO_FEW, as sl_tilt_fit's (no values); nor is it a tilt beyond the
// largest a pole may have (max_tan_q16), else INCONSISTENT (sl_tiltobs.h, 3.).
static void gate_result(sl_tiltobs_t *o, sl_tiltobs_ring_t *r)
{
    if (r->res.quality != (uint8_t)SL_TILT_FITTED && r->res.quality != (uint8_t)SL_TILT_AMBIGUOUS) {
        return;
    }
    const int64_t tx = r->res.tx_q24, ty = r->res.ty_q24;
    const int64_t lim = (int64_t)o->max_tan_q16 << 8; // Q24
    if ((uint32_t)r->count - marked(r, SL_TILT_OBS_RAMP) < SL_TILT_MIN_OBS) {
        const uint8_t n_obs = r->res.n_obs;
        memset(&r->res, 0, sizeof r->res);
        r->res.n_obs = n_obs;
        r->res.quality = (uint8_t)SL_TILT_TOO_FEW;
    } else if (o->max_tan_q16 != 0U && tx * tx + ty * ty > lim * lim) {
        r->res.quality = (uint8_t)SL_TILT_INCONSISTENT;
        memset(&r->res.mirror, 0, sizeof r->res.mirror);
        r->res.mirror_mask = 0U;
        o->stats.too_steep++;
    }
}

void sl_tiltobs_fit_pending(sl_tiltobs_t *o)
{
    SL_ASSERT(o != NULL);
    if (o->pending == 0U) {
        return;
    }
    // Fits: rings with a new observation, round robin, bounded per call.
    uint32_t done = 0;
    for (uint32_t k = 0; k < (uint32_t)SL_CFG_TILT_TRACKS && done < (uint32_t)SL_CFG_TILT_FITS_PER_ROTATION; k++) {
        const uint32_t idx = ((uint32_t)o->rr + k) % (uint32_t)SL_CFG_TILT_TRACKS;
        sl_tiltobs_ring_t *r = &o->ring[idx];
        if (r->track_id == 0U || r->fresh == 0U) {
            continue;
        }
        (void)sl_tilt_fit(r->obs, r->count, &o->prm, &o->work, &r->res);
        o->stats.fits++;
        done++;
        // Observations recorded while the track was not confirmed (sl_tiltobs.h, 2.) are
        // trusted less: INCONSISTENT with them, they go and the fit is redone (within the
        // bound, as below). They do not count as outliers.
        const uint32_t unconf = r->res.quality == (uint8_t)SL_TILT_INCONSISTENT
                                    ? marked(r, SL_TILT_OBS_UNCONFIRMED) : 0U;
        if (SL_CFG_TILT_FITS_PER_ROTATION >= 2 && unconf != 0U && unconf < r->count) {
            if (done >= (uint32_t)SL_CFG_TILT_FITS_PER_ROTATION) {
                o->rr = (uint8_t)idx;
                break;
            }
            o->stats.unconfirmed_dropped += drop_unconfirmed(r);
            (void)sl_tilt_fit(r->obs, r->count, &o->prm, &o->work, &r->res);
            o->stats.fits++;
            done++;
        }
        // Outliers (sl_tiltobs.h, "Outlier rejection"). One gross outlier (a bound the
        // profile could not clean) makes a whole pass INCONSISTENT, or, in a FITTED fit (an
        // AMBIGUOUS one: under both its readings), lies far beyond the scale of the other
        // residuals: drop the observation with the largest residual in sigmas and fit
        // again, at most one in SL_TILTOBS_OUTLIER_DIV of the observations per ring (a pole
        // that is not straight, or a wrong association, stays INCONSISTENT). The second fit
        // counts against the bound: without room for it the ring stays fresh and starts the
        // next call. After a drop from a FITTED or AMBIGUOUS fit the ring stays fresh: the
        // next call looks for another.
        bool again = false;
        const bool incons = r->res.quality == (uint8_t)SL_TILT_INCONSISTENT;
        uint32_t w = 0U;
        if (SL_CFG_TILT_FITS_PER_ROTATION >= 2 && outlier_of(r, &w)) {
            if (done >= (uint32_t)SL_CFG_TILT_FITS_PER_ROTATION) {
                o->rr = (uint8_t)idx;
                break;
            }
            drop_obs(r, w);
            r->dropped++;
            if (incons) {
                o->stats.outliers++;
            } else {
                o->stats.gross++;
                again = true;
            }
            (void)sl_tilt_fit(r->obs, r->count, &o->prm, &o->work, &r->res);
            o->stats.fits++;
            done++;
        }
        gate_result(o, r);
        r->fitted = 1U;
        if (!again) {
            r->fresh = 0U;
            o->pending--;
        }
        o->rr = (uint8_t)((idx + 1U) % (uint32_t)SL_CFG_TILT_TRACKS);
    }
}

#define RAD_Q24_PER_CDEG 2928LL       // pi / 18000 * 2^24 (2928.2)
#define CDEG_PER_RAD_Q16 375493621LL  // 18000 / pi * 2^16

// 1-sigma of the path lean atan(t_n), t_n = the tilt vector's component on the path's normal
// (`tn_q24`; `tp_q24` the one along the path, vehicle frame): d t_n = (t_n / |t|) d|t| +
// t_p d phi, d|t| = (1 + |t|^2) d psi; when the direction is not determined, the tilt sigma
// (the larger one, sl_tilt.h) in every direction. Then / (1 + t_n^2). O(1).
static uint16_t lean_sigma_cdeg(uint16_t psi_sigma_cdeg, uint16_t phi_sigma_cdeg, int64_t tp_q24,
                                int64_t tn_q24)
{
    const int64_t an = (tn_q24 < 0) ? -tn_q24 : tn_q24;
    const int64_t ap = (tp_q24 < 0) ? -tp_q24 : tp_q24;
    const int64_t t2_q24 = (an * an + ap * ap) >> 24;                       // |t|^2
    const int64_t tnorm_q24 = (int64_t)sl_fx_isqrt64((uint64_t)t2_q24 << 24);
    const int64_t along_q24 = (((int64_t)psi_sigma_cdeg * RAD_Q24_PER_CDEG) *
                               (((int64_t)1 << 24) + t2_q24)) >> 24;        // sigma of |t|
    int64_t a1 = along_q24;
    int64_t a2 = 0;
    if (phi_sigma_cdeg < 18000U && tnorm_q24 > 0) {
        a1 = (along_q24 * an) / tnorm_q24;
        a2 = (((int64_t)phi_sigma_cdeg * RAD_Q24_PER_CDEG) * ap) >> 24;
    }
    const int64_t sig_q24 = (int64_t)sl_fx_isqrt64((uint64_t)(a1 * a1) + (uint64_t)(a2 * a2));
    const int64_t lean_q24 = (sig_q24 << 24) / (((int64_t)1 << 24) + ((an * an) >> 24));
    const int64_t cdeg = (lean_q24 * CDEG_PER_RAD_Q16 + ((int64_t)1 << 39)) >> 40;
    return (cdeg > (int64_t)UINT16_MAX) ? (uint16_t)UINT16_MAX : (uint16_t)cdeg;
}

// Reading `mirror` (false: the fit's best; true: an AMBIGUOUS fit's other one) of ring `r`
// in the vehicle frame at the current pose (sl_tiltobs_vehicle, _vehicle_mirror).
static bool vehicle_reading(const sl_tiltobs_t *o, const sl_tiltobs_ring_t *r, bool mirror,
                            sl_tiltobs_vehicle_t *out)
{
    SL_ASSERT(o != NULL && out != NULL);
    memset(out, 0, sizeof *out);
    if (r == NULL || r->fitted == 0U) {
        return false;
    }
    const sl_tilt_result_t *res = &r->res;
    const sl_tilt_reading_t *m = &res->mirror;
    out->quality = res->quality;
    if (mirror && res->quality != (uint8_t)SL_TILT_AMBIGUOUS) {
        return false;
    }
    if (res->quality != (uint8_t)SL_TILT_FITTED && res->quality != (uint8_t)SL_TILT_AMBIGUOUS) {
        return true;
    }
    const int64_t rtx = mirror ? m->tx_q24 : res->tx_q24;
    const int64_t rty = mirror ? m->ty_q24 : res->ty_q24;
    sl_q30_t s;
    sl_q30_t c;
    sl_tilt_sincos_q30(o->odom.yaw, &s, &c);
    const int32_t yaw_cdeg = sl_incline_bam32_to_cdeg(o->odom.yaw); // signed
    int32_t phi = ((mirror ? m->phi_cdeg : res->phi_cdeg) - yaw_cdeg) % 36000;
    if (phi < 0) {
        phi += 36000;
    }
    out->psi_cdeg = mirror ? m->psi_cdeg : res->psi_cdeg;
    out->phi_cdeg = phi;
    out->psi_sigma_cdeg = mirror ? m->psi_sigma_cdeg : res->psi_sigma_cdeg;
    out->phi_sigma_cdeg = mirror ? m->phi_sigma_cdeg : res->phi_sigma_cdeg;
    const int64_t dx = r->anchor_x_um + (mirror ? m->base_x_um : res->base_x_um) - o->odom.x_um;
    const int64_t dy = r->anchor_y_um + (mirror ? m->base_y_um : res->base_y_um) - o->odom.y_um;
    const int64_t bx = sl_fx_rshift_round64(dx * c + dy * s, 30U);
    const int64_t by = sl_fx_rshift_round64(dy * c - dx * s, 30U);
    out->base_x_um = sat32(bx);
    out->base_y_um = sat32(by);
    // Tilt vector's y component in the vehicle frame (Q24), towards the path = -sign(y_b).
    const int64_t ty_v = sl_fx_rshift_round64(rty * c - rtx * s, 30U);
    const int64_t towards = (by >= 0) ? -ty_v : ty_v;
    const sl_bam32_t lean = sl_incline_atan2_bam32(sat32(towards), (int32_t)0x1000000);
    out->lean_path_cdeg = sl_incline_bam32_to_cdeg(lean);
    const int64_t tx_v = sl_fx_rshift_round64(rtx * c + rty * s, 30U);
    out->lean_path_sigma_cdeg = lean_sigma_cdeg(out->psi_sigma_cdeg, out->phi_sigma_cdeg, tx_v, ty_v);
    return true;
}

bool sl_tiltobs_vehicle(const sl_tiltobs_t *o, const sl_tiltobs_ring_t *r,
                        sl_tiltobs_vehicle_t *out)
{
    return vehicle_reading(o, r, false, out);
}

bool sl_tiltobs_vehicle_mirror(const sl_tiltobs_t *o, const sl_tiltobs_ring_t *r,
                               sl_tiltobs_vehicle_t *out)
{
    return vehicle_reading(o, r, true, out);
}
