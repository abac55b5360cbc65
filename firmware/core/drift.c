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

// Start of the run of occupied bins (single-bin gaps allowed) that reaches the last bin,
// or -1 when the last bin is not occupied.
static int32_t ground_start(const uint8_t *power, uint16_t bins, uint16_t lo, uint16_t thr)
{
    if (bins == 0U || power[bins - 1U] < thr) {
        return -1;
    }
    int32_t g = (int32_t)bins - 1;
    while (g > (int32_t)lo) {
        if (power[g - 1] >= thr) {
            g--;
        } else if (g - 2 >= (int32_t)lo && power[g - 2] >= thr) {
            g -= 2;
        } else {
            break;
        }
    }
    return g;
}

void sl_drift_row(sl_drift_t *d, const sl_board_t *board, uint16_t az, const uint8_t *power,
                  uint16_t bins, uint32_t bin_um, uint16_t threshold)
{
    SL_ASSERT(d != NULL && board != NULL && power != NULL);
    if (az != d->watch_az || az >= d->azimuths || bin_um == 0U) {
        return;
    }
    const uint16_t lo = board->near_exclusion_bins;
    const int32_t g = ground_start(power, bins, lo, threshold);
    if (g < 0 || g <= (int32_t)lo) {
        d->stats.no_ground++;
        return;
    }
    for (int32_t b = (int32_t)lo; b + 1 < g - 2; b++) {
        if (power[b] >= threshold && power[b + 1] >= threshold) {
            d->stats.occupied++;
            return;
        }
    }
    const uint64_t s_um = ((uint64_t)(uint32_t)g * 2U + 1U) * bin_um / 2U;
    const uint64_t h_um = board->radar_height_um;
    if (s_um <= h_um || s_um > (uint64_t)INT32_MAX) {
        d->stats.outliers++;
        return;
    }
    const uint32_t r_um = sl_fx_isqrt64(s_um * s_um - h_um * h_um);
    const int32_t live = sl_incline_bam32_to_cdeg(
        sl_incline_atan2_bam32((int32_t)h_um, (int32_t)(r_um > (uint32_t)INT32_MAX ? (uint32_t)INT32_MAX : r_um)));
    const int32_t diff = live - (int32_t)board->theta_cdeg[az];
    if (diff > SL_DRIFT_OUTLIER_CDEG || diff < -SL_DRIFT_OUTLIER_CDEG) {
        d->stats.outliers++;
        return;
    }
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
    int16_t v[SL_DRIFT_SECTORS];
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
    d->drift_cdeg = d->valid ? (int16_t)(((int32_t)v[(m - 1U) / 2U] + (int32_t)v[m / 2U]) / 2) : 0;
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
    return d->valid ? d->drift_cdeg : (int16_t)0;
}
