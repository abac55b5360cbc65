// SPDX-License-Identifier: MIT
// Injected on purpose by the static-analysis self tests: an out-of-bounds read and a
// division by zero that cppcheck and clang-tidy must report.
#include <stdint.h>
int32_t sl_inject_defect(int32_t x);
int32_t sl_inject_defect(int32_t x)
{
    int32_t a[4] = {0, 1, 2, 3};
    int32_t d = 0;
    if (x > 3) {
        return a[4];
    }
    return x / d;
}
