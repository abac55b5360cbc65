// SPDX-License-Identifier: MIT
// Unit tests for sl_thresh.h: SWAR thresholds against a one-bin-at-a-time reference.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "shadowlean/sl_thresh.h"

#define MAXB 600U

static uint64_t rng = 0x243F6A8885A308D3ULL;
static uint32_t rnd32(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 16);
}

static void ref_u8(const uint8_t *row, uint32_t bins, uint32_t t, uint32_t *bits)
{
    memset(bits, 0, SL_BITS_WORDS(bins) * 4U);
    for (uint32_t k = 0; k < bins; k++) {
        if (row[k] >= t) {
            bits[k / 32U] |= 1U << (k % 32U);
        }
    }
}

static void check_rows_equal(const uint32_t *a, const uint32_t *b, uint32_t bins)
{
    for (uint32_t w = 0; w < SL_BITS_WORDS(bins); w++) {
        if (a[w] != b[w]) {
            fail_msg("word %u: got 0x%08x want 0x%08x (bins %u)", (unsigned)w, (unsigned)a[w],
                     (unsigned)b[w], (unsigned)bins);
        }
    }
}

static void test_thresh_bit_layout_is_bin_32w_plus_b(void **state)
{
    (void)state;
    uint8_t row[64] = {0};
    row[0] = 200;
    row[33] = 200;
    row[63] = 200;
    uint32_t bits[2] = {0xDEADBEEFU, 0xDEADBEEFU};
    sl_thresh_u8(row, 64, 100, bits);
    assert_int_equal(bits[0], 0x00000001U);
    assert_int_equal(bits[1], 0x80000002U);
    assert_true(sl_bits_get(bits, 33));
    assert_false(sl_bits_get(bits, 34));
    sl_bits_put(bits, 34, true);
    assert_int_equal(bits[1], 0x80000006U);
    sl_bits_put(bits, 0, false);
    assert_int_equal(bits[0], 0U);
}

// Every threshold 0..300 against every byte value at every position within a lane, over
// lengths that exercise the 32-bin words and the scalar tail.
static void test_thresh_u8_matches_reference_for_every_threshold_and_value(void **state)
{
    (void)state;
    static uint8_t row[MAXB + 8];
    static uint32_t got[SL_BITS_WORDS(MAXB) + 1], want[SL_BITS_WORDS(MAXB) + 1];
    for (uint32_t k = 0; k < MAXB + 8U; k++) {
        row[k] = (uint8_t)((k * 7U) & 0xFFU); // 7 is odd: all 256 values, shifted per lane
    }
    static const uint32_t lens[] = {1, 7, 8, 31, 32, 33, 64, 95, 256, 257, 512, 600};
    for (uint32_t t = 0; t <= 300U; t++) {
        for (size_t li = 0; li < sizeof lens / sizeof lens[0]; li++) {
            for (uint32_t off = 0; off < 8U; off++) {
                const uint32_t n = lens[li];
                memset(got, 0xA5, sizeof got);
                sl_thresh_u8(row + off, n, (uint16_t)t, got);
                ref_u8(row + off, n, t, want);
                check_rows_equal(got, want, n);
            }
        }
    }
}

static void test_thresh_u8_handles_empty_and_saturated_rows(void **state)
{
    (void)state;
    uint8_t zero[512], sat[512];
    memset(zero, 0, sizeof zero);
    memset(sat, 255, sizeof sat);
    uint32_t bits[16];
    sl_thresh_u8(zero, 512, 1, bits);
    for (int w = 0; w < 16; w++) {
        assert_int_equal(bits[w], 0U);
    }
    sl_thresh_u8(zero, 512, 0, bits); // threshold 0: everything occupied
    for (int w = 0; w < 16; w++) {
        assert_int_equal(bits[w], UINT32_MAX);
    }
    sl_thresh_u8(sat, 512, 255, bits);
    for (int w = 0; w < 16; w++) {
        assert_int_equal(bits[w], UINT32_MAX);
    }
    sl_thresh_u8(sat, 512, 256, bits); // above the 8-bit scale: nothing
    for (int w = 0; w < 16; w++) {
        assert_int_equal(bits[w], 0U);
    }
    // Padding bits of a partial last word stay 0, even with threshold 0.
    bits[1] = 0xFFFFFFFFU;
    sl_thresh_u8(sat, 40, 0, bits);
    assert_int_equal(bits[1], 0xFFU);
    sl_thresh_u8(sat, 40, 10, bits);
    assert_int_equal(bits[1], 0xFFU);
    // bins = 0 writes nothing.
    bits[0] = 0x1234U;
    sl_thresh_u8(NULL, 0, 10, bits);
    assert_int_equal(bits[0], 0x1234U);
}

static void test_thresh_u8_table_matches_reference_for_all_value_pairs(void **state)
{
    (void)state;
    static uint8_t row[256 + 8], tab[256 + 8];
    uint32_t got[9], want[9];
    for (uint32_t y = 0; y < 256U; y++) {
        for (uint32_t k = 0; k < 264U; k++) {
            row[k] = (uint8_t)(k * 11U);
            tab[k] = (uint8_t)(y + (k & 1U) * 3U * (k & 4U)); // mostly y, some neighbours
        }
        for (uint32_t off = 0; off < 8U; off += 3U) {
            const uint32_t n = 256U - off;
            sl_thresh_u8_table(row + off, n, tab + off, got);
            memset(want, 0, sizeof want);
            for (uint32_t k = 0; k < n; k++) {
                if (row[off + k] >= tab[off + k]) {
                    want[k / 32U] |= 1U << (k % 32U);
                }
            }
            check_rows_equal(got, want, n);
        }
    }
    // Random rows and tables, random lengths.
    static uint8_t r2[MAXB], t2[MAXB];
    static uint32_t g2[SL_BITS_WORDS(MAXB)], w2[SL_BITS_WORDS(MAXB)];
    for (int it = 0; it < 2000; it++) {
        const uint32_t n = 1U + rnd32() % MAXB;
        for (uint32_t k = 0; k < n; k++) {
            r2[k] = (uint8_t)rnd32();
            t2[k] = (uint8_t)rnd32();
        }
        sl_thresh_u8_table(r2, n, t2, g2);
        memset(w2, 0, sizeof w2);
        for (uint32_t k = 0; k < n; k++) {
            if (r2[k] >= t2[k]) {
                w2[k / 32U] |= 1U << (k % 32U);
            }
        }
        check_rows_equal(g2, w2, n);
    }
}

static void test_thresh_u16_matches_reference_at_lane_edges(void **state)
{
    (void)state;
    static uint16_t row[MAXB];
    static uint32_t got[SL_BITS_WORDS(MAXB)], want[SL_BITS_WORDS(MAXB)];
    static const uint32_t ts[] = {0,     1,     2,     255,   256,   32766, 32767,
                                  32768, 32769, 40000, 65534, 65535, 65536, 100000};
    static const uint16_t edge[] = {0, 1, 255, 256, 32766, 32767, 32768, 32769, 65534, 65535};
    for (int it = 0; it < 300; it++) {
        const uint32_t n = 1U + rnd32() % MAXB;
        for (uint32_t k = 0; k < n; k++) {
            const uint32_t r = rnd32();
            row[k] = (r & 1U) ? edge[(r >> 1) % 10U] : (uint16_t)(r >> 8);
        }
        for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
            sl_thresh_u16(row, n, ts[i], got);
            memset(want, 0, sizeof want);
            for (uint32_t k = 0; k < n; k++) {
                if (row[k] >= ts[i]) {
                    want[k / 32U] |= 1U << (k % 32U);
                }
            }
            check_rows_equal(got, want, n);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_thresh_bit_layout_is_bin_32w_plus_b),
        cmocka_unit_test(test_thresh_u8_matches_reference_for_every_threshold_and_value),
        cmocka_unit_test(test_thresh_u8_handles_empty_and_saturated_rows),
        cmocka_unit_test(test_thresh_u8_table_matches_reference_for_all_value_pairs),
        cmocka_unit_test(test_thresh_u16_matches_reference_at_lane_edges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
