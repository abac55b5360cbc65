// SPDX-License-Identifier: MIT
// SL_ASSERT is overridable for the whole build: this test compiles a core source
// (firmware/core/thresh.c, see test_assert.cmake) with SL_ASSERT overridden (user header) to a
// recorder, and checks that a caller bug inside the core reaches the override (instead of
// the default trap), with the failing line, and that valid calls never do.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "shadowlean/sl_thresh.h"

int g_assert_line;
int g_assert_count;
jmp_buf g_assert_jmp;

void test_assert_hook(int line);
void test_assert_hook(int line)
{
    g_assert_line = line;
    g_assert_count++;
    longjmp(g_assert_jmp, 1); // like a board's fault handler: never back into the core
}

static void test_assert_override_is_used_by_the_core(void **state)
{
    (void)state;
    uint32_t bits[1] = {0};
    const uint8_t row[32] = {0};
    g_assert_count = 0;
    sl_thresh_u8(row, 32, 10, bits); // valid: no assertion
    assert_int_equal(g_assert_count, 0);
    if (setjmp(g_assert_jmp) == 0) {
        sl_thresh_u8(NULL, 32, 10, bits); // caller bug: NULL row
        fail_msg("the core returned after a failed SL_ASSERT");
    }
    assert_int_equal(g_assert_count, 1);
    assert_true(g_assert_line > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_assert_override_is_used_by_the_core),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
