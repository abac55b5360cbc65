// SPDX-License-Identifier: MIT
// Unit tests for sl_mask.h: the bit-sliced counters against a naive reference that stores
// the last n rows of every azimuth and intersects them, for every n in 1..32.
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "shadowlean/sl_mask.h"

static sl_mask_t mask; // 150 KB: static, as a firmware would hold it

static uint64_t rng = 0x9E3779B97F4A7C15ULL;
static uint32_t rnd32(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 16);
}

// ---- naive reference: a ring of the last n received rows per azimuth
#define RAZ 12
#define RWORDS (SL_MASK_WORDS)
typedef struct {
    uint32_t hist[RAZ][32][RWORDS];
    uint32_t count[RAZ]; // rows in the current run of history (saturates at 32)
    uint32_t head[RAZ];
    uint32_t missed[RAZ];
    int seen[RAZ];
    uint32_t n, w, words, bins, max_missed; // w: current window (sl_mask_set_window)
} ref_t;
static ref_t ref;

static uint32_t tailmask(uint32_t bins, uint32_t w)
{
    if (w + 1U == SL_BITS_WORDS(bins) && (bins % 32U) != 0U) {
        return (1U << (bins % 32U)) - 1U;
    }
    return UINT32_MAX;
}

static void ref_init(uint32_t n, uint32_t bins, uint32_t max_missed)
{
    memset(&ref, 0, sizeof ref);
    ref.n = n;
    ref.w = n;
    ref.bins = bins;
    ref.words = SL_BITS_WORDS(bins);
    ref.max_missed = max_missed;
}

static void ref_update(uint32_t az, const uint32_t *bits)
{
    if (ref.seen[az]) {
        return;
    }
    ref.seen[az] = 1;
    ref.head[az] = (ref.head[az] + 1U) % 32U;
    for (uint32_t w = 0; w < ref.words; w++) {
        ref.hist[az][ref.head[az]][w] = bits[w] & tailmask(ref.bins, w);
    }
    if (ref.count[az] < 32U) {
        ref.count[az]++;
    }
}

static void ref_end_rotation(void)
{
    for (uint32_t a = 0; a < RAZ; a++) {
        if (ref.seen[a]) {
            ref.missed[a] = 0;
        } else {
            ref.missed[a]++; // counted with or without history
            if (ref.missed[a] > ref.max_missed) {
                ref.count[a] = 0; // history dropped
            }
        }
        ref.seen[a] = 0;
    }
}

static void ref_stable(uint32_t az, uint32_t *occ, uint32_t *fr)
{
    for (uint32_t w = 0; w < ref.words; w++) {
        if (ref.count[az] < ref.w) {
            occ[w] = 0;
            fr[w] = 0;
            continue;
        }
        uint32_t all1 = UINT32_MAX, all0 = UINT32_MAX;
        for (uint32_t i = 0; i < ref.w; i++) {
            const uint32_t v = ref.hist[az][(ref.head[az] + 32U - i) % 32U][w];
            all1 &= v;
            all0 &= ~v;
        }
        occ[w] = all1;
        fr[w] = all0 & tailmask(ref.bins, w);
    }
}

static void check_az(uint32_t az, const uint32_t *occ, const uint32_t *fr, const char *where)
{
    uint32_t ro[RWORDS], rf[RWORDS];
    ref_stable(az, ro, rf);
    for (uint32_t w = 0; w < ref.words; w++) {
        if (occ[w] != ro[w] || fr[w] != rf[w]) {
            fail_msg("%s: n=%u bins=%u az=%u word=%u occ 0x%08x/0x%08x free 0x%08x/0x%08x",
                     where, (unsigned)ref.n, (unsigned)ref.bins, (unsigned)az, (unsigned)w,
                     (unsigned)occ[w], (unsigned)ro[w], (unsigned)fr[w], (unsigned)rf[w]);
        }
    }
}

// Rows with long runs (so n = 32 becomes reachable) plus noisy and saturated regions.
typedef struct {
    uint32_t base[RAZ][RWORDS];
} scene_t;
static scene_t scene;

static void make_row(uint32_t az, uint32_t *bits, uint32_t flip_shift)
{
    for (uint32_t w = 0; w < ref.words; w++) {
        uint32_t flips = 0;
        for (uint32_t b = 0; b < 32U; b++) {
            if ((rnd32() >> flip_shift) == 0U) {
                flips |= 1U << b;
            }
        }
        scene.base[az][w] ^= flips; // a persistent change: the run restarts
        uint32_t v = scene.base[az][w];
        if (w == 1U) {
            v = rnd32(); // a noisy word: nothing ever stable for n >= 2
        }
        if (w == 2U) {
            v = UINT32_MAX; // saturated word
        }
        bits[w] = v | (rnd32() & ~tailmask(ref.bins, w)); // junk beyond `bins` is ignored
    }
}

// `vary_window`: before each rotation, a random window 1..n (sl_mask_set_window) for both.
static void run_random_w(uint32_t n, uint32_t bins, uint32_t max_missed, uint32_t rotations,
                         uint32_t miss_per_256, bool vary_window)
{
    assert_int_equal(sl_mask_init(&mask, RAZ, (uint16_t)bins, (uint8_t)n, (uint8_t)max_missed),
                     SL_OK);
    ref_init(n, bins, max_missed);
    for (uint32_t a = 0; a < RAZ; a++) {
        for (uint32_t w = 0; w < RWORDS; w++) {
            scene.base[a][w] = rnd32();
        }
    }
    uint32_t bits[RWORDS], occ[RWORDS], fr[RWORDS];
    for (uint32_t r = 0; r < rotations; r++) {
        // A few rotations lose a burst of consecutive rows, others lose single rows.
        const int burst = (rnd32() % 16U) == 0U;
        if (vary_window) {
            const uint32_t w = 1U + rnd32() % n;
            assert_int_equal(sl_mask_set_window(&mask, (uint8_t)w), SL_OK);
            ref.w = w;
        }
        for (uint32_t a = 0; a < RAZ; a++) {
            if ((rnd32() % 256U) < miss_per_256 || (burst && a < RAZ / 2U)) {
                continue;
            }
            make_row(a, bits, 22U); // per-bin flip probability 2^-10 per row
            const sl_err_t e = sl_mask_update(&mask, (uint16_t)a, bits, occ, fr);
            assert_int_equal(e, SL_OK);
            ref_update(a, bits);
            check_az(a, occ, fr, "update");
            if ((rnd32() % 64U) == 0U) {
                // A duplicate in the same rotation is ignored.
                make_row(a, bits, 3U);
                assert_int_equal(sl_mask_update(&mask, (uint16_t)a, bits, occ, fr),
                                 SL_ERR_STATE);
                check_az(a, occ, fr, "duplicate");
            }
        }
        sl_mask_end_rotation(&mask);
        ref_end_rotation();
        for (uint32_t a = 0; a < RAZ; a++) {
            const bool h = sl_mask_stable(&mask, (uint16_t)a, occ, fr);
            assert_int_equal(h, ref.count[a] > 0U);
            check_az(a, occ, fr, "end_rotation");
            assert_int_equal(sl_mask_missed(&mask, (uint16_t)a) > 0U, ref.missed[a] > 0U);
        }
    }
}

static void run_random(uint32_t n, uint32_t bins, uint32_t max_missed, uint32_t rotations,
                       uint32_t miss_per_256)
{
    run_random_w(n, bins, max_missed, rotations, miss_per_256, false);
}

static void test_mask_equals_naive_n_plane_reference_for_every_n(void **state)
{
    (void)state;
    for (uint32_t n = 1; n <= SL_CFG_MASK_FRAMES_MAX; n++) {
        run_random(n, 96, 2, 3U * n + 20U, 8); // 3 words: a pair and an odd tail word
        run_random(n, 70, 0, 2U * n + 10U, 4); // bins not a multiple of 32
        run_random(n, SL_CFG_MASK_BINS, 3, 2U * n + 10U, 20);
    }
}

static void test_mask_is_stable_after_exactly_n_equal_rows(void **state)
{
    (void)state;
    const uint8_t n = 4;
    assert_int_equal(sl_mask_init(&mask, 8, 64, n, 1), SL_OK);
    uint32_t row[2] = {0x0000000FU, 0x80000000U};
    uint32_t occ[2], fr[2];
    for (int i = 1; i <= 4; i++) {
        assert_int_equal(sl_mask_update(&mask, 3, row, occ, fr), SL_OK);
        sl_mask_end_rotation(&mask);
        if (i < 4) {
            assert_int_equal(occ[0], 0U);
            assert_int_equal(fr[0], 0U);
        }
    }
    assert_int_equal(occ[0], 0x0000000FU);
    assert_int_equal(occ[1], 0x80000000U);
    assert_int_equal(fr[0], 0xFFFFFFF0U);
    assert_int_equal(fr[1], 0x7FFFFFFFU);
    // One bin flips: it leaves both planes, for n more rows.
    row[0] = 0x0000000EU;
    for (int i = 1; i <= 4; i++) {
        assert_int_equal(sl_mask_update(&mask, 3, row, occ, fr), SL_OK);
        sl_mask_end_rotation(&mask);
        assert_int_equal(occ[0], 0x0000000EU);
        assert_int_equal(fr[0], i < 4 ? 0xFFFFFFF0U : 0xFFFFFFF1U);
    }
    // n = 1: every row is its own stable plane.
    assert_int_equal(sl_mask_init(&mask, 8, 64, 1, 1), SL_OK);
    assert_int_equal(sl_mask_update(&mask, 0, row, occ, fr), SL_OK);
    assert_int_equal(occ[0], row[0]);
    assert_int_equal(fr[0], ~row[0]);
}

static void test_mask_holds_a_missing_azimuth_then_resets_it(void **state)
{
    (void)state;
    const uint8_t n = 3;
    assert_int_equal(sl_mask_init(&mask, 8, 32, n, 2), SL_OK);
    uint32_t row[1] = {0x00F0F000U}, occ[1], fr[1];
    for (int i = 0; i < 3; i++) {
        assert_int_equal(sl_mask_update(&mask, 5, row, occ, fr), SL_OK);
        sl_mask_end_rotation(&mask);
    }
    assert_int_equal(occ[0], 0x00F0F000U);
    // Two rotations without azimuth 5: held (still stable), counted as stale, not frames.
    for (int i = 1; i <= 2; i++) {
        sl_mask_end_rotation(&mask);
        assert_int_equal(sl_mask_missed(&mask, 5), i);
        assert_true(sl_mask_stable(&mask, 5, occ, fr));
        assert_int_equal(occ[0], 0x00F0F000U);
        assert_int_equal(fr[0], ~0x00F0F000U);
    }
    assert_int_equal(mask.stats.stale_rows, 2U);
    // It comes back with a changed bin: the counters continue from the held state.
    row[0] = 0x00F0F001U;
    assert_int_equal(sl_mask_update(&mask, 5, row, occ, fr), SL_OK);
    sl_mask_end_rotation(&mask);
    assert_int_equal(sl_mask_missed(&mask, 5), 0U);
    assert_int_equal(occ[0], 0x00F0F000U);
    assert_int_equal(fr[0], ~0x00F0F001U);
    // Three missed rotations (> max_missed = 2): history dropped.
    for (int i = 0; i < 3; i++) {
        sl_mask_end_rotation(&mask);
    }
    assert_false(sl_mask_has_history(&mask, 5));
    assert_false(sl_mask_stable(&mask, 5, occ, fr));
    assert_int_equal(occ[0], 0U);
    assert_int_equal(fr[0], 0U);
    assert_int_equal(mask.stats.resets, 1U);
    // A new run needs n rows again.
    for (int i = 1; i <= 3; i++) {
        assert_int_equal(sl_mask_update(&mask, 5, row, occ, fr), SL_OK);
        sl_mask_end_rotation(&mask);
        assert_int_equal(occ[0], i < 3 ? 0U : 0x00F0F001U);
    }
}

// sl_mask_set_window(): a random window 1..n per rotation equals the reference's "equal in
// the last w received rows", for every n, with missing rows and history resets.
static void test_mask_shorter_window_equals_reference_for_every_n(void **state)
{
    (void)state;
    for (uint32_t n = 1; n <= SL_CFG_MASK_FRAMES_MAX; n++) {
        run_random_w(n, 96, 2, 3U * n + 20U, 8, true);
        run_random_w(n, 70, 1, 2U * n + 10U, 4, true);
    }
}

// A window change keeps the counters: after a stop (w back to n) a bin equal for n rows is
// stable at once; w = 1 is the plain current row; out-of-range windows are refused.
static void test_mask_window_change_keeps_history(void **state)
{
    (void)state;
    const uint8_t n = 16;
    assert_int_equal(sl_mask_init(&mask, 4, 32, n, 2), SL_OK);
    uint32_t row[1] = {0x0000F00FU}, occ[1], fr[1];
    assert_int_equal(sl_mask_set_window(&mask, 1), SL_OK);
    assert_int_equal(sl_mask_update(&mask, 2, row, occ, fr), SL_OK); // first row of a run
    assert_int_equal(occ[0], 0x0000F00FU);
    assert_int_equal(fr[0], ~0x0000F00FU);
    sl_mask_end_rotation(&mask);
    assert_int_equal(sl_mask_set_window(&mask, 3), SL_OK);
    for (int i = 2; i <= 16; i++) {
        assert_int_equal(sl_mask_update(&mask, 2, row, occ, fr), SL_OK);
        sl_mask_end_rotation(&mask);
        assert_int_equal(occ[0], i >= 3 ? 0x0000F00FU : 0U);
    }
    // 16 equal rows: stable for the full window too, without new rows.
    assert_int_equal(sl_mask_set_window(&mask, 16), SL_OK);
    assert_true(sl_mask_stable(&mask, 2, occ, fr));
    assert_int_equal(occ[0], 0x0000F00FU);
    assert_int_equal(sl_mask_set_window(&mask, 0), SL_ERR_ARG);
    assert_int_equal(sl_mask_set_window(&mask, 17), SL_ERR_ARG);
    assert_int_equal(mask.window, 16);
}

static void test_mask_rejects_bad_arguments_and_azimuths(void **state)
{
    (void)state;
    assert_int_equal(sl_mask_init(NULL, 8, 32, 4, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, 0, 32, 4, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, SL_CFG_MAX_AZIMUTHS + 1, 32, 4, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, 8, 0, 4, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, 8, SL_CFG_ROI_BINS + 1, 4, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, 8, SL_CFG_MASK_BINS + 1, 4, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, 8, 32, 0, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, 8, 32, SL_CFG_MASK_FRAMES_MAX + 1, 1), SL_ERR_ARG);
    assert_int_equal(sl_mask_init(&mask, 8, 32, 4, 1), SL_OK);
    uint32_t row[1] = {1U}, occ[1] = {7U};
    assert_int_equal(sl_mask_update(&mask, 8, row, occ, NULL), SL_ERR_RANGE);
    assert_int_equal(occ[0], 7U);
    assert_int_equal(mask.stats.bad_azimuth, 1U);
    assert_false(sl_mask_stable(&mask, 9, occ, NULL));
    assert_int_equal(occ[0], 0U);
    assert_int_equal(sl_mask_missed(&mask, 900), 0U);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mask_equals_naive_n_plane_reference_for_every_n),
        cmocka_unit_test(test_mask_is_stable_after_exactly_n_equal_rows),
        cmocka_unit_test(test_mask_holds_a_missing_azimuth_then_resets_it),
        cmocka_unit_test(test_mask_shorter_window_equals_reference_for_every_n),
        cmocka_unit_test(test_mask_window_change_keeps_history),
        cmocka_unit_test(test_mask_rejects_bad_arguments_and_azimuths),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
