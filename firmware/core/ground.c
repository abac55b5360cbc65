// SPDX-License-Identifier: MIT
// The ground from the shadow's edge: edges per sector, the plane, the hazards (sl_ground.h).
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_ground.h"
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_tilt.h"

#if SL_CFG_GROUND

#define K_SECT ((uint32_t)SL_CFG_GROUND_SECTORS)
#define W_EXP 28         // weights: 2^W_EXP / sigma^2, sigma in 1/16 mm
#define SIG2_MIN 256U    // sigma >= 1 mm (16^2 in (1/16 mm)^2)

void sl_ground_cfg_default(sl_ground_cfg_t *cfg, const sl_board_t *board)
{
    SL_ASSERT(cfg != NULL);
    const sl_vscale_t s = SL_VSCALE_CTS350X;
    memset(cfg, 0, sizeof *cfg);
    cfg->scale = s;
    cfg->threshold = board != NULL ? board->threshold : 40U;
    cfg->margin_bins = 10U;
    cfg->plateau_bins = 32U;
    cfg->floor_bins = 8U;
    cfg->search_in_bins = 32U;
    cfg->search_out_bins = 48U;
    cfg->avg_rotations = 8U;
    cfg->reads = SL_CFG_GROUND_READS;
    cfg->avg_dist_um = 750000U;
    cfg->sigma_min_q8 = 26U;
    cfg->decay_pow = 3U;
    cfg->stale_rotations = 8U;
    cfg->confirm = 3U;
    cfg->drop_um = 150000U;
    cfg->step_um = 80000U;
    cfg->good_sigma_mm = 20U;
    cfg->good_sigma_cdeg = 30U;
    cfg->front_um = 0;
}

// First azimuth of sector k: ceil(k A / K).
static uint16_t sector_first(const sl_ground_t *g, uint32_t k)
{
    return (uint16_t)((k * g->board->azimuths + K_SECT - 1U) / K_SECT);
}

// Sector k's azimuths this rotation: offsets o0, o0 + stride, ... within the sector,
// stride = len / reads, o0 = phase mod stride (over the rotations every azimuth).
static uint32_t sector_stride(const sl_ground_t *g, uint32_t len)
{
    const uint32_t st = len / g->cfg.reads;
    return st > 0U ? st : 1U;
}

// The first azimuth sector k reads this rotation.
static uint16_t sector_az(const sl_ground_t *g, uint32_t k)
{
    const uint32_t a = sector_first(g, k);
    const uint32_t len = (uint32_t)sector_first(g, k + 1U) - a;
    return (uint16_t)(a + (len > 0U ? (uint32_t)g->phase % sector_stride(g, len) : 0U));
}

static void want_sector(sl_ground_t *g, uint32_t k)
{
    g->next_sector = (uint8_t)k;
    g->next_az = k < K_SECT ? sector_az(g, k) : UINT16_MAX;
}

// After reading `az` of the wanted sector: its next azimuth, else the next sector's.
static void want_next(sl_ground_t *g, uint16_t az)
{
    const uint32_t k = g->next_sector;
    const uint32_t a = sector_first(g, k);
    const uint32_t len = (uint32_t)sector_first(g, k + 1U) - a;
    const uint32_t st = sector_stride(g, len);
    const uint32_t nxt = (uint32_t)az + st;
    if (((uint32_t)az - a) / st + 1U < g->cfg.reads && nxt < a + len) {
        g->next_az = (uint16_t)nxt;
    } else {
        want_sector(g, k + 1U);
    }
}

sl_err_t sl_ground_init(sl_ground_t *g, const sl_board_t *board, const sl_ground_cfg_t *cfg)
{
    if (g == NULL || board == NULL || board->azimuths < K_SECT || board->geom == NULL ||
        board->bin_size_um == 0U) {
        return SL_ERR_ARG;
    }
    sl_ground_cfg_t c;
    if (cfg != NULL) {
        c = *cfg;
    } else {
        sl_ground_cfg_default(&c, board);
    }
    if (c.margin_bins == 0U || c.margin_bins > 32U || c.plateau_bins == 0U ||
        c.plateau_bins > 64U || c.floor_bins == 0U || c.floor_bins > 64U ||
        c.avg_rotations == 0U || c.reads == 0U || c.reads > 8U ||
        (uint32_t)c.avg_rotations * c.reads > 255U || c.confirm == 0U || c.drop_um == 0U || c.drop_um > 10000000U || c.step_um == 0U ||
        c.step_um > 10000000U ||
        c.stale_rotations == 0U || c.decay_pow > 4U || sl_vscale_lp(&c.scale, 1U) == INT32_MIN) {
        return SL_ERR_ARG;
    }
    memset(g, 0, sizeof *g);
    g->cfg = c;
    g->board = board;
    g->bin_um = board->bin_size_um;
    g->az_step_bam = (uint32_t)(((uint64_t)1 << 32) / board->azimuths);
    g->yaw_bam = (uint32_t)(int32_t)(((int64_t)board->radar_yaw_cdeg * 4294967296LL) / 36000);
    // power of a value i below the window's largest, Q16 (SL_VSCALE_LOG2)
    for (uint32_t i = 0; i < SL_GROUND_LUT; i++) {
        const int32_t lp = (int32_t)((i * 65536U) / (c.scale.cpo_q8 != 0U ? c.scale.cpo_q8 : 1U));
        const uint32_t v = sl_lp_to_lin_q16(-lp);
        g->pow_q16[i] = (uint16_t)(v > UINT16_MAX ? UINT16_MAX : v);
    }
    sl_ground_set_bin_size(g, board->bin_size_um);
    g->decay_q8 = (int16_t)(c.decay_pow * 256U);
    for (uint32_t k = 0; k < K_SECT; k++) {
        g->sec[k].age = UINT8_MAX;
    }
    want_sector(g, 0U);
    return SL_OK;
}

void sl_ground_set_bin_size(sl_ground_t *g, uint32_t bin_um)
{
    SL_ASSERT(g != NULL);
    if (bin_um != 0U && g->board != NULL) {
        g->bin_um = bin_um;
        // e0 = H / sin(theta) / bin in bins Q8 = e0_num / sin_q30
        g->e0_num = (int64_t)(((uint64_t)g->board->radar_height_um << 38) / bin_um);
        g->near_bins = (uint16_t)(((uint64_t)g->board->near_exclusion_bins *
                                       g->board->bin_size_um + bin_um - 1U) / bin_um);
    }
}

// Power of a value relative to the window's largest value `vmax`, Q16 (LOG2: the table,
// 0 more than SL_GROUND_LUT values below; LINEAR: the value itself).
static uint32_t power_of(const sl_ground_t *g, uint8_t v, uint8_t vmax)
{
    if (g->cfg.scale.kind == (uint8_t)SL_VSCALE_LINEAR) {
        return v;
    }
    const uint32_t i = (uint32_t)vmax - v;
    return i < SL_GROUND_LUT ? g->pow_q16[i] : 0U;
}

// Two adjacent bins set in bits [lo, end) (b and b + 1 both inside), word-wise.
static bool pair_in(const uint32_t *bits, uint32_t lo, uint32_t end)
{
    if (end < lo + 2U) {
        return false;
    }
    for (uint32_t w = lo >> 5; (w << 5) < end; w++) {
        const uint32_t next = ((w + 1U) << 5) < end ? bits[w + 1U] : 0U;
        uint32_t pairs = bits[w] & ((bits[w] >> 1) | (next << 31));
        const uint32_t base = w << 5;
        if (lo > base) {
            pairs &= ~0U << (lo - base);
        }
        if (end - 1U < base + 32U) {
            const uint32_t n = end - 1U - base;
            pairs &= (n == 0U) ? 0U : (~0U >> (32U - n));
        }
        if (pairs != 0U) {
            return true;
        }
    }
    return false;
}

// The ground's level falls with range as (e / r)^n (n_q8 = n x 256). L0 = S / (A - f) (bins
// Q8, the window's end to the edge) took the plateau's mean as the level at the edge: the
// level there is (A - f) / w, w = (e / kc)^n (kc the plateau's centre), and the window
// integrates it as L - n L^2 / (2 e) to second order: L = L1 + n L1^2 / (2 e), L1 = w L0,
// with e = a1 - L (twice).
static int64_t decay_corrected(int32_t n_q8, int64_t l0_q8, int32_t a1, int32_t p1)
{
    if (n_q8 <= 0 || l0_q8 <= 0) {
        return l0_q8;
    }
    const int64_t kc_q8 = ((int64_t)a1 + p1) << 7;
    int64_t l = l0_q8;
    for (int it = 0; it < 2; it++) {
        const int64_t e_q8 = ((int64_t)a1 << 8) - l;
        if (e_q8 <= 0) {
            return l0_q8;
        }
        const int64_t r_q16 = (e_q8 << 16) / kc_q8; // < 1
        // w = 2^(n log2 r): log2 r in Q8 octaves (<= 0)
        const int32_t lr_q8 = (sl_lin_log2_q16((uint64_t)(r_q16 > 0 ? r_q16 : 1)) - 16 * 65536) / 256;
        const int64_t w_q16 = sl_lp_to_lin_q16((int32_t)(((int64_t)n_q8 * lr_q8) / 256));
        const int64_t l1 = (l0_q8 * w_q16) >> 16;
        l = l1 + (((int64_t)n_q8 * l1 * l1) >> 8) / (2 * e_q8);
    }
    return l;
}

int32_t sl_ground_edge_q8(const sl_ground_t *g, const uint8_t *row, uint32_t bins,
                          const uint32_t *bits, uint32_t bits_n, int32_t e0_q8,
                          sl_ground_edge_aux_t *aux)
{
    SL_ASSERT(g != NULL && row != NULL);
    const sl_ground_cfg_t *cfg = &g->cfg;
    const int32_t near = g->near_bins;
    const int32_t n = bins > 0x7FFFU ? 0x7FFF : (int32_t)bins;
    const int32_t thr = (int32_t)cfg->threshold;
    const int32_t m = cfg->margin_bins;
    const int32_t np = cfg->plateau_bins;
    const int32_t e0 = e0_q8 >> 8;
    int32_t lo = e0 - (int32_t)cfg->search_in_bins;
    if (lo < near + 1) {
        lo = near + 1;
    }
    const int32_t hi = e0 + (int32_t)cfg->search_out_bins;
    if (hi + m + np > n || e0 <= lo) {
        return SL_GROUND_EDGE_SHORT;
    }
    // 1. coarse start c: from e0, back through the ground run (single-bin gaps), or on to
    // the first two adjacent ground bins
    int32_t c = e0;
    if ((int32_t)row[c] >= thr) {
        while (c > lo) {
            if ((int32_t)row[c - 1] >= thr) {
                c--;
            } else if ((int32_t)row[c - 2] >= thr && c - 2 >= lo) {
                c -= 2;
            } else {
                break;
            }
        }
        if (c <= lo) {
            return SL_GROUND_EDGE_BAD; // ground from the window's start on: no edge inside
        }
    } else {
        while (c < hi && ((int32_t)row[c] < thr || (int32_t)row[c + 1] < thr)) {
            c++;
        }
        if (c >= hi) {
            return SL_GROUND_EDGE_NO_GROUND;
        }
    }
    // 2. something standing in the shadow on this azimuth: two adjacent bins >= threshold
    // in [near, c - m) (the response's rise before the edge and speckle gaps that end the
    // coarse run late stay out of it)
    const int32_t oe = c - m;
    const int32_t ob = bits != NULL ? (oe < (int32_t)bits_n ? oe : (int32_t)bits_n) : near;
    if (bits != NULL && ob > near && pair_in(bits, (uint32_t)near, (uint32_t)ob)) {
        return SL_GROUND_EDGE_OCCUPIED;
    }
    for (int32_t k = ob > near ? ob - 1 : near; k + 1 < oe; k++) {
        if ((int32_t)row[k] >= thr && (int32_t)row[k + 1] >= thr) {
            return SL_GROUND_EDGE_OCCUPIED;
        }
    }
    // 3. the half-power point: the area estimator (again when it moved the window)
    int32_t e_q8 = 0;
    for (int it = 0; it < 2; it++) {
        const int32_t a0 = c - m > near ? c - m : near + 1;
        const int32_t a1 = c + m;
        const int32_t f0 = a0 - (int32_t)cfg->floor_bins > near ? a0 - (int32_t)cfg->floor_bins
                                                                : near;
        const int32_t p1 = a1 + np;
        if (p1 > n || a0 >= a1) {
            return SL_GROUND_EDGE_SHORT;
        }
        uint8_t vmax = 0U;
        for (int32_t k = f0; k < p1; k++) {
            vmax = row[k] > vmax ? row[k] : vmax;
        }
        // one pass: the floor's, the window's and the plateau's sums
        uint32_t sf = 0U, sw = 0U, sa = 0U;
        int32_t lit = 0;
        for (int32_t k = f0; k < p1; k++) {
            const uint32_t pk = power_of(g, row[k], vmax);
            if (k < a0) {
                sf += pk;
            } else if (k < a1) {
                sw += pk;
            } else {
                sa += pk;
                lit += (int32_t)row[k] >= thr ? 1 : 0;
            }
        }
        if (4 * lit < np) {
            return SL_GROUND_EDGE_BAD; // not a run of ground after the edge
        }
        const uint32_t f = f0 < a0 ? sf / (uint32_t)(a0 - f0) : 0U;
        const uint32_t A = sa / (uint32_t)np;
        if (4U * A <= 5U * f || A == 0U) {
            return SL_GROUND_EDGE_BAD; // no contrast (a weaker test selects speckle peaks)
        }
        const int64_t s = (int64_t)sw - (int64_t)f * (a1 - a0);
        const uint32_t af = A - f;
        int64_t q = (s * 256) / (int64_t)af;
        q = decay_corrected(g->decay_q8, q, a1, p1);
        if (aux != NULL) {
            // the ground's level at the edge in the scale's power (the sector's weight)
            const uint64_t pv = cfg->scale.kind == (uint8_t)SL_VSCALE_LINEAR
                                    ? 65536U
                                    : sl_vscale_power(&cfg->scale, vmax, 16);
            const uint64_t lv = ((uint64_t)af * pv) >> 16;
            aux->level = lv == 0U ? 1U : (lv > (1U << 26) ? (1U << 26) : (uint32_t)lv);
            // the plateau's halves: the first's share of its power, and their centres
            const int32_t mid = a1 + np / 2;
            uint32_t s1 = 0U;
            for (int32_t k = a1; k < mid; k++) {
                s1 += power_of(g, row[k], vmax);
            }
            aux->share1_q16 = sa > 0U ? (uint32_t)(((uint64_t)s1 << 16) / sa) : 32768U;
            // log2 of the centres' ratio, Q16 octaves
            const uint64_t k1 = (uint64_t)(a1 + mid), k2 = (uint64_t)(mid + p1);
            aux->lever_q16 = (uint32_t)(sl_lin_log2_q16(k2 << 16) - sl_lin_log2_q16(k1 << 16));
        }
        e_q8 = (int32_t)(((int64_t)a1 << 8) - q);
        if (e_q8 < (a0 << 8) || e_q8 > (a1 << 8)) {
            return SL_GROUND_EDGE_BAD;
        }
        // the window's tails: with the edge within 3 bins of its centre the response's
        // mass beyond either end (m = 10, sigma 3.4 bins) moves e by < 0.03 bin
        const int32_t c2 = (e_q8 + 128) >> 8;
        if (c2 - c <= 3 && c - c2 <= 3) {
            break;
        }
        c = c2;
        if (c - m <= near) {
            return SL_GROUND_EDGE_BAD;
        }
    }
    return e_q8;
}

static uint8_t avg_n(const sl_ground_t *g)
{
    uint32_t n = g->cfg.avg_rotations;
    if (g->moving && g->step_um > 0U) {
        const uint32_t d = g->cfg.avg_dist_um / g->step_um;
        n = d < 1U ? 1U : (d < n ? d : n);
    }
    return (uint8_t)n;
}

static void add_sample(sl_ground_t *g, uint32_t k, uint16_t az, int32_t e_q8, uint32_t w)
{
    const sl_board_t *b = g->board;
    const sl_incline_geom_t *geo = &b->geom[az];
    const int64_t s_um = ((int64_t)e_q8 * (int64_t)g->bin_um) >> 8;
    if (s_um <= 0 || s_um > 30000000) {
        g->stats.bad_edge++;
        return;
    }
    const int32_t rho_um = (int32_t)((s_um * geo->cos_theta_q30) >> 30);
    const int32_t d_um = (int32_t)((s_um * geo->sin_theta_q30) >> 30);
    const sl_bam32_t phi = (sl_bam32_t)(uint32_t)((uint32_t)az * g->az_step_bam + g->yaw_bam);
    sl_q30_t sp, cp;
    sl_tilt_sincos_q30(phi, &sp, &cp);
    const int32_t x_um = (int32_t)(((int64_t)rho_um * cp) >> 30);
    const int32_t y_um = (int32_t)(-(((int64_t)rho_um * sp) >> 30));
    sl_ground_sector_t *s = &g->sec[k];
    g->stats.samples++;
    s->fresh = true;
    s->age = 0U;
    // this sample's residual on the last plane, summed over the rotation
    const sl_ground_plane_t *pl = &g->plane;
    if (pl->quality != (uint8_t)SL_GROUND_NONE) {
        const int64_t dp = (int64_t)pl->height_mm * 1000 + (((int64_t)pl->slope_x_q16 * x_um +
                                                              (int64_t)pl->slope_y_q16 * y_um) >> 16);
        const int64_t r = ((int64_t)d_um - dp) / 1000;
        const int32_t rs = (int32_t)s->rot_sum_mm + (int32_t)(r > 30000 ? 30000 : (r < -30000 ? -30000 : r));
        s->rot_sum_mm = (int16_t)(rs > INT16_MAX ? INT16_MAX : (rs < INT16_MIN ? INT16_MIN : rs));
        s->rot_n++;
    }
    if (s->n == 0U) {
        s->x_um = x_um;
        s->y_um = y_um;
        s->d_um = d_um;
        s->var_q = 0U;
        s->n = 1U;
        s->nv = 1U;
        s->wsum = w;
        return;
    }
    // Weighted by the ground's level at the edge: sum w e = sum (w (c + m) - S) has no
    // ratio in it, so the mean carries no bias from a noisy level (one sample's
    // S / (A - f) does). The mean over avg_n() samples, the scatter over avg_rotations.
    const uint32_t nm = avg_n(g) * g->cfg.reads;
    const uint32_t n1 = (uint32_t)s->n + 1U > nm ? nm : (uint32_t)s->n + 1U;
    const uint32_t nvm = (uint32_t)g->cfg.avg_rotations * g->cfg.reads;
    const uint32_t nv = (uint32_t)s->nv + 1U > nvm ? nvm : (uint32_t)s->nv + 1U;
    uint64_t W = (uint64_t)s->wsum - s->wsum / n1 + w;
    W = W > UINT32_MAX ? UINT32_MAX : W;
    const int64_t f_q16 = (int64_t)(((uint64_t)w << 16) / (W > 0U ? W : 1U));
    const int32_t dd = d_um - s->d_um;
    s->x_um += (int32_t)(((int64_t)(x_um - s->x_um) * f_q16) >> 16);
    s->y_um += (int32_t)(((int64_t)(y_um - s->y_um) * f_q16) >> 16);
    s->d_um += (int32_t)(((int64_t)dd * f_q16) >> 16);
    s->wsum = (uint32_t)W;
    // var = (1 - 1/nv) (var + dd^2 / nv), in (10 um)^2; a deviation counts at most
    // 3 sigma (3 sqrt(var), at least 1 cm) so that one change of the ground (a sector
    // driving onto a drop-off) does not make the sector's sigma hide it
    int64_t dq = dd / 10;
    int64_t cap = 3 * (int64_t)sl_fx_isqrt64(s->var_q);
    cap = cap < 1000 ? 1000 : (cap > 65535 ? 65535 : cap);
    dq = dq > cap ? cap : (dq < -cap ? -cap : dq);
    const uint64_t v = (uint64_t)s->var_q + (uint64_t)(dq * dq) / nv;
    const uint64_t vn = v * (nv - 1U) / nv;
    s->var_q = vn > UINT32_MAX ? UINT32_MAX : (uint32_t)vn;
    s->n = (uint8_t)n1;
    s->nv = (uint8_t)nv;
}

// The decay's exponent from the plateaus' halves over many samples: n = log2(P1 / P2) /
// log2(k2 / k1), with P1, P2 the halves' shares summed (a ratio of sums: speckle averages
// out) and the lever the mean log2 ratio of their centres; the sums halve every
// SL_GROUND_DECAY_SAMPLES samples (a running window).
static void learn_decay(sl_ground_t *g, const sl_ground_edge_aux_t *aux)
{
    if (aux->lever_q16 == 0U) {
        return;
    }
    g->dec_h1 += aux->share1_q16;
    g->dec_h2 += 65536U - aux->share1_q16;
    g->dec_lever += aux->lever_q16;
    g->dec_n++;
    if (g->dec_n >= SL_GROUND_DECAY_SAMPLES) {
        const int64_t lr = sl_lin_log2_q16(g->dec_h1) - sl_lin_log2_q16(g->dec_h2); // Q16
        const int64_t lever = (int64_t)(g->dec_lever / g->dec_n);
        int64_t n_q8 = lever > 0 ? (lr * 256) / lever : 0;
        n_q8 = n_q8 < 0 ? 0 : (n_q8 > 6 * 256 ? 6 * 256 : n_q8);
        g->decay_q8 = (int16_t)n_q8;
        g->dec_h1 >>= 1;
        g->dec_h2 >>= 1;
        g->dec_lever >>= 1;
        g->dec_n >>= 1;
    }
}

void sl_ground_row(sl_ground_t *g, uint16_t az, const uint8_t *row, uint32_t bins,
                   const uint32_t *bits, uint32_t bits_n)
{
    SL_ASSERT(g != NULL);
    while (g->next_sector < K_SECT && az > g->next_az) {
        want_next(g, g->next_az); // the wanted row was lost
    }
    if (g->next_sector >= K_SECT || az != g->next_az) {
        return;
    }
    const uint32_t k = g->next_sector;
    want_next(g, az);
    if (row == NULL) {
        g->stats.short_rows++;
        return;
    }
    const int32_t sin_q30 = g->board->geom[az].sin_theta_q30;
    if (sin_q30 <= 0) {
        g->stats.bad_edge++;
        return;
    }
    // e0: the flat ground's edge, H / sin(theta) in bins Q8
    const int32_t e0_q8 = (int32_t)(g->e0_num / sin_q30);
    sl_ground_edge_aux_t aux = {32768U, 0U, 1U};
    const int32_t e = sl_ground_edge_q8(g, row, bins, bits, bits_n, e0_q8, &aux);
    switch (e) {
    case SL_GROUND_EDGE_NO_GROUND:
        g->stats.no_ground++;
        return;
    case SL_GROUND_EDGE_OCCUPIED:
        g->stats.occupied++;
        return;
    case SL_GROUND_EDGE_BAD:
        g->stats.bad_edge++;
        return;
    case SL_GROUND_EDGE_SHORT:
        g->stats.short_rows++;
        return;
    default:
        break;
    }
    add_sample(g, k, az, e, aux.level);
    learn_decay(g, &aux);
}

void sl_ground_set_motion(sl_ground_t *g, bool valid, int32_t speed_mm_s, uint32_t rotation_us)
{
    SL_ASSERT(g != NULL);
    g->moving = false;
    g->step_um = 0U;
    g->step_x_um = 0;
    if (!valid) {
        return;
    }
    const int64_t st = (int64_t)speed_mm_s * (int64_t)rotation_us / 1000;
    g->step_x_um = sl_fx_sat32(st);
    g->step_um = (uint32_t)(st < 0 ? -st : st);
    g->moving = g->step_um > 0U;
}

// (num x 2^k) / den for den > 0, |num| < 2^62, saturating at +-2^62; k may be negative.
static int64_t muldiv_pow2(int64_t num, int64_t den, int k)
{
    if (den <= 0) {
        return 0;
    }
    const bool neg = num < 0;
    uint64_t un = (uint64_t)(neg ? -num : num);
    const uint64_t ud = (uint64_t)den;
    if (k < 0) {
        un = k <= -63 ? 0U : un >> (unsigned)-k;
        k = 0;
    }
    uint64_t q = un / ud;
    uint64_t r = un % ud;
    const uint64_t lim = (uint64_t)1 << 62;
    for (int i = 0; i < k; i++) {
        if (q >= lim >> 1) {
            q = lim;
            break;
        }
        r <<= 1;
        q <<= 1;
        if (r >= ud) {
            r -= ud;
            q |= 1U;
        }
    }
    return neg ? -(int64_t)q : (int64_t)q;
}

// A sector's variance of d, (1/16 mm)^2: the scatter of its mean plus the floor.
static uint32_t sector_sig2(const sl_ground_t *g, const sl_ground_sector_t *s, uint16_t az)
{
    // one sample's variance: the observed scatter (var_q, (10 um)^2 = x 64 / 2500 in
    // (1/16 mm)^2) shrunk towards the prior (half the response's half-power width, 4 bins,
    // as a depth) with SL_GROUND_PRIOR_WEIGHT samples' weight: a few samples' scatter is
    // often far below the truth
    const int64_t pr = ((int64_t)4 * g->bin_um * g->board->geom[az].sin_theta_q30 >> 30) * 16 / 1000;
    const uint64_t obs = (uint64_t)s->var_q * 64U / 2500U;
    const uint64_t one = (obs * s->nv + (uint64_t)(pr * pr) * SL_GROUND_PRIOR_WEIGHT) /
                         ((uint64_t)s->nv + SL_GROUND_PRIOR_WEIGHT);
    const uint64_t v = one / (s->n > 0U ? s->n : 1U);
    // floor: sigma_min_q8 bins x bin x sin(theta), 1/16 mm
    const int64_t fl = ((int64_t)g->cfg.sigma_min_q8 * g->bin_um / 256 *
                        g->board->geom[az].sin_theta_q30 >> 30) * 16 / 1000;
    uint64_t s2 = v + (uint64_t)(fl * fl);
    if (s2 < SIG2_MIN) {
        s2 = SIG2_MIN;
    }
    return s2 > UINT32_MAX ? UINT32_MAX : (uint32_t)s2;
}

typedef struct fit_out {
    int64_t a_raw_q12;     // slope x 2^16 (d in 1/16 mm per mm: x 2^12)
    int64_t b_raw_q12;
    int32_t h_q4;          // depth at the radar's foot, 1/16 mm
    uint64_t var_a_q32;    // slope variance x 2^32
    uint64_t var_b_q32;
    uint64_t var_h_q8;     // (1/16 mm)^2
    uint8_t n;
    uint8_t quads;
} fit_out_t;

static int32_t x_mm(const sl_ground_sector_t *s)
{
    return s->x_um / 1000;
}
static int32_t y_mm(const sl_ground_sector_t *s)
{
    return s->y_um / 1000;
}
static int32_t d_q4(const sl_ground_sector_t *s)
{
    return (int32_t)(((int64_t)s->d_um * 16) / 1000);
}

// Weighted least squares of d = h + a x + b y over the sectors with in_fit set.
static bool fit_plane(const sl_ground_t *g, const uint32_t *w, fit_out_t *o)
{
    int64_t sw = 0, sx = 0, sy = 0, sd = 0;
    uint32_t n = 0U;
    uint8_t quads = 0U;
    for (uint32_t k = 0; k < K_SECT; k++) {
        const sl_ground_sector_t *s = &g->sec[k];
        if (!s->in_fit) {
            continue;
        }
        sw += w[k];
        sx += (int64_t)w[k] * x_mm(s);
        sy += (int64_t)w[k] * y_mm(s);
        sd += (int64_t)w[k] * d_q4(s);
        n++;
        quads |= (uint8_t)(1U << ((x_mm(s) >= 0 ? 0U : 1U) + (y_mm(s) >= 0 ? 0U : 2U)));
    }
    o->n = (uint8_t)n;
    o->quads = (uint8_t)((quads & 1U) + ((quads >> 1) & 1U) + ((quads >> 2) & 1U) + ((quads >> 3) & 1U));
    if (n < SL_GROUND_MIN_SECTORS || o->quads < 3U || sw <= 0) {
        return false;
    }
    const int32_t mx = (int32_t)(sx / sw), my = (int32_t)(sy / sw), md = (int32_t)(sd / sw);
    int64_t xx = 0, xy = 0, yy = 0, xd = 0, yd = 0;
    for (uint32_t k = 0; k < K_SECT; k++) {
        const sl_ground_sector_t *s = &g->sec[k];
        if (!s->in_fit) {
            continue;
        }
        const int64_t cx = x_mm(s) - mx, cy = y_mm(s) - my, cd = d_q4(s) - md;
        xx += (int64_t)w[k] * cx * cx;
        xy += (int64_t)w[k] * cx * cy;
        yy += (int64_t)w[k] * cy * cy;
        xd += (int64_t)w[k] * cx * cd;
        yd += (int64_t)w[k] * cy * cd;
    }
    // scale the moments to < 2^26 so that the 2 x 2 products fit
    int64_t mmax = xx;
    mmax = yy > mmax ? yy : mmax;
    mmax = (xy < 0 ? -xy : xy) > mmax ? (xy < 0 ? -xy : xy) : mmax;
    mmax = (xd < 0 ? -xd : xd) > mmax ? (xd < 0 ? -xd : xd) : mmax;
    mmax = (yd < 0 ? -yd : yd) > mmax ? (yd < 0 ? -yd : yd) : mmax;
    int sh = 0;
    while ((mmax >> sh) >= ((int64_t)1 << 26)) {
        sh++;
    }
    xx >>= sh;
    xy >>= sh;
    yy >>= sh;
    xd >>= sh;
    yd >>= sh;
    const int64_t det = xx * yy - xy * xy;
    if (det <= 0) {
        return false;
    }
    o->a_raw_q12 = muldiv_pow2(yy * xd - xy * yd, det, 12);
    o->b_raw_q12 = muldiv_pow2(xx * yd - xy * xd, det, 12);
    // Var(a) in raw units = 2^(W_EXP - sh) yy / det; x 2^24 (raw) = x 2^32 (true, Q16^2)
    o->var_a_q32 = (uint64_t)muldiv_pow2(yy, det, W_EXP - sh + 24);
    o->var_b_q32 = (uint64_t)muldiv_pow2(xx, det, W_EXP - sh + 24);
    const int64_t cov_q32 = -muldiv_pow2(xy, det, W_EXP - sh + 24);
    o->h_q4 = (int32_t)(md - ((o->a_raw_q12 * mx) >> 12) - ((o->b_raw_q12 * my) >> 12));
    // Var(h at the foot) = 1 / W + mx^2 Var(a) + my^2 Var(b) + 2 mx my Cov(a, b);
    // slopes' variances are per (1/16 mm / mm)^2 x 2^24: x mm^2 / 2^24
    int64_t vh = muldiv_pow2(1, sw, W_EXP);
    vh += ((int64_t)mx * mx * (int64_t)(o->var_a_q32 >> 8)) >> 16;
    vh += ((int64_t)my * my * (int64_t)(o->var_b_q32 >> 8)) >> 16;
    vh += (2 * (int64_t)mx * my * (cov_q32 >> 8)) >> 16;
    o->var_h_q8 = vh > 0 ? (uint64_t)vh : 0U;
    return true;
}

static int32_t resid_q4(const sl_ground_sector_t *s, const fit_out_t *o)
{
    return d_q4(s) - o->h_q4 - (int32_t)((o->a_raw_q12 * x_mm(s)) >> 12) -
           (int32_t)((o->b_raw_q12 * y_mm(s)) >> 12);
}

static int32_t slope_cdeg(int64_t q16)
{
    const sl_bam32_t a = sl_incline_atan2_bam32(sl_fx_sat32(q16), 65536);
    return (int32_t)sl_fx_rshift_round64((int64_t)(int32_t)a * 36000, 32);
}

static uint16_t sigma_cdeg(uint64_t var_q32)
{
    // sigma (slope, Q16) -> rad -> 0.01 deg (x 18000 / pi = 22918 / 4)
    const uint64_t q16 = sl_fx_isqrt64(var_q32);
    const uint64_t c = (q16 * 22918U + (1U << 17)) >> 18;
    return c > UINT16_MAX ? UINT16_MAX : (uint16_t)c;
}

static uint16_t sat_u16(uint64_t v)
{
    return v > UINT16_MAX ? UINT16_MAX : (uint16_t)v;
}

// The hazard point's horizontal distance from the radar.
static int32_t hazard_dist(const sl_ground_sector_t *s)
{
    const uint64_t d2 = (uint64_t)((int64_t)s->hx_um * s->hx_um) + (uint64_t)((int64_t)s->hy_um * s->hy_um);
    return sl_fx_sat32((int64_t)sl_fx_isqrt64(d2));
}

static void hazards(sl_ground_t *g, const fit_out_t *o, const uint32_t *sig2, const uint16_t *azs)
{
    const int32_t drop = (int32_t)(g->cfg.drop_um * 16U / 1000U);
    const int32_t step = (int32_t)(g->cfg.step_um * 16U / 1000U);
    for (uint32_t k = 0; k < K_SECT; k++) {
        sl_ground_sector_t *s = &g->sec[k];
        if (s->n == 0U || s->age > g->cfg.stale_rotations) {
            s->kind = SL_GROUND_FLAT;
            s->votes = 0U;
            continue;
        }
        const int32_t r = resid_q4(s, o);
        const uint64_t v = (uint64_t)sig2[k] + o->var_h_q8;
        s->resid_mm = r / 16;
        const int32_t ar = r < 0 ? -r : r;
        const int32_t lim = r > 0 ? drop : step;
        // the sigma (a square root) where it is reported: beyond the clearing level
        s->sigma_mm = ar * 3 >= lim * 2 || s->kind != SL_GROUND_FLAT
                          ? sat_u16(sl_fx_isqrt64(v) / 16U)
                          : 0U;
        if (!s->fresh || s->nv < (uint32_t)g->cfg.avg_rotations * g->cfg.reads) {
            continue; // no vote before the sector's scatter is known over a full window
        }
        uint8_t now;
        if (ar > lim && (uint64_t)ar * (uint64_t)ar > 16U * v) {
            now = r > 0 ? SL_GROUND_DROP : SL_GROUND_STEP;
        } else if (ar * 3 < lim * 2) {
            now = SL_GROUND_FLAT;
        } else {
            continue; // between the clearing level and the threshold: no vote either way
        }
        if (now == s->kind) {
            s->votes = 0U;
        } else {
            if (s->votes == 0U || s->vote_kind != now) {
                s->votes = 0U;
                s->vote_kind = now;
                // where the ray over the chassis edge meets the plane: the ground at the
                // plane's level ends inside that (rho = h / (tan(theta) - slope along))
                const sl_incline_geom_t *geo = &g->board->geom[azs[k]];
                const int64_t rho = (int64_t)sl_fx_isqrt64((uint64_t)((int64_t)s->x_um * s->x_um +
                                                                      (int64_t)s->y_um * s->y_um));
                int64_t along_q16 = 0;
                if (rho > 0) {
                    along_q16 = (o->a_raw_q12 * s->x_um + o->b_raw_q12 * s->y_um) / rho;
                }
                const int64_t tan_q16 =
                    geo->cos_theta_q30 > 0
                        ? ((int64_t)geo->sin_theta_q30 << 16) / geo->cos_theta_q30
                        : (int64_t)1 << 30;
                const int64_t den = tan_q16 - along_q16;
                const int64_t ring = den > 0 ? (((int64_t)o->h_q4 * 1000 / 16) << 16) / den : rho;
                // the point of the ring along the sector; the ground's end crossed the ring
                // between the last rotation on the plane and the next one (one step later):
                // the middle of that, moved back by the forward travel since
                if (rho > 0) {
                    s->hx_um = sl_fx_sat32((int64_t)s->x_um * ring / rho + g->step_x_um / 2 -
                                           (int64_t)s->since_mm * 1000);
                    s->hy_um = sl_fx_sat32((int64_t)s->y_um * ring / rho);
                }
                s->dist_um = hazard_dist(s);
            }
            s->votes++;
            if (s->votes >= g->cfg.confirm) {
                s->kind = now;
                s->votes = 0U;
            }
        }
    }
}

// One parameter: the fit's x (variance v) and the prior's xp (vp + q). A fit more than
// 4 sigma off the prior: the prior is dropped (the attitude really changed).
static bool fuse1(int64_t *x, uint64_t *v, int64_t xp, uint64_t vp, uint64_t q)
{
    const uint64_t vq = vp + q;
    const uint64_t vs = *v + vq;
    const int64_t d = *x - xp;
    const uint64_t ad = (uint64_t)(d < 0 ? -d : d);
    if (vs == 0U || ad > 4U * sl_fx_isqrt64(vs)) {
        return false;
    }
    // x + (xp - x) v / (v + vq): shifts keep the products in 64 bits
    int sh = 0;
    while ((vs >> sh) > ((uint64_t)1 << 30)) {
        sh++;
    }
    const int64_t num = (int64_t)(*v >> sh);
    const int64_t den = (int64_t)(vs >> sh);
    *x -= den > 0 ? (d * num) / den : 0;
    *v = den > 0 ? (uint64_t)(((*v >> sh) * (vq >> sh)) / (uint64_t)den) << sh : *v;
    return true;
}

// The plane filtered over rotations: the fit fused with the previous rotation's plane
// plus the process noise (SL_GROUND_Q_*: how far the attitude may move in a rotation);
// the result is the next rotation's prior.
static void fuse_prior(sl_ground_t *g, fit_out_t *o)
{
    if (g->prior_ok) {
        fit_out_t f = *o;
        bool ok = fuse1(&f.a_raw_q12, &f.var_a_q32, g->prior_a_q16, g->prior_va, SL_GROUND_Q_SLOPE);
        ok = ok && fuse1(&f.b_raw_q12, &f.var_b_q32, g->prior_b_q16, g->prior_vb, SL_GROUND_Q_SLOPE);
        int64_t h = f.h_q4;
        ok = ok && fuse1(&h, &f.var_h_q8, g->prior_h_q4, g->prior_vh, SL_GROUND_Q_H);
        f.h_q4 = (int32_t)h;
        if (ok) {
            *o = f;
        }
    }
    g->prior_ok = true;
    g->prior_a_q16 = sl_fx_sat32(o->a_raw_q12);
    g->prior_b_q16 = sl_fx_sat32(o->b_raw_q12);
    g->prior_h_q4 = o->h_q4;
    g->prior_va = o->var_a_q32 > UINT32_MAX ? UINT32_MAX : (uint32_t)o->var_a_q32;
    g->prior_vb = o->var_b_q32 > UINT32_MAX ? UINT32_MAX : (uint32_t)o->var_b_q32;
    g->prior_vh = o->var_h_q8 > UINT32_MAX ? UINT32_MAX : (uint32_t)o->var_h_q8;
}

// A hazard holds or is being voted for.
static bool suspect(const sl_ground_sector_t *s)
{
    return s->kind != SL_GROUND_FLAT || (s->votes > 0U && s->vote_kind != SL_GROUND_FLAT);
}

void sl_ground_end_rotation(sl_ground_t *g)
{
    SL_ASSERT(g != NULL);
    uint32_t w[SL_CFG_GROUND_SECTORS];
    uint32_t sig2[SL_CFG_GROUND_SECTORS];
    uint16_t azs[SL_CFG_GROUND_SECTORS];
    uint32_t n_flat = 0U;
    for (uint32_t k = 0; k < K_SECT; k++) {
        sl_ground_sector_t *s = &g->sec[k];
        if (s->age < UINT8_MAX && !s->fresh) {
            s->age++;
        }
        // travel towards the sector's direction: since its last sample on the plane, and
        // since a hazard's onset
        if (s->rot_n > 0U) {
            // the rotation's samples on the plane on average (within a quarter of the
            // threshold on their side): the ring still on the ground's level
            const int32_t mr = (int32_t)s->rot_sum_mm / (int32_t)s->rot_n;
            if (mr * 4000 < (int32_t)g->cfg.drop_um && -mr * 4000 < (int32_t)g->cfg.step_um) {
                s->since_mm = 0U;
            }
        }
        s->rot_sum_mm = 0;
        s->rot_n = 0U;
        if (g->moving) {
            // the forward travel: since the last rotation on the plane, and the hazard's
            // point moving back in the vehicle frame (straight motion)
            const int32_t sm = (int32_t)s->since_mm + g->step_x_um / 1000;
            s->since_mm = (uint16_t)(sm < 0 ? 0 : (sm > UINT16_MAX ? UINT16_MAX : sm));
            if (s->votes > 0U || s->kind != SL_GROUND_FLAT) {
                s->hx_um = sl_fx_sat32((int64_t)s->hx_um - g->step_x_um);
                s->dist_um = hazard_dist(s);
            }
        }
        azs[k] = sector_az(g, k);
        s->in_fit = s->n > 0U && s->age <= g->cfg.stale_rotations;
        sig2[k] = s->in_fit ? sector_sig2(g, s, azs[k]) : UINT32_MAX;
        w[k] = s->in_fit ? (uint32_t)(((uint64_t)1 << W_EXP) / sig2[k]) : 0U;
        if (s->in_fit && !suspect(s)) {
            n_flat++;
        }
    }
    // sectors with a hazard, confirmed or being voted for, stay out of the plane while
    // enough others remain
    if (n_flat >= SL_GROUND_MIN_SECTORS) {
        for (uint32_t k = 0; k < K_SECT; k++) {
            if (suspect(&g->sec[k])) {
                g->sec[k].in_fit = false;
            }
        }
    }
    // the gate: sectors far off the previous rotation's plane (its attitude can have moved
    // by the process noise since) stay out of this one's fit; a drop-off coming into the
    // ring ahead is then terrain, not pitch. Without enough sectors left, no gate.
    const uint32_t lim0 = g->cfg.drop_um < g->cfg.step_um ? g->cfg.drop_um : g->cfg.step_um;
    const int32_t half0 = (int32_t)(lim0 * 8U / 1000U);
    uint32_t gated = 0U;
    if (g->prior_ok) {
        fit_out_t pr;
        memset(&pr, 0, sizeof pr);
        pr.a_raw_q12 = g->prior_a_q16;
        pr.b_raw_q12 = g->prior_b_q16;
        pr.h_q4 = g->prior_h_q4;
        uint32_t left = 0U;
        for (uint32_t k = 0; k < K_SECT; k++) {
            sl_ground_sector_t *s = &g->sec[k];
            if (!s->in_fit) {
                continue;
            }
            const int32_t r = resid_q4(s, &pr);
            const int32_t ar = r < 0 ? -r : r;
            const uint64_t v = (uint64_t)sig2[k] + g->prior_vh + SL_GROUND_Q_H;
            if (ar > half0 && (uint64_t)ar * (uint64_t)ar > 4U * v) {
                s->in_fit = false;
                gated |= 1U << (k & 31U);
            } else {
                left++;
            }
        }
        if (left < SL_GROUND_MIN_SECTORS) {
            for (uint32_t k = 0; k < K_SECT; k++) {
                if ((gated >> (k & 31U)) & 1U) {
                    g->sec[k].in_fit = true;
                }
            }
        }
    }
    fit_out_t o;
    memset(&o, 0, sizeof o);
    bool ok = fit_plane(g, w, &o);
    if (ok) {
        // robust: the sectors far off the plane (beyond half the smaller threshold and
        // 2 sigma) leave it, twice (a drop-off over the front arc otherwise tilts it)
        const uint32_t lim = g->cfg.drop_um < g->cfg.step_um ? g->cfg.drop_um : g->cfg.step_um;
        const int32_t half = (int32_t)(lim * 8U / 1000U);
        for (int pass = 0; pass < 2; pass++) {
            bool out = false;
            for (uint32_t k = 0; k < K_SECT; k++) {
                sl_ground_sector_t *s = &g->sec[k];
                if (!s->in_fit) {
                    continue;
                }
                const int32_t r = resid_q4(s, &o);
                const int32_t ar = r < 0 ? -r : r;
                if (ar > half && (uint64_t)ar * (uint64_t)ar > 4U * (uint64_t)sig2[k]) {
                    s->in_fit = false;
                    out = true;
                }
            }
            fit_out_t o2;
            memset(&o2, 0, sizeof o2);
            if (!out || !fit_plane(g, w, &o2)) {
                break;
            }
            o = o2;
        }
        // dispersion: chi2 / dof above 1 widens the sigmas
        uint64_t chi2 = 0U;
        for (uint32_t k = 0; k < K_SECT; k++) {
            if (g->sec[k].in_fit) {
                const int64_t r = resid_q4(&g->sec[k], &o);
                chi2 += (uint64_t)(r * r) * w[k];
            }
        }
        chi2 >>= 12; // / 2^W_EXP, x 2^16
        const uint64_t dof = (uint64_t)o.n - 3U;
        const uint64_t disp_q16 = chi2 / dof;
        if (disp_q16 > 65536U) {
            o.var_a_q32 = o.var_a_q32 > (UINT64_MAX >> 20) ? UINT64_MAX >> 4 : (o.var_a_q32 * disp_q16) >> 16;
            o.var_b_q32 = o.var_b_q32 > (UINT64_MAX >> 20) ? UINT64_MAX >> 4 : (o.var_b_q32 * disp_q16) >> 16;
            o.var_h_q8 = o.var_h_q8 > (UINT64_MAX >> 20) ? UINT64_MAX >> 4 : (o.var_h_q8 * disp_q16) >> 16;
        }
        fuse_prior(g, &o);
    } else {
        g->prior_ok = false;
    }
    sl_ground_plane_t *pl = &g->plane;
    if (ok) {
        g->stats.planes++;
        pl->sectors = o.n;
        // the depth below the radar along the vehicle's z at its foot is h; the height
        // above the plane (perpendicular) is h / sqrt(1 + a^2 + b^2)
        const uint64_t n2 = ((uint64_t)1 << 32) + (uint64_t)(o.a_raw_q12 * o.a_raw_q12) +
                            (uint64_t)(o.b_raw_q12 * o.b_raw_q12);
        const uint64_t nq16 = sl_fx_isqrt64(n2);
        pl->height_mm = (int32_t)(((int64_t)o.h_q4 * 4096) / (int64_t)(nq16 > 0U ? nq16 : 1U));
        pl->slope_x_q16 = sl_fx_sat32(o.a_raw_q12);
        pl->slope_y_q16 = sl_fx_sat32(o.b_raw_q12);
        pl->pitch_cdeg = slope_cdeg(-o.a_raw_q12);
        pl->roll_cdeg = slope_cdeg(o.b_raw_q12);
        pl->height_sigma_mm = sat_u16(sl_fx_isqrt64(o.var_h_q8) / 16U);
        pl->pitch_sigma_cdeg = sigma_cdeg(o.var_a_q32);
        pl->roll_sigma_cdeg = sigma_cdeg(o.var_b_q32);
        const bool good = pl->height_sigma_mm <= g->cfg.good_sigma_mm &&
                          pl->pitch_sigma_cdeg <= g->cfg.good_sigma_cdeg &&
                          pl->roll_sigma_cdeg <= g->cfg.good_sigma_cdeg;
        pl->quality = good ? (uint8_t)SL_GROUND_GOOD : (uint8_t)SL_GROUND_COARSE;
        hazards(g, &o, sig2, azs);
    } else {
        g->stats.no_plane++;
        memset(pl, 0, sizeof *pl);
        pl->quality = SL_GROUND_NONE;
        for (uint32_t k = 0; k < K_SECT; k++) {
            if (g->sec[k].age > g->cfg.stale_rotations) {
                g->sec[k].kind = SL_GROUND_FLAT;
            }
        }
    }
    for (uint32_t k = 0; k < K_SECT; k++) {
        g->sec[k].fresh = false;
    }
    g->phase = (uint16_t)(g->phase + 1U);
    want_sector(g, 0U);
}

int sl_ground_worst(const sl_ground_t *g)
{
    SL_ASSERT(g != NULL);
    int best = -1;
    int32_t best_r = -1;
    for (uint32_t k = 0; k < K_SECT; k++) {
        const sl_ground_sector_t *s = &g->sec[k];
        const int32_t ar = s->resid_mm < 0 ? -s->resid_mm : s->resid_mm;
        if (s->kind != SL_GROUND_FLAT && ar > best_r) {
            best = (int)k;
            best_r = ar;
        }
    }
    return best;
}

int32_t sl_ground_sector_cdeg(const sl_ground_t *g, uint32_t k)
{
    SL_ASSERT(g != NULL);
    const uint32_t a2 = (uint32_t)sector_first(g, k) + (uint32_t)sector_first(g, k + 1U);
    int32_t c = (int32_t)((uint64_t)a2 * 18000U / g->board->azimuths) + g->board->radar_yaw_cdeg;
    c %= 36000;
    return c < 0 ? c + 36000 : c;
}

#endif // SL_CFG_GROUND
