// n-frame consistency mask with bit-sliced count-down run counters (sl_mask.h).
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_mask.h"

#if SL_CFG_MASK_FRAMES_MAX > 255
#error "frames are stored in uint8_t"
#endif

#define ST_HISTORY 1U
#define ST_SEEN 2U

// Lanes: pairs of words on 64-bit targets. Every operation below is bitwise, so a pair of
// uint32 words loaded into a uint64 (memcpy) maps back bit for bit on either endianness.
#if UINTPTR_MAX > 0xFFFFFFFFU
typedef uint64_t lane_t;
#else
typedef uint32_t lane_t;
#endif
#define LANE_WORDS ((uint32_t)(sizeof(lane_t) / sizeof(uint32_t)))

static inline lane_t ld(const uint32_t *p)
{
    lane_t v;
    memcpy(&v, p, sizeof v);
    return v;
}

static inline void st(uint32_t *p, lane_t v)
{
    memcpy(p, &v, sizeof v);
}

// One lane: x = new row, *l = last row, c[0..P) = counter planes (k, count-down).
// Returns the stable mask after the update (k == 0).
static inline lane_t step(lane_t x, lane_t *l, lane_t *c, unsigned P, uint32_t nm1)
{
    const lane_t d = x ^ *l;
    *l = x;
    lane_t nz = 0;
    for (unsigned p = 0; p < P; p++) {
        nz |= c[p];
    }
    // k -= 1 where the bin is unchanged and k > 0: ripple borrow through the planes.
    lane_t b = nz & ~d;
    for (unsigned p = 0; p < P; p++) {
        const lane_t t = ~c[p] & b;
        c[p] ^= b;
        b = t;
    }
    // k = n - 1 where the bin changed.
    lane_t nz2 = 0;
    for (unsigned p = 0; p < P; p++) {
        c[p] = (((nm1 >> p) & 1U) != 0U) ? (c[p] | d) : (c[p] & ~d);
        nz2 |= c[p];
    }
    return ~nz2;
}

// Update `words` words of one azimuth. P is a compile-time constant at every call site
// (see update_dispatch), so the plane loops unroll and the planes stay in registers.
static inline void update_row(uint32_t (*pl)[SL_ROI_WORDS], const uint32_t *x, uint32_t *occ,
                              uint32_t *fr, uint32_t words, unsigned P, uint32_t nm1)
{
    uint32_t w = 0;
    for (; w + LANE_WORDS <= words; w += LANE_WORDS) {
        lane_t c[SL_MASK_COUNTER_PLANES + 1];
        lane_t l = ld(&pl[0][w]);
        const lane_t xv = ld(&x[w]);
        for (unsigned p = 0; p < P; p++) {
            c[p] = ld(&pl[1U + p][w]);
        }
        const lane_t s = step(xv, &l, c, P, nm1);
        st(&pl[0][w], l);
        for (unsigned p = 0; p < P; p++) {
            st(&pl[1U + p][w], c[p]);
        }
        if (occ != NULL) {
            st(&occ[w], s & xv);
        }
        if (fr != NULL) {
            st(&fr[w], s & ~xv);
        }
    }
    // Odd tail word (64-bit lanes only): same step on a zero-extended word.
    for (; w < words; w++) {
        lane_t c[SL_MASK_COUNTER_PLANES + 1];
        lane_t l = pl[0][w];
        const lane_t xv = x[w];
        for (unsigned p = 0; p < P; p++) {
            c[p] = pl[1U + p][w];
        }
        const lane_t s = step(xv, &l, c, P, nm1);
        pl[0][w] = (uint32_t)l;
        for (unsigned p = 0; p < P; p++) {
            pl[1U + p][w] = (uint32_t)c[p];
        }
        if (occ != NULL) {
            occ[w] = (uint32_t)(s & xv);
        }
        if (fr != NULL) {
            fr[w] = (uint32_t)(s & ~xv);
        }
    }
}

static void update_dispatch(uint32_t (*pl)[SL_ROI_WORDS], const uint32_t *x, uint32_t *occ,
                            uint32_t *fr, uint32_t words, unsigned P, uint32_t nm1)
{
    switch (P) {
    case 0:
        update_row(pl, x, occ, fr, words, 0U, nm1);
        break;
#if SL_MASK_COUNTER_PLANES >= 1
    case 1:
        update_row(pl, x, occ, fr, words, 1U, nm1);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 2
    case 2:
        update_row(pl, x, occ, fr, words, 2U, nm1);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 3
    case 3:
        update_row(pl, x, occ, fr, words, 3U, nm1);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 4
    case 4:
        update_row(pl, x, occ, fr, words, 4U, nm1);
        break;
#endif
#if SL_MASK_COUNTER_PLANES >= 5
    case 5:
        update_row(pl, x, occ, fr, words, 5U, nm1);
        break;
#endif
    default:
        SL_ASSERT(0);
        break;
    }
}

// Read-only view of the stable planes of one azimuth with history.
static void stable_row(const uint32_t (*pl)[SL_ROI_WORDS], uint32_t *occ, uint32_t *fr,
                       uint32_t words, unsigned P)
{
    for (uint32_t w = 0; w < words; w++) {
        uint32_t nz = 0;
        for (unsigned p = 0; p < P; p++) {
            nz |= pl[1U + p][w];
        }
        if (occ != NULL) {
            occ[w] = ~nz & pl[0][w];
        }
        if (fr != NULL) {
            fr[w] = ~nz & ~pl[0][w];
        }
    }
}

sl_err_t sl_mask_init(sl_mask_t *m, uint16_t azimuths, uint16_t bins, uint8_t frames,
                      uint8_t max_missed)
{
    if (m == NULL || azimuths == 0U || azimuths > SL_CFG_MAX_AZIMUTHS || bins == 0U ||
        bins > SL_CFG_ROI_BINS || frames == 0U || frames > SL_CFG_MASK_FRAMES_MAX ||
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
    uint32_t(*pl)[SL_ROI_WORDS] = m->planes[az];
    const uint32_t words = m->words;
    const unsigned P = m->counter_planes;
    const uint32_t nm1 = (uint32_t)m->frames - 1U;
    // Bits beyond `bins` in the last word are kept at zero in the state.
    const uint32_t tail = (m->bins % 32U) != 0U ? (((uint32_t)1U << (m->bins % 32U)) - 1U)
                                                : UINT32_MAX;
    const uint32_t *x = bits;
    uint32_t xbuf[SL_ROI_WORDS];
    if (tail != UINT32_MAX) {
        // Rare configuration (bins not a multiple of 32): mask a private copy.
        memcpy(xbuf, bits, words * sizeof(uint32_t));
        xbuf[words - 1U] &= tail;
        x = xbuf;
    }
    if ((m->state[az] & ST_HISTORY) == 0U) {
        // First row of a run: L = X, k = n - 1 everywhere.
        for (uint32_t w = 0; w < words; w++) {
            pl[0][w] = x[w];
            for (unsigned p = 0; p < P; p++) {
                pl[1U + p][w] = (((nm1 >> p) & 1U) != 0U) ? UINT32_MAX : 0U;
            }
            if (occ != NULL) {
                occ[w] = (P == 0U) ? x[w] : 0U;
            }
            if (free_ != NULL) {
                free_[w] = (P == 0U) ? (~x[w] & (w + 1U == words ? tail : UINT32_MAX)) : 0U;
            }
        }
    } else {
        update_dispatch(pl, x, occ, free_, words, P, nm1);
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
    stable_row((const uint32_t(*)[SL_ROI_WORDS])m->planes[az], occ, free_, words,
               m->counter_planes);
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
