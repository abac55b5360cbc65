// SPDX-License-Identifier: MIT
// Unit tests of the theta drift watch (sl_drift.h) on synthetic rows of the paper-sim board:
// ground clutter from the slant range H / sin(theta_live) outwards, in the masked range the
// pipeline reads (135 bins: up to the board's shadow edge).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include <math.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_drift.h"
#include "shadowlean/sl_thresh.h"

#define BINS 135U
#define THR 40U

static const double kPi = 3.14159265358979323846;

static const sl_board_t *board(void)
{
    const sl_board_t *b = sl_board_find("paper-sim");
    assert_non_null(b);
    return b;
}

// A row whose ground starts where a vehicle with theta `theta_deg` lights it.
static void ground_row(uint8_t *row, double theta_deg, const sl_board_t *b)
{
    memset(row, 0, BINS);
    const double s = b->radar_height_um / sin(theta_deg * kPi / 180.0);
    for (unsigned k = 0; k < BINS; k++) {
        if ((k + 1U) * (double)b->bin_size_um > s) {
            row[k] = 60U; // this bin holds some ground
        }
    }
    for (unsigned k = 0; k < b->near_exclusion_bins; k++) {
        row[k] = 90U; // the near-field band (ignored)
    }
}

// One rotation: the watched azimuth's row, then the end of the rotation.
static void rotation(sl_drift_t *d, const sl_board_t *b, const uint8_t *row)
{
    uint32_t bits[(BINS + 31U) / 32U];
    sl_thresh_u8(row, BINS, THR, bits); // as the pipeline thresholds the row
    sl_drift_row(d, b, d->watch_az, bits, NULL, BINS, b->bin_size_um);
    sl_drift_end_rotation(d);
}

static void test_drift_nominal_vehicle_gives_a_valid_estimate_near_zero(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[BINS];
    ground_row(row, 26.0, b);
    for (int r = 0; r < 16; r++) {
        assert_false(d.fault);
        rotation(&d, b, row);
    }
    assert_true(d.valid);
    assert_true(abs(sl_drift_cdeg(&d)) <= 25); // half a bin ~ 0.1 deg
    assert_false(d.fault);
    assert_int_equal(d.stats.samples, 16);
    for (int r = 0; r < 200; r++) {
        rotation(&d, b, row);
        assert_false(d.fault);
    }
}

static void test_drift_no_estimate_before_enough_sectors(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[BINS];
    ground_row(row, 30.0, b); // 4 deg off
    // 5 sectors x 2 samples need 8 + 4 + 1 = 13 rotations at one sample per rotation
    for (int r = 0; r < 12; r++) {
        rotation(&d, b, row);
        assert_false(d.valid);
        assert_int_equal(sl_drift_cdeg(&d), 0);
    }
    rotation(&d, b, row);
    assert_true(d.valid);
    assert_in_range(sl_drift_cdeg(&d), 380, 420);
}

static void test_drift_step_of_2deg_raises_the_fault_within_32_rotations_and_clears(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[BINS];
    ground_row(row, 26.0, b);
    for (int r = 0; r < 40; r++) {
        rotation(&d, b, row);
    }
    assert_false(d.fault);
    ground_row(row, 28.0, b);
    int raised = -1;
    for (int r = 0; r < 64; r++) {
        rotation(&d, b, row);
        if (d.fault && raised < 0) {
            raised = r + 1;
        }
    }
    assert_true(raised > 0 && raised <= 32);
    assert_in_range(sl_drift_cdeg(&d), 175, 225);
    // back to nominal (the load removed): cleared again, after the same persistence
    ground_row(row, 26.0, b);
    int cleared = -1;
    for (int r = 0; r < 64; r++) {
        rotation(&d, b, row);
        if (!d.fault && cleared < 0) {
            cleared = r + 1;
        }
    }
    assert_true(cleared > 0 && cleared <= 32);
}

static void test_drift_rejects_occupied_rows_missing_ground_and_outliers(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[BINS];
    // a pole in the shadow: a run of 10 bins at 3 m
    ground_row(row, 26.0, b);
    memset(row + 70, 120, 10);
    rotation(&d, b, row);
    assert_int_equal(d.stats.occupied, 1);
    assert_int_equal(d.stats.samples, 0);
    // a two-bin return across a word boundary (bins 63, 64) is one too
    ground_row(row, 26.0, b);
    row[63] = 50U;
    row[64] = 50U;
    rotation(&d, b, row);
    assert_int_equal(d.stats.occupied, 2);
    assert_int_equal(d.stats.samples, 0);
    // isolated noise bins in the shadow are not a target
    ground_row(row, 26.0, b);
    row[60] = 50U;
    row[90] = 50U;
    rotation(&d, b, row);
    assert_int_equal(d.stats.samples, 1);
    // theta smaller than the board's: the ground starts beyond the row (one-sided watch)
    ground_row(row, 24.0, b);
    rotation(&d, b, row);
    assert_int_equal(d.stats.no_ground, 1);
    // a wall running through the whole shadow: 20 deg off
    ground_row(row, 46.0, b);
    rotation(&d, b, row);
    assert_int_equal(d.stats.outliers, 1);
    assert_int_equal(d.stats.samples, 1);
    // a row of another azimuth than the watched one is ignored
    ground_row(row, 26.0, b);
    uint32_t bits[(BINS + 31U) / 32U];
    sl_thresh_u8(row, BINS, THR, bits);
    sl_drift_row(&d, b, (uint16_t)((d.watch_az + 1U) % b->azimuths), bits, NULL, BINS,
                 b->bin_size_um);
    assert_int_equal(d.stats.samples, 1);
}

static void test_drift_median_ignores_a_minority_of_sectors(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t nominal[BINS], wall[BINS];
    ground_row(nominal, 26.0, b);
    ground_row(wall, 31.0, b); // 5 deg: a kerb or a parked car in two sectors
    for (int r = 0; r < 200; r++) {
        const uint32_t sector = (uint32_t)d.watch_az * SL_DRIFT_SECTORS / b->azimuths;
        rotation(&d, b, (sector == 2U || sector == 5U) ? wall : nominal);
        assert_false(d.fault);
    }
    assert_true(d.valid);
    assert_true(abs(sl_drift_cdeg(&d)) <= 25);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drift_nominal_vehicle_gives_a_valid_estimate_near_zero),
        cmocka_unit_test(test_drift_no_estimate_before_enough_sectors),
        cmocka_unit_test(test_drift_step_of_2deg_raises_the_fault_within_32_rotations_and_clears),
        cmocka_unit_test(test_drift_rejects_occupied_rows_missing_ground_and_outliers),
        cmocka_unit_test(test_drift_median_ignores_a_minority_of_sectors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
