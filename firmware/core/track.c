// SPDX-License-Identifier: MIT
// Tracks over rotations: gated association, 1-D Kalman on alpha, warning hysteresis.
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_track.h"

void sl_track_cfg_default(sl_track_cfg_t *cfg)
{
    SL_ASSERT(cfg != NULL);
    cfg->range_gate_um = 300000U;
    cfg->az_gate = 3U;
    cfg->q_cdeg = 20U;
    cfg->min_sigma_cdeg = 50U;
    cfg->max_sigma_cdeg = 300U;
    cfg->hysteresis_cdeg = 100U;
    cfg->confirm = 3U;
    cfg->caution_abs = true;
    cfg->consist_range_um = 200000U;
    cfg->consist_az = 3U;
    cfg->confirm_min = 3U;
}

sl_err_t sl_track_init(sl_tracker_t *tr, const sl_board_t *board, const sl_track_cfg_t *cfg)
{
    if (tr == NULL || board == NULL || board->azimuths == 0U) {
        return SL_ERR_ARG;
    }
    sl_track_cfg_t c;
    if (cfg != NULL) {
        c = *cfg;
    } else {
        sl_track_cfg_default(&c);
    }
    if (c.az_gate == 0U || c.range_gate_um == 0U) {
        return SL_ERR_ARG;
    }
    memset(tr, 0, sizeof *tr);
    tr->board = board;
    tr->cfg = c;
    tr->next_id = 1U;
    return SL_OK;
}

static uint32_t az_dist(uint32_t a, uint32_t b, uint32_t n)
{
    uint32_t d = (a > b ? a - b : b - a) % n;
    return (d > n - d) ? n - d : d;
}

// Raw level of alpha `a` with every threshold lowered by `lower` (cdeg). A threshold <= 0
// disables its level.
static uint8_t raw_level(const sl_tracker_t *tr, int32_t a, int32_t lower)
{
    const sl_board_t *b = tr->board;
    if (b->danger_lean_cdeg > 0 && (int64_t)a >= (int64_t)b->danger_lean_cdeg - lower) {
        return (uint8_t)SL_WARN_DANGER;
    }
    const int64_t m = tr->cfg.caution_abs ? (a < 0 ? -(int64_t)a : (int64_t)a) : (int64_t)a;
    if (b->caution_lean_cdeg > 0 && m >= (int64_t)b->caution_lean_cdeg - lower) {
        return (uint8_t)SL_WARN_CAUTION;
    }
    return (uint8_t)SL_WARN_NONE;
}

// `correlated`: the measurement's error is the same as last time, not a new independent
// draw, so the variance is not allowed below the measurement's own: its bounds are
// identical to the previous one's (a static scene quantised the same way every rotation),
// or a bound is coarse (SL_TARGET_COARSE: sl_profile.h, "Uncertainty of the bounds").
// `restart`: the first measurement from a range profile after the mask's (see "Filter").
static void filter_update(const sl_tracker_t *tr, sl_track_t *t, int32_t z_cdeg,
                          uint16_t sigma_cdeg, bool correlated, bool restart)
{
    const uint64_t sz = sigma_cdeg > tr->cfg.min_sigma_cdeg ? sigma_cdeg : tr->cfg.min_sigma_cdeg;
    const uint64_t r = sz * sz;
    if (t->valid_hits == 0U || restart) {
        t->alpha_q8 = sl_fx_sat32((int64_t)z_cdeg * 256);
        t->var_cdeg2 = sl_fx_usat32((int64_t)(r == 0U ? 1U : r));
    } else {
        const uint64_t p = (uint64_t)t->var_cdeg2 + (uint64_t)tr->cfg.q_cdeg * tr->cfg.q_cdeg;
        const uint64_t k = (p << 16) / (p + r + 0U); // Q16 gain in [0, 65536]
        const int64_t e = (int64_t)z_cdeg * 256 - t->alpha_q8;
        t->alpha_q8 = sl_fx_sat32(t->alpha_q8 + sl_fx_rshift_round64((int64_t)k * e, 16U));
        uint64_t pn = sl_fx_urshift_round64((65536U - k) * p, 16U);
        if (correlated && pn < r) {
            pn = r;
        }
        t->var_cdeg2 = sl_fx_usat32((int64_t)(pn == 0U ? 1U : pn));
    }
    t->alpha_cdeg = (int32_t)sl_fx_rshift_round64(t->alpha_q8, 8U);
    const uint32_t s = sl_fx_isqrt64(t->var_cdeg2);
    t->sigma_cdeg = (uint16_t)(s > 0xFFFFU ? 0xFFFFU : s);
    if (t->valid_hits < 0xFFFFU) {
        t->valid_hits++;
    }
}

static void level_update(sl_tracker_t *tr, sl_track_t *t)
{
    const uint8_t raw = raw_level(tr, t->alpha_cdeg, 0);
    if (raw > t->level) {
        if (t->sigma_cdeg <= tr->cfg.max_sigma_cdeg) {
            if (t->streak < 0xFFU) {
                t->streak++;
            }
            const uint8_t need = tr->cfg.confirm == 0U ? 1U : tr->cfg.confirm;
            if (t->streak >= need) {
                t->level = raw;
                t->streak = 0U;
                tr->stats.level_changes++;
            }
        }
        return;
    }
    t->streak = 0U;
    const uint8_t keep = raw_level(tr, t->alpha_cdeg, (int32_t)tr->cfg.hysteresis_cdeg);
    if (keep < t->level) {
        t->level = keep;
        tr->stats.level_changes++;
    }
}

// ---- static-object prediction and confirmation

static void confirm_update(sl_tracker_t *tr, sl_track_t *t);

// sin of a bam32 angle in Q15 (Bhaskara I: 16 u (1 - u) / (5 - 4 u (1 - u)) for x = pi u,
// |error| < 0.0017).
static int32_t sin_q15(uint32_t bam)
{
    const uint64_t u = (uint64_t)(bam & 0x7FFFFFFFU) >> 16; // fraction of pi, Q15
    const uint64_t p = u * (32768U - u);                    // Q30, <= 2^28
    const int32_t s = (int32_t)(((16U * p) << 15) / ((5ULL << 30) - 4U * p));
    return (bam & 0x80000000U) != 0U ? -s : s;
}

void sl_track_predict_static(const sl_board_t *board, uint16_t az, uint32_t r_um,
                             uint32_t disp_um, uint16_t *az_out, uint32_t *r_out)
{
    SL_ASSERT(board != NULL && az_out != NULL && r_out != NULL && board->azimuths != 0U);
    const uint32_t n = board->azimuths;
    if (disp_um == 0U) {
        *az_out = az;
        *r_out = r_um;
        return;
    }
    // Keep |x|, |y| < 2^31 so that the squares below fit (1 km is far beyond any shadow).
    const uint32_t lim = 0x40000000U; // 2^30
    r_um = r_um > lim ? lim : r_um;
    disp_um = disp_um > lim ? lim : disp_um;
    // Bearing from vehicle forward, clockwise, bam32.
    const int64_t yaw = (int64_t)board->radar_yaw_cdeg * 4294967296LL / 36000;
    const uint32_t b = (uint32_t)(((uint64_t)az << 32) / n + (uint64_t)yaw);
    const int64_t x = (((int64_t)r_um * sin_q15(b + 0x40000000U)) >> 15) - (int64_t)disp_um;
    const int64_t y = ((int64_t)r_um * sin_q15(b)) >> 15;
    const uint64_t r2 = (uint64_t)(x * x) + (uint64_t)(y * y); // < 2^63
    *r_out = sl_fx_isqrt64(r2);
    // atan2 on values scaled into int32 (|x|, |y| < 2^31: shift by 2 for margin).
    const sl_bam32_t b2 = sl_incline_atan2_bam32((int32_t)(y >> 2), (int32_t)(x >> 2));
    const uint32_t rel = b2 - (uint32_t)yaw;
    *az_out = (uint16_t)(((((uint64_t)rel * n) + 0x80000000ULL) >> 32) % n);
}

void sl_track_set_reverse(sl_tracker_t *tr, bool reverse)
{
    SL_ASSERT(tr != NULL);
    tr->motion_reverse = reverse;
}

// The track's predicted position for this update. Reversing by d is the mirror image of
// driving forward by d seen from the bearing turned by half a turn.
static void predict(const sl_tracker_t *tr, sl_track_t *t)
{
    if (!tr->motion_reverse) {
        sl_track_predict_static(tr->board, t->az, t->r1_um, tr->motion_um, &t->pred_az,
                                &t->pred_r1_um);
        return;
    }
    const uint16_t n = tr->board->azimuths;
    const uint16_t half = (uint16_t)(n / 2U);
    uint16_t paz;
    sl_track_predict_static(tr->board, (uint16_t)((t->az + half) % n), t->r1_um, tr->motion_um,
                            &paz, &t->pred_r1_um);
    t->pred_az = (uint16_t)((paz + n - half) % n);
}

// Azimuths from `a` to the target's detection group (0 inside it): a pole leaning across
// the line of sight spans 10-15 azimuths, and which of them is its representative (the
// lowest visible point, SLANT) moves as the vehicle passes, while a static object's
// predicted bearing stays inside the group. Without a group (az_count 0): to its azimuth.
static uint32_t az_dist_group(uint32_t a, const sl_target_t *g, uint32_t n)
{
    if (g->az_count <= 1U) {
        return az_dist(a, g->az, n);
    }
    const uint32_t off = (a + n - (g->az_first % n)) % n; // clockwise from the group's first
    if (off < g->az_count) {
        return 0U;
    }
    const uint32_t to_first = n - off;                  // back to az_first
    const uint32_t to_last = off - (g->az_count - 1U); // on past the last
    return to_first < to_last ? to_first : to_last;
}

// Range from `r` to the target's range extent (0 inside it): from the inner bound of its
// group's union (sl_detect_union_r1_um) to r2. The nearest point of a slender pole leaning across the line of sight lies on
// one azimuth of its group on one rotation and on another on the next (the union's inner
// bound of a SLANT target, a representative run's first bin otherwise: 0.2-0.35 m apart on a
// 20 deg lean at 3-4 m), while the static point the track followed stays on the pole, inside
// its extent.
static uint32_t range_dist_extent(uint32_t r, const sl_target_t *g, uint32_t bin_um)
{
    const uint32_t lo = sl_detect_union_r1_um(g, bin_um);
    const uint32_t hi = g->r2_um > g->r1_um ? g->r2_um : g->r1_um;
    if (r < lo) {
        return lo - r;
    }
    return r > hi ? r - hi : 0U;
}

// Evidence after an association (consistent or not with the static prediction).
static void evidence_update(sl_tracker_t *tr, sl_track_t *t, const sl_target_t *g, uint32_t yaw_az)
{
    const uint32_t da = az_dist_group(t->pred_az, g, tr->board->azimuths);
    const uint32_t dr = range_dist_extent(t->pred_r1_um, g, tr->board->bin_size_um);
    const uint8_t cap = (uint8_t)(tr->cfg.confirm_min > 253U ? 255U : tr->cfg.confirm_min + 2U);
    if (da <= (uint32_t)tr->cfg.consist_az + yaw_az && dr <= tr->cfg.consist_range_um) {
        if (t->evidence < cap) {
            t->evidence++;
        }
    } else {
        t->evidence = 1U;
        tr->stats.inconsistent++;
    }
    confirm_update(tr, t);
}

static void confirm_update(sl_tracker_t *tr, sl_track_t *t)
{
    const uint8_t c = t->evidence >= tr->cfg.confirm_min ? 1U : 0U;
    if (c != 0U && t->confirmed == 0U) {
        tr->stats.confirmations++;
    }
    t->confirmed = c;
}

static void track_take(sl_tracker_t *tr, sl_track_t *t, const sl_target_t *g, uint64_t now_us)
{
    const bool repeat = t->valid_hits != 0U && t->r1_um == g->r1_um && t->r2_um == g->r2_um;
    t->az = g->az;
    t->r1_um = g->r1_um;
    t->r2_um = g->r2_um;
    t->last_flag = g->incline_flag;
    t->last_slant = (g->flags & SL_TARGET_SLANT) != 0U ? 1U : 0U;
    if (now_us < t->last_seen_us) {
        tr->stats.time_backwards++;
    } else {
        t->last_seen_us = now_us;
    }
    t->updated = 1U;
    if (t->hits < 0xFFFFU) {
        t->hits++;
    }
    if (g->incline_flag == (uint8_t)SL_INCLINE_VALID) {
        const bool profiled = (g->flags & SL_TARGET_PROFILE) != 0U;
        const bool correlated = repeat || (g->flags & SL_TARGET_COARSE) != 0U;
        filter_update(tr, t, g->alpha_cdeg, g->sigma_cdeg, correlated,
                      profiled && t->profiled == 0U);
        if (profiled) {
            t->profiled = 1U;
        }
        level_update(tr, t);
    }
}

static uint16_t new_id(sl_tracker_t *tr)
{
    for (;;) {
        uint16_t id = tr->next_id++;
        if (id == 0U) {
            continue;
        }
        bool used = false;
        for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
            if (tr->tracks[i].live != 0U && tr->tracks[i].id == id) {
                used = true;
                break;
            }
        }
        if (!used) {
            return id;
        }
    }
}

// Azimuth gate widened by the angle the ego displacement subtends at r1:
// d / r1 rad = d * naz / (2 pi r1) azimuth steps (710/113 ~ 2 pi, rounded up).
static uint64_t gate_az(const sl_tracker_t *tr, const sl_track_t *t, uint64_t base)
{
    uint64_t ag = base;
    if (tr->motion_um != 0U) {
        const uint64_t naz = tr->board->azimuths;
        const uint64_t r1 = t->r1_um > 100000U ? t->r1_um : 100000U; // >= 0.1 m
        ag += ((uint64_t)tr->motion_um * naz * 113U + r1 * 710U - 1U) / (r1 * 710U);
    }
    return ag;
}

uint16_t sl_track_gate_az(const sl_tracker_t *tr, const sl_track_t *t)
{
    SL_ASSERT(tr != NULL && t != NULL);
    const uint64_t yaw_az = ((uint64_t)tr->motion_yaw_bam * tr->board->azimuths + 0xFFFFFFFFULL) >> 32;
    const uint64_t ag = gate_az(tr, t, (uint64_t)tr->cfg.az_gate + yaw_az);
    return (uint16_t)(ag > 0xFFFFU ? 0xFFFFU : ag);
}

void sl_track_update(sl_tracker_t *tr, const sl_target_t *targets, uint32_t n,
                     uint64_t now_us)
{
    SL_ASSERT(tr != NULL && (targets != NULL || n == 0U));
    tr->stats.updates++;
    if (n > SL_CFG_MAX_TARGETS) {
        tr->stats.full += n - SL_CFG_MAX_TARGETS;
        n = SL_CFG_MAX_TARGETS;
    }
    const uint32_t naz = tr->board->azimuths;
    const uint64_t ag0 = tr->cfg.az_gate, rg = (uint64_t)tr->cfg.range_gate_um + tr->motion_um;
    // Yaw per update in azimuth steps (rounded up).
    const uint64_t yaw_az = ((uint64_t)tr->motion_yaw_bam * naz + 0xFFFFFFFFULL) >> 32;
    bool used[SL_CFG_MAX_TARGETS];
    for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
        sl_track_t *t = &tr->tracks[i];
        t->updated = 0U;
        used[i] = false;
        if (t->live != 0U) {
            predict(tr, t);
        }
    }
    // Greedy global nearest neighbour. Cost |d az| / ag + |d r| / rg, scaled by ag * rg,
    // d az to the target's group (0 inside it: the representative of a pole leaning across
    // the line of sight moves within the group's 10-15 azimuths; groups at one range do not
    // overlap), ties broken by d az to its representative.
    for (;;) {
        uint32_t bi = 0, bj = 0;
        uint64_t best = UINT64_MAX;
        uint32_t best_rep = UINT32_MAX;
        for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
            const sl_track_t *t = &tr->tracks[i];
            if (t->live == 0U || t->updated != 0U) {
                continue;
            }
            const uint64_t ag = gate_az(tr, t, ag0 + yaw_az);
            for (uint32_t j = 0; j < n; j++) {
                if (used[j]) {
                    continue;
                }
                const sl_target_t *g = &targets[j];
                const uint32_t da = az_dist_group(t->pred_az, g, naz);
                const uint32_t dr = t->pred_r1_um > g->r1_um ? t->pred_r1_um - g->r1_um
                                                             : g->r1_um - t->pred_r1_um;
                if (da > ag || dr > rg) {
                    continue;
                }
                const uint64_t cost = (uint64_t)da * rg + (uint64_t)dr * ag;
                if (cost > best) {
                    continue;
                }
                const uint32_t da_rep = az_dist(t->pred_az, g->az, naz);
                if (cost < best || da_rep < best_rep) {
                    best = cost;
                    best_rep = da_rep;
                    bi = i;
                    bj = j;
                }
            }
        }
        if (best == UINT64_MAX) {
            break;
        }
        used[bj] = true;
        evidence_update(tr, &tr->tracks[bi], &targets[bj], (uint32_t)yaw_az);
        track_take(tr, &tr->tracks[bi], &targets[bj], now_us);
        tr->stats.associated++;
    }
    // Tracks not seen for too long are dropped (before opening new ones: frees slots).
    for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
        sl_track_t *t = &tr->tracks[i];
        if (t->live == 0U || t->updated != 0U) {
            continue;
        }
        // A rotation without an association: the object is carried to where a static one
        // is now (so the next prediction starts from there) and loses one evidence.
        t->az = t->pred_az;
        t->r1_um = t->pred_r1_um;
        if (t->evidence > 0U) {
            t->evidence--;
            confirm_update(tr, t);
        }
        if (now_us < t->last_seen_us) {
            tr->stats.time_backwards++;
            continue;
        }
        if (now_us - t->last_seen_us > tr->board->track_timeout_us) {
            t->live = 0U;
            tr->live--;
            tr->stats.dropped++;
        }
    }
    // New tracks for the remaining targets.
    for (uint32_t j = 0; j < n; j++) {
        if (used[j]) {
            continue;
        }
        sl_track_t *t = NULL;
        for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
            if (tr->tracks[i].live == 0U) {
                t = &tr->tracks[i];
                break;
            }
        }
        if (t == NULL) {
            tr->stats.full++;
            continue;
        }
        memset(t, 0, sizeof *t);
        t->id = new_id(tr);
        t->live = 1U;
        t->first_seen_us = now_us;
        t->last_seen_us = now_us;
        t->evidence = 1U;
        confirm_update(tr, t);
        tr->live++;
        tr->stats.created++;
        track_take(tr, t, &targets[j], now_us);
    }
}

void sl_track_set_motion(sl_tracker_t *tr, uint32_t disp_um, uint32_t yaw_bam32)
{
    SL_ASSERT(tr != NULL);
    tr->motion_um = disp_um;
    tr->motion_yaw_bam = yaw_bam32;
}

sl_warn_level_t sl_track_max_level(const sl_tracker_t *tr)
{
    SL_ASSERT(tr != NULL);
    uint8_t m = (uint8_t)SL_WARN_NONE;
    for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
        if (tr->tracks[i].live != 0U && tr->tracks[i].level > m) {
            m = tr->tracks[i].level;
        }
    }
    return (sl_warn_level_t)m;
}

const sl_track_t *sl_track_find(const sl_tracker_t *tr, uint16_t id)
{
    SL_ASSERT(tr != NULL);
    for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
        if (tr->tracks[i].live != 0U && tr->tracks[i].id == id) {
            return &tr->tracks[i];
        }
    }
    return NULL;
}
