// SPDX-License-Identifier: MIT
// Drift watch: the live ground-return start against the board's theta (sl_drift.h).
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_drift.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_fx.h"
#include "shadowlean/sl_incline.h"

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

// Start of the run of occupied bins (single-bin gaps allowed) that reaches the last bin,
// or -1 when the last bin is not occupied.
static int32_t ground_start(const uint32_t *bits, uint16_t bins, uint16_t lo)
{
    if (bins == 0U || !bit(bits, (int32_t)bins - 1)) {
        return -1;
    }
    int32_t g = (int32_t)bins - 1;
    while (g > (int32_t)lo) {
        if (bit(bits, g - 1)) {
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

void sl_drift_row(sl_drift_t *d, const sl_board_t *board, uint16_t az, const uint32_t *bits,
                  uint16_t bins, uint32_t bin_um)
{
    SL_ASSERT(d != NULL && board != NULL && bits != NULL);
    if (az != d->watch_az || az >= d->azimuths || bin_um == 0U) {
        return;
    }
    const uint16_t lo = board->near_exclusion_bins;
    const int32_t g = ground_start(bits, bins, lo);
    if (g < 0 || g <= (int32_t)lo) {
        d->stats.no_ground++;
        return;
    }
    if (g - 2 > (int32_t)lo + 1 && pair_in(bits, lo, (uint32_t)g - 2U)) {
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
