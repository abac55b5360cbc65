// SPDX-License-Identifier: MIT
// Unit tests of the theta drift watch (sl_drift.h) on synthetic rows of the paper-sim board:
// ground clutter from the slant range H / sin(theta_live) outwards, in the masked range the
// pipeline reads (135 bins: up to the board's shadow edge), and with the raw tail past it.
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

#define TAIL SL_DRIFT_EXTRA_BINS
#define FULL (BINS + TAIL)

// A row of `n` bins whose ground starts where a vehicle with theta `theta_deg` lights it.
static void ground_row_n(uint8_t *row, double theta_deg, const sl_board_t *b, unsigned n)
{
    memset(row, 0, n);
    const double s = b->radar_height_um / sin(theta_deg * kPi / 180.0);
    for (unsigned k = 0; k < n; k++) {
        if ((k + 1U) * (double)b->bin_size_um > s) {
            row[k] = 60U; // this bin holds some ground
        }
    }
    for (unsigned k = 0; k < b->near_exclusion_bins; k++) {
        row[k] = 90U; // the near-field band (ignored)
    }
}

static void ground_row(uint8_t *row, double theta_deg, const sl_board_t *b)
{
    ground_row_n(row, theta_deg, b, BINS);
}

// One rotation with the tail: the raw message holds FULL bins (8-bit, or 16-bit with the
// power in the high byte), the mask the first BINS; `settled`: the mask's bins are all
// stable (occupied or free), else none is (the window still filling).
static void rotation_tail(sl_drift_t *d, const sl_board_t *b, const uint8_t *row, bool settled,
                          bool wide)
{
    uint32_t bits[(BINS + 31U) / 32U];
    uint32_t free_[(BINS + 31U) / 32U];
    uint8_t raw16[2U * FULL];
    sl_thresh_u8(row, BINS, THR, bits);
    for (unsigned w = 0; w < (BINS + 31U) / 32U; w++) {
        free_[w] = settled ? ~bits[w] : 0U;
        if (!settled) {
            bits[w] = 0U;
        }
    }
    for (unsigned k = 0; k < FULL; k++) {
        raw16[2U * k] = 0x5AU; // low byte: below the shift
        raw16[2U * k + 1U] = row[k];
    }
    const sl_proto_fft_t f = {.id = wide ? 31U : 30U, .bytes_per_bin = wide ? 2U : 1U,
                              .bins = FULL, .bin_data = wide ? raw16 : row};
    sl_drift_tail(d, &f, BINS, 8U, THR);
    sl_drift_row(d, b, d->watch_az, bits, free_, BINS, b->bin_size_um);
    sl_drift_end_rotation(d);
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
    // theta smaller than the board's: the ground starts beyond the row (no tail: one-sided)
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

static void test_drift_shrinking_theta_is_seen_in_the_tail_with_its_sign(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[FULL];
    ground_row_n(row, 26.0, b, FULL);
    for (int r = 0; r < 40; r++) {
        rotation_tail(&d, b, row, true, false);
    }
    assert_true(d.valid);
    assert_true(abs(sl_drift_cdeg(&d)) <= 25);
    assert_false(d.fault);
    // the body rises: theta 24 deg, the ground starts past the mask's 135 bins (~145)
    ground_row_n(row, 24.0, b, FULL);
    int raised = -1;
    for (int r = 0; r < 64; r++) {
        rotation_tail(&d, b, row, true, false);
        if (d.fault && raised < 0) {
            raised = r + 1;
        }
    }
    assert_true(raised > 0 && raised <= 32);
    assert_in_range(sl_drift_cdeg(&d), -225, -175); // the sign: theta smaller
    assert_int_equal(d.stats.no_ground, 0);
    // the same rows without their tail: nothing past the mask, no ground (one-sided)
    rotation(&d, b, row);
    assert_int_equal(d.stats.no_ground, 1);
}

static void test_drift_tail_of_16bit_rows_and_6deg_shrink(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[FULL];
    ground_row_n(row, 20.0, b, FULL); // ground from ~172: only in the tail
    for (int r = 0; r < 48; r++) {
        rotation_tail(&d, b, row, true, true);
    }
    assert_true(d.fault);
    assert_in_range(sl_drift_cdeg(&d), -640, -560);
}

static void test_drift_tail_is_not_joined_to_an_unsettled_mask(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[FULL];
    // the window still filling (no stable bins): the tail alone would put the ground start
    // at the join, whatever the truth; it is not used
    ground_row_n(row, 26.0, b, FULL);
    for (int r = 0; r < 40; r++) {
        rotation_tail(&d, b, row, false, false);
    }
    assert_int_equal(d.stats.samples, 0);
    assert_int_equal(d.stats.no_ground, 40);
    assert_false(d.valid);
    // a message that ends at the mask: no tail
    sl_drift_init(&d, b);
    const sl_proto_fft_t f = {.id = 30U, .bytes_per_bin = 1U, .bins = BINS, .bin_data = row};
    sl_drift_tail(&d, &f, BINS, 8U, THR);
    assert_int_equal(d.tail_n, 0);
    sl_drift_tail(&d, NULL, BINS, 8U, THR);
    assert_int_equal(d.tail_n, 0);
}

static void test_drift_tail_keeps_the_occupied_rejection(void **state)
{
    (void)state;
    const sl_board_t *b = board();
    sl_drift_t d;
    sl_drift_init(&d, b);
    uint8_t row[FULL];
    ground_row_n(row, 22.0, b, FULL); // ground from ~157
    memset(row + 70, 120, 10);        // a pole standing in the shadow
    rotation_tail(&d, b, row, true, false);
    assert_int_equal(d.stats.occupied, 1);
    assert_int_equal(d.stats.samples, 0);
    ground_row_n(row, 22.0, b, FULL);
    row[140] = 80U; // a two-bin return past the mask, before the ground
    row[141] = 80U;
    rotation_tail(&d, b, row, true, false);
    assert_int_equal(d.stats.occupied, 2);
    ground_row_n(row, 22.0, b, FULL);
    rotation_tail(&d, b, row, true, false);
    assert_int_equal(d.stats.samples, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drift_nominal_vehicle_gives_a_valid_estimate_near_zero),
        cmocka_unit_test(test_drift_no_estimate_before_enough_sectors),
        cmocka_unit_test(test_drift_step_of_2deg_raises_the_fault_within_32_rotations_and_clears),
        cmocka_unit_test(test_drift_rejects_occupied_rows_missing_ground_and_outliers),
        cmocka_unit_test(test_drift_median_ignores_a_minority_of_sectors),
        cmocka_unit_test(test_drift_shrinking_theta_is_seen_in_the_tail_with_its_sign),
        cmocka_unit_test(test_drift_tail_of_16bit_rows_and_6deg_shrink),
        cmocka_unit_test(test_drift_tail_is_not_joined_to_an_unsettled_mask),
        cmocka_unit_test(test_drift_tail_keeps_the_occupied_rejection),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
