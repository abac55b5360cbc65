// SPDX-License-Identifier: MIT
// Unit tests for sl_fx.h: narrowing helpers and the integer square root.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "shadowlean/sl_err.h"
#include "shadowlean/sl_fx.h"

static void test_fx_rshift_rounds_half_up(void **state)
{
    (void)state;
    assert_int_equal(sl_fx_rshift_round64(3, 1), 2);   // 1.5 -> 2
    assert_int_equal(sl_fx_rshift_round64(-3, 1), -1); // -1.5 -> -1 (half up)
    assert_int_equal(sl_fx_rshift_round64(5, 2), 1);   // 1.25 -> 1
    assert_int_equal(sl_fx_rshift_round64(-5, 2), -1); // -1.25 -> -1
    assert_int_equal(sl_fx_rshift_round64(-6, 2), -1); // -1.5 -> -1
    assert_int_equal(sl_fx_rshift_round64(-7, 2), -2); // -1.75 -> -2
}

static void test_fx_saturates_at_both_ends(void **state)
{
    (void)state;
    assert_int_equal(sl_fx_sat32((int64_t)INT32_MAX + 5), INT32_MAX);
    assert_int_equal(sl_fx_sat32((int64_t)INT32_MIN - 5), INT32_MIN);
    assert_int_equal(sl_fx_usat32(-1), 0);
    assert_int_equal(sl_fx_usat32((int64_t)UINT32_MAX + 1), UINT32_MAX);
    assert_int_equal(sl_fx_sat16(40000), INT16_MAX);
    assert_int_equal(sl_fx_sat16(-40000), INT16_MIN);
    assert_int_equal(sl_fx_abs32(INT32_MIN), INT32_MAX);
    assert_int_equal(sl_fx_abs32(-7), 7);
    assert_int_equal(sl_fx_urshift_round64(UINT64_MAX, 1), (uint64_t)1 << 63);
}

static void test_fx_mul_q30_matches_real_product(void **state)
{
    (void)state;
    const sl_q30_t half = SL_Q30_ONE / 2;
    assert_int_equal(sl_fx_mul_q30(half, half), SL_Q30_ONE / 4);
    assert_int_equal(sl_fx_mul_q30(-half, half), -(SL_Q30_ONE / 4));
    // -2 * -2 = 4 does not fit Q2.30: saturates.
    assert_int_equal(sl_fx_mul_q30(INT32_MIN, INT32_MIN), INT32_MAX);
}

static void test_fx_isqrt_is_exact_floor(void **state)
{
    (void)state;
    static const uint64_t xs[] = {0, 1, 2, 3, 4, 15, 16, 17, 99, 100, 0xFFFFFFFFu,
                                  0x100000000ull, 0xFFFFFFFE00000001ull, UINT64_MAX};
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++) {
        const uint64_t r = sl_fx_isqrt64(xs[i]);
        assert_true(r * r <= xs[i]);
        assert_true((r + 1) > 0xFFFFFFFFull || (r + 1) * (r + 1) > xs[i]);
    }
    uint64_t x = 0x9E3779B97F4A7C15ull;
    for (int i = 0; i < 100000; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        const uint64_t v = x >> (i % 40);
        const uint64_t r = sl_fx_isqrt64(v);
        assert_true(r * r <= v);
        assert_true((r + 1) > 0xFFFFFFFFull || (r + 1) * (r + 1) > v);
    }
}

static void test_err_names_every_code(void **state)
{
    (void)state;
    assert_string_equal(sl_err_str(SL_OK), "SL_OK");
    assert_string_equal(sl_err_str(SL_ERR_MALFORMED), "SL_ERR_MALFORMED");
    assert_string_equal(sl_err_str((sl_err_t)-99), "SL_ERR_?");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fx_rshift_rounds_half_up),
        cmocka_unit_test(test_fx_saturates_at_both_ends),
        cmocka_unit_test(test_fx_mul_q30_matches_real_product),
        cmocka_unit_test(test_fx_isqrt_is_exact_floor),
        cmocka_unit_test(test_err_names_every_code),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
