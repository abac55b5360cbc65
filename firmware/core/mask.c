// SPDX-License-Identifier: MIT
// n-frame consistency mask with bit-sliced count-down run counters (sl_mask.h).
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_mask.h"

#if SL_CFG_MASK_FRAMES_MAX > 255
#error "frames are stored in uint8_t"
#endif

// The per-P specialisations below rely on inlining with P constant (then the plane loops
// unroll and the planes stay in registers); compilers otherwise keep one generic copy.
#if defined(__GNUC__)
#define FORCE_INLINE static inline __attribute__((always_inline))
#else
#define FORCE_INLINE static inline
#endif

#define ST_HISTORY 1U
#define ST_SEEN 2U

// Lanes: pairs of words on 64-bit targets. Every operation below is bitwise, so a pair of
// uint32 words loaded into a uint64 (memcpy) maps back bit for bit on either endianness.
#if SL_CFG_SWAR_BITS == 64
typedef uint64_t lane_t;
#else
typedef uint32_t lane_t;
#endif
#define LANE_WORDS ((uint32_t)(sizeof(lane_t) / sizeof(uint32_t)))

// A 64-bit lane is two words that are only 4-byte aligned: memcpy, which 64-bit targets
// inline as one (unaligned-capable) load/store. A 32-bit lane is one aligned word: a plain
// load/store (on ARMv6-M GCC cannot inline memcpy, and a call per lane cost 31 % of the
// per-azimuth instructions).
static inline lane_t ld(const uint32_t *p)
{
#if SL_CFG_SWAR_BITS == 64
    lane_t v;
    memcpy(&v, p, sizeof v);
    return v;
#else
    return *p;
#endif
}

static inline void st(uint32_t *p, lane_t v)
{
#if SL_CFG_SWAR_BITS == 64
    memcpy(p, &v, sizeof v);
#else
    *p = v;
#endif
}

// Load/store one lane at word w: a full lane (memcpy), or a single word (the odd tail).
FORCE_INLINE lane_t lane_ld(const uint32_t *p, bool one)
{
    return one ? (lane_t)p[0] : ld(p);
}

FORCE_INLINE void lane_st(uint32_t *p, lane_t v, bool one)
{
    if (one) {
        p[0] = (uint32_t)v;
    } else {
        st(p, v);
    }
}

// Update one lane of one azimuth. P (counter planes) and `one` are compile-time constants
// at every call site, so the plane code below folds to straight-line code on scalars
// (unused planes are constant 0). k counts down: see sl_mask.h.
//   d = x ^ L;  k -= 1 where !d && k > 0 (borrow chain);  k = n - 1 where d;  L = x;
//   stable = (k == 0).
// Window test k < t for a constant t (bit-sliced, MSB plane first): tp[p] = bit p of t as
// a lane mask, allm = all ones when t >= 2^P (every bin stable). See sl_mask.h.
FORCE_INLINE lane_t lane_lt(lane_t c0, lane_t c1, lane_t c2, lane_t c3, lane_t c4, unsigned P,
                            const lane_t *tp, lane_t allm)
{
    lane_t lt = 0, eq = ~(lane_t)0;
    if (P > 4U) {
        lt |= eq & ~c4 & tp[4];
        eq &= ~(c4 ^ tp[4]);
    }
    if (P > 3U) {
        lt |= eq & ~c3 & tp[3];
        eq &= ~(c3 ^ tp[3]);
    }
    if (P > 2U) {
        lt |= eq & ~c2 & tp[2];
        eq &= ~(c2 ^ tp[2]);
    }
    if (P > 1U) {
        lt |= eq & ~c1 & tp[1];
        eq &= ~(c1 ^ tp[1]);
    }
    if (P > 0U) {
        lt |= eq & ~c0 & tp[0];
    }
    (void)eq;
    return lt | allm;
}

// Per-row constants of the window test: t = n - w + 1 (k < t <=> k <= n - w).
typedef struct win {
    bool on;      // w < n (else the plain k == 0 test)
    lane_t allm;  // t >= 2^P
    lane_t tp[5];
} win_t;

static void win_make(win_t *wn, unsigned P, uint32_t n, uint32_t w)
{
    const uint32_t t = n - w + 1U;
    wn->on = w < n;
    wn->allm = (t >= ((uint32_t)1U << P)) ? ~(lane_t)0 : (lane_t)0;
    for (unsigned p = 0; p < 5U; p++) {
        wn->tp[p] = (((t >> p) & 1U) != 0U) ? ~(lane_t)0 : (lane_t)0;
    }
}

FORCE_INLINE void lane_update(uint32_t (*pl)[SL_MASK_WORDS], const uint32_t *x, uint32_t *occ,
                              uint32_t *fr, uint32_t w, unsigned P, const lane_t *rp, bool one,
                              bool full)
{
    const lane_t xv = lane_ld(&x[w], one);
    const lane_t d = xv ^ lane_ld(&pl[0][w], one);
    lane_t c0 = 0, c1 = 0, c2 = 0, c3 = 0, c4 = 0, b, t;
    if (P > 0U) {
        c0 = lane_ld(&pl[1][w], one);
    }
    if (P > 1U) {
        c1 = lane_ld(&pl[2][w], one);
    }
    if (P > 2U) {
        c2 = lane_ld(&pl[3][w], one);
    }
    if (P > 3U) {
        c3 = lane_ld(&pl[4][w], one);
    }
    if (P > 4U) {
        c4 = lane_ld(&pl[5][w], one);
    }
    b = (c0 | c1 | c2 | c3 | c4) & ~d; // decrement: unchanged and k > 0
    if (P > 0U) {
        t = ~c0 & b;
        // Borrow step, then reset to n - 1 where d (n = 2^P: n - 1 is all ones).
        c0 = full ? ((c0 ^ b) | d) : (((c0 ^ b) & ~d) | (d & rp[0]));
        b = t;
    }
    if (P > 1U) {
        t = ~c1 & b;
        c1 = full ? ((c1 ^ b) | d) : (((c1 ^ b) & ~d) | (d & rp[1]));
        b = t;
    }
    if (P > 2U) {
        t = ~c2 & b;
        c2 = full ? ((c2 ^ b) | d) : (((c2 ^ b) & ~d) | (d & rp[2]));
        b = t;
    }
    if (P > 3U) {
        t = ~c3 & b;
        c3 = full ? ((c3 ^ b) | d) : (((c3 ^ b) & ~d) | (d & rp[3]));
        b = t;
    }
    if (P > 4U) {
        c4 = full ? ((c4 ^ b) | d) : (((c4 ^ b) & ~d) | (d & rp[4]));
    }
    (void)t;
    const lane_t s = ~(c0 | c1 | c2 | c3 | c4);
    lane_st(&pl[0][w], xv, one);
    if (P > 0U) {
        lane_st(&pl[1][w], c0, one);
    }
    if (P > 1U) {
        lane_st(&pl[2][w], c1, one);
    }
    if (P > 2U) {
        lane_st(&pl[3][w], c2, one);
    }
    if (P > 3U) {
        lane_st(&pl[4][w], c3, one);
    }
    if (P > 4U) {
        lane_st(&pl[5][w], c4, one);
    }
    if (occ != NULL) {
        lane_st(&occ[w], s & xv, one);
    }
    if (fr != NULL) {
        lane_st(&fr[w], s & ~xv, one);
    }
}

FORCE_INLINE void update_row(uint32_t (*pl)[SL_MASK_WORDS], const uint32_t *x, uint32_t *occ,
                             uint32_t *fr, uint32_t words, unsigned P, uint32_t nm1, bool full)
{
    lane_t rp[5];
    for (unsigned p = 0; p < 5U; p++) {
        rp[p] = (((nm1 >> p) & 1U) != 0U) ? ~(lane_t)0 : (lane_t)0;
    }
    uint32_t w = 0;
    for (; w + LANE_WORDS <= words; w += LANE_WORDS) {
        lane_update(pl, x, occ, fr, w, P, rp, false, full);
    }
    for (; w < words; w++) {
        lane_update(pl, x, occ, fr, w, P, rp, true, full);
    }
}

// Specialised on P and on n being a power of two (reset value all ones: one OR per plane).
#define UPD(P_, F_) update_row(pl, x, occ, fr, words, (P_), nm1, (F_))
static void update_dispatch(uint32_t (*pl)[SL_MASK_WORDS], const uint32_t *x, uint32_t *occ,
                            uint32_t *fr, uint32_t words, unsigned P, uint32_t nm1)
{
    const bool full = nm1 == (((uint32_t)1U << P) - 1U);
    switch (P * 2U + (full ? 1U : 0U)) {
    case 1: // n = 1
        UPD(0U, true);
        break;
#if SL_MASK_COUNTER_PLANES >= 1
    case 3: // n = 2
        UPD(1U, true);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 2
    case 4:
        UPD(2U, false);
        break;
    case 5:
        UPD(2U, true);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 3
    case 6:
        UPD(3U, false);
        break;
    case 7:
        UPD(3U, true);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 4
    case 8:
        UPD(4U, false);
        break;
    case 9:
        UPD(4U, true);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 5
    case 10:
        UPD(5U, false);
        break;
    case 11:
        UPD(5U, true);
        break;
#endif
    default:
        SL_ASSERT(0);
        break;
    }
}
#undef UPD

// Stable planes of one azimuth with history, specialised on P like the update.
FORCE_INLINE void stable_words(const uint32_t (*pl)[SL_MASK_WORDS], uint32_t *occ, uint32_t *fr,
                               uint32_t words, unsigned P, const win_t *wn)
{
    for (uint32_t w = 0; w < words; w++) {
        const uint32_t c0 = P > 0U ? pl[1][w] : 0U, c1 = P > 1U ? pl[2][w] : 0U;
        const uint32_t c2 = P > 2U ? pl[3][w] : 0U, c3 = P > 3U ? pl[4][w] : 0U;
        const uint32_t c4 = P > 4U ? pl[5][w] : 0U;
        uint32_t s;
        if (wn->on) {
            s = (uint32_t)lane_lt(c0, c1, c2, c3, c4, P, wn->tp, wn->allm);
        } else {
            s = ~(c0 | c1 | c2 | c3 | c4);
        }
        if (occ != NULL) {
            occ[w] = s & pl[0][w];
        }
        if (fr != NULL) {
            fr[w] = s & ~pl[0][w];
        }
    }
}

static void stable_row(const uint32_t (*pl)[SL_MASK_WORDS], uint32_t *occ, uint32_t *fr,
                       uint32_t words, unsigned P, const win_t *wn)
{
    switch (P) {
    case 0:
        stable_words(pl, occ, fr, words, 0U, wn);
        break;
#if SL_MASK_COUNTER_PLANES >= 1
    case 1:
        stable_words(pl, occ, fr, words, 1U, wn);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 2
    case 2:
        stable_words(pl, occ, fr, words, 2U, wn);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 3
    case 3:
        stable_words(pl, occ, fr, words, 3U, wn);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 4
    case 4:
        stable_words(pl, occ, fr, words, 4U, wn);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 5
    case 5:
        stable_words(pl, occ, fr, words, 5U, wn);
        break;
#endif
    default:
        SL_ASSERT(0);
        break;
    }
}

sl_err_t sl_mask_init(sl_mask_t *m, uint16_t azimuths, uint16_t bins, uint8_t frames,
                      uint8_t max_missed)
{
    if (m == NULL || azimuths == 0U || azimuths > SL_CFG_MAX_AZIMUTHS || bins == 0U ||
        bins > SL_CFG_MASK_BINS || frames == 0U || frames > SL_CFG_MASK_FRAMES_MAX ||
        max_missed == 255U) {
        return SL_ERR_ARG;
    }
    memset(m, 0, sizeof *m);
    m->azimuths = azimuths;
    m->bins = bins;
    m->words = (uint16_t)SL_BITS_WORDS(bins);
    m->frames = frames;
    m->counter_planes = (uint8_t)SL_MASK_PLANES_FOR(frames);
    m->max_missed = max_missed;
    m->window = frames;
    return SL_OK;
}

sl_err_t sl_mask_set_window(sl_mask_t *m, uint8_t w)
{
    SL_ASSERT(m != NULL);
    if (w == 0U || w > m->frames) {
        return SL_ERR_ARG;
    }
    m->window = w;
    return SL_OK;
}

void sl_mask_reset(sl_mask_t *m)
{
    SL_ASSERT(m != NULL);
    for (uint32_t a = 0; a < m->azimuths; a++) {
        m->state[a] = 0U;
        m->missed[a] = 0U;
    }
}

sl_err_t sl_mask_update(sl_mask_t *m, uint16_t az, const uint32_t *bits, uint32_t *occ,
                        uint32_t *free_)
{
    SL_ASSERT(m != NULL && bits != NULL);
    if (az >= m->azimuths) {
        m->stats.bad_azimuth++;
        return SL_ERR_RANGE;
    }
    if ((m->state[az] & ST_SEEN) != 0U) {
        m->stats.duplicate_rows++;
        (void)sl_mask_stable(m, az, occ, free_);
        return SL_ERR_STATE;
    }
    uint32_t(*pl)[SL_MASK_WORDS] = m->planes[az];
    const uint32_t words = m->words;
    const unsigned P = m->counter_planes;
    const uint32_t nm1 = (uint32_t)m->frames - 1U;
    // Bits beyond `bins` in the last word are kept at zero in the state.
    const uint32_t tail = (m->bins % 32U) != 0U ? (((uint32_t)1U << (m->bins % 32U)) - 1U)
                                                : UINT32_MAX;
    const uint32_t *x = bits;
    uint32_t xbuf[SL_MASK_WORDS];
    if (tail != UINT32_MAX) {
        // Rare configuration (bins not a multiple of 32): mask a private copy.
        memcpy(xbuf, bits, words * sizeof(uint32_t));
        xbuf[words - 1U] &= tail;
        x = xbuf;
    }
    // The first row of a run (k = n - 1) is stable only for a window of 1.
    const bool first_stable = m->window == 1U;
    if ((m->state[az] & ST_HISTORY) == 0U) {
        // First row of a run: L = X, k = n - 1 everywhere.
        for (uint32_t w = 0; w < words; w++) {
            pl[0][w] = x[w];
            for (unsigned p = 0; p < P; p++) {
                pl[1U + p][w] = (((nm1 >> p) & 1U) != 0U) ? UINT32_MAX : 0U;
            }
            if (occ != NULL) {
                occ[w] = first_stable ? x[w] : 0U;
            }
            if (free_ != NULL) {
                free_[w] = first_stable ? (~x[w] & (w + 1U == words ? tail : UINT32_MAX)) : 0U;
            }
        }
    } else {
        if (m->window == m->frames) {
            update_dispatch(pl, x, occ, free_, words, P, nm1);
        } else if (m->window == 1U) {
            // A window of one row (moving fast): the stable planes are the row itself.
            update_dispatch(pl, x, NULL, NULL, words, P, nm1);
            for (uint32_t w = 0; w < words; w++) {
                if (occ != NULL) {
                    occ[w] = x[w];
                }
                if (free_ != NULL) {
                    free_[w] = ~x[w];
                }
            }
        } else {
            // Shorter window (moving): update the state, then the windowed stable test in
            // a second pass (keeps the window logic out of the static hot path).
            update_dispatch(pl, x, NULL, NULL, words, P, nm1);
            win_t wn;
            win_make(&wn, P, m->frames, m->window);
            stable_row((const uint32_t(*)[SL_MASK_WORDS])pl, occ, free_, words, P, &wn);
        }
        if (free_ != NULL) {
            free_[words - 1U] &= tail;
        }
    }
    m->state[az] = (uint8_t)(ST_HISTORY | ST_SEEN);
    m->stats.rows++;
    return SL_OK;
}

void sl_mask_end_rotation(sl_mask_t *m)
{
    SL_ASSERT(m != NULL);
    for (uint32_t a = 0; a < m->azimuths; a++) {
        const uint8_t s = m->state[a];
        if ((s & ST_SEEN) != 0U) {
            m->missed[a] = 0U;
            m->state[a] = ST_HISTORY;
        } else if ((s & ST_HISTORY) != 0U) {
            m->stats.stale_rows++;
            if (m->missed[a] < 255U) {
                m->missed[a]++;
            }
            if (m->missed[a] > m->max_missed) {
                m->state[a] = 0U;
                m->stats.resets++;
            }
        } else {
            // No history: nothing held; keep counting so callers can see the gap.
            if (m->missed[a] < 255U) {
                m->missed[a]++;
            }
        }
    }
    m->stats.rotations++;
}

bool sl_mask_stable_prefix(const sl_mask_t *m, uint16_t az, uint32_t words, uint32_t *occ,
                           uint32_t *free_)
{
    SL_ASSERT(m != NULL);
    if (words > m->words) {
        words = m->words;
    }
    if (az >= m->azimuths || (m->state[az] & ST_HISTORY) == 0U) {
        for (uint32_t w = 0; w < words; w++) {
            if (occ != NULL) {
                occ[w] = 0U;
            }
            if (free_ != NULL) {
                free_[w] = 0U;
            }
        }
        return false;
    }
    win_t wn;
    win_make(&wn, m->counter_planes, m->frames, m->window);
    stable_row((const uint32_t(*)[SL_MASK_WORDS])m->planes[az], occ, free_, words,
               m->counter_planes, &wn);
    if (free_ != NULL && words == m->words && (m->bins % 32U) != 0U) {
        free_[words - 1U] &= ((uint32_t)1U << (m->bins % 32U)) - 1U;
    }
    return true;
}

bool sl_mask_stable(const sl_mask_t *m, uint16_t az, uint32_t *occ, uint32_t *free_)
{
    SL_ASSERT(m != NULL);
    return sl_mask_stable_prefix(m, az, m->words, occ, free_);
}

uint8_t sl_mask_missed(const sl_mask_t *m, uint16_t az)
{
    SL_ASSERT(m != NULL);
    return (az < m->azimuths) ? m->missed[az] : 0U;
}

bool sl_mask_has_history(const sl_mask_t *m, uint16_t az)
{
    SL_ASSERT(m != NULL);
    return (az < m->azimuths) && ((m->state[az] & ST_HISTORY) != 0U);
}
