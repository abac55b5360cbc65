// SPDX-License-Identifier: MIT
// Unit tests for the core's bit scanning (firmware/core/bits.h): the count of trailing
// zeros and the next set / next clear bin, against bit-by-bit references. test_bits_table
// (test_bits.cmake) compiles the same tests with SL_NO_INTRINSICS: the de Bruijn table that
// ARMv6-M and RISC-V without Zbb run, on every host.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "bits.h"

#if defined(SL_NO_INTRINSICS) && defined(SL_BITS_CTZ_BUILTIN)
#error "SL_NO_INTRINSICS must select the portable count of trailing zeros"
#endif

static uint32_t ref_ctz(uint32_t v)
{
    uint32_t n = 0;
    while ((v & 1U) == 0U) {
        v >>= 1;
        n++;
    }
    return n;
}

static uint32_t ref_get(const uint32_t *b, uint32_t k)
{
    return (b[k >> 5] >> (k & 31U)) & 1U;
}

static uint32_t ref_next(const uint32_t *b, uint32_t pos, uint32_t end, uint32_t want)
{
    while (pos < end && ref_get(b, pos) != want) {
        pos++;
    }
    return pos < end ? pos : end;
}

static uint32_t xorshift(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *s = x;
    return x;
}

static void test_bits_ctz_matches_the_reference(void **state)
{
    (void)state;
    for (uint32_t k = 0; k < 32U; k++) {
        assert_int_equal(sl_bits_ctz32(1U << k), k);
        assert_int_equal(sl_bits_ctz32(UINT32_MAX << k), k);
        assert_int_equal(sl_bits_ctz32((1U << k) | 0x80000000U), k);
    }
    uint32_t seed = 0x9E3779B9U;
    for (int i = 0; i < 100000; i++) {
        const uint32_t v = xorshift(&seed) | 0x80000000U; // non-zero
        const uint32_t w = v >> (xorshift(&seed) & 31U);  // sparse low bits too
        assert_int_equal(sl_bits_ctz32(v), ref_ctz(v));
        assert_int_equal(sl_bits_ctz32(w), ref_ctz(w));
    }
}

static void test_bits_next_set_and_clear_match_the_reference(void **state)
{
    (void)state;
    uint32_t row[6];
    uint32_t seed = 12345U;
    for (int i = 0; i < 2000; i++) {
        // densities from empty to full, runs crossing word boundaries
        const uint32_t mode = (uint32_t)i % 5U;
        for (uint32_t w = 0; w < 6U; w++) {
            const uint32_t r = xorshift(&seed);
            row[w] = mode == 0U ? 0U
                     : mode == 1U ? UINT32_MAX
                     : mode == 2U ? r & xorshift(&seed) & xorshift(&seed)
                     : mode == 3U ? r | xorshift(&seed)
                                  : r;
        }
        const uint32_t end = xorshift(&seed) % (6U * 32U + 1U);
        for (uint32_t pos = 0; pos <= end + 2U && pos < 6U * 32U; pos++) {
            assert_int_equal(sl_bits_next_set(row, pos, end), ref_next(row, pos, end, 1U));
            assert_int_equal(sl_bits_next_clear(row, pos, end), ref_next(row, pos, end, 0U));
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bits_ctz_matches_the_reference),
        cmocka_unit_test(test_bits_next_set_and_clear_match_the_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
