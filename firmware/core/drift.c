// SPDX-License-Identifier: MIT
// Drift watch: the live ground-return start against the board's theta (sl_drift.h).
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_config.h"
#include "shadowlean/sl_drift.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_thresh.h"

void sl_drift_init(sl_drift_t *d, const sl_board_t *board)
{
    SL_ASSERT(d != NULL && board != NULL);
    memset(d, 0, sizeof *d);
    d->azimuths = board->azimuths;
}

static bool bit(const uint32_t *bits, int32_t k)
{
    return ((bits[(uint32_t)k >> 5] >> ((uint32_t)k & 31U)) & 1U) != 0U;
}

// Start of the run of occupied bins (single-bin gaps allowed) that reaches the last bin
// (or, when `gap_at_end`, the one before it), or -1 when it is not occupied.
static int32_t ground_start(const uint32_t *bits, uint32_t bins, uint16_t lo, bool gap_at_end)
{
    if (bins == 0U) {
        return -1;
    }
    int32_t g = (int32_t)bins - 1;
    if (!bit(bits, g)) {
        if (!gap_at_end || g == 0 || !bit(bits, g - 1)) {
            return -1;
        }
        g--;
    }
    while (g > (int32_t)lo) {
        if (((uint32_t)g & 31U) == 0U && g >= (int32_t)lo + 32 &&
            bits[((uint32_t)g >> 5) - 1U] == ~0U) {
            g -= 32; // a whole word of ground below g: the same as 32 single steps
        } else if (bit(bits, g - 1)) {
            g--;
        } else if (g - 2 >= (int32_t)lo && bit(bits, g - 2)) {
            g -= 2;
        } else {
            break;
        }
    }
    return g;
}

// Two adjacent occupied bins b, b + 1 with lo <= b and b + 1 < end: word-wise.
static bool pair_in(const uint32_t *bits, uint32_t lo, uint32_t end)
{
    for (uint32_t w = lo >> 5; (w << 5) < end; w++) {
        const uint32_t next = ((w + 1U) << 5) < end ? bits[w + 1U] : 0U;
        uint32_t pairs = bits[w] & ((bits[w] >> 1) | (next << 31));
        const uint32_t base = w << 5;
        if (lo > base) {
            pairs &= ~0U << (lo - base);
        }
        if (end - 1U < base + 32U) { // b + 1 < end <=> b < end - 1
            const uint32_t n = end - 1U - base;
            pairs &= (n == 0U) ? 0U : (~0U >> (32U - n));
        }
        if (pairs != 0U) {
            return true;
        }
    }
    return false;
}

void sl_drift_tail(sl_drift_t *d, const sl_proto_fft_t *f, uint16_t from, uint8_t pow16_shift,
                   uint16_t threshold)
{
    SL_ASSERT(d != NULL);
    d->tail_n = 0U;
    if (f == NULL || f->bin_data == NULL || (f->bytes_per_bin != 1U && f->bytes_per_bin != 2U) ||
        pow16_shift > 15U) {
        return;
    }
    const uint8_t *data = f->bin_data;
    const uint32_t n_bins = f->bins;
    const uint32_t bytes_per_bin = f->bytes_per_bin;
    memset(d->tail, 0, sizeof d->tail);
    d->tail_n = 0U;
    d->tail_from = from;
    if (n_bins <= from) {
        return; // the message ends at the mask: no tail
    }
    uint32_t n = n_bins - from;
    if (n > SL_DRIFT_EXTRA_BINS) {
        n = SL_DRIFT_EXTRA_BINS;
    }
    if (bytes_per_bin == 1U) {
        sl_thresh_u8(data + from, n, threshold, d->tail); // word-wise, as the mask's
    } else {
        for (uint32_t k = 0; k < n; k++) {
            const uint32_t i = from + k;
            uint32_t v = ((uint32_t)data[2U * i] | ((uint32_t)data[2U * i + 1U] << 8)) >> pow16_shift;
            v = v > 255U ? 255U : v;
            if (v >= threshold) {
                d->tail[k >> 5] |= 1U << (k & 31U);
            }
        }
    }
    d->tail_n = (uint8_t)n;
}

// The last two bins of a row of n bins are stable: occupied (bits) or free (free_).
static bool settled_end(const uint32_t *bits, const uint32_t *free_, uint32_t n)
{
    if (free_ == NULL || n < 2U) {
        return false;
    }
    const int32_t k = (int32_t)n - 1;
    return (bit(bits, k) || bit(free_, k)) && (bit(bits, k - 1) || bit(free_, k - 1));
}

void sl_drift_row(sl_drift_t *d, const sl_board_t *board, uint16_t az, const uint32_t *bits,
                  const uint32_t *free_, uint16_t bins, uint32_t bin_um)
{
    SL_ASSERT(d != NULL && board != NULL && bits != NULL);
    if (az != d->watch_az || az >= d->azimuths || bin_um == 0U) {
        return;
    }
    const uint16_t lo = board->near_exclusion_bins;
    // The mask's row, joined with the tail when there is one for this row's end.
    uint32_t row[SL_BITS_WORDS(SL_CFG_MASK_BINS) + SL_DRIFT_EXTRA_BINS / 32U];
    const uint32_t mask_n = bins <= SL_CFG_MASK_BINS ? bins : SL_CFG_MASK_BINS;
    const uint32_t mw = SL_BITS_WORDS(mask_n);
    memcpy(row, bits, mw * sizeof row[0]);
    uint32_t n = mask_n;
    // The join needs the mask settled at its end: its last two bins stable (occupied or
    // free). Otherwise (the window filling, the vehicle moving, ground flickering at the
    // edge) the mask's end says nothing and a tail would put the ground start at the join.
    bool tail = false;
    if (d->tail_n > 0U && d->tail_from == mask_n) {
        tail = settled_end(bits, free_, mask_n);
    }
    if (tail) {
        if ((mask_n & 31U) != 0U) {
            row[mw - 1U] &= ~0U >> (32U - (mask_n & 31U)); // bits past the mask's end: 0
        }
        memset(&row[mw], 0, sizeof row - mw * sizeof row[0]);
        const uint32_t w0 = n >> 5;
        const uint32_t sh = n & 31U;
        for (uint32_t i = 0; i < SL_DRIFT_EXTRA_BINS / 32U; i++) {
            row[w0 + i] |= d->tail[i] << sh;
            if (sh != 0U && w0 + i + 1U < sizeof row / sizeof row[0]) {
                row[w0 + i + 1U] |= d->tail[i] >> (32U - sh);
            }
        }
        n += d->tail_n;
    }
    const int32_t g = ground_start(row, n, lo, tail);
    if (g < 0 || g <= (int32_t)lo) {
        d->stats.no_ground++;
        return;
    }
    if (g - 2 > (int32_t)lo + 1 && pair_in(row, lo, (uint32_t)g - 2U)) {
        d->stats.occupied++;
        return;
    }
    // theta_live - theta to first order: (H / S - sin) / cos = (H - S sin) / (S cos), with
    // the board's own trig (Q30); one 64-bit division. Error: 0.5 tan(theta) x drift^2,
    // 0.02 deg at 2 deg, 0.3 deg at the 8 deg outlier bound.
    const int64_t s_um = (int64_t)((((uint64_t)(uint32_t)g * 2U + 1U) * bin_um) / 2U);
    const sl_incline_geom_t *geo = &board->geom[az];
    const int64_t num = ((int64_t)board->radar_height_um << 30) - s_um * (int64_t)geo->sin_theta_q30;
    const int64_t den = (s_um * (int64_t)geo->cos_theta_q30) >> 30;
    if (den <= 0) {
        d->stats.outliers++;
        return;
    }
    const int64_t delta_q30 = num / den;                    // radians, Q30
    const int64_t cdeg = sl_fx_rshift_round64(delta_q30 * 22918, 32); // x 18000 / pi
    if (cdeg > SL_DRIFT_OUTLIER_CDEG || cdeg < -SL_DRIFT_OUTLIER_CDEG) {
        d->stats.outliers++;
        return;
    }
    const int32_t diff = (int32_t)cdeg;
    const uint32_t k = (uint32_t)az * SL_DRIFT_SECTORS / d->azimuths;
    if (d->n[k] == 0U) {
        d->est_cdeg[k] = (int16_t)diff;
    } else {
        const int32_t e = d->est_cdeg[k];
        d->est_cdeg[k] = (int16_t)(e + (diff - e) / 2);
    }
    if (d->n[k] < UINT8_MAX) {
        d->n[k]++;
    }
    d->stats.samples++;
}

void sl_drift_end_rotation(sl_drift_t *d)
{
    SL_ASSERT(d != NULL);
    int16_t v[SL_DRIFT_SECTORS] = {0};
    uint32_t m = 0U;
    for (uint32_t k = 0; k < SL_DRIFT_SECTORS; k++) {
        if (d->n[k] >= SL_DRIFT_MIN_SAMPLES) {
            // insertion sort: at most 8 values
            uint32_t j = m;
            while (j > 0U && v[j - 1U] > d->est_cdeg[k]) {
                v[j] = v[j - 1U];
                j--;
            }
            v[j] = d->est_cdeg[k];
            m++;
        }
    }
    d->valid = m >= SL_DRIFT_MIN_SECTORS;
    d->drift_cdeg = 0;
    if (d->valid) {
        d->drift_cdeg = (int16_t)(((int32_t)v[(m - 1U) / 2U] + (int32_t)v[m / 2U]) / 2);
    }
    const bool over = d->valid && (d->drift_cdeg > SL_DRIFT_FAULT_CDEG ||
                                   d->drift_cdeg < -SL_DRIFT_FAULT_CDEG);
    if (over != d->fault) {
        d->persist++;
        if (d->persist >= SL_DRIFT_PERSIST) {
            d->fault = over;
            d->persist = 0U;
        }
    } else {
        d->persist = 0U;
    }
    d->tail_n = 0U; // the tail belongs to this rotation's watched row
    if (d->azimuths > 0U) {
        d->watch_az = (uint16_t)(((uint32_t)d->watch_az + SL_DRIFT_STEP) % d->azimuths);
    }
}

int16_t sl_drift_cdeg(const sl_drift_t *d)
{
    SL_ASSERT(d != NULL);
    if (!d->valid) {
        return 0;
    }
    return d->drift_cdeg;
}
