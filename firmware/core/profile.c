// SPDX-License-Identifier: MIT
// Range profiles beside the bit mask and smear-aware bounds from them (sl_profile.h).
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_profile.h"

#include "bits.h"
#include "compiler.h"
#include "shadowlean/sl_thresh.h"

#define SLOPE_MIN_Q8 128U   // 0.5 value per bin
#define SLOPE_MAX_Q8 6144U  // 24 values per bin
#define LEAD_TOL_VALUES 3U  // sl_profile_lead_edge: the third bin within 3 values (1.5 dB)
#define FIT_BINS 8U
#define FIT_MIN_BINS 4U
#define CAL_GATE_N 4U       // fits before the +-30 % gate applies
#define LOCAL_BINS 6U       // bins of the local tail fit during the walk
#define SPAN_BINS 3U        // steps of the walk's span test (a shallow step among tail steps)
#define ALIGN_BINS 2U       // neighbouring rows whose returns end this far apart are summed
#define SL_PROFILE_EDGE_RETRIES 8U // walks again after a stop beyond the shadow edge (step 4')

void sl_profile_cfg_default(sl_profile_cfg_t *cfg)
{
    SL_ASSERT(cfg != NULL);
    cfg->max_frames = 128U;
    cfg->lead_bins = 6U;
    cfg->max_idle = 4U;
    cfg->min_frames = 2U;
    cfg->prior_slope_q8 = 0U;
    cfg->prior_front_bins = 0U;
    cfg->prior_r2_offset_um = 0;
}

sl_err_t sl_profile_init(sl_profile_t *pr, uint16_t azimuths, uint16_t near_bins,
                         const sl_profile_cfg_t *cfg)
{
    if (pr == NULL || azimuths == 0U || azimuths > SL_CFG_MAX_AZIMUTHS) {
        return SL_ERR_ARG;
    }
    sl_profile_cfg_t c;
    if (cfg != NULL) {
        c = *cfg;
    } else {
        sl_profile_cfg_default(&c);
    }
    if (c.max_frames < 2U || c.max_frames > 257U ||
        (c.prior_slope_q8 != 0U &&
         (c.prior_slope_q8 < SLOPE_MIN_Q8 || c.prior_slope_q8 > SLOPE_MAX_Q8)) ||
        c.prior_front_bins == 1U || c.prior_front_bins >= SL_PROFILE_LEAD_HIST ||
        c.prior_r2_offset_um > SL_PROFILE_R2_OFFSET_MAX_UM ||
        c.prior_r2_offset_um < -SL_PROFILE_R2_OFFSET_MAX_UM) {
        return SL_ERR_ARG;
    }
    memset(pr, 0, sizeof *pr);
    pr->cfg = c;
    pr->azimuths = azimuths;
    pr->near_bins = near_bins;
    memset(pr->slot_of, SL_PROFILE_NONE, sizeof pr->slot_of);
    pr->slope_q8 = c.prior_slope_q8; // cal_n 0: the first self-fit replaces it
    pr->front_bins = c.prior_front_bins; // until SL_PROFILE_LEAD_MIN rises of its own
    pr->r2_offset_um = c.prior_r2_offset_um; // until SL_PROFILE_RESID_MIN samples of its own
    return SL_OK;
}

static void slot_add(const sl_profile_t *pr, sl_profile_slot_t *s, const uint8_t *power,
                     uint32_t n)
{
    if (s->frames >= pr->cfg.max_frames) {
        for (uint32_t k = 0; k < SL_CFG_PROFILE_BINS; k++) {
            s->sum[k] = (uint16_t)(s->sum[k] >> 1);
        }
        s->frames = (uint16_t)(s->frames >> 1);
#if SL_CFG_FIT
        s->fit_frames = (uint16_t)(s->fit_frames >> 1); // the same mean: the fit stands
        for (uint32_t k = 0; k < SL_CFG_PROFILE_BINS; k++) {
            s->sq[k] >>= 1;
        }
#endif
    }
    const uint32_t b0 = s->bin0;
    const uint32_t m = n > b0 ? (n - b0 < SL_CFG_PROFILE_BINS ? n - b0 : SL_CFG_PROFILE_BINS) : 0U;
    for (uint32_t k = 0; k < m; k++) {
        s->sum[k] = (uint16_t)(s->sum[k] + power[b0 + k]);
#if SL_CFG_FIT
        s->sq[k] += (uint32_t)power[b0 + k] * power[b0 + k];
#endif
    }
    s->frames++;
}

// The first free slot, SL_CFG_PROFILE_SLOTS when every one is in use.
static uint32_t free_slot(const sl_profile_t *pr)
{
    for (uint32_t i = 0; i < SL_CFG_PROFILE_SLOTS; i++) {
        if (pr->slot[i].live == 0U) {
            return i;
        }
    }
    return SL_CFG_PROFILE_SLOTS;
}

// Slot `i` starts watching azimuth `az` (no row yet), its window from `first` - lead_bins:
// a claim on evidence, an assignment to a target or a reservation for a track. The caller
// keeps n_live and the counters (and unlinks a slot it takes from another azimuth).
static sl_profile_slot_t *slot_start(sl_profile_t *pr, uint32_t i, uint32_t az, uint32_t first)
{
    sl_profile_slot_t *s = &pr->slot[i];
    memset(s, 0, sizeof *s);
    s->live = 1U;
    s->seen = 1U;
    s->az = (uint16_t)az;
    s->bin0 = (uint16_t)(first > pr->cfg.lead_bins ? first - pr->cfg.lead_bins : 0U);
    pr->slot_of[az] = (uint8_t)i;
    return s;
}

void sl_profile_row(sl_profile_t *pr, uint16_t az, const uint8_t *power, uint32_t n,
                    const uint32_t *bits, uint32_t win)
{
    SL_ASSERT(pr != NULL && power != NULL && bits != NULL);
    if (az >= pr->azimuths) {
        return;
    }
    const uint32_t hi = win < n ? win : n;
    const uint32_t first = pr->near_bins < hi ? sl_bits_next_set(bits, pr->near_bins, hi) : hi;
    const uint8_t si = pr->slot_of[az];
    if (si != SL_PROFILE_NONE) {
        sl_profile_slot_t *s = &pr->slot[si];
        if (first < hi) {
            s->seen = 1U;
        }
        slot_add(pr, s, power, n);
        return;
    }
    if (first >= hi) {
        return;
    }
    const uint32_t i = pr->n_live < SL_CFG_PROFILE_SLOTS ? free_slot(pr) : SL_CFG_PROFILE_SLOTS;
    if (i == SL_CFG_PROFILE_SLOTS) {
        pr->stats.claim_full += pr->moving == 0U ? 1U : 0U;
        return;
    }
    if (pr->moving != 0U && sl_bits_next_clear(bits, first, hi) + 2U > hi) {
        return; // moving: a free slot for a run ending clear of the window's end
    }
    pr->n_live++;
    pr->stats.claims++;
    sl_profile_slot_t *s = slot_start(pr, i, az, first);
    // A first sighting while moving (no track expects it: clutter, a pole's far edge) does
    // not teach the stream's front part: a false front moves every r1 and clears the 3D-tilt
    // histories (front_news).
    s->lead_seen = pr->moving;
    slot_add(pr, s, power, n);
}

void sl_profile_end_rotation(sl_profile_t *pr, bool reset)
{
    SL_ASSERT(pr != NULL);
    if (reset) {
        pr->stats.resets++;
    }
    pr->moving = reset ? 1U : 0U;
    for (uint32_t i = 0; i < SL_CFG_PROFILE_SLOTS; i++) {
        sl_profile_slot_t *s = &pr->slot[i];
        if (s->live == 0U) {
            continue;
        }
        if (s->seen != 0U) {
            s->idle = 0U;
        } else if (++s->idle > pr->cfg.max_idle) {
            s->live = 0U;
            pr->slot_of[s->az] = SL_PROFILE_NONE;
            pr->n_live--;
            pr->stats.released++;
            continue;
        }
        s->seen = 0U;
        if (reset) {
            // Moving: the sums are cleared and the slot is freed: the pole is at another
            // azimuth next rotation (sl_profile_reserve gives the slots to where it will be).
            s->live = 0U;
            s->frames = 0U;
            pr->slot_of[s->az] = SL_PROFILE_NONE;
            pr->n_live--;
        }
    }
}

// Least-squares slope (decay, > 0 for a falling tail) of sum[e-m+1 .. e], per frame, Q8.
// 0 when the bins rise. 32-bit only (no 64-bit division helper on v6-M, whose frames sat on
// the deepest stack chain), exact for every input the 64-bit form took: with m <= FIT_BINS
// (8) and uint16 sums, num = m * sum((m-1)/2 - x) y <= 64 * 65535, so num * 256 < 2^31, and
// d = m sxx - sx^2 <= 336; the denominator d * frames is formed only when it fits 32 bits
// (num * 256 + den / 2 < 2^32 then), else the rounded quotient is 0 (2 num 256 < 2^32 <= den).
static uint32_t fit_slope_q8(const uint16_t *sum, uint32_t e, uint32_t m, uint32_t frames)
{
    SL_ASSERT(m >= 2U && m <= FIT_BINS);
    uint32_t sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (uint32_t x = 0; x < m; x++) {
        const uint32_t y = sum[e + 1U - m + x];
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    // num = sx sy - m sxy (decay); both products < 2^24
    const uint32_t a = sx * sy, b = m * sxy;
    const uint32_t d = m * sxx - sx * sx;
    if (a <= b || d == 0U || frames == 0U) {
        return 0U;
    }
    const uint32_t num = a - b;
    if (frames > UINT32_MAX / d) {
        return 0U;
    }
    const uint32_t den = d * frames;
    const uint32_t q = (num * 256U + den / 2U) / den;
    return q > 0xFFFFU ? 0xFFFFU : q;
}

// The step after the run's last bin above the threshold falls by more than two tail slopes
// `s` (Q8 values per bin per frame).
// 32 bits (no 64-bit multiply helper on the deepest stack chain): the drop x 256 < 2^24, and
// with s clamped to 2^20 (far above any plausible slope) 2 frames s < 2^31 for frames <= 1023.
static bool is_cliff(const uint16_t *sum, uint32_t last, uint32_t frames, uint32_t s)
{
    if (sum[last] <= sum[last + 1U]) {
        return false;
    }
    const uint32_t drop = ((uint32_t)sum[last] - (uint32_t)sum[last + 1U]) * 256U;
    const uint32_t sc = s > (1UL << 20) ? (uint32_t)(1UL << 20) : s;
    return drop > 2U * frames * sc;
}

// A return that ends in a cliff: its last bins are its own (r2 = `last`).
static sl_profile_bounds_t cliff(uint32_t i1, uint32_t last, uint32_t e)
{
    // every member set (no memset: this sits on the deepest stack chain, sl_pipeline_feed)
    const sl_profile_bounds_t r = {(uint16_t)i1, (uint16_t)last, (uint16_t)e, 0U,
                                   (uint8_t)SL_PROFILE_SLOPE_CLIFF, (uint8_t)SL_PROFILE_OK, 0U, 0U};
    return r;
}

// One extraction; `fit_max` (<= FIT_BINS) caps the size of the tail fit (bins ending at e).
// `e_cap` caps the tail's end e (the walk's start; UINT32_MAX: none); `tol` (Q8 values x
// frames) is the noise of one step of the sums beyond rounding (0: a static scene's sums).
static sl_profile_bounds_t extract_once(const uint16_t *sum, uint32_t n, uint32_t frames,
                                        uint32_t threshold, uint32_t hint, uint32_t cal_slope_q8,
                                        uint32_t fit_max, uint32_t cliff_end, uint32_t e_cap,
                                        uint32_t tol)
{
    sl_profile_bounds_t r;
    memset(&r, 0, sizeof r);
    SL_ASSERT(sum != NULL);
    if (frames == 0U || frames > SL_PROFILE_MAX_FRAMES || n < 2U) {
        r.fail = (uint8_t)SL_PROFILE_NO_SLOT;
        return r;
    }
    const uint32_t thr = frames * threshold;
    const uint32_t thr_e = frames * (threshold + threshold / 4U);
    // 1. leading edge
    uint32_t j = hint > 3U ? hint - 3U : 0U;
    while (j < n && sum[j] < thr) {
        j++;
    }
    if (j >= n || j > hint + 3U) {
        r.fail = (uint8_t)SL_PROFILE_NO_RUN;
        return r;
    }
    while (j > 0U && sum[j - 1U] >= thr) {
        j--; // the mean starts before the mask's (AND) first bin
    }
    if (j == 0U) {
        r.fail = (uint8_t)SL_PROFILE_LEAD_CUT;
        return r;
    }
    const uint32_t i1 = j;
    // 2. the run above the threshold (gaps <= 2 bridged), and the end of the usable tail
    uint32_t last = i1;
    uint32_t e = i1;
    for (uint32_t k = i1; k < n; k++) {
        if (sum[k] >= thr) {
            last = k;
            if (sum[k] >= thr_e) {
                e = k;
            }
        } else if (k > last + 2U) {
            break;
        }
    }
    if (last + 3U >= n) {
        r.fail = (uint8_t)SL_PROFILE_TAIL_CUT;
        return r;
    }
    if (e > e_cap) {
        e = e_cap > i1 ? e_cap : i1;
    }
    // 3. tail slope: self fit, else the calibration
    uint32_t m = e - i1 + 1U;
    m = m > fit_max ? fit_max : m;
    uint32_t s = m >= FIT_MIN_BINS ? fit_slope_q8(sum, e, m, frames) : 0U;
    r.slope_src = SL_PROFILE_SLOPE_FIT;
    if (s < SLOPE_MIN_Q8 || s > SLOPE_MAX_Q8) {
        s = cal_slope_q8;
        r.slope_src = SL_PROFILE_SLOPE_CAL;
        if (s < SLOPE_MIN_Q8 || s > SLOPE_MAX_Q8) {
            // No slope to compare with (a short flat return, nothing calibrated yet): still
            // a cliff when the step after the run falls by more than two of the steepest
            // plausible tail slopes (a drop no smear tail makes).
            if (last < cliff_end && is_cliff(sum, last, frames, SLOPE_MAX_Q8)) {
                return cliff(i1, last, e);
            }
            r.fail = (uint8_t)SL_PROFILE_NO_TAIL;
            r.slope_src = 0U;
            return r;
        }
    }
    r.slope_q8 = (uint16_t)s;
    // a drop beyond two slopes and the step's noise (one rotation's rows near the noise floor
    // can fall by three slopes in one step)
    r.end_drop = is_cliff(sum, last, frames, s + tol / (2U * frames)) ? 1U : 0U;
    // No tail at all: the return ends in a cliff (the step after its last bin above the
    // threshold falls by more than two tail slopes), so its last bins are its own. Not at
    // or beyond `cliff_end` (the shadow edge): a pole's own return ends inside the shadow,
    // so a drop there ends a smear tail (where it meets the floor, or where the smear's
    // support ends) and the walk from e decides.
    // Nor after a tail: a run whose last FIT_BINS bins fall like the stream's calibrated
    // slope (within the calibration's +-30 % gate) is a smear tail, whatever ends it (one
    // rotation's rows near the floor can drop by three slopes in one step).
    const bool tail_before = r.slope_src == SL_PROFILE_SLOPE_FIT && m == FIT_BINS &&
                             s * 10U >= cal_slope_q8 * 7U && s * 10U <= cal_slope_q8 * 13U;
    if (last < cliff_end && r.end_drop != 0U && !tail_before) {
        r = cliff(i1, last, e);
        r.slope_q8 = (uint16_t)s;
        return r;
    }
    // 4. walk back over the tail: bin j is tail while S[j-1] - S[j] >= F (s_loc - s_loc / 6)
    //    (the bin before decays into it like the tail: it holds little power of its own).
    //    32-bit: frames <= SL_PROFILE_MAX_FRAMES and s_loc <= SLOPE_MAX_Q8 give frames x s_loc
    //    < 2^23, tol is clamped to 2^24 (beyond it every step passes anyway: 2^16 values x
    //    frames), sums < 2^16: every term below is within +-2^26.
    uint32_t s_loc = s; // Q8 per frame
    if (r.slope_src == SL_PROFILE_SLOPE_FIT && m > FIT_MIN_BINS) {
        // A tail that steepens towards the pole (convex in the log: a power law, or a fast
        // component under a slow one): the fit over m bins straddles the bend and is steeper
        // than the tail where the walk starts, whose shallower steps would then read as the
        // pole's own. Start from the slope of the FIT_MIN_BINS bins ending at e when the
        // whole fit (also the refit on a short tail, whose first bin may be the pole's
        // partly lit last one) is steeper by a quarter and a value per bin; the local fit
        // takes over as the walk goes.
        const uint32_t sf = fit_slope_q8(sum, e, FIT_MIN_BINS, frames);
        if (sf >= SLOPE_MIN_Q8 && 4U * s >= 5U * sf && s >= sf + 256U) {
            s_loc = sf;
        }
    }
    const int32_t tl = tol > (1UL << 24) ? (int32_t)(1L << 24) : (int32_t)tol;
    const int32_t f256 = (int32_t)frames * 256;
    j = e;
    while (j > i1) {
        const int32_t dlt = (int32_t)sum[j - 1U] - (int32_t)sum[j]; // x F, values
        const int32_t fs = (int32_t)frames * (int32_t)s_loc;      // Q8
        const int32_t lim = (int32_t)frames * (int32_t)(s_loc - s_loc / 6U) - tl; // Q8
        if (dlt * 256 < lim) {
            // Rounding: 8-bit values of a static scene are not dithered, so a tail step can
            // read up to one value short of the slope; it is still tail when it is short by
            // less than one value and it and the step after it (already walked) fall by at
            // least two slopes less one value (the rounding bound of a two-step difference).
            const bool pair_after =
                j + 1U <= e && dlt * 256 > fs - f256 - tl &&
                ((int32_t)sum[j - 1U] - (int32_t)sum[j + 1U]) * 256 >= 2 * fs - f256 - tl;
            // A knee between two smear components, while the slope still comes from the
            // first fit (which may straddle it): one shallow step is passed when the step
            // before it and both together fall like the tail.
            bool knee = false;
            if (!pair_after && j >= i1 + 2U && j + LOCAL_BINS - 1U > e) {
                const int32_t d1 = (int32_t)sum[j - 2U] - (int32_t)sum[j - 1U];
                const int32_t d2 = (int32_t)sum[j - 2U] - (int32_t)sum[j];
                knee = d1 * 256 >= lim && d2 * 256 >= 2 * lim;
            }
            // Noise on one bin: a shallow step passes when the fall over the (up to)
            // SPAN_BINS steps that end in it is that of as many tail steps, less a value.
            // That fall is a difference of two bins, as noisy as one step and SPAN_BINS
            // times its signal: one bin read high or low no longer ends the walk, while the
            // pole's own bins before the step (flat, or the leading edge) fall by far less.
            bool span = false;
            if (!pair_after && !knee && j >= i1 + 2U) {
                const uint32_t kk = j - i1 < SPAN_BINS ? j - i1 : SPAN_BINS;
                const int32_t dk = (int32_t)sum[j - kk] - (int32_t)sum[j];
                span = dk * 256 >= (int32_t)kk * (lim + tl) - f256 - tl;
            }
            if (!pair_after && !knee && !span) {
                break;
            }
        }
        j--;
        // follow a tail that steepens towards the pole: the slope fitted on the LOCAL_BINS
        // tail bins nearest to the walk (j .. j + LOCAL_BINS - 1), when plausible
        if (j + LOCAL_BINS - 1U <= e) {
            const uint32_t sl = fit_slope_q8(sum, j + LOCAL_BINS - 1U, LOCAL_BINS, frames);
            if (sl >= SLOPE_MIN_Q8 && sl <= SLOPE_MAX_Q8) {
                s_loc = sl;
            }
        }
    }
    r.i1 = (uint16_t)i1;
    r.i2 = (uint16_t)j;
    r.e = (uint16_t)e;
    r.fail = (uint8_t)SL_PROFILE_OK;
    return r;
}

// One extraction with the tail's end capped at `e_cap`, and the refit of step 4.
static sl_profile_bounds_t extract_capped(const uint16_t *sum, uint32_t n, uint32_t frames,
                                          uint32_t threshold, uint32_t hint, uint32_t cal_slope_q8,
                                          uint32_t cliff_end, uint32_t e_cap, uint32_t tol)
{
    sl_profile_bounds_t r = extract_once(sum, n, frames, threshold, hint, cal_slope_q8, FIT_BINS,
                                         cliff_end, e_cap, tol);
    // The first fit may reach into the pole's own bins when the tail is short: refit on the
    // tail the walk found (when it has >= FIT_MIN_BINS and < FIT_BINS bins) and walk again.
    if (r.fail == (uint8_t)SL_PROFILE_OK && r.slope_src == SL_PROFILE_SLOPE_FIT &&
        (uint32_t)r.i2 + FIT_BINS > r.e && (uint32_t)r.e >= (uint32_t)r.i2 + FIT_MIN_BINS) {
        const sl_profile_bounds_t r2 = extract_once(sum, n, frames, threshold, hint, cal_slope_q8,
                                                    (uint32_t)r.e - r.i2, cliff_end, e_cap, tol);
        if (r2.fail == (uint8_t)SL_PROFILE_OK) {
            r = r2;
        }
    }
    return r;
}

sl_profile_bounds_t sl_profile_extract(const uint16_t *sum, uint32_t n, uint32_t frames,
                                       uint32_t threshold, uint32_t hint, uint32_t cal_slope_q8,
                                       uint32_t cliff_end)
{
    return sl_profile_extract_noisy(sum, n, frames, threshold, hint, cal_slope_q8, cliff_end, 0U);
}

sl_profile_bounds_t sl_profile_extract_noisy(const uint16_t *sum, uint32_t n, uint32_t frames,
                                             uint32_t threshold, uint32_t hint,
                                             uint32_t cal_slope_q8, uint32_t cliff_end,
                                             uint32_t tol_q8)
{
    // A walk that stops at or beyond the shadow edge stopped on the smear, not on the pole
    // (a pole's own return ends inside the shadow): typically where a kernel of finite
    // support ends while its tail is still strong, the tail's last bins bend down (fewer
    // sources reach them), the first fit over them is too steep and the regular tail before
    // them reads as the pole's own. The bins from the stop on are tail: walk again from the
    // bin before it, with a fit that ends there (step 4'), but only where the tail there
    // falls like a smear tail: within a factor 1/2 .. 3/2 of the stream's calibrated slope
    // (of the first walk's fit before any calibration; the bend makes that one steeper). A
    // pole whose own bins reach beyond the edge falls there as it does (slowly), not as the
    // smear, and stays beyond (SHADOW). Each retry moves the start back by at least one
    // bin; at most SL_PROFILE_EDGE_RETRIES.
    // (One call of extract_capped, inlined, and one bounds struct in this frame: a rejected
    // retry is recomputed from the accepted cap; this sits on the deepest stack chain.)
    uint32_t cap = UINT32_MAX;     // the accepted cap
    uint32_t try_cap = UINT32_MAX; // the cap of this pass
    uint32_t prev_i2 = 0U, k = 0U, ref = 0U;
    bool redo = false, done = false;
    sl_profile_bounds_t r;
    while (!done) {
        r = extract_capped(sum, n, frames, threshold, hint, cal_slope_q8, cliff_end, try_cap,
                           tol_q8);
        if (redo) {
            done = true; // the accepted pass again
        } else if (k > 0U && (r.fail != (uint8_t)SL_PROFILE_OK || (uint32_t)r.i2 >= prev_i2 ||
                              (uint32_t)r.slope_q8 * 2U < ref ||
                              (uint32_t)r.slope_q8 * 2U > ref * 3U)) {
            k--;
            try_cap = cap;
            redo = true;
        } else {
            cap = try_cap;
            if (k == SL_PROFILE_EDGE_RETRIES || r.fail != (uint8_t)SL_PROFILE_OK ||
                r.slope_src == SL_PROFILE_SLOPE_CLIFF || (uint32_t)r.i2 < cliff_end ||
                (uint32_t)r.i2 < (uint32_t)r.i1 + FIT_MIN_BINS + 1U) {
                done = true;
            } else {
                if (k == 0U) {
                    ref = cal_slope_q8 != 0U ? cal_slope_q8 : r.slope_q8;
                }
                prev_i2 = r.i2;
                try_cap = prev_i2 - 1U;
                k++;
            }
        }
    }
    r.retried = (uint8_t)k;
    return r;
}

// round(65536 x 10^(-k/20)), k = 0..48 values (0.5 dB each), saturated at 65535.
static const uint16_t k_fill_q16[SL_PROFILE_FILL_VALUES + 1U] = {
    65535U, 58409U, 52057U, 46396U, 41350U, 36854U, 32846U, 29274U, 26090U, 23253U, 20724U,
    18471U, 16462U, 14672U, 13076U, 11654U, 10387U, 9257U,  8250U,  7353U,  6554U,  5841U,
    5206U,  4640U,  4135U,  3685U,  3285U,  2927U,  2609U,  2325U,  2072U,  1847U,  1646U,
    1467U,  1308U,  1165U,  1039U,  926U,   825U,   735U,   655U,   584U,   521U,   464U,
    414U,   369U,   328U,   293U,   261U};

uint32_t sl_profile_fill_q16(uint32_t edge_sum, uint32_t ref_sum, uint32_t frames)
{
    if (frames == 0U || edge_sum >= ref_sum) {
        return 65535U;
    }
    const uint32_t dv = ref_sum - edge_sum; // values x frames
    const uint32_t k = dv / frames;
    if (k >= SL_PROFILE_FILL_VALUES) {
        return 0U;
    }
    // linear between whole values; (dv % frames) < frames <= 2^16, so no overflow
    const uint32_t fr = ((dv % frames) << 8) / frames; // Q8
    return ((uint32_t)k_fill_q16[k] * (256U - fr) + (uint32_t)k_fill_q16[k + 1U] * fr) >> 8;
}

// Power of the first bin over the second's, Q16, for a first bin lit over f (Q16) whose lit
// part starts delta (Q16 bins) past the foot: (sqrt(f + d) - sqrt(d)) / (sqrt(1 + f + d) -
// sqrt(f + d)).
static uint64_t lead_ratio_q16(uint64_t f, uint64_t d, uint64_t sd)
{
    const uint64_t a = sl_fx_isqrt64((f + d) << 16);
    const uint64_t c = sl_fx_isqrt64((f + d + 65536U) << 16);
    return ((a - sd) << 16) / (c - a);
}

// P_num / P_den in Q16 from two summed values (sl_profile_fill_q16's scale), either may be
// the larger: 2^32 when the numerator is SL_PROFILE_FILL_VALUES or more values above.
static uint64_t power_ratio_q16(uint32_t num_sum, uint32_t den_sum, uint32_t frames)
{
    if (num_sum <= den_sum) {
        return sl_profile_fill_q16(num_sum, den_sum, frames);
    }
    const uint32_t inv = sl_profile_fill_q16(den_sum, num_sum, frames);
    return inv == 0U ? ((uint64_t)1U << 32) : ((uint64_t)1U << 32) / inv;
}

uint32_t sl_profile_lead_fill_q16(uint32_t first_sum, uint32_t second_sum, uint32_t frames,
                                  uint32_t delta_q16)
{
    if (delta_q16 >= SL_PROFILE_LEAD_END_Q16) {
        return sl_profile_fill_q16(first_sum, second_sum, frames);
    }
    const uint64_t q = power_ratio_q16(first_sum, second_sum, frames); // P1 / P2
    if (delta_q16 == 0U) {
        // at the foot, closed form: q = f + sqrt(f (1 + f)) <=> f = q^2 / (1 + 2 q), full from
        // q = 1 + sqrt(2) on (below it q^2 < 2^35)
        if (q >= 158217U) {
            return 65535U;
        }
        const uint64_t f = (q * q) / (65536U + 2U * q);
        return f >= 65535U ? 65535U : (uint32_t)f;
    }
    const uint64_t d = delta_q16;
    const uint64_t sd = sl_fx_isqrt64(d << 16);
    if (q >= lead_ratio_q16(65536U, d, sd)) {
        return 65535U;
    }
    // the ratio grows with f: bisection to 1/256 bin (0.2 mm on the CTS350-X)
    uint64_t lo = 0U, hi = 65536U;
    for (uint32_t k = 0U; k < 8U; k++) {
        const uint64_t mid = (lo + hi) >> 1;
        if (lead_ratio_q16(mid, d, sd) <= q) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    const uint64_t f = (lo + hi) >> 1;
    return f >= 65535U ? 65535U : (uint32_t)f;
}

static void calibrate(sl_profile_t *pr, uint32_t s)
{
    if (pr->cal_n >= CAL_GATE_N) {
        const uint32_t c = pr->slope_q8;
        if (s * 10U < c * 7U || s * 10U > c * 13U) {
            pr->stats.cal_rejected++;
            return;
        }
    }
    if (pr->cal_n == 0U) {
        pr->slope_q8 = (uint16_t)s;
    } else {
        pr->slope_q8 = (uint16_t)((7U * pr->slope_q8 + s + 4U) / 8U);
    }
    if (pr->cal_n < 0xFFFFU) {
        pr->cal_n++;
    }
    pr->stats.cal_accepted++;
}

bool sl_profile_clean(const sl_profile_t *pr)
{
    SL_ASSERT(pr != NULL);
    return pr->clean_n >= SL_PROFILE_CAL_SMEAR_N && pr->cal_n < SL_PROFILE_CAL_SMEAR_N &&
           pr->cut_n < SL_PROFILE_CAL_SMEAR_N && pr->cfg.prior_slope_q8 == 0U;
}

bool sl_profile_cut(const sl_profile_t *pr)
{
    SL_ASSERT(pr != NULL);
    return pr->cut_n >= SL_PROFILE_CAL_SMEAR_N;
}

uint32_t sl_profile_coarse_sigma_um(uint32_t bin_um)
{
    // b / sqrt(3): 37,837 / 65,536 = 0.577346 (1 / sqrt(3) = 0.577350)
    return (uint32_t)(((uint64_t)bin_um * 37837U + 32768U) >> 16);
}

// Bins of the monotone stretch at `k`: steps of at least `frames` (one value per bin per
// frame of the sums; 0: any step that does not fall), up from `k` towards `lim` (> k) or
// down towards `lim` (< k), read as rising towards `k`.
// Used for the ramps of sl_profile.h, "Uncertainty of the bounds".
static uint32_t ramp_bins(const uint16_t *sum, uint32_t k, uint32_t lim, uint32_t frames)
{
    uint32_t n = 0U;
    if (lim > k) {
        while (k + n < lim && (uint32_t)sum[k + n + 1U] >= (uint32_t)sum[k + n] + frames) {
            n++;
        }
    } else {
        while (k - n > lim && (uint32_t)sum[k - n - 1U] >= (uint32_t)sum[k - n] + frames) {
            n++;
        }
    }
    return n;
}

// Whether the falling ramp of `n` (>= 3) bins that ends in bin `k` falls faster in its half
// nearer `k` (by half a value per bin): a tail flattening towards the pole, the end of a
// kernel of finite support (the log of a power that reaches zero falls ever faster), which a
// pole's own return does not do (its power per bin falls fastest right after its brightest
// point).
static SL_NOINLINE bool falls_faster_near(const uint16_t *sum, uint32_t k, uint32_t n,
                                          uint32_t frames)
{
    // rates x h (n - h), 32 bits: sums < 2^16, n < 64, frames <= 257
    const uint32_t h = n / 2U, m = k - h;
    const uint32_t near = (uint32_t)(sum[m] - sum[k]) * (n - h);
    const uint32_t far = (uint32_t)(sum[k - n] - sum[m]) * h;
    return 2U * near >= 2U * far + frames * h * (n - h);
}

// One more sample in cell `k` of the histogram `h` (`n` cells of counts); the counts are
// halved when they reach `keep` in all (recent samples count). @return the count in all.
static uint32_t hist_count(uint8_t *h, uint32_t n, uint32_t k, uint32_t keep)
{
    h[k]++;
    uint32_t total = 0U;
    for (uint32_t i = 0; i < n; i++) {
        total += h[i];
    }
    if (total >= keep) {
        total = 0U;
        for (uint32_t i = 0; i < n; i++) {
            h[i] = (uint8_t)(h[i] >> 1);
            total += h[i];
        }
    }
    return total;
}

// One branch-2 return's rise into the stream's front part ("Front part" in sl_profile.h):
// counted, the counts halved at SL_PROFILE_LEAD_KEEP, and the front re-read: known when the
// smallest rise held by an eighth of them is 3 bins or more (7 of 8 rise so far), as that
// rise; lost when half rise by a bin at most. `front_news` when it becomes known.
static void learn_front(sl_profile_t *pr, uint32_t rise)
{
    const uint32_t total =
        hist_count(pr->lead_n, SL_PROFILE_LEAD_HIST,
                   rise < SL_PROFILE_LEAD_HIST ? rise : SL_PROFILE_LEAD_HIST - 1U,
                   SL_PROFILE_LEAD_KEEP);
    if (total < SL_PROFILE_LEAD_MIN) {
        return;
    }
    // The smallest rise held by an eighth of them (q8) and by half (q2).
    uint32_t cum = 0U;
    uint32_t q8 = SL_PROFILE_LEAD_HIST, q2 = SL_PROFILE_LEAD_HIST;
    for (uint32_t k = 0; k < SL_PROFILE_LEAD_HIST; k++) {
        cum += pr->lead_n[k];
        q8 = (q8 == SL_PROFILE_LEAD_HIST && 8U * cum >= total) ? k : q8;
        q2 = (q2 == SL_PROFILE_LEAD_HIST && 2U * cum >= total) ? k : q2;
    }
    if (pr->front_bins == 0U) {
        if (q8 >= 3U) { // (q2 >= q8)
            pr->front_bins = (uint8_t)q8;
            pr->front_news = 1U;
        }
    } else {
        // Once known, until most returns rise by a bin at most (hysteresis: a front of 2 bins
        // shows its median at 2-3).
        pr->front_bins = (uint8_t)(q2 <= 1U ? 0U : (q8 >= 2U ? q8 : 2U));
    }
}

// One walked return's residual r2 - r1 / cos(theta) (`r2_um` before the walk-end offset;
// "Online calibration" in sl_profile.h): within one bin `b` either way (an upright pole) it
// is counted, the counts halved at SL_PROFILE_RESID_KEEP, and from SL_PROFILE_RESID_MIN
// samples on r2_offset_um = minus their mean.
static SL_NOINLINE void learn_resid(sl_profile_t *pr, uint32_t r1_um, uint32_t r2_um,
                                    const sl_incline_geom_t *g, uint32_t b)
{
    if (g->cos_theta_q30 <= 0 || b == 0U || b > (1UL << 20)) { // bins up to 1 m: 32-bit mean
        return;
    }
    const uint64_t up = (((uint64_t)r1_um << 30) + ((uint32_t)g->cos_theta_q30 >> 1)) /
                        (uint32_t)g->cos_theta_q30;
    const int64_t res = (int64_t)r2_um - (int64_t)up;
    if (res < -(int64_t)b || res >= (int64_t)b) {
        return; // not near upright
    }
    const uint32_t cell = (uint32_t)(res + (int64_t)b) * (SL_PROFILE_RESID_CELLS / 2U) / b;
    pr->stats.resid_samples++;
    const uint32_t total =
        hist_count(pr->resid_n, SL_PROFILE_RESID_CELLS, cell, SL_PROFILE_RESID_KEEP);
    if (total < SL_PROFILE_RESID_MIN) {
        return;
    }
    // Their mean, from the cells' centres x_c = c + 1/2: residual = b (x / 8 - 1) = b (sum
    // n_c (2c + 1) - 16 total) / (16 total). The mean, not the median: a walk's end is
    // bimodal (the pole's last own bin, or the one before it), and what reads the bounds
    // averages them (the tracker's fusion, the 3D fit's least squares), so it is the mean
    // residual that biases what reaches the bus. (The numerator is within 16 total b: 32 bits.)
    int32_t k = 0;
    for (uint32_t c = 0; c < SL_PROFILE_RESID_CELLS; c++) {
        k += (int32_t)pr->resid_n[c] * (int32_t)(2U * c + 1U);
    }
    k -= (int32_t)(SL_PROFILE_RESID_CELLS * total);
    pr->r2_offset_um = -(k * (int32_t)b) / ((int32_t)SL_PROFILE_RESID_CELLS * (int32_t)total);
}

// The first bin (absolute) of slot `si`'s row at or above the threshold, searched from
// absolute bin `a1` - 3 over FIT_BINS + 3 bins; UINT32_MAX when there is none.
static uint32_t row_first(const sl_profile_t *pr, uint32_t si, uint32_t a1, uint32_t threshold)
{
    const sl_profile_slot_t *o = &pr->slot[si];
    const uint32_t thr = (uint32_t)o->frames * threshold;
    uint32_t j = a1 > (uint32_t)o->bin0 + 3U ? a1 - o->bin0 - 3U : 0U;
    const uint32_t end = j + FIT_BINS + 3U;
    while (j < end && j + 1U < SL_CFG_PROFILE_BINS && o->sum[j] < thr) {
        j++;
    }
    return (j < end && j + 1U < SL_CFG_PROFILE_BINS && o->sum[j] >= thr) ? o->bin0 + j
                                                                          : UINT32_MAX;
}

// The rise of slot `si`'s own row ("Front part"): ramp_bins from its first bin at or above
// the threshold (`*first`: row_first from absolute bin `a1`), over at most FIT_BINS bins;
// `*strong`: the brightest of those bins is T/2 above the threshold.
static SL_NOINLINE uint32_t own_rise(const sl_profile_t *pr, uint32_t si, uint32_t a1,
                                     uint32_t threshold, bool *strong, uint32_t *first)
{
    const sl_profile_slot_t *o = &pr->slot[si];
    *strong = false;
    const uint32_t f = row_first(pr, si, a1, threshold);
    *first = f;
    if (f == UINT32_MAX) {
        return 0U;
    }
    const uint32_t j = f - o->bin0;
    const uint32_t lim = j + FIT_BINS < SL_CFG_PROFILE_BINS ? j + FIT_BINS : SL_CFG_PROFILE_BINS - 1U;
    uint32_t top = 0U;
    for (uint32_t k = j; k <= lim; k++) {
        top = o->sum[k] > top ? o->sum[k] : top;
    }
    *strong = top >= (uint32_t)o->frames * (threshold + threshold / 2U);
    return ramp_bins(o->sum, j, lim, o->frames);
}

// Slot of target `t`'s neighbouring azimuth on side `d` (0: az - 1, 1: az + 1) when that
// azimuth lies in t's detection group and is watched with rows; SL_PROFILE_NONE otherwise.
static uint8_t group_neighbour(const sl_profile_t *pr, const sl_target_t *t, uint32_t d)
{
    const uint32_t az_n = pr->azimuths;
    const uint32_t nb = d == 0U ? (t->az + az_n - 1U) % az_n : (t->az + 1U) % az_n;
    if ((nb + az_n - t->az_first % az_n) % az_n >= t->az_count || nb == t->az) {
        return (uint8_t)SL_PROFILE_NONE; // not in the group
    }
    const uint8_t ni = pr->slot_of[nb];
    return (ni != SL_PROFILE_NONE && pr->slot[ni].frames != 0U) ? ni : (uint8_t)SL_PROFILE_NONE;
}

// Whether target `t`'s neighbouring azimuths in its group (watched, with rows) start where
// its own row does (within a bin), and there is at least one: the pole's rows hold it at the
// same ranges, as they do with a kernel's front part. A pole leaning across the line of
// sight holds other heights at other ranges on each azimuth, and the beam's azimuth pattern
// weighs its slanted piece so that a row's own return rises (measured: 2-4 bins on the
// leaning-away returns of poles leaning along the path, without a front).
static SL_NOINLINE bool starts_aligned(const sl_profile_t *pr, const sl_target_t *t,
                                       uint32_t own_first, uint32_t threshold)
{
    uint32_t seen = 0U;
    for (uint32_t d = 0; d < 2U; d++) {
        const uint8_t ni = group_neighbour(pr, t, d);
        if (ni == SL_PROFILE_NONE) {
            continue;
        }
        const uint32_t f = row_first(pr, ni, own_first, threshold);
        if (f == UINT32_MAX || f + 1U < own_first || f > own_first + 1U) {
            return false;
        }
        seen++;
    }
    return seen != 0U;
}

// Bins of a walked return's rise (`pb`, starting at absolute bin `a1`) that its r1 moves
// past ("Front part"): min(its rise, the stream's front), r1 staying before r2. The rise is
// the longer of its own azimuth's row's (one rotation's rows of an oblique pole may start
// elsewhere) and the rows' sum's (less noise to break a rise's shallow steps). A leaning-
// away return (`branch2`) strong enough to show a front, whose neighbouring rows start
// where its own does, counts its rise, once per slot.
static SL_NOINLINE uint32_t front_skip(sl_profile_t *pr, uint32_t si, const uint16_t *sum,
                                       uint32_t n, uint32_t frames, uint32_t threshold,
                                       const sl_profile_bounds_t *pb, uint32_t a1, bool branch2,
                                       const sl_target_t *t)
{
    bool strong = false;
    uint32_t f = UINT32_MAX;
    const uint32_t own = own_rise(pr, si, a1, threshold, &strong, &f);
    const uint32_t in_sum =
        ramp_bins(sum, pb->i1, pb->i1 + FIT_BINS < n ? pb->i1 + FIT_BINS : n - 1U, frames);
    const uint32_t rise = own > in_sum ? own : in_sum;
    sl_profile_slot_t *o = &pr->slot[si];
    if (o->lead_seen == 0U && strong && branch2) {
        o->lead_seen = 1U;
        if (starts_aligned(pr, t, f, threshold)) { // strong: f is a bin
            learn_front(pr, rise);
        }
    }
    uint32_t skip = rise < pr->front_bins ? rise : pr->front_bins;
    if (pb->i1 + skip >= pb->i2) {
        skip = pb->i2 > pb->i1 ? pb->i2 - pb->i1 - 1U : 0U;
    }
    return skip;
}

// Bins (>= 3, else 0) of the falling ramp that ends in r2 and may be a smear tail: into a
// cliff, the steps of at least a value per bin; at the end of a walk, when those steps fall
// faster near r2 (falls_faster_near: a kernel of finite support, whether its end is a drop
// or lies under a weaker, longer component the walk removed), every bin over which the
// profile does not rise into r2 (near the pole such a kernel falls by less than a value
// per bin: flat after rounding).
static uint32_t tail_ramp(const uint16_t *sum, const sl_profile_bounds_t *pb, uint32_t frames)
{
    const uint32_t n = ramp_bins(sum, pb->i2, pb->i1, frames);
    if (n < 3U) {
        return 0U;
    }
    if (pb->slope_src == (uint8_t)SL_PROFILE_SLOPE_CLIFF) {
        return n;
    }
    return falls_faster_near(sum, pb->i2, n, frames) ? ramp_bins(sum, pb->i2, pb->i1, 0U) : 0U;
}

// Where a row's return ends, for comparing neighbouring rows (combine_neighbours): the last
// bin (absolute) of the first run at or after bin `first` (bins >= frames x thr, gaps <= 2
// bridged) that is within thr / 4 values per frame of the run's highest bin. A row's beam
// gain is an offset and the smear the same kernel, so rows that hold the pole at the same
// ranges end there within a bin or two (speckle moves the highest bin); a row that holds an
// oblique pole's other ranges ends elsewhere.
static uint32_t row_end(const sl_profile_slot_t *q, uint32_t first, uint32_t thr)
{
    const uint32_t f = q->frames;
    uint32_t j = first > q->bin0 ? first - q->bin0 : 0U;
    while (j < SL_CFG_PROFILE_BINS && q->sum[j] < f * thr) {
        j++;
    }
    if (j >= SL_CFG_PROFILE_BINS) {
        return UINT32_MAX / 2U; // no return: ends nowhere near a return
    }
    uint32_t mx = 0U, last = j;
    for (; j < SL_CFG_PROFILE_BINS; j++) {
        if (q->sum[j] >= f * thr) {
            last = j;
            mx = q->sum[j] > mx ? q->sum[j] : mx;
        } else if (j > last + 2U) {
            break;
        }
    }
    uint32_t e = last;
    while (e > 0U && (uint32_t)q->sum[e] + f * (thr / 4U) < mx) {
        e--;
    }
    return q->bin0 + e;
}

// The rows of target `t`'s azimuth (slot `si`) and of its two neighbours, when they belong
// to its detection group and are watched, summed into pr->scratch over the bins all of them
// cover (a neighbour whose window starts after the target's first bin - 3 would cut the
// leading edge: left out). Adjacent azimuths (0.9 deg on the CTS350-X) lie inside one beam
// width (1.8 deg), so they hold the same pole at the same ranges with their own speckle;
// except a pole oblique to the beam (leaning partly across the line of sight), whose end
// is 5-7 bins apart on neighbouring azimuths: a neighbour whose return ends more than
// ALIGN_BINS from the target's (row_end) is left out (`stats.misaligned`). Summed, its tail
// lay over the target's own bins and read as the target's tail (under a tail that
// steepens near the pole the walk took 8 and 13 own bins of a pole leaning towards the
// path for smear), and its disagreement widened every step test of the walk.
// `*bin0` / `*n`: the summed window. @return the rows summed (0: none).
static uint32_t combine_neighbours(sl_profile_t *pr, const sl_target_t *t, uint8_t si,
                                   uint32_t thr, uint32_t *bin0, uint32_t *n, uint32_t *tol_q8)
{
    const sl_profile_slot_t *use[3];
    uint32_t k = 0;
    use[k++] = &pr->slot[si];
    uint32_t lo = pr->slot[si].bin0;
    uint32_t hi = lo + SL_CFG_PROFILE_BINS;
    const uint32_t end0 = row_end(&pr->slot[si], t->bin_first, thr);
    for (uint32_t d = 0; d < 2U; d++) {
        const uint8_t ni = group_neighbour(pr, t, d);
        if (ni == SL_PROFILE_NONE || (uint32_t)pr->slot[ni].bin0 + 3U > t->bin_first) {
            continue;
        }
        const sl_profile_slot_t *q = &pr->slot[ni];
        const uint32_t end = row_end(q, t->bin_first, thr);
        if (end + ALIGN_BINS < end0 || end > end0 + ALIGN_BINS) {
            pr->stats.misaligned++; // its return ends elsewhere: not the same ranges
            continue;
        }
        lo = q->bin0 > lo ? q->bin0 : lo;
        hi = (uint32_t)q->bin0 + SL_CFG_PROFILE_BINS < hi ? (uint32_t)q->bin0 + SL_CFG_PROFILE_BINS
                                                          : hi;
        use[k++] = q;
    }
    if (k < 2U) {
        return pr->slot[si].frames;
    }
    uint32_t frames = 0;
    memset(pr->scratch, 0, sizeof pr->scratch);
    for (uint32_t i = 0; i < k; i++) {
        const uint32_t off = lo - use[i]->bin0;
        for (uint32_t j = 0; j < hi - lo; j++) {
            pr->scratch[j] = (uint16_t)(pr->scratch[j] + use[i]->sum[off + j]);
        }
        frames += use[i]->frames;
    }
    // The noise of one step of the sum (Q8 values): the rows hold the same pole at the same
    // ranges, so their steps differ by their noise only (a row's beam gain is an offset, the
    // shape is common). Over the bins the sum holds above the threshold: the mean range of
    // the rows' steps, sigma = range / 1.128 (two rows) or / 1.693 (three); the sum's step
    // sigma is sqrt(k) times that; two of them, less the one value of rounding the walk
    // allows already. Noise-free rows (neighbours at other gains) agree: 0.
    // Only behind the sum's brightest bin (the tail: the pole's own bins lie at other ranges
    // on the neighbours of an oblique pole) and where every row is above the threshold.
    uint32_t top = 0U;
    for (uint32_t j = 1; j < hi - lo; j++) {
        top = pr->scratch[j] > pr->scratch[top] ? j : top;
    }
    uint32_t acc = 0U, cnt = 0U;
    for (uint32_t j = top + 1U; j < hi - lo; j++) {
        int32_t mn = 0, mx = 0;
        bool all = true;
        for (uint32_t i = 0; i < k; i++) {
            const uint32_t off = lo - use[i]->bin0;
            const uint32_t a = use[i]->sum[off + j - 1U], b = use[i]->sum[off + j];
            all = all && b >= use[i]->frames * thr;
            const int32_t d = (int32_t)a - (int32_t)b;
            mn = (i == 0U || d < mn) ? d : mn;
            mx = (i == 0U || d > mx) ? d : mx;
        }
        if (!all) {
            break; // the tail's end on one row
        }
        acc += (uint32_t)(mx - mn);
        cnt++;
    }
    *tol_q8 = 0U;
    if (cnt != 0U) {
        uint32_t w = acc * ((k == 2U) ? 642U : 524U); // 2 sqrt(k) / E[range of k normals] x 256
        w /= cnt;
        *tol_q8 = w > frames * 256U ? w - frames * 256U : 0U;
    }
    *bin0 = lo;
    *n = hi - lo;
    return frames;
}

bool sl_profile_lead_edge(const uint16_t *sum3, uint32_t frames, uint32_t delta_q16,
                          uint32_t *f_q16)
{
    SL_ASSERT(sum3 != NULL && f_q16 != NULL);
    const uint32_t f = sl_profile_lead_fill_q16(sum3[0], sum3[1], frames, delta_q16);
    *f_q16 = f;
    // P3 / P2 the model predicts (1 for an end), and the profile's, Q16
    uint64_t pred = 65536U;
    if (delta_q16 < SL_PROFILE_LEAD_END_Q16) {
        const uint64_t d = (uint64_t)f + delta_q16;
        const uint64_t s1 = sl_fx_isqrt64(d << 16);
        const uint64_t s2 = sl_fx_isqrt64((d + 65536U) << 16);
        const uint64_t s3 = sl_fx_isqrt64((d + 131072U) << 16);
        pred = ((s3 - s2) << 16) / (s2 - s1);
    }
    const uint64_t obs = power_ratio_q16(sum3[2], sum3[1], frames);
    // within LEAD_TOL_VALUES values either way (x 10^(-k/20), the fill table's step)
    const uint64_t tol = k_fill_q16[LEAD_TOL_VALUES];
    return obs * tol <= pred * 65536U && pred * tol <= obs * 65536U;
}

// How far past the foot of the pole's line its lit part starts, in Q16 bins (the leading
// edge's model, sl_profile_lead_fill_q16): 0 when r1 is the foot (branch 2); on branch 1 the
// top end lies on the +beta ray, alpha - beta from the foot: r1 (1 - cos(alpha - beta)),
// with 1 - cos x = x^2 / 2 - x^4 / 24 (x < 60 deg here: within 0.3 %).
static uint32_t lead_delta_q16(const sl_incline_result_t *res, const sl_incline_geom_t *g,
                               uint64_t r1_um, uint64_t bin_um)
{
    if (res->branch != (uint8_t)SL_INCLINE_BRANCH_1 || bin_um == 0U) {
        return 0U;
    }
    const int32_t x_bam = (int32_t)(res->alpha_bam32 - g->beta_bam32);
    const int64_t ax = x_bam < 0 ? -(int64_t)x_bam : (int64_t)x_bam;
    if (ax >= ((int64_t)1 << 29)) { // 45 deg: far from the foot, an end
        return SL_PROFILE_LEAD_END_Q16;
    }
    const int64_t x_q30 = (ax * 1686629713LL) >> 30; // bam32 -> rad (pi/2 in Q30)
    const int64_t x2 = (x_q30 * x_q30) >> 30;
    const int64_t one_minus_cos = x2 / 2 - ((x2 * x2) >> 30) / 24; // Q30
    const uint64_t d = ((r1_um * (uint64_t)one_minus_cos) >> 14) / bin_um; // Q16 bins
    return d >= SL_PROFILE_LEAD_END_Q16 ? SL_PROFILE_LEAD_END_Q16 : (uint32_t)d;
}

// The sigma of `res` when the truth lies anywhere between it and `far` (the bounds at the
// other end of an interval; the fold when they give no valid estimate), uniform: its own
// sigma and the difference / sqrt(3) (the RMS about one end), saturated.
static uint16_t end_sigma(const sl_incline_result_t *res, const sl_incline_result_t *far,
                          const sl_incline_geom_t *g)
{
    const int32_t fold =
        (sl_incline_bam32_to_cdeg(g->beta_bam32) - sl_incline_bam32_to_cdeg(g->theta_bam32)) / 2;
    const int64_t d = (int64_t)res->alpha_cdeg -
                      (far->flag == (uint8_t)SL_INCLINE_VALID ? far->alpha_cdeg : fold);
    const uint32_t sg = sl_fx_isqrt64((uint64_t)res->sigma_cdeg * res->sigma_cdeg +
                                      (uint64_t)(d * d + 1) / 3U);
    return (uint16_t)(sg > UINT16_MAX ? UINT16_MAX : sg);
}

// A target the profile could not check, in a stream not known to be clean (known to smear:
// SL_PROFILE_CAL_SMEAR_N self-fits, or a prior; or nothing known yet: fewer than
// SL_PROFILE_CAL_SMEAR_N returns seen to end in a cliff): its r2 is the mask's, the
// threshold crossing of a tail shortened by the board's d(r), a prior and not a measurement
// (a board without d keeps the whole tail).
// r2 is then known only to lie between r1 and that end: its sigma the extent / sqrt(12), at
// least the elongation applied and a bin, so alpha's sigma holds what the unremoved or
// overcorrected tail can do, the target is COARSE (its error repeats) and no warning level
// is raised on it (sl_track.h: levels rise only at a filtered sigma <= max_sigma). Alpha is
// unchanged.
// Cold start: the first rotations of every stream (moving: the first hits of every track,
// before a slot is reserved for it) come before any evidence either way.
static SL_NOINLINE void widen_unverified(const sl_profile_t *pr, const sl_board_t *board,
                                         sl_target_t *t, bool cut)
{
    if ((sl_profile_clean(pr) && !cut) || board->geom == NULL ||
        t->incline_flag != (uint8_t)SL_INCLINE_VALID) {
        return;
    }
    // r2 anywhere between r1 and the mask's end (uniform: the extent / sqrt(12)), at least
    // the correction d applied and a bin
    uint32_t s2 = t->r2_um > t->r1_um
                      ? (uint32_t)(((uint64_t)(t->r2_um - t->r1_um) * 37837U) >> 17)
                      : 0U;
    if (t->elong_um > 0 && (uint32_t)t->elong_um > s2) {
        s2 = (uint32_t)t->elong_um;
    }
    if (s2 < board->bin_size_um) {
        s2 = board->bin_size_um;
    }
    const uint32_t s1 = sl_detect_r1_sigma_um(t, board->range_sigma_um);
    const uint32_t sigma_r = sl_incline_bounds_sigma_um(t->r1_um, t->r2_um, s1, s2);
    const sl_incline_geom_t *g = &board->geom[t->az];
    sl_incline_result_t res =
        sl_incline_estimate(t->r1_um, t->r2_um, g, sigma_r, board->theta_sigma_cdeg);
    if (res.flag == (uint8_t)SL_INCLINE_VALID) {
        // Where alpha is flat in r2 (rho large on branch 1) the linearised sigma says
        // nothing of the interval: the alpha at its other end (r2 one bin past r1, or the
        // fold when that gives no valid estimate) bounds it, uniform between (the
        // difference / sqrt(3) about this end, as the ramps of sl_profile_refine).
        const uint32_t lo2 = t->r1_um + board->bin_size_um;
        if (lo2 < t->r2_um) {
            const sl_incline_result_t far =
                sl_incline_estimate(t->r1_um, lo2, g, sigma_r, board->theta_sigma_cdeg);
            res.sigma_cdeg = end_sigma(&res, &far, g);
        }
        if (res.sigma_cdeg > t->sigma_cdeg) {
            t->sigma_cdeg = res.sigma_cdeg;
        }
    }
    t->flags = (uint16_t)(t->flags | SL_TARGET_COARSE);
}

// The target keeps the mask's bounds for reason `why` (counted), unverified unless the
// stream is known clean (widen_unverified). @return why.
static uint8_t keep_mask(sl_profile_t *pr, const sl_board_t *board, sl_target_t *t, uint8_t why)
{
    pr->stats.fallback[why]++;
    widen_unverified(pr, board, t, false);
    return why;
}

uint8_t sl_profile_refine(sl_profile_t *pr, const sl_board_t *board, uint32_t threshold,
                          sl_target_t *t)
{
    SL_ASSERT(pr != NULL && board != NULL && t != NULL);
    const uint8_t si = t->az < pr->azimuths ? pr->slot_of[t->az] : (uint8_t)SL_PROFILE_NONE;
    if (si == SL_PROFILE_NONE || pr->slot[si].frames == 0U || t->bin_first < pr->slot[si].bin0) {
        const uint8_t why = (si != SL_PROFILE_NONE && pr->slot[si].frames != 0U)
                                ? (uint8_t)SL_PROFILE_LEAD_CUT
                                : (uint8_t)SL_PROFILE_NO_SLOT;
        return keep_mask(pr, board, t, why);
    }
    const sl_profile_slot_t *s = &pr->slot[si];
    const uint16_t *sum = s->sum;
    uint32_t frames = s->frames;
    uint32_t bin0 = s->bin0;
    uint32_t n = SL_CFG_PROFILE_BINS;
    uint32_t tol = 0U;
    bool spatial = false;
    bool single = false;
    if (frames < pr->cfg.min_frames) {
        // Too few rotations summed (moving: cleared every rotation): this rotation's rows
        // of the neighbouring azimuths of the group, aligned on their bins.
        frames = combine_neighbours(pr, t, si, threshold, &bin0, &n, &tol);
        spatial = true;
        if (frames < pr->cfg.min_frames) {
            // One row (no neighbour in the group, or none ending where it ends): too few to
            // walk a tail over or calibrate on, but a return that ends in a cliff no smear
            // tail makes is the stream's evidence all the same, as summed rows' cliffs are
            // (below: NO_TAIL or CUT, the mask's bounds); anything else is FEW_FRAMES.
            single = true;
        } else {
            sum = pr->scratch;
        }
    }
    // Bins from the first that starts at or beyond the shadow edge on: no cliff there.
    uint32_t cliff_end = UINT32_MAX;
    if (t->shadow_slant_um != 0U && board->bin_size_um != 0U) {
        const uint32_t eb = (t->shadow_slant_um + board->bin_size_um - 1U) / board->bin_size_um;
        cliff_end = eb > bin0 ? eb - bin0 : 0U;
    }
    // A pole leaning across the beam (SL_TARGET_SLANT): its azimuth holds the lowest visible
    // point, its run there [bin_last - occupied + 1, bin_last] (the bounds are the group's
    // union extent); only r2 is measured here.
    const bool slant = (t->flags & SL_TARGET_SLANT) != 0U;
    const uint32_t first =
        slant && t->occupied != 0U && (uint32_t)t->bin_last + 1U >= (uint32_t)t->occupied
            ? (uint32_t)t->bin_last + 1U - t->occupied
            : t->bin_first;
    const sl_profile_bounds_t pb = sl_profile_extract_noisy(sum, n, frames, threshold, first - bin0,
                                                            pr->slope_q8, cliff_end, tol);
    if (single && (pb.fail != (uint8_t)SL_PROFILE_OK || pb.slope_src != SL_PROFILE_SLOPE_CLIFF ||
                   !is_cliff(sum, pb.i2, frames, SLOPE_MAX_Q8))) {
        return keep_mask(pr, board, t, (uint8_t)SL_PROFILE_FEW_FRAMES);
    }
    if (pb.fail != (uint8_t)SL_PROFILE_OK) {
        return keep_mask(pr, board, t, pb.fail);
    }
    bool cut = false;
    if (pb.slope_src == SL_PROFILE_SLOPE_CLIFF) {
        // A return whose bins before its last (a partly lit bin) fall faster and faster into
        // the cliff is cut off, not ended: by the support of a smear kernel (the log of a
        // power that reaches zero), or by the beam's edge (a slanted pole leaving the
        // azimuth). Evidence on the stream ("Cut-off returns"): a kernel of finite support
        // cuts every return so, the beam only some. (A walk's tail is no such evidence: a
        // short tail after flatter own bins falls faster near its end too.)
        const uint32_t k = pb.i2 - 1U;
        const uint32_t nr = pb.i2 > pb.i1 + 3U ? ramp_bins(sum, k, pb.i1, frames) : 0U;
        cut = nr >= 3U && falls_faster_near(sum, k, nr, frames);
        if (cut && single) {
            // One row cut off is mostly the beam's edge on an oblique pole (whose neighbours
            // end elsewhere): no evidence on the stream's smear, and FEW_FRAMES as before.
            return keep_mask(pr, board, t, (uint8_t)SL_PROFILE_FEW_FRAMES);
        }
        if (cut) {
            pr->cut_n = pr->cut_n < UINT8_MAX ? (uint8_t)(pr->cut_n + 1U) : pr->cut_n;
            // Until the stream is known clean, a cut-off cliff takes back a clean one: it
            // becomes clean on SL_PROFILE_CAL_SMEAR_N more clean cliffs than cut ones
            // (once clean, only a net run of cut ones, cut_n, undoes it).
            if (pr->clean_n < SL_PROFILE_CAL_SMEAR_N && pr->clean_n > 0U) {
                pr->clean_n--;
            }
            pr->stats.cut_ends++;
        } else {
            pr->clean_n = pr->clean_n < UINT8_MAX ? (uint8_t)(pr->clean_n + 1U) : pr->clean_n;
            pr->cut_n = pr->cut_n > 0U ? (uint8_t)(pr->cut_n - 1U) : 0U;
        }
    }
    // The mask's bounds: for a return cut off, or in a stream whose returns are (a smear no
    // tail model here describes: what a walk would take for a tail may be the kernel's own
    // shape), unverified whatever the stream; while moving, for a cliff (neighbouring
    // azimuths serve to remove a smear tail; without one the mask's run is the return's own,
    // while a mean over azimuths that see an oblique pole at other ranges would end
    // elsewhere), unverified unless the stream is known clean.
    cut = cut || sl_profile_cut(pr);
    if (cut || (spatial && pb.slope_src == SL_PROFILE_SLOPE_CLIFF)) {
        pr->stats.fallback[SL_PROFILE_NO_TAIL]++;
        t->flags = (uint16_t)(t->flags | SL_TARGET_NO_TAIL);
        if (cut) {
            t->flags = (uint16_t)(t->flags | SL_TARGET_CUT);
        }
        widen_unverified(pr, board, t, cut);
        return (uint8_t)SL_PROFILE_NO_TAIL;
    }
    if (pb.slope_src == SL_PROFILE_SLOPE_FIT) {
        calibrate(pr, pb.slope_q8);
    }
    const uint64_t b = board->bin_size_um;
    if (spatial) {
        pr->stats.spatial++;
    }
    const uint64_t i1 = (uint64_t)bin0 + pb.i1, i2 = (uint64_t)bin0 + pb.i2;
    // The detector's bounds are half-bin centres + radius terms (- d on r2): keep the
    // radius terms, replace the centres, drop d.
    const int64_t r1_hb_mask = (int64_t)((((uint64_t)2U * t->bin_first + 1U) * b + 1U) / 2U);
    const int64_t r2_hb_mask = (int64_t)((((uint64_t)2U * t->bin_last + 1U) * b + 1U) / 2U);
    const int64_t r1_term = (int64_t)t->r1_um - r1_hb_mask;
    const int64_t r2_term = (int64_t)t->r2_um - (r2_hb_mask - (int64_t)t->elong_um);
    const int64_t r1_hb = (int64_t)(((2U * i1 + 1U) * b + 1U) / 2U);
    int64_t r2_hb = (int64_t)(((2U * i2 + 1U) * b + 1U) / 2U);
    // The walk's end over rotations summed moved by what the stream's upright poles say it
    // misses ("Online calibration"; within a bin either way); not one rotation's rows
    // (moving), not a walk that took every bin after the first for tail (no end of the pole
    // found: r2 = r1, INVALID, as before).
    const bool walk_end = !spatial && pb.slope_src != SL_PROFILE_SLOPE_CLIFF;
    int32_t r2_off = 0;
    if (walk_end && pb.i2 > pb.i1) {
        const int32_t bb = (int32_t)b;
        r2_off = pr->r2_offset_um > bb ? bb : (pr->r2_offset_um < -bb ? -bb : pr->r2_offset_um);
        r2_hb += r2_off;
    }
    if (pb.slope_src == SL_PROFILE_SLOPE_CLIFF && pb.i2 > pb.i1) {
        // Sub-bin far edge (see sl_profile_fill_q16): the last own bin's lit fraction from
        // its power against the own bin before it.
        const uint32_t f = sl_profile_fill_q16(sum[pb.i2], sum[pb.i2 - 1U], frames);
        r2_hb = (int64_t)(i2 * b + ((uint64_t)f * b + 32768U) / 65536U);
    }
    if (!slant) {
        t->r1_um = sl_fx_usat32(r1_hb + r1_term);
    }
    t->r2_um = sl_fx_usat32(r2_hb + r2_term);
    t->elong_um = sl_fx_sat32(r2_hb_mask - r2_hb);
    t->flags = (uint16_t)((t->flags & ~(SL_TARGET_ELONG | SL_TARGET_COARSE | SL_TARGET_WALKED)) |
                          SL_TARGET_PROFILE |
                          (pb.slope_src != SL_PROFILE_SLOPE_CLIFF ? SL_TARGET_WALKED : 0U));
    // Uncertainty of the bounds: a walk's end under a smear tail, and one rotation's edges
    // (neighbouring rows, moving), are known to two bins; a cliff or summed rotations'
    // leading edge to the board's range sigma; r1's radius from width adds its own size.
    uint32_t s1 = board->range_sigma_um, s2 = s1;
    const uint32_t coarse = sl_profile_coarse_sigma_um(board->bin_size_um);
    if (pb.slope_src != SL_PROFILE_SLOPE_CLIFF && s2 < coarse) {
        s2 = coarse;
    }
    if (spatial && s1 < coarse) {
        s1 = coarse;
    }
    s1 = sl_detect_r1_sigma_um(t, s1); // the radius from width (sl_detect.h stage 6)
    uint32_t sigma_r = s1;
    if (s1 != s2) {
        sigma_r = sl_incline_bounds_sigma_um(t->r1_um, t->r2_um, s1, s2);
    }
    if (s1 != board->range_sigma_um || s2 != board->range_sigma_um) {
        t->flags = (uint16_t)(t->flags | SL_TARGET_COARSE);
    }
    if (board->geom != NULL) {
        sl_incline_result_t res = sl_incline_estimate(t->r1_um, t->r2_um, &board->geom[t->az],
                                                      sigma_r, board->theta_sigma_cdeg);
        uint32_t lead = pb.i1;
        uint64_t front_um = 0U; // half the front part r1 moved past: the rest is its sigma
        if (!slant && pb.slope_src != SL_PROFILE_SLOPE_CLIFF) {
            // Front part (sl_profile.h): a branch-2 return's rise, its neighbours starting
            // where it does, is the stream's front; every walked target's r1 moves past it.
            const uint32_t skip =
                front_skip(pr, si, sum, n, frames, threshold, &pb, (uint32_t)i1,
                           res.flag == (uint8_t)SL_INCLINE_VALID &&
                               res.branch == (uint8_t)SL_INCLINE_BRANCH_2,
                           t);
            if (skip != 0U) {
                // Where the pole starts within the rise, no rule here can say (a long own
                // return's smear and a partly lit bin rise too): r1 at the middle of the
                // front's bins, its sigma over all of them (the ramps below).
                lead += skip;
                front_um = (uint64_t)skip * b / 2U;
                t->r1_um = sl_fx_usat32((int64_t)t->r1_um + (int64_t)front_um);
                if (s1 != s2) {
                    sigma_r = sl_incline_bounds_sigma_um(t->r1_um, t->r2_um, s1, s2);
                }
                res = sl_incline_estimate(t->r1_um, t->r2_um, &board->geom[t->az], sigma_r,
                                          board->theta_sigma_cdeg);
                pr->stats.front_skipped++;
            }
        }
        if (!slant && pb.slope_src == SL_PROFILE_SLOPE_CLIFF && pb.i2 >= pb.i1 + 3U &&
            res.flag == (uint8_t)SL_INCLINE_VALID) {
            // Sub-bin leading edge (step 6): the first bin's lit fraction from its power
            // against the second's, with the model of the branch the bounds gave, when the
            // third bin follows the same model (else the centre is kept, `lead_kept`).
            uint32_t f = 0U;
            if (sl_profile_lead_edge(&sum[pb.i1], frames,
                                     lead_delta_q16(&res, &board->geom[t->az], i1 * b, b), &f)) {
                const int64_t r1_sub =
                    (int64_t)((i1 + 1U) * b - ((uint64_t)f * b + 32768U) / 65536U);
                t->r1_um = sl_fx_usat32(r1_sub + r1_term);
                res = sl_incline_estimate(t->r1_um, t->r2_um, &board->geom[t->az], sigma_r,
                                          board->theta_sigma_cdeg);
            } else {
                pr->stats.lead_kept++;
            }
        }
        // Ramps (sl_profile.h, "Uncertainty of the bounds"): a smear kernel with a front
        // part or a finite support, which no tail fit sees, would leave the edges anywhere
        // along them. The alpha stays; its sigma holds the alpha at the ramps' other ends
        // (uniform between: the difference / sqrt(3)), or at the fold when the bounds there
        // give no valid estimate. A slanted pole's r1 is not read here: no ramp at r1.
        if (res.flag == (uint8_t)SL_INCLINE_VALID) {
            const uint32_t up = !slant && res.branch == (uint8_t)SL_INCLINE_BRANCH_1
                                    ? ramp_bins(sum, lead, pb.e, frames)
                                    : 0U;
            // A front ramp is a smear of its own: the target's cliff may then end its kernel.
            // After a restarted walk (step 4') r2 ends a tail whose first stop lay beyond the
            // shadow edge, and where the restarted walk stops is known only up to where the
            // tail could still go on: the bins over which the profile does not rise into r2
            // (ramp_bins with no minimum step; a kernel linear in power falls by less than a
            // value per bin near the pole, flat after rounding), from 3 on.
            uint32_t down = 0U;
            if (pb.retried != 0U) {
                down = ramp_bins(sum, pb.i2, pb.i1, 0U);
                down = down >= 3U ? down : 0U;
            } else if (pr->slope_q8 != 0U || up >= 3U) {
                down = tail_ramp(sum, &pb, frames);
            }
            const uint64_t lo1 = (uint64_t)t->r1_um + (up >= 3U ? up * b : 0U) + front_um;
            const uint64_t dn2 = (uint64_t)down * b;
            if (lo1 != t->r1_um || dn2 != 0U) {
                const sl_incline_result_t far = sl_incline_estimate(
                    sl_fx_usat32((int64_t)lo1), dn2 < t->r2_um ? t->r2_um - (uint32_t)dn2 : 0U,
                    &board->geom[t->az], sigma_r, board->theta_sigma_cdeg);
                res.sigma_cdeg = end_sigma(&res, &far, &board->geom[t->az]);
                t->flags = (uint16_t)(t->flags | SL_TARGET_COARSE);
                if (up >= 3U || dn2 != 0U) {
                    t->flags = (uint16_t)(t->flags | SL_TARGET_RAMP);
                    pr->stats.ramps++;
                }
            }
        }
        // An upright pole's residual ("Online calibration"): a walk's end over rotations
        // summed, both bounds this return's own (not SLANT), no ramp at either; once per slot.
        if (walk_end && !slant && (t->flags & SL_TARGET_RAMP) == 0U &&
            pr->slot[si].resid_seen == 0U) {
            pr->slot[si].resid_seen = 1U;
            learn_resid(pr, t->r1_um, (uint32_t)((int64_t)t->r2_um - r2_off),
                        &board->geom[t->az], (uint32_t)b);
        }
        t->alpha_cdeg = res.alpha_cdeg;
        t->sigma_cdeg = res.sigma_cdeg;
        t->incline_flag = res.flag;
        t->incline_branch = res.branch;
    }
    pr->stats.extracted++;
    return (uint8_t)SL_PROFILE_OK;
}

void sl_profile_assign(sl_profile_t *pr, const sl_target_t *targets, uint32_t n)
{
    SL_ASSERT(pr != NULL && (targets != NULL || n == 0U));
    uint8_t keep[SL_CFG_PROFILE_SLOTS];
    memset(keep, 0, sizeof keep);
    for (uint32_t j = 0; j < n; j++) {
        const uint16_t az = targets[j].az;
        if (az < pr->azimuths && pr->slot_of[az] != SL_PROFILE_NONE) {
            keep[pr->slot_of[az]] = 1U;
        }
    }
    for (uint32_t j = 0; j < n; j++) {
        const sl_target_t *t = &targets[j];
        if (t->az >= pr->azimuths || pr->slot_of[t->az] != SL_PROFILE_NONE) {
            continue;
        }
        // A free slot, else one watching an azimuth that is no target's (claimed on
        // evidence that did not become a target, or a target's former azimuth).
        uint32_t pick = SL_CFG_PROFILE_SLOTS;
        for (uint32_t i = 0; i < SL_CFG_PROFILE_SLOTS; i++) {
            if (pr->slot[i].live == 0U) {
                pick = i;
                break;
            }
            if (pick == SL_CFG_PROFILE_SLOTS && keep[i] == 0U) {
                pick = i;
            }
        }
        if (pick == SL_CFG_PROFILE_SLOTS) {
            pr->stats.assign_full++;
            continue;
        }
        const sl_profile_slot_t *old = &pr->slot[pick];
        if (old->live != 0U) {
            pr->slot_of[old->az] = SL_PROFILE_NONE;
            pr->stats.stolen++;
        } else {
            pr->n_live++;
        }
        (void)slot_start(pr, pick, t->az, t->bin_first);
        keep[pick] = 1U;
        pr->stats.assigned++;
    }
}

uint32_t sl_profile_reserve(sl_profile_t *pr, uint16_t az, uint16_t bin_first, uint32_t half)
{
    SL_ASSERT(pr != NULL);
    if (az >= pr->azimuths) {
        return 0U;
    }
    const uint32_t n = 2U * half + 1U < pr->azimuths ? 2U * half + 1U : pr->azimuths;
    const uint32_t start = ((uint32_t)az + pr->azimuths - half % pr->azimuths) % pr->azimuths;
    uint32_t got = 0;
    for (uint32_t k = 0; k < n; k++) {
        const uint32_t a = (start + k) % pr->azimuths;
        if (pr->slot_of[a] != SL_PROFILE_NONE) {
            got++; // already watched (another track's neighbour)
            continue;
        }
        const uint32_t pick = free_slot(pr);
        if (pick == SL_CFG_PROFILE_SLOTS) {
            pr->stats.reserve_full++;
            continue;
        }
        // The track's r1 is the pole's; its return starts the stream's front part earlier.
        (void)slot_start(pr, pick, a,
                         bin_first > pr->front_bins ? (uint32_t)bin_first - pr->front_bins : 0U);
        pr->n_live++;
        pr->stats.reserved++;
        got++;
    }
    return got;
}

#if SL_CFG_FIT
// E[log2 P] of an exponentially distributed power P lies log2(e) x Euler's gamma below
// log2 E[P]: 0.833 octave, Q8. Profile sums are means of 8-bit values, i.e. of log power on
// a LOG2 scale: the noise floor's mean power (sl_response_floor_lp) is moved by as much to
// be the background the sums see.
#define SPECKLE_LOG_BIAS_Q8 213

// lp (Q8) of a sum's mean value over `frames` rows: the scale's lp table interpolated
// between whole values.
static int32_t mean_lp(const sl_response_t *resp, uint32_t sum, uint32_t frames)
{
    const uint32_t v0 = sum / frames;
    if (v0 >= 255U) {
        return resp->lp_q8[255];
    }
    const int32_t fr = (int32_t)(((sum - v0 * frames) << 8) / frames);
    const int32_t l0 = resp->lp_q8[v0];
    const int32_t l1 = resp->lp_q8[v0 + 1U];
    return l0 + ((l1 - l0) * fr) / 256;
}

// The fit's observed and background powers for samples 0 .. n - 1 of `sum` (bin0 + k), in
// a common scale with the window's brightest sample at 2^24.
static void fit_inputs(sl_profile_t *pr, const sl_response_t *resp, const uint16_t *sum,
                       uint32_t n, uint32_t frames, uint32_t bin0)
{
    int32_t top = INT32_MIN;
    for (uint32_t k = 0; k < n; k++) {
        const int32_t lp = mean_lp(resp, sum[k], frames);
        pr->fit_y[k] = (uint32_t)lp;
        top = lp > top ? lp : top;
    }
    const int32_t bias = resp->scale.kind == (uint8_t)SL_VSCALE_LOG2 ? SPECKLE_LOG_BIAS_Q8 : 0;
    // The response is known over its taps only: below the level of its outermost taps the
    // model cannot tell a return's far sidelobes from the floor, and a step to nothing beyond
    // them would read as position. The background is at least the brightest sample times
    // that level (the taps are Q22 of the centre, the brightest sample 2^24).
    const uint32_t te = resp->tap_q22[0] > resp->tap_q22[SL_RESP_TAPS - 1]
                            ? resp->tap_q22[0]
                            : resp->tap_q22[SL_RESP_TAPS - 1];
    const uint32_t f_min = te < (1U << 22) ? te << 2 : 1U << 24;
    for (uint32_t k = 0; k < n; k++) {
        int32_t fl = sl_response_floor_lp(resp, bin0 + k);
        fl = (fl == INT32_MIN || fl < resp->lp_q8[0]) ? resp->lp_q8[0] : fl;
        const uint32_t f = sl_lp_to_lin_q16(fl - bias - top + 8 * 256);
        pr->fit_f[k] = f > f_min ? f : (f_min == 0U ? 1U : f_min);
        pr->fit_y[k] = sl_lp_to_lin_q16((int32_t)pr->fit_y[k] - top + 8 * 256);
    }
}

// A fitted position (bins Q8 from sample 0 of a window starting at bin `bin0`) as a range:
// sample k is bin bin0 + k, whose centre lies at (bin0 + k + 1/2) bins.
static int64_t fit_range_um(uint32_t bin0, int32_t x_q8, uint32_t bin_um)
{
    const int64_t q8 = (int64_t)bin0 * 256 + 128 + x_q8;
    return (q8 * (int64_t)bin_um + 128) / 256;
}

static uint32_t fit_sigma_um(uint32_t s_q8, uint32_t bin_um)
{
    const uint64_t v = ((uint64_t)s_q8 * bin_um + 128U) / 256U;
    return v > UINT32_MAX ? UINT32_MAX : (uint32_t)v;
}

// The target's bounds and alpha from a fit `o` of the window at `bin0`.
static void apply_fit(const sl_board_t *board, const sl_rfit_out_t *o, uint32_t bin0,
                      bool summed, sl_target_t *t)
{
    const uint32_t b = board->bin_size_um;
    const bool slant = (t->flags & SL_TARGET_SLANT) != 0U;
    // The detector's bounds are half-bin centres + radius terms (- d on r2): keep the
    // radius terms, replace the centres, drop d.
    const int64_t r1_hb_mask = (int64_t)((((uint64_t)2U * t->bin_first + 1U) * b + 1U) / 2U);
    const int64_t r2_hb_mask = (int64_t)((((uint64_t)2U * t->bin_last + 1U) * b + 1U) / 2U);
    const int64_t r1_term = (int64_t)t->r1_um - r1_hb_mask;
    const int64_t r2_term = (int64_t)t->r2_um - (r2_hb_mask - (int64_t)t->elong_um);
    const int64_t r2 = fit_range_um(bin0, o->b_q8, b);
    if (!slant) {
        t->r1_um = sl_fx_usat32(fit_range_um(bin0, o->a_q8, b) + r1_term);
    }
    t->r2_um = sl_fx_usat32(r2 + r2_term);
    t->elong_um = sl_fx_sat32(r2_hb_mask - r2);
    t->flags = (uint16_t)((t->flags & ~(SL_TARGET_ELONG | SL_TARGET_COARSE | SL_TARGET_WALKED)) |
                          SL_TARGET_PROFILE | (summed ? SL_TARGET_COARSE : 0U));
    if (board->geom == NULL) {
        return;
    }
    const uint32_t s1 = sl_detect_r1_sigma_um(t, fit_sigma_um(o->sigma_a_q8, b));
    const uint32_t s2 = fit_sigma_um(o->sigma_b_q8, b);
    const uint32_t sr = sl_incline_bounds_sigma_corr_um(t->r1_um, t->r2_um, s1, s2,
                                                        slant ? 0 : o->corr_q15);
    const sl_incline_result_t res =
        sl_incline_estimate(t->r1_um, t->r2_um, &board->geom[t->az], sr, board->theta_sigma_cdeg);
    t->alpha_cdeg = res.alpha_cdeg;
    t->sigma_cdeg = res.sigma_cdeg;
    t->incline_flag = res.flag;
    t->incline_branch = res.branch;
    if (o->quality == (uint8_t)SL_RFIT_OUT_OF_MODEL) {
        // a return the model does not explain: no lean to stand behind
        t->alpha_cdeg = 0;
        t->incline_flag = (uint8_t)SL_INCLINE_OUT_OF_DOMAIN;
        t->incline_branch = (uint8_t)SL_INCLINE_BRANCH_NONE;
    }
}

// The fit's window inside a profile of n bins from bin0: the target's run (the mask's
// first to last bin) and half the response's support either side (-20 dB on the CTS350-X
// lobe), cut at the shadow edge (beyond it the lit ground returns). *lo: its first sample.
// @return its samples.
static uint32_t fit_window(const sl_board_t *board, const sl_target_t *t, uint32_t bin0,
                           uint32_t n, uint32_t *lo)
{
    const uint32_t half = SL_CFG_RESP_HALF / 2U;
    const uint32_t first = t->bin_first > bin0 ? t->bin_first - bin0 : 0U;
    *lo = first > half ? first - half : 0U;
    uint32_t hi = (t->bin_last > bin0 ? t->bin_last - bin0 : 0U) + half + 1U;
    hi = hi < n ? hi : n;
    if (t->shadow_slant_um != 0U && board->bin_size_um != 0U) {
        const uint32_t eb = t->shadow_slant_um / board->bin_size_um;
        const uint32_t e = eb > bin0 ? eb - bin0 : 0U;
        hi = e < hi ? e : hi;
    }
    return hi > *lo ? hi - *lo : 0U;
}

// Independent looks in a slot's mean over `frames` rows (Q8, >= 256): the speckle of a
// return's bins (those within 10 dB of its brightest, where the floor's own noise is far
// below) splits into a part frozen over the rows (a parked vehicle) and a part drawn anew
// each row; nu, the changing part's share of an exponential power's variance, is their
// variance over the rows against that of one draw (LOG2: (1.85 x values per octave)^2
// values^2, the log of an exponential; LINEAR: mean^2), at most 1. The mean of the logs of
// `frames` draws of which nu change has the variance of (1 - nu) + nu / frames single draws,
// and a mean of L independent powers that of 1 / L draws over 1.645 (the trigamma function at
// 1): looks = 1 / (1.645 ((1 - nu) + nu / frames)), at least 1.
static uint16_t temporal_looks_q8(const sl_response_t *resp, const sl_profile_slot_t *s,
                                  uint32_t lo, uint32_t n)
{
    const uint64_t f = s->frames;
    if (f < 2U) {
        return 256U;
    }
    uint32_t top = 0U;
    for (uint32_t k = lo; k < lo + n; k++) {
        top = s->sum[k] > top ? s->sum[k] : top;
    }
    const bool lin = resp->scale.kind != (uint8_t)SL_VSCALE_LOG2;
    // LOG2: 10 dB = 3.32 octaves; LINEAR: a tenth of the power
    const uint64_t below = lin ? 0U : (f * 850U * resp->scale.cpo_q8) >> 16;
    uint64_t vsum = 0U, ref = 0U;
    for (uint32_t k = lo; k < lo + n; k++) {
        const uint64_t sk = s->sum[k];
        const bool bright = lin ? sk * 10U >= top : sk + below >= top;
        if (bright && f * s->sq[k] >= sk * sk) {
            vsum += f * s->sq[k] - sk * sk; // variance x f^2
            // one exponential draw's variance x f^2
            ref += lin ? sk * sk : (f * f * (474U * (uint64_t)resp->scale.cpo_q8 >> 8) *
                                    (474U * (uint64_t)resp->scale.cpo_q8 >> 8)) >> 16;
        }
    }
    if (ref == 0U) {
        return 256U;
    }
    const uint64_t nu_q16 = vsum >= ref ? 65536U : (vsum << 16) / ref;
    // 1.645 ((1 - nu) + nu / f), Q16
    const uint64_t d = (107807U * ((65536U - nu_q16) + nu_q16 / f)) >> 16;
    const uint64_t l = d == 0U ? 65535U : (256U << 16) / d;
    return (uint16_t)(l < 256U ? 256U : (l > 65535U ? 65535U : l));
}

// Fits the window [lo, lo + n) of `sum` (`frames` rows, from bin0) into `o`; a warm start
// from `warm` (bounds from bin0, Q8) when given.
// A fit gives bounds with sigmas (OUT_OF_MODEL included: it says so on the bus).
static bool fit_usable(uint8_t quality, uint32_t sa_q8, uint32_t sb_q8)
{
    return quality != (uint8_t)SL_RFIT_NO_SIGNAL && sa_q8 != UINT32_MAX && sb_q8 != UINT32_MAX;
}

// One fit of `in` with density `shape` into `o`, from `in`'s warm start when it has one, again
// from the moments when that leads nowhere.
static void fit_shape(sl_profile_t *pr, const sl_response_t *resp, sl_rfit_in_t *in,
                      uint8_t shape, sl_rfit_out_t *o)
{
    in->shape = shape;
    const uint8_t warm = in->warm;
    pr->stats.fits++;
    sl_err_t e = sl_rfit_ws(resp, in, &pr->fit_ws, o);
    if (e == SL_OK && in->warm != 0U &&
        (o->quality == (uint8_t)SL_RFIT_NOT_CONVERGED || o->sigma_a_q8 == UINT32_MAX ||
         o->sigma_b_q8 == UINT32_MAX)) {
        in->warm = 0U; // the earlier bounds led nowhere: from the moments
        pr->stats.fits++;
        e = sl_rfit_ws(resp, in, &pr->fit_ws, o);
    }
    in->warm = warm;
    if (e != SL_OK) {
        memset(o, 0, sizeof *o);
        o->quality = (uint8_t)SL_RFIT_NO_SIGNAL;
    }
}

// Fits the window [lo, lo + n) of `sum` (`frames` rows, from bin0) into `o`; a warm start
// from `warm` (bounds from bin0, Q8) when given. Both densities are fitted, a slender
// target's (FOOT: its power at its closest point) and a flat one (UNIFORM: a return of the
// same power per bin, as a target whose elevation pattern or reflectivity evens it out), and
// the one that explains the samples better (the lower negative log-likelihood: the same
// data, looks and parameters) is taken.
static void fit_run(sl_profile_t *pr, const sl_response_t *resp, const uint16_t *sum,
                    uint32_t frames, uint32_t bin0, uint32_t lo, uint32_t n, uint16_t looks_q8,
                    const sl_profile_slot_t *warm, sl_rfit_out_t *o)
{
    fit_inputs(pr, resp, &sum[lo], n, frames, bin0 + lo);
    sl_rfit_in_t in;
    memset(&in, 0, sizeof in);
    in.y = pr->fit_y;
    in.f = pr->fit_f;
    in.n = (uint16_t)n;
    in.looks_q8 = looks_q8;
    in.origin_q8 = (bin0 + lo) * 256U + 128U;
    if (warm != NULL) {
        in.warm = 1U;
        in.a0_q8 = warm->fit_a_q8 - (int32_t)(lo * 256U);
        in.b0_q8 = warm->fit_b_q8 - (int32_t)(lo * 256U);
    }
    sl_rfit_out_t flat;
    fit_shape(pr, resp, &in, (uint8_t)SL_RFIT_FOOT, o);
    fit_shape(pr, resp, &in, (uint8_t)SL_RFIT_UNIFORM, &flat);
    const bool foot_ok = fit_usable(o->quality, o->sigma_a_q8, o->sigma_b_q8);
    if (fit_usable(flat.quality, flat.sigma_a_q8, flat.sigma_b_q8) &&
        (!foot_ok || flat.nll_q16 < o->nll_q16)) {
        *o = flat;
        pr->stats.fits_flat++;
    }
    pr->stats.fit_quality[o->quality & 3U]++;
    o->a_q8 += (int32_t)(lo * 256U); // from bin0
    o->b_q8 += (int32_t)(lo * 256U);
}

// The slot's last fit as a fit's result, and a fit's result kept in the slot.
static void slot_fit_get(const sl_profile_slot_t *s, sl_rfit_out_t *o)
{
    o->a_q8 = s->fit_a_q8;
    o->b_q8 = s->fit_b_q8;
    o->sigma_a_q8 = s->fit_sa_q8;
    o->sigma_b_q8 = s->fit_sb_q8;
    o->corr_q15 = s->fit_corr_q15;
    o->quality = s->fit_quality;
}

static void slot_fit_put(sl_profile_slot_t *s, const sl_rfit_out_t *o)
{
    s->fit_a_q8 = o->a_q8;
    s->fit_b_q8 = o->b_q8;
    s->fit_sa_q8 = o->sigma_a_q8;
    s->fit_sb_q8 = o->sigma_b_q8;
    s->fit_corr_q15 = o->corr_q15;
    s->fit_quality = o->quality;
}

uint8_t sl_profile_refine_fit(sl_profile_t *pr, const sl_board_t *board,
                              const sl_response_t *resp, uint32_t threshold, sl_target_t *t)
{
    SL_ASSERT(pr != NULL && board != NULL && resp != NULL && t != NULL);
    const uint8_t si = t->az < pr->azimuths ? pr->slot_of[t->az] : (uint8_t)SL_PROFILE_NONE;
    if (si == SL_PROFILE_NONE || pr->slot[si].frames == 0U || t->bin_first < pr->slot[si].bin0) {
        const uint8_t why = (si != SL_PROFILE_NONE && pr->slot[si].frames != 0U)
                                ? (uint8_t)SL_PROFILE_LEAD_CUT
                                : (uint8_t)SL_PROFILE_NO_SLOT;
        pr->stats.fallback[why]++;
        widen_unverified(pr, board, t, true);
        return why;
    }
    sl_profile_slot_t *s = &pr->slot[si];
    const uint16_t *sum = s->sum;
    uint32_t frames = s->frames;
    uint32_t bin0 = s->bin0;
    uint32_t n = SL_CFG_PROFILE_BINS;
    const bool summed = frames >= pr->cfg.min_frames;
    if (!summed) {
        uint32_t tol = 0U;
        const uint32_t f = combine_neighbours(pr, t, si, threshold, &bin0, &n, &tol);
        if (f > frames) {
            sum = pr->scratch;
            frames = f;
            pr->stats.spatial++;
        }
    }
    uint32_t lo = 0U;
    n = fit_window(board, t, bin0, n, &lo);
    if (n < 8U) {
        pr->stats.fallback[SL_PROFILE_TAIL_CUT]++;
        widen_unverified(pr, board, t, true);
        return (uint8_t)SL_PROFILE_TAIL_CUT;
    }
    sl_rfit_out_t o;
    memset(&o, 0, sizeof o);
    if (summed && s->fit_frames != 0U && s->frames < s->fit_frames + s->fit_frames / 4U + 1U) {
        // The sum grew by less than a quarter since its last fit: that fit stands (a
        // summed fit's error repeats from rotation to rotation anyway: COARSE).
        pr->stats.fits_reused++;
        slot_fit_get(s, &o);
    } else {
        const bool had = summed && s->fit_frames != 0U && fit_usable(s->fit_quality,
                                                                     s->fit_sa_q8, s->fit_sb_q8);
        fit_run(pr, resp, sum, frames, bin0, lo, n,
                summed ? temporal_looks_q8(resp, s, lo, n) : 256U, had ? s : NULL, &o);
        if (had && !fit_usable(o.quality, o.sigma_a_q8, o.sigma_b_q8)) {
            // a refit without a usable answer keeps the slot's last one (counted)
            pr->stats.fits_kept++;
            s->fit_frames = s->frames;
            slot_fit_get(s, &o);
        } else if (summed) {
            s->fit_frames = s->frames;
            slot_fit_put(s, &o);
        }
    }
    if (!fit_usable(o.quality, o.sigma_a_q8, o.sigma_b_q8)) {
        pr->stats.fallback[SL_PROFILE_NO_RUN]++;
        widen_unverified(pr, board, t, true);
        return (uint8_t)SL_PROFILE_NO_RUN;
    }
    apply_fit(board, &o, bin0, summed, t);
    pr->stats.extracted++;
    return (uint8_t)SL_PROFILE_OK;
}
#endif // SL_CFG_FIT
