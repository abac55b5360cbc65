// SPDX-License-Identifier: MIT
#include "shadowlean/sl_fx.h"

uint32_t sl_fx_isqrt64(uint64_t x)
{
    // Bit-by-bit (restoring) square root: exact floor, constant 32 iterations.
    uint64_t res = 0;
    uint64_t bit = (uint64_t)1 << 62;
    while (bit > x) {
        bit >>= 2;
    }
    while (bit != 0U) {
        if (x >= res + bit) {
            x -= res + bit;
            res = (res >> 1) + bit;
        } else {
            res >>= 1;
        }
        bit >>= 2;
    }
    return (uint32_t)res;
}
