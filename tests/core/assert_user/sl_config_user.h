// SPDX-License-Identifier: MIT
// test_assert's user configuration header (SL_CFG_USER_HEADER): overrides SL_ASSERT for the
// core sources compiled into the test, the way an integrator does for a product.
#ifndef TEST_ASSERT_SL_CONFIG_USER_H
#define TEST_ASSERT_SL_CONFIG_USER_H
void test_assert_hook(int line);
#define SL_ASSERT(x)                                                                         \
    do {                                                                                     \
        if (!(x)) {                                                                          \
            test_assert_hook(__LINE__);                                                      \
        }                                                                                    \
    } while (0)
#endif
