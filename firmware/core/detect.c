// SPDX-License-Identifier: MIT
// Pole extraction inside the shadow, grouping over azimuths, corrections (sl_detect.h).
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_detect.h"

#include "bits.h"
#include "compiler.h"
#include "shadowlean/sl_fx.h"

#define CF_NEAR 0x01U
#define CF_SHADOW 0x02U
#define CF_SPAN 0x04U
#define CF_WRAPS 0x08U
#define CF_AMP 0x10U    // an amplitude row was seen for a run of the group
#define CF_STRONG 0x20U // ... and some run rose clearly above its floor
#define CF_TAIL 0x40U   // a run's tail crosses the edge within the bound of its own peak
                        // (the same bit as SL_TARGET_TAIL_EDGE, copied to the target)
#if CF_TAIL != SL_TARGET_TAIL_EDGE
#error "CF_TAIL must equal SL_TARGET_TAIL_EDGE"
#endif

#define ST_FREE 0U
#define ST_OPEN 1U
#define ST_CLOSED 2U

#define EMPTY_LO 0xFFFFU
// Depth of the inner-edge slab whose columns give the width radius (bins after the first).
#define RADIUS_SLAB_BINS 2U
#define EMPTY_HI 0U

// 2^32 / (2 pi), rounded: radians -> bam32.
#define BAM_PER_RAD 683565276ULL
// pi * 2^16, rounded: r * w_bam * pi / 2^32 = half-angle arc of a bam32 width w at range r.
#define PI_Q16 205887ULL

void sl_detect_cfg_default(sl_detect_cfg_t *cfg)
{
    SL_ASSERT(cfg != NULL);
    cfg->max_pole_diameter_um = 300000U;
    cfg->max_radius_um = 150000U;
    cfg->beam_width_cdeg = 180U;
    cfg->gap_bins = 2U;
    cfg->link_bins = 1U;
    cfg->width_slack_az = 1U;
    cfg->radius_from_width = true;
    cfg->weak_margin = 6U;
    cfg->weak_contrast = 20U;
    cfg->max_lean_tan_q16 = 37837U; // tan(30 deg) x 2^16
}

// ---- bit scanning: bits.h (shared with the range profiles)

// ---- geometry helpers

int32_t sl_detect_elong_um(const sl_board_t *board, uint32_t r_um)
{
    SL_ASSERT(board != NULL);
    const uint32_t n = board->elong_points;
    if (n == 0U) {
        return 0;
    }
    const uint32_t *r = board->elong_range_um;
    const int32_t *dv = board->elong_d_um;
    const uint32_t last = (n > SL_CFG_MAX_ELONG_POINTS ? SL_CFG_MAX_ELONG_POINTS : n) - 1U;
    if (r_um <= r[0]) {
        return dv[0];
    }
    if (r_um >= r[last]) {
        return dv[last];
    }
    uint32_t i = 0;
    while (i + 1U < last && r_um >= r[i + 1U]) {
        i++;
    }
    if (r[i + 1U] <= r[i]) {
        return dv[i]; // not ascending: no interpolation across a bad segment
    }
    const int64_t num = ((int64_t)dv[i + 1U] - (int64_t)dv[i]) * (int64_t)(r_um - r[i]);
    return sl_fx_sat32((int64_t)dv[i] + num / (int64_t)(r[i + 1U] - r[i]));
}

// S(az)^2 = shadow ground range^2 + H^2, um^2 (0 without shadow tables).
static uint64_t shadow_slant_sq(const sl_board_t *board, uint16_t az)
{
    uint64_t rs;
    if (board->shadow_um != NULL) {
        rs = board->shadow_um[az];
    } else if (board->shadow_bins != NULL) {
        rs = ((uint64_t)board->shadow_bins[az] + 1U) * board->bin_size_um;
    } else {
        return 0U;
    }
    const uint64_t h = board->radar_height_um;
    return rs * rs + h * h;
}

uint32_t sl_detect_shadow_slant_um(const sl_board_t *board, uint16_t az)
{
    SL_ASSERT(board != NULL);
    return sl_fx_isqrt64(shadow_slant_sq(board, az));
}

// r * w_bam * pi / 2^32: the half-width arc (small angle) of a bam32 angle w at range r.
static uint64_t half_arc_um(uint64_t r_um, uint64_t w_bam)
{
    // r * w * pi / 2^32 = (r * w) * PI_Q16 / 2^48, split so nothing overflows 64 bits
    // (r * w < 2^64 for r < 2^32 um and w <= 2^32; the dropped 24 bits are < 1 um).
    const uint64_t t = r_um * w_bam;
    return ((t >> 24) * PI_Q16) >> 24;
}

void sl_detect_correct(const sl_board_t *board, const sl_detect_cfg_t *cfg, uint16_t az,
                       uint16_t bin_first, uint16_t bin_last, uint16_t az_count,
                       sl_target_t *t)
{
    SL_ASSERT(board != NULL && t != NULL);
    sl_detect_cfg_t defcfg;
    if (cfg == NULL) {
        sl_detect_cfg_default(&defcfg);
        cfg = &defcfg;
    }
    (void)az;
    const uint64_t b = board->bin_size_um;
    t->r1_raw_um = sl_fx_usat32((int64_t)((uint64_t)bin_first * b));
    t->r2_raw_um = sl_fx_usat32((int64_t)(((uint64_t)bin_last + 1U) * b));
    // Half-bin: the centres of the first and last occupied bins, rounded half up.
    const uint64_t r1_hb = (((uint64_t)2U * bin_first + 1U) * b + 1U) / 2U;
    const uint64_t r2_hb = (((uint64_t)2U * bin_last + 1U) * b + 1U) / 2U;
    const int32_t d = sl_detect_elong_um(board, sl_fx_usat32((int64_t)r2_hb));
    t->elong_um = d;
    t->flags = (uint16_t)(t->flags & ~(SL_TARGET_RADIUS_BOARD | SL_TARGET_RADIUS_WIDTH |
                                       SL_TARGET_RADIUS_CLAMPED | SL_TARGET_ELONG));
    if (d != 0) {
        t->flags |= SL_TARGET_ELONG;
    }
    int64_t r2 = (int64_t)r2_hb - (int64_t)d;
    const uint64_t beam_bam = ((uint64_t)cfg->beam_width_cdeg << 32) / 36000U;
    uint64_t radius;
    if (board->pole_radius_um != 0U) {
        radius = board->pole_radius_um;
        t->flags |= SL_TARGET_RADIUS_BOARD;
    } else if (!cfg->radius_from_width) {
        radius = 0U;
    } else {
        const uint64_t step = board->azimuths != 0U ? ((uint64_t)1U << 32) / board->azimuths
                                                   : 0U;
        const uint64_t width = (az_count > 0U ? (uint64_t)az_count - 1U : 0U) * step;
        radius = width > beam_bam ? half_arc_um(r1_hb, width - beam_bam) : 0U;
        t->flags |= SL_TARGET_RADIUS_WIDTH;
        // A beam footprint wider than four times the estimated diameter cannot resolve
        // it: one azimuth step more or less is then most of the estimate (docs/DESIGN.md,
        // "Detection"; a 60 mm pole under a 1.8 deg beam at 4 m is still resolved).
        if (half_arc_um(r1_hb, beam_bam) > 4U * radius) {
            radius = 0U;
        }
        if (radius > cfg->max_radius_um) {
            radius = cfg->max_radius_um;
            t->flags |= SL_TARGET_RADIUS_CLAMPED;
        }
    }
    t->radius_um = (uint32_t)radius;
    // Front surface -> axis on r1; on r2 only the part of the radius the beam does not see
    // around the silhouette (L = half footprint of the beam at r1).
    const uint64_t l = half_arc_um(r1_hb, beam_bam);
    if (radius > l) {
        r2 += (int64_t)sl_fx_isqrt64(radius * radius - l * l);
    }
    t->r1_um = sl_fx_usat32((int64_t)(r1_hb + radius));
    t->r2_um = sl_fx_usat32(r2);
}

uint32_t sl_detect_r1_sigma_um(const sl_target_t *t, uint32_t base_um)
{
    SL_ASSERT(t != NULL);
    if ((t->flags & SL_TARGET_RADIUS_WIDTH) == 0U || t->radius_um == 0U) {
        return base_um;
    }
    const uint64_t r = t->radius_um;
    return sl_fx_isqrt64((uint64_t)base_um * base_um + (r * r + 1U) / 3U);
}

uint32_t sl_detect_union_r1_um(const sl_target_t *t, uint32_t bin_um)
{
    SL_ASSERT(t != NULL);
    const uint64_t sub = (uint64_t)(t->ext_grow & 15U) * bin_um +
                         ((t->flags & SL_TARGET_RADIUS_WIDTH) != 0U ? t->radius_um : 0U);
    return (uint64_t)t->r1_um > sub ? (uint32_t)(t->r1_um - sub) : 0U;
}

// ---- groups

static void ext_union(uint16_t *lo, uint16_t *hi, uint16_t f, uint16_t l)
{
    if (f < *lo) {
        *lo = f;
    }
    if (l > *hi) {
        *hi = l;
    }
}

static void entry_add(sl_detect_azrun_t *e, uint16_t f, uint16_t l, uint16_t count)
{
    if (e->count == 0U) {
        e->first = f;
        e->last = l;
    } else {
        e->first = f < e->first ? f : e->first;
        e->last = l > e->last ? l : e->last;
    }
    const uint32_t n = (uint32_t)e->count + count;
    e->count = (uint16_t)(n > 0xFFFFU ? 0xFFFFU : n);
}

// Extent of c on azimuth x (x in {az_last - 1, az_last}), or empty.
static void ext_at(const sl_detect_cand_t *c, uint32_t x, uint16_t *lo, uint16_t *hi)
{
    if (x == c->az_last) {
        *lo = c->last_lo;
        *hi = c->last_hi;
    } else if (x + 1U == c->az_last && c->az_first <= x) {
        *lo = c->prev_lo;
        *hi = c->prev_hi;
    } else {
        *lo = EMPTY_LO;
        *hi = EMPTY_HI;
    }
}

static bool overlaps(uint16_t lo, uint16_t hi, uint32_t f, uint32_t l, uint32_t tol)
{
    return lo <= hi && f <= (uint32_t)hi + tol && (uint32_t)lo <= l + tol;
}

// Strength class of a run's or a group's flags: weak = an amplitude row was seen and nothing
// rose clearly above the threshold or its floor (CF_AMP without CF_STRONG); strong = CF_STRONG;
// neither (no amplitude row, or a run at the shadow edge, which is not graded) links to both.
static inline bool is_weak(uint8_t flags)
{
    return (flags & (CF_AMP | CF_STRONG)) == CF_AMP;
}

// Move src's azimuth entries into dst at offset (src first azimuth - dst first azimuth).
// dst_span: dst's entries in use (0 .. dst_span - 1); those src reaches beyond them start
// empty (entries beyond a group's span are never initialised: sl_detect_cand_t).
static void entries_merge(sl_detect_cand_t *dst, const sl_detect_cand_t *src, uint32_t offset,
                          uint32_t dst_span)
{
    const uint32_t span = (uint32_t)src->az_last - src->az_first + 1U;
    for (uint32_t k = dst_span; k < offset + span && k < SL_CFG_DETECT_MAX_SPAN; k++) {
        dst->run[k].count = 0U;
    }
    for (uint32_t i = 0; i < span && i < SL_CFG_DETECT_MAX_SPAN; i++) {
        const sl_detect_azrun_t *e = &src->run[i];
        if (e->count == 0U) {
            continue;
        }
        if (offset + i < SL_CFG_DETECT_MAX_SPAN) {
            // the peaks (read only while d->peaks, when every entry of the rotation has one)
            const uint8_t pk = src->peak[i], pd = dst->peak[offset + i];
            dst->peak[offset + i] = dst->run[offset + i].count == 0U || pk > pd ? pk : pd;
            entry_add(&dst->run[offset + i], e->first, e->last, e->count);
        } else {
            dst->flags |= CF_SPAN;
        }
    }
    if (span > SL_CFG_DETECT_MAX_SPAN) {
        dst->flags |= CF_SPAN;
    }
}

// Open groups are also kept in a bitmap so that the per-row loops visit only them (a long
// rotation can keep one group open across many azimuths, e.g. ground at the shadow edge
// while moving).
#define OPEN_WORDS ((SL_CFG_DETECT_MAX_CANDIDATES + 31) / 32)

static void open_set(sl_detect_t *d, const sl_detect_cand_t *c)
{
    const uint32_t i = (uint32_t)(c - d->cand);
    d->open_bits[i >> 5] |= (uint32_t)1U << (i & 31U);
}

static void open_clr(sl_detect_t *d, const sl_detect_cand_t *c)
{
    const uint32_t i = (uint32_t)(c - d->cand);
    d->open_bits[i >> 5] &= ~((uint32_t)1U << (i & 31U));
}

// Merge src into dst; both are open and touch azimuth a - 1 or a. Not inlined: a rare path,
// out of the run loop (inlined it cost that loop 14 instructions per azimuth on the clutter
// capture).
static SL_NOINLINE void cand_merge(sl_detect_t *d, sl_detect_cand_t *dst,
                                   sl_detect_cand_t *src)
{
    const uint32_t last = dst->az_last > src->az_last ? dst->az_last : src->az_last;
    uint16_t llo = EMPTY_LO, lhi = EMPTY_HI, plo = EMPTY_LO, phi = EMPTY_HI, lo, hi;
    ext_at(dst, last, &lo, &hi);
    ext_union(&llo, &lhi, lo, hi);
    ext_at(src, last, &lo, &hi);
    ext_union(&llo, &lhi, lo, hi);
    ext_at(dst, last - 1U, &lo, &hi);
    ext_union(&plo, &phi, lo, hi);
    ext_at(src, last - 1U, &lo, &hi);
    ext_union(&plo, &phi, lo, hi);
    if (src->az_first < dst->az_first) {
        // Shift dst's entries right to make room in front.
        const uint32_t sh = (uint32_t)dst->az_first - src->az_first;
        for (uint32_t i = SL_CFG_DETECT_MAX_SPAN; i-- > 0U;) {
            if (i >= sh) {
                dst->run[i] = dst->run[i - sh];
                dst->peak[i] = dst->peak[i - sh];
            } else {
                dst->run[i].count = 0U;
            }
        }
        // Entries pushed past the end: only possible when the merged span overflows.
        if ((uint32_t)dst->az_last - src->az_first + 1U > SL_CFG_DETECT_MAX_SPAN) {
            dst->flags |= CF_SPAN;
        }
        dst->az_first = src->az_first;
    }
    entries_merge(dst, src, (uint32_t)src->az_first - dst->az_first,
                  (uint32_t)dst->az_last - dst->az_first + 1U);
    dst->flags |= src->flags;
    dst->az_last = (uint16_t)last;
    dst->last_lo = llo;
    dst->last_hi = lhi;
    dst->prev_lo = plo;
    dst->prev_hi = phi;
    src->state = ST_FREE; // src was open
    open_clr(d, src);
    d->n_open--;
}

static void cand_attach(sl_detect_cand_t *c, uint32_t a, uint16_t f, uint16_t l, uint16_t count,
                        uint8_t rflags)
{
    if ((uint32_t)c->az_last + 1U == a) {
        c->prev_lo = c->last_lo;
        c->prev_hi = c->last_hi;
        c->last_lo = f;
        c->last_hi = l;
        c->az_last = (uint16_t)a;
        if (a - c->az_first < SL_CFG_DETECT_MAX_SPAN) {
            c->run[a - c->az_first].count = 0U; // a new azimuth: its entry starts empty
        }
    } else {
        ext_union(&c->last_lo, &c->last_hi, f, l);
    }
    const uint32_t idx = a - c->az_first;
    if (idx < SL_CFG_DETECT_MAX_SPAN) {
        entry_add(&c->run[idx], f, l, count);
    } else {
        c->flags |= CF_SPAN;
    }
    c->flags |= rflags;
}

// The link table (sl_detect_links_t) of a row: the groups open when azimuth a's row began
// (all end on a - 1; a group opened by an earlier run of this row has no extent on a - 1
// and cannot link), in slot order, each with its extent on a - 1 (hi widened by
// cfg.link_bins). A merge points the absorbed group's entries at the survivor and widens
// both to the survivor's union extent, so a later run sees exactly what it would see
// walking the open groups (first linkable in slot order = survivor, merged extents), at a
// compare or two per group instead of a walk of the open set.
//
// Run [f, l] on azimuth a (flags rflags) continues each group whose extent on a - 1 it
// overlaps (cfg.link_bins of slack) and which is of the same strength class: a weak run
// never joins a group holding a strong one and a strong run never joins a group of weak
// runs (sl_detect.h stage 2: weak clutter can neither widen, break nor bridge a pole's
// group). The first such group in slot order takes the run and absorbs the others; none:
// a new group.
static sl_detect_cand_t *add_run(sl_detect_t *d, sl_detect_links_t *t, uint32_t a, uint32_t f,
                                 uint32_t l, uint32_t count, uint8_t rflags)
{
    d->stats.runs++;
    sl_detect_cand_t *dst = NULL;
    const uint32_t l_tol = l + d->cfg.link_bins;
    const uint32_t n = t->n;
    for (uint32_t k = 0; k < n; k++) {
        if (f > t->hi_tol[k] || t->lo[k] > l_tol) {
            continue;
        }
        sl_detect_cand_t *c = &d->cand[t->slot[k]];
        if (c == dst || (is_weak(rflags) && (c->flags & CF_STRONG) != 0U) ||
            ((rflags & CF_STRONG) != 0U && is_weak(c->flags))) {
            continue;
        }
        if (dst == NULL) {
            dst = c;
            continue;
        }
        cand_merge(d, dst, c);
        uint16_t lo, hi;
        ext_at(dst, a - 1U, &lo, &hi);
        const uint32_t h = (uint32_t)hi + d->cfg.link_bins;
        const uint8_t ds = (uint8_t)(dst - d->cand), cs = (uint8_t)(c - d->cand);
        for (uint32_t j = 0; j < n; j++) {
            if (t->slot[j] == cs || t->slot[j] == ds) {
                t->slot[j] = ds;
                t->lo[j] = lo;
                t->hi_tol[j] = (uint16_t)(h > 0xFFFFU ? 0xFFFFU : h);
            }
        }
    }
    if (dst == NULL) {
        for (uint32_t i = 0; i < SL_CFG_DETECT_MAX_CANDIDATES; i++) {
            if (d->cand[i].state == ST_FREE) {
                dst = &d->cand[i];
                break;
            }
        }
        if (dst == NULL) {
            d->stats.cand_overflow++;
            return NULL;
        }
        // Only the header and the first entry: entries join as the group grows.
        dst->state = ST_OPEN;
        dst->flags = 0U;
        open_set(d, dst);
        d->n_open++;
        dst->az_first = (uint16_t)a;
        dst->az_last = (uint16_t)a;
        dst->last_lo = (uint16_t)f;
        dst->last_hi = (uint16_t)l;
        dst->prev_lo = EMPTY_LO;
        dst->prev_hi = EMPTY_HI;
        dst->run[0].count = 0U;
    }
    cand_attach(dst, a, (uint16_t)f, (uint16_t)l, (uint16_t)(count > 0xFFFFU ? 0xFFFFU : count),
                rflags);
    return dst;
}

// Width test: most azimuths a pole of diameter D at range r1 can cover.
static uint32_t allowed_span(const sl_detect_t *d, uint32_t r1_um)
{
    if (r1_um == 0U || d->step_bam == 0U) {
        return 0xFFFFFFFFU;
    }
    const uint64_t w = (uint64_t)d->cfg.max_pole_diameter_um * BAM_PER_RAD / r1_um +
                       d->beam_bam;
    const uint64_t n = w / d->step_bam + 1U + d->cfg.width_slack_az;
    return n > 0xFFFFFFFFU ? 0xFFFFFFFFU : (uint32_t)n;
}

// ---- clutter rejection and slots by evidence (stage 4 clutter tests, stage 4b)

// rho of the run as measured: r2 before the board's elongation model d(r2) was subtracted.
// Smear only lengthens a return, so this is an upper bound of the true ratio whatever the
// actual smear; d is a model (tabulated for one sensor setting, or not calibrated at all)
// and may overcorrect by many bins. Never below the corrected rho (a negative d).
static uint64_t rho_measured_q28(const sl_target_t *t, uint32_t rho_q28)
{
    uint64_t rho = rho_q28;
    if ((t->elong_um > 0) && (t->r1_um != 0U)) {
        const uint64_t r2m = (uint64_t)t->r2_um + (uint64_t)(uint32_t)t->elong_um;
        const uint64_t m = (r2m << 28) / t->r1_um;
        rho = (m > rho) ? m : rho;
    }
    return rho;
}

int sl_detect_clutter_reason(const sl_board_t *board, const sl_target_t *t, uint32_t rho_q28)
{
    SL_ASSERT(board != NULL && t != NULL);
    if (t->bin_last <= t->bin_first) {
        return SL_DETECT_REJ_SHORT;
    }
    if (board->geom == NULL) {
        return -1; // no tables: no model to test
    }
    if (t->incline_flag == (uint8_t)SL_INCLINE_OUT_OF_DOMAIN) {
        return SL_DETECT_REJ_RHO;
    }
    if (t->incline_flag == (uint8_t)SL_INCLINE_INVALID ||
        t->incline_flag == (uint8_t)SL_INCLINE_AMBIGUOUS) {
        if (t->r1_um == 0U) {
            return SL_DETECT_REJ_RHO;
        }
        // The test is on the measured run, not on the elongation-corrected r2: a return
        // whose corrected r2 falls at or below r1 (INVALID) or below the fold may still be
        // a pole leaning away, smeared less than the model says (docs/DESIGN.md, "Range
        // extraction").
        const uint64_t rho = rho_measured_q28(t, rho_q28);
        if ((t->incline_flag == (uint8_t)SL_INCLINE_INVALID) && (rho <= ((uint64_t)1U << 28))) {
            return SL_DETECT_REJ_RHO; // r1 >= r2 even as measured
        }
        // One bin of quantisation below the fold, in UQ4.28: b / r1 * 2^28.
        const uint64_t tol = ((uint64_t)board->bin_size_um << 28) / t->r1_um;
        const uint64_t amb = board->geom[t->az].rho_amb_q28;
        if ((rho + tol) < amb) {
            return SL_DETECT_REJ_RHO;
        }
    }
    return -1;
}

uint16_t sl_detect_evidence(uint32_t occupied_total, uint32_t az_with_run, uint32_t extent_bins)
{
    const uint64_t e = 4ULL * occupied_total + 16ULL * az_with_run + 8ULL * extent_bins;
    return (uint16_t)(e > 0xFFFFU ? 0xFFFFU : e);
}

void sl_detect_hints_clear(sl_detect_t *d)
{
    SL_ASSERT(d != NULL);
    memset(d->hint_bits, 0, sizeof d->hint_bits);
}

void sl_detect_hint(sl_detect_t *d, uint16_t az, uint16_t half_width)
{
    SL_ASSERT(d != NULL);
    const uint32_t n = d->azimuths;
    if (az >= n || n == 0U) {
        return;
    }
    const uint32_t w = (uint32_t)half_width * 2U + 1U;
    const uint32_t cnt = w < n ? w : n;
    uint32_t a = ((uint32_t)az + n - ((uint32_t)half_width % n)) % n;
    for (uint32_t i = 0; i < cnt; i++) {
        d->hint_bits[a >> 5] |= (uint32_t)1U << (a & 31U);
        a = a + 1U == n ? 0U : a + 1U;
    }
}

// A target that passed every test takes a free slot; with none free it replaces the target
// with the least evidence when it has more (ties keep the earlier one). One drop counted
// either way.
static void slot_take(sl_detect_t *d, const sl_target_t *t)
{
    if (d->n_targets < d->max_targets) {
        d->targets[d->n_targets++] = *t;
        d->stats.targets++;
        return;
    }
    d->stats.target_overflow++;
    if (d->n_targets == 0U) {
        return;
    }
    uint32_t weakest = 0;
    for (uint32_t i = 1; i < d->n_targets; i++) {
        if (d->targets[i].evidence < d->targets[weakest].evidence) {
            weakest = i;
        }
    }
    if (t->evidence > d->targets[weakest].evidence) {
        d->targets[weakest] = *t;
    }
}

// Whether azimuth `a` is hinted (sl_detect_hint: a confirmed track is expected there).
static inline bool is_hinted(const sl_detect_t *d, uint32_t a)
{
    return ((d->hint_bits[a >> 5] >> (a & 31U)) & 1U) != 0U;
}

// Last bin of an entry's own return (sl_detect.h stage 4): its last bin less the smear tail
// its peak leaves, floor((peak - T) / slope) bins with the stream's self-calibrated slope,
// at least its first bin; without a measured peak or a slope, its last bin.
static uint32_t own_last(const sl_detect_t *d, const sl_detect_cand_t *c, uint32_t i)
{
    const sl_detect_azrun_t *r = &c->run[i];
    const uint32_t t = d->amp_threshold, peak = c->peak[i];
    if (!d->peaks || peak <= t) {
        return r->last;
    }
    const uint32_t tail = (peak - t) * 256U / d->tail_slope_q8;
    return (uint32_t)r->last >= (uint32_t)r->first + tail ? (uint32_t)r->last - tail : r->first;
}

// Whether entry `i`'s smear tail (own_last) is at least `missing` bins long: its run may
// miss that many near the threshold. Without the division: floor((peak - T) 256 / slope)
// >= m <=> (peak - T) 256 >= m slope (own_last's tail is also capped at last - first, which
// a run missing bins always exceeds).
static bool tail_holds(const sl_detect_t *d, const sl_detect_cand_t *c, uint32_t i,
                       uint32_t missing)
{
    const uint32_t t = d->amp_threshold, peak = c->peak[i];
    return d->peaks && peak > t && (peak - t) * 256U >= missing * (uint32_t)d->tail_slope_q8;
}

// WIDE exception for a pole leaning across the line of sight (sl_detect.h stage 4, "Leaning
// across the line of sight"): true when the group of `span` azimuths (wider than a vertical
// pole at its representative run `rep`) is one line, thin and no wider than a lean of
// cfg.max_lean_tan_q16 can make it; then its union extent in *uf_out, *ul_out and the offset
// of its new representative azimuth (the pole's lowest point) in *bottom. Not inlined: a
// rare path (groups wider than a pole, while moving), off finalize's stack frame.
static SL_NOINLINE bool slender_lean(const sl_detect_t *d, const sl_detect_cand_t *c, uint32_t span,
                                     const sl_detect_azrun_t *rep, uint16_t az, uint16_t *uf_out,
                                     uint16_t *ul_out, uint32_t *bottom)
{
    const sl_board_t *bd = d->board;
    if (d->cfg.max_lean_tan_q16 == 0U || bd->geom == NULL || span > SL_CFG_DETECT_MAX_SPAN) {
        return false;
    }
    // One line crossing the azimuths: every run whole (no gap), and the runs stepping through
    // range one way (each first and last bin at most one bin against the direction of the
    // group's ends: a speckled edge). Weak clutter along the shadow edge is broken and
    // wanders.
    const sl_detect_azrun_t *r0 = &c->run[0];
    const sl_detect_azrun_t *rn = &c->run[span - 1U];
    const bool down = rn->first < r0->first;
    uint32_t uf = rep->first, ul = rep->last, occ = 0U, pf = 0U, pl = 0U, own_max = 0U;
    bool first_run = true;
    for (uint32_t i = 0; i < span; i++) {
        const sl_detect_azrun_t *r = &c->run[i];
        if (r->count == 0U) {
            continue;
        }
        // Whole, but for gaps the smear tail can hold: bins missed near the threshold
        // behind the own extent (no more than the tail's bins). A weak run leaves no tail
        // and must be whole.
        const uint32_t own = own_last(d, c, i);
        if ((uint32_t)r->count + ((uint32_t)r->last - own) < (uint32_t)r->last - r->first + 1U) {
            return false;
        }
        // An own last bin estimated from the peak and the tail's end (own < last) is as
        // noisy as that end: two bins against the direction (one for a first bin, or a run
        // without a tail: weak clutter's runs have none).
        uint32_t ot = 1U;
        if (own < (uint32_t)r->last) {
            ot = 2U;
        }
        if (!first_run && (down ? (r->first > pf + 1U || own > pl + ot)
                                : (r->first + 1U < pf || own + ot < pl))) {
            return false;
        }
        first_run = false;
        pf = r->first;
        pl = own;
        uf = r->first < uf ? r->first : uf;
        ul = r->last > ul ? r->last : ul;
        own_max = own > own_max ? own : own_max;
        occ += own - r->first + 1U;
    }
    const uint32_t allowed = allowed_span(d, uf * bd->bin_size_um + bd->bin_size_um / 2U);
    if (occ > (own_max - uf + 1U) * allowed) {
        return false; // fills the span like a wall, not like one line crossing it
    }
    const uint64_t b = bd->bin_size_um;
    const uint64_t r_first = (2U * (uint64_t)uf + 1U) * b / 2U;
    const uint64_t r_last = (2U * (uint64_t)ul + 1U) * b / 2U;
    const sl_incline_geom_t *g = &bd->geom[az];
    const uint64_t sin_t = g->sin_theta_q30 > 0 ? (uint64_t)g->sin_theta_q30 : 0U;
    const uint64_t sin_b = g->sin_beta_q30 > 0 ? (uint64_t)g->sin_beta_q30 : 0U;
    // visible height (um) x tan(max lean): the sideways reach of the pole's top
    const uint64_t height = (r_last * sin_t + r_first * sin_b) >> 30;
    const uint64_t reach = (height * d->cfg.max_lean_tan_q16) >> 16;
    const uint64_t w_bam = reach * BAM_PER_RAD / r_first;
    if ((uint64_t)span > (uint64_t)allowed + (w_bam + d->step_bam - 1U) / d->step_bam) {
        return false;
    }
    *uf_out = (uint16_t)uf;
    *ul_out = (uint16_t)ul;
    // The representative: of the azimuths whose run ends on ul (the pole's lowest visible
    // point, which a beam width sees on 2-3 of them), the middle one.
    uint32_t lo = span, hi = 0U;
    for (uint32_t i = 0; i < span; i++) {
        if (c->run[i].count != 0U && own_last(d, c, i) == own_max) {
            lo = i < lo ? i : lo;
            hi = i;
        }
    }
    *bottom = (lo + hi) / 2U;
    return true;
}

// sl_target_t.ext_grow of a group: its union extent (min first / max last bin over all its
// azimuths) beyond the representative run, two saturating nibbles.
static uint8_t union_grow(const sl_detect_cand_t *c, const sl_detect_azrun_t *rep, uint32_t span)
{
    uint32_t f = rep->first, l = rep->last;
    for (uint32_t i = 0; i < span && i < SL_CFG_DETECT_MAX_SPAN; i++) {
        if (c->run[i].count != 0U) {
            f = c->run[i].first < f ? c->run[i].first : f;
            l = c->run[i].last > l ? c->run[i].last : l;
        }
    }
    f = (uint32_t)rep->first - f;
    l -= rep->last;
    return (uint8_t)((f < SL_TARGET_EXT_SAT ? f : SL_TARGET_EXT_SAT) |
                     ((l < SL_TARGET_EXT_SAT ? l : SL_TARGET_EXT_SAT) << 4));
}

// A finalized group leaves the open set (its span overflow counted).
static void group_release(sl_detect_t *d, sl_detect_cand_t *c)
{
    if ((c->flags & CF_SPAN) != 0U) {
        d->stats.span_overflow++;
    }
    c->state = ST_FREE;
    open_clr(d, c);
}

static void finalize(sl_detect_t *d, sl_detect_cand_t *c)
{
    d->stats.groups++;
    const sl_board_t *bd = d->board;
    const uint32_t span = (uint32_t)c->az_last - c->az_first + 1U;
    if ((c->flags & (CF_NEAR | CF_SHADOW)) == 0U && is_weak(c->flags)) {
        // A group of weak runs only (stage 2 keeps them apart from strong ones) is clutter
        // whatever its shape: WEAK, before the tests that need its representative run.
        group_release(d, c);
        d->stats.rejected[SL_DETECT_REJ_WEAK]++;
        return;
    }
    // Representative azimuth: most occupied bins, then nearest the middle, then lowest.
    uint32_t best = 0, best_cnt = 0, best_dist = 0xFFFFFFFFU;
    for (uint32_t i = 0; i < span && i < SL_CFG_DETECT_MAX_SPAN; i++) {
        const uint32_t cnt = c->run[i].count;
        const uint32_t two_i = 2U * i;
        const uint32_t dist = two_i > span - 1U ? two_i - (span - 1U) : (span - 1U) - two_i;
        if (cnt > best_cnt || (cnt == best_cnt && cnt > 0U && dist < best_dist)) {
            best = i;
            best_cnt = cnt;
            best_dist = dist;
        }
    }
    const sl_detect_azrun_t *rep = &c->run[best];
    uint16_t az = (uint16_t)(((uint32_t)c->az_first + best) % d->azimuths);
    sl_target_t t;
    memset(&t, 0, sizeof t);
    t.az = az;
    t.az_first = c->az_first;
    t.az_count = (uint16_t)(span > 0xFFFFU ? 0xFFFFU : span);
    t.bin_first = rep->first;
    t.bin_last = rep->last;
    t.occupied = (uint8_t)(rep->count < 0xFFU ? rep->count : 0xFFU);
    // Radius width (docs/DESIGN.md, "Detection"): the contiguous columns around the representative
    // azimuth whose run reaches into the slab [first, first + RADIUS_SLAB_BINS] at the
    // pole's inner edge, not the whole group, which a leaning pole widens in bearing along
    // its length.
    // The slab is RADIUS_SLAB_BINS + 1 bins deep: the silhouette of a round pole lies about
    // R behind its front surface, which only the middle columns show.
    const uint32_t slab = (uint32_t)rep->first + RADIUS_SLAB_BINS;
    uint32_t lo = best, hi = best;
    while (lo > 0U && c->run[lo - 1U].count != 0U && c->run[lo - 1U].first <= slab &&
           c->run[lo - 1U].last >= rep->first) {
        lo--;
    }
    while (hi + 1U < span && hi + 1U < SL_CFG_DETECT_MAX_SPAN && c->run[hi + 1U].count != 0U &&
           c->run[hi + 1U].first <= slab && c->run[hi + 1U].last >= rep->first) {
        hi++;
    }
    // A group wider than a vertical pole can be: a pole leaning across the line of sight
    // (stage 4) when slender; its bounds are then the union extent.
    const uint32_t allowed = allowed_span(d, (uint32_t)rep->first * bd->bin_size_um +
                                                 bd->bin_size_um / 2U);
    bool slant = false;
    if (span > allowed && d->slant && (c->flags & (CF_SPAN | CF_NEAR | CF_SHADOW)) == 0U &&
        slender_lean(d, c, span, rep, az, &t.bin_first, &t.bin_last, &best)) {
        slant = true; // bounds: the union extent; representative: the lowest point's azimuth
        rep = &c->run[best];
        az = (uint16_t)(((uint32_t)c->az_first + best) % d->azimuths);
        t.az = az;
        t.occupied = (uint8_t)(rep->count < 0xFFU ? rep->count : 0xFFU);
        lo = hi = best; // no radius from the width of a leaning pole
    }
    // The tests on the group's shape first (SHORT among them: a single-bin run, most of the
    // strong clutter); the corrections (an isqrt or two) only for a group that passes them,
    // then SHADOW on its corrected r2.
    int reason = -1;
    if ((c->flags & CF_NEAR) != 0U) {
        reason = SL_DETECT_REJ_NEAR;
    } else if ((c->flags & CF_SHADOW) != 0U) {
        reason = SL_DETECT_REJ_SHADOW;
    } else if ((c->flags & CF_SPAN) != 0U || (span > allowed && !slant)) {
        reason = SL_DETECT_REJ_WIDE;
    } else if ((uint32_t)rep->count < (uint32_t)rep->last - rep->first + 1U &&
               !tail_holds(d, c, best, (uint32_t)rep->last - rep->first + 1U - rep->count)) {
        // a gap, but for the bins a smear tail can miss near the threshold (as stage 4's
        // one line: no more than its tail's bins; a run without a tail must be whole)
        reason = SL_DETECT_REJ_BROKEN;
    } else if (t.bin_last <= t.bin_first) {
        reason = SL_DETECT_REJ_SHORT; // as sl_detect_clutter_reason, before the corrections
    }
    group_release(d, c);
    if (reason < 0) {
        sl_detect_correct(bd, &d->cfg, az, t.bin_first, t.bin_last, (uint16_t)(hi - lo + 1U),
                          &t);
        // r2 >= S = floor(sqrt(S^2)) <=> (r2 + 1)^2 > S^2: the square root (sl_target_t's
        // shadow_slant_um) only for an accepted target, below.
        // (S < 2^32: a saturated r2 is beyond it, and its square would wrap)
        const uint64_t r2p = (uint64_t)t.r2_um + 1U;
        if ((c->flags & CF_TAIL) == 0U &&
            (t.r2_um == UINT32_MAX || r2p * r2p > shadow_slant_sq(bd, az))) {
            reason = SL_DETECT_REJ_SHADOW;
        }
    }
    if (reason >= 0) {
        d->stats.rejected[reason]++;
        return;
    }
    if ((c->flags & CF_WRAPS) != 0U) {
        t.flags |= SL_TARGET_WRAPS;
    }
    if (slant) {
        t.flags |= SL_TARGET_SLANT;
    }
    t.flags |= (uint8_t)(c->flags & CF_TAIL); // CF_TAIL == SL_TARGET_TAIL_EDGE
    uint32_t rho_q28 = 0U;
    if (bd->geom != NULL) {
        // Sigma of the bounds: r1 with a radius from width is uncertain by the radius.
        const uint32_t s1 = sl_detect_r1_sigma_um(&t, bd->range_sigma_um);
        uint32_t sigma_r = bd->range_sigma_um;
        if (s1 != sigma_r) {
            sigma_r = sl_incline_bounds_sigma_um(t.r1_um, t.r2_um, s1, bd->range_sigma_um);
            t.flags |= SL_TARGET_COARSE;
        }
        const sl_incline_result_t res = sl_incline_estimate(t.r1_um, t.r2_um, &bd->geom[az],
                                                            sigma_r, bd->theta_sigma_cdeg);
        t.alpha_cdeg = res.alpha_cdeg;
        t.sigma_cdeg = res.sigma_cdeg;
        t.incline_flag = res.flag;
        t.incline_branch = res.branch;
        rho_q28 = res.rho_q28;
    } else {
        t.incline_flag = (uint8_t)SL_INCLINE_OUT_OF_DOMAIN;
    }
    reason = sl_detect_clutter_reason(bd, &t, rho_q28);
    if (reason >= 0) {
        d->stats.rejected[reason]++;
        return;
    }
    uint32_t occ_total = 0U, az_runs = 0U;
    for (uint32_t i = 0; i < span && i < SL_CFG_DETECT_MAX_SPAN; i++) {
        occ_total += c->run[i].count;
        az_runs += c->run[i].count != 0U ? 1U : 0U;
    }
    t.evidence = sl_detect_evidence(occ_total, az_runs, (uint32_t)rep->last - rep->first + 1U);
    if (d->union_ext && !slant) {
        t.ext_grow = union_grow(c, rep, span);
    }
    if (is_hinted(d, az)) {
        const uint32_t e = (uint32_t)t.evidence + SL_DETECT_EVIDENCE_TRACK;
        t.evidence = (uint16_t)(e > 0xFFFFU ? 0xFFFFU : e);
    }
    t.shadow_slant_um = sl_detect_shadow_slant_um(bd, az);
    slot_take(d, &t);
}

// WEAK test of one run [s, e) against the amplitude row (sl_detect.h stage 4): CF_AMP, plus
// CF_STRONG when its peak is >= threshold + weak_margin or >= floor + weak_contrast, the
// floor being the mean of the gap_bins + 1 bins on each side (free by construction).
static uint8_t run_strength(const sl_detect_t *d, uint32_t s, uint32_t e)
{
    const uint8_t *p = d->amp;
    const uint32_t nb = d->amp_bins;
    if (p == NULL || s >= nb) {
        return 0U;
    }
    const uint32_t strong_at = (uint32_t)d->amp_threshold + d->cfg.weak_margin;
    uint32_t peak = 0U;
    for (uint32_t k = s; k < e && k < nb; k++) {
        peak = p[k] > peak ? p[k] : peak;
        if (peak >= strong_at) {
            return (uint8_t)(CF_AMP | CF_STRONG); // clearly above the threshold
        }
    }
    const uint32_t side = (uint32_t)d->cfg.gap_bins + 1U;
    const uint32_t b0 = s > side ? s - side : 0U;
    const uint32_t e1 = e >= nb ? e : (e + side < nb ? e + side : nb);
    uint32_t sum = 0U;
    if (s - b0 == side && e1 - e == side) { // the common case: both sides whole, one loop
        for (uint32_t k = 0; k < side; k++) {
            sum += (uint32_t)p[b0 + k] + p[e + k];
        }
    } else {
        for (uint32_t k = b0; k < s; k++) {
            sum += p[k];
        }
        for (uint32_t k = e; k < e1; k++) {
            sum += p[k];
        }
    }
    const uint32_t cnt = (s - b0) + (e1 - e);
    const uint32_t floor_v = cnt != 0U ? sum / cnt : 0U;
    const bool strong = peak >= floor_v + d->cfg.weak_contrast;
    return (uint8_t)(CF_AMP | (strong ? CF_STRONG : 0U));
}

// Highest value of amplitude row p over bins [s, e) (0 when empty).
static uint32_t row_peak(const uint8_t *p, uint32_t s, uint32_t e)
{
    uint32_t peak = 0U;
    for (uint32_t k = s; k < e; k++) {
        peak = p[k] > peak ? p[k] : peak;
    }
    return peak;
}

// While d->peaks (sl_detect_begin: moving with a known tail slope): the highest amplitude
// value of run [s, e) of `count` occupied bins into its entry of group g on azimuth a (the
// entry's own when the run is all it holds: its count is the run's; else the larger).
// 0 without an amplitude row. Not inlined: off sl_detect_row's loop when not moving.
static SL_NOINLINE void note_peak(const sl_detect_t *d, sl_detect_cand_t *g, uint32_t a,
                                  uint32_t s, uint32_t e, uint32_t count)
{
    const uint32_t idx = a - g->az_first;
    if (idx >= SL_CFG_DETECT_MAX_SPAN) {
        return;
    }
    const uint32_t peak =
        d->amp == NULL ? 0U : row_peak(d->amp, s, e < d->amp_bins ? e : d->amp_bins);
    g->peak[idx] = (uint32_t)g->run[idx].count == count || peak > g->peak[idx]
                       ? (uint8_t)peak
                       : g->peak[idx];
}

void sl_detect_set_tail_slope(sl_detect_t *d, uint16_t slope_q8)
{
    SL_ASSERT(d != NULL);
    d->tail_slope_q8 = slope_q8;
}

// Stage 1 at the shadow edge for a run [s, e) reaching past the window end `win` or the
// d(S) edge `edge` (sl_detect.h). With an amplitude row the run's part beyond the window
// must look like a smear tail of its part inside: below the inside peak, and decaying:
// with a known tail slope, ending within ceil((peak - T) 256 / slope) bins of the window;
// without one, its first half stronger than its second by >= 1/2 value per bin of
// separation (the profiles' smallest plausible slope). Then TAIL, else SHADOW. Without an
// amplitude row the d(S) rule: SHADOW when the last bin reaches `edge`. Not inlined: a rare
// path, out of sl_detect_row's loop.
static SL_NOINLINE uint8_t edge_rule(const sl_detect_t *d, uint32_t s, uint32_t e,
                                     uint32_t win, uint32_t edge)
{
    const uint8_t *p = d->amp;
    if (p == NULL || e > d->amp_bins || s >= win || e <= win) {
        return e - 1U >= edge ? (uint8_t)CF_SHADOW : 0U;
    }
    // (called for runs reaching the d(S) edge only: a shorter one keeps the r2 - d test)
    const uint32_t peak_in = row_peak(p, s, win);
    const uint32_t o = e - win; // bins beyond the window
    if (d->tail_slope_q8 != 0U) {
        const uint32_t t = d->amp_threshold;
        const uint32_t tail =
            peak_in > t ? ((peak_in - t) * 256U + d->tail_slope_q8 - 1U) / d->tail_slope_q8 : 0U;
        if (o > tail) {
            return CF_SHADOW;
        }
    }
    for (uint32_t k = win; k < e; k++) {
        if (p[k] >= peak_in) {
            return CF_SHADOW; // as strong beyond the edge as inside: not its tail
        }
    }
    if (d->tail_slope_q8 != 0U) {
        return CF_TAIL;
    }
    const uint32_t h = o / 2U;
    if (h == 0U) {
        return CF_TAIL; // one bin beyond, below the peak
    }
    uint32_t s1 = 0U, s2 = 0U;
    for (uint32_t k = 0; k < h; k++) {
        s1 += p[win + k];
        s2 += p[e - h + k];
    }
    // pairs k, k + (o - h) bins apart: a tail falls >= (o - h) / 2 values over each
    return s1 >= s2 && 2U * (s1 - s2) >= h * (o - h) ? (uint8_t)CF_TAIL : (uint8_t)CF_SHADOW;
}

void sl_detect_set_amplitude(sl_detect_t *d, const uint8_t *power, uint16_t bins,
                             uint8_t threshold)
{
    SL_ASSERT(d != NULL);
    d->amp = power;
    d->amp_bins = power != NULL ? bins : 0U;
    d->amp_threshold = threshold;
}

// A group that can no longer grow (no run on the azimuth before the current one) leaves the
// open set: finalized, or, when it starts at azimuth 0, kept for the wrap merge at the end
// of the rotation.
static void close_group(sl_detect_t *d, sl_detect_cand_t *c)
{
    d->n_open--;
    open_clr(d, c);
    if (c->az_first == 0U) {
        c->state = ST_CLOSED;
    } else {
        finalize(d, c);
    }
}

// Walk the open set before row a: close the groups with no run on a - 1 and, when the row
// has runs (`links`), enter the others (all end on a - 1) in the row's link table with
// their extent there (last_*), in slot order. One call site: inlined.
static void open_walk(sl_detect_t *d, uint32_t a, bool links)
{
    sl_detect_links_t *t = &d->links;
    const uint32_t tol = d->cfg.link_bins;
    uint32_t n = 0U;
    for (uint32_t w = 0; w < OPEN_WORDS; w++) {
        uint32_t bits = d->open_bits[w];
        while (bits != 0U) {
            const uint32_t i = w * 32U + sl_bits_ctz32(bits);
            bits &= bits - 1U;
            sl_detect_cand_t *c = &d->cand[i];
            if ((uint32_t)c->az_last + 1U < a) {
                close_group(d, c);
            } else if (links) {
                const uint32_t h = (uint32_t)c->last_hi + tol;
                t->lo[n] = c->last_lo;
                t->hi_tol[n] = (uint16_t)(h > 0xFFFFU ? 0xFFFFU : h);
                t->slot[n] = (uint8_t)i;
                n++;
            }
        }
    }
    t->n = (uint8_t)n;
}

sl_err_t sl_detect_init(sl_detect_t *d, const sl_board_t *board, const sl_detect_cfg_t *cfg)
{
    if (d == NULL || board == NULL || board->bin_size_um == 0U || board->azimuths == 0U ||
        board->azimuths > SL_CFG_MAX_AZIMUTHS || board->roi_bins == 0U ||
        board->roi_bins > SL_CFG_ROI_BINS ||
        (board->shadow_um == NULL && board->shadow_bins == NULL)) {
        return SL_ERR_ARG;
    }
    memset(d, 0, sizeof *d);
    d->board = board;
    if (cfg != NULL) {
        d->cfg = *cfg;
    } else {
        sl_detect_cfg_default(&d->cfg);
    }
    d->azimuths = board->azimuths;
    d->bins = board->roi_bins;
    d->near_bins = board->near_exclusion_bins;
    d->step_bam = (uint32_t)(((uint64_t)1U << 32) / board->azimuths);
    d->beam_bam = (uint32_t)(((uint64_t)d->cfg.beam_width_cdeg << 32) / 36000U);
    const uint32_t mt = board->max_targets == 0U ? SL_CFG_MAX_TARGETS : board->max_targets;
    d->max_targets = (uint8_t)(mt > SL_CFG_MAX_TARGETS ? SL_CFG_MAX_TARGETS : mt);
    const uint64_t b = board->bin_size_um;
    for (uint16_t a = 0; a < board->azimuths; a++) {
        const uint64_t s = sl_detect_shadow_slant_um(board, a);
        const uint64_t win = (s + b - 1U) / b;
        const int64_t e2 = 2 * ((int64_t)s + sl_detect_elong_um(board, (uint32_t)s)) - (int64_t)b;
        const uint64_t edge = e2 <= 0 ? 0U : ((uint64_t)e2 + 2U * b - 1U) / (2U * b);
        d->win_bins[a] = (uint16_t)(win > 0xFFFFU ? 0xFFFFU : win);
        d->edge_bins[a] = (uint16_t)(edge > 0xFFFFU ? 0xFFFFU : edge);
    }
    sl_detect_begin(d);
    return SL_OK;
}

void sl_detect_begin(sl_detect_t *d)
{
    SL_ASSERT(d != NULL);
    for (uint32_t i = 0; i < SL_CFG_DETECT_MAX_CANDIDATES; i++) {
        d->cand[i].state = ST_FREE;
    }
    memset(d->open_bits, 0, sizeof d->open_bits);
    d->n_targets = 0U;
    d->n_open = 0U;
    d->last_az = -1;
    d->peaks = d->slant && d->tail_slope_q8 != 0U; // fixed for the rotation (stage 4)
}

// Stages 1 and 2 of row az after open_walk: the runs in [near, win) (gaps bridged, the
// shadow edge tested, graded), each added to the groups through the row's link table. Not
// inlined: its locals stay off the chain that finalises the groups open_walk closes (the
// Cortex-M stack budget, tests/core/build/stack_budget.py).
static SL_NOINLINE void row_runs(sl_detect_t *d, uint32_t az, const uint32_t *occ,
                                 uint32_t limit, uint32_t win)
{
    const uint32_t near = d->near_bins;
    const uint32_t edge = d->edge_bins[az];
    const uint32_t gap = d->cfg.gap_bins;
    uint32_t pos = near;
    while (pos < win) {
        const uint32_t s = sl_bits_next_set(occ, pos, win);
        if (s >= win) {
            break;
        }
        uint8_t rf = 0U;
        if (s == near && near > 0U && sl_bits_get(occ, near - 1U)) {
            rf |= CF_NEAR;
        }
        uint32_t e = sl_bits_next_clear(occ, s, limit); // one past the last occupied bin
        uint32_t count = e - s;
        while (e < limit) {
            // Bridge gaps of up to `gap` free bins (the run is then broken).
            const uint32_t stop = (e + gap + 1U) < limit ? (e + gap + 1U) : limit;
            const uint32_t s2 = sl_bits_next_set(occ, e, stop);
            if (s2 >= stop) {
                break;
            }
            const uint32_t e2 = sl_bits_next_clear(occ, s2, limit);
            count += e2 - s2;
            e = e2;
        }
        if (e >= limit || e - 1U >= edge) {
            // at the d(S) edge (a run ending before it: r2 less d(r2) tested at the end)
            rf |= e >= limit ? (uint8_t)CF_SHADOW : edge_rule(d, s, e, win, edge);
        }
        if ((rf & CF_SHADOW) == 0U) { // a SHADOW group is rejected anyway
            rf |= run_strength(d, s, e);
        }
        sl_detect_cand_t *g = add_run(d, &d->links, az, s, e - 1U, count, rf);
        if (d->peaks && g != NULL && (rf & CF_SHADOW) == 0U) {
            note_peak(d, g, az, s, e, count); // (a SHADOW group's entries are never read)
        }
        pos = e;
    }
}

sl_err_t sl_detect_row(sl_detect_t *d, uint16_t az, const uint32_t *occ, uint32_t words)
{
    SL_ASSERT(d != NULL && (occ != NULL || words == 0U));
    if (az >= d->azimuths || (int32_t)az <= d->last_az) {
        d->stats.order_errors++;
        d->amp = NULL;
        return SL_ERR_RANGE;
    }
    d->last_az = az;
    d->stats.rows++;
    const uint32_t limit = words * 32U < d->bins ? words * 32U : d->bins;
    const uint32_t win = d->win_bins[az] < limit ? d->win_bins[az] : limit;
    const uint32_t near = d->near_bins;
    // Fast exit for the common azimuth: nothing occupied in [near, win) (the last word is
    // not trimmed at win: a set bit beyond it only costs the exact scan below).
    uint32_t any = 0U;
    if (win > near) {
        any = occ[near >> 5] & (UINT32_MAX << (near & 31U));
        for (uint32_t w = (near >> 5) + 1U; w <= (win - 1U) >> 5; w++) {
            any |= occ[w];
        }
    }
    if (any == 0U && d->n_open == 0U) {
        d->amp = NULL;
        return SL_OK;
    }
    open_walk(d, az, any != 0U);
    if (any != 0U) {
        row_runs(d, az, occ, limit, win);
    }
    d->amp = NULL;
    return SL_OK;
}

sl_ssize_t sl_detect_end(sl_detect_t *d)
{
    SL_ASSERT(d != NULL);
    const uint32_t n = d->azimuths;
    // Wrap: groups on the last azimuth continue into groups that started on azimuth 0.
    for (uint32_t i = 0; i < SL_CFG_DETECT_MAX_CANDIDATES; i++) {
        sl_detect_cand_t *c = &d->cand[i];
        if (c->state != ST_OPEN || c->az_last != n - 1U || n < 2U) {
            continue;
        }
        for (uint32_t j = 0; j < SL_CFG_DETECT_MAX_CANDIDATES; j++) {
            sl_detect_cand_t *c0 = &d->cand[j];
            if (j == i || c0->state == ST_FREE || c0->az_first != 0U ||
                (is_weak(c->flags) && (c0->flags & CF_STRONG) != 0U) ||
                ((c->flags & CF_STRONG) != 0U && is_weak(c0->flags)) ||
                !overlaps(c->last_lo, c->last_hi, c0->run[0].first, c0->run[0].last,
                          d->cfg.link_bins)) {
                continue;
            }
            const uint32_t span = n - c->az_first; // c ends on azimuth n - 1
            entries_merge(c, c0, span, span);
            const uint32_t last = n + c0->az_last;
            c->az_last = (uint16_t)(last > 0xFFFFU ? 0xFFFFU : last);
            c->flags |= (uint8_t)(c0->flags | CF_WRAPS);
            if (c0->state == ST_OPEN) {
                d->n_open--;
            }
            c0->state = ST_FREE;
            open_clr(d, c0);
            break;
        }
    }
    for (uint32_t i = 0; i < SL_CFG_DETECT_MAX_CANDIDATES; i++) {
        if (d->cand[i].state != ST_FREE) {
            finalize(d, &d->cand[i]);
        }
    }
    d->stats.rotations++;
    d->last_az = (int32_t)n; // further rows are order errors until sl_detect_begin()
    return (sl_ssize_t)d->n_targets;
}

sl_ssize_t sl_detect_rotation_from_mask(sl_detect_t *d, const sl_mask_t *mask)
{
    SL_ASSERT(d != NULL && mask != NULL);
    uint32_t occ[SL_ROI_WORDS];
    sl_detect_begin(d);
    const uint32_t n = d->azimuths < mask->azimuths ? d->azimuths : mask->azimuths;
    for (uint32_t a = 0; a < n; a++) {
        // Enough words to see a run reach the edge bin (then it is SHADOW anyway).
        uint32_t words = SL_BITS_WORDS((uint32_t)d->edge_bins[a] + 1U);
        if (words > mask->words) {
            words = mask->words;
        }
        if (sl_mask_stable_prefix(mask, (uint16_t)a, words, occ, NULL)) {
            (void)sl_detect_row(d, (uint16_t)a, occ, words);
        }
    }
    return sl_detect_end(d);
}

uint16_t sl_detect_bins_needed(const sl_detect_t *d)
{
    SL_ASSERT(d != NULL);
    uint32_t m = 0;
    for (uint32_t a = 0; a < d->azimuths; a++) {
        const uint32_t e = (uint32_t)d->edge_bins[a] + 1U;
        m = e > m ? e : m;
    }
    return (uint16_t)(m < d->bins ? m : d->bins);
}
