// SPDX-License-Identifier: MIT
/// @file bits.h
/// @brief Bit scanning over packed bit rows (one bit per range bin, 32-bit little-endian
/// words of bins: bit k of word w is bin 32 w + k), shared by detection and the range
/// profiles. Internal to the core (not an installed header). Portable: a de Bruijn count of
/// trailing zeros, no compiler builtin, no division. Each call is O(words scanned).
#ifndef SHADOWLEAN_CORE_BITS_H
#define SHADOWLEAN_CORE_BITS_H

#include <stdint.h>

/// Count of trailing zeros of a non-zero word.
static inline uint32_t sl_bits_ctz32(uint32_t v)
{
    static const uint8_t tab[32] = {0,  1,  28, 2,  29, 14, 24, 3,  30, 22, 20,
                                    15, 25, 17, 4,  8,  31, 27, 13, 23, 21, 19,
                                    16, 7,  26, 12, 18, 6,  11, 5,  10, 9};
    return tab[((v & (0U - v)) * 0x077CB531U) >> 27];
}

/// First set bin in [pos, end) of `b`, or end.
static inline uint32_t sl_bits_next_set(const uint32_t *b, uint32_t pos, uint32_t end)
{
    while (pos < end) {
        const uint32_t w = b[pos >> 5] >> (pos & 31U);
        if (w != 0U) {
            pos += sl_bits_ctz32(w);
            return pos < end ? pos : end;
        }
        pos = (pos | 31U) + 1U;
    }
    return end;
}

/// First clear bin in [pos, end) of `b`, or end.
static inline uint32_t sl_bits_next_clear(const uint32_t *b, uint32_t pos, uint32_t end)
{
    while (pos < end) {
        const uint32_t w = ~b[pos >> 5] >> (pos & 31U);
        if (w != 0U) {
            pos += sl_bits_ctz32(w);
            return pos < end ? pos : end;
        }
        pos = (pos | 31U) + 1U;
    }
    return end;
}

#endif // SHADOWLEAN_CORE_BITS_H
