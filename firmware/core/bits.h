// SPDX-License-Identifier: MIT
/// @file bits.h
/// @brief Bit scanning over packed bit rows (one bit per range bin, 32-bit little-endian
/// words of bins: bit k of word w is bin 32 w + k), shared by detection and the range
/// profiles. Internal to the core (not an installed header). Portable: the count of
/// trailing zeros is a builtin only where the CPU has one (sl_bits_ctz32), no division. Each
/// call is O(words scanned).
#ifndef SHADOWLEAN_CORE_BITS_H
#define SHADOWLEAN_CORE_BITS_H

#include <stdint.h>

/// Count of trailing zeros of a non-zero word: the compiler's builtin where the CPU has a
/// count instruction (x86 TZCNT/BSF, AArch64 and ARMv7-M/ARMv8-M RBIT + CLZ, s390x FLOGR),
/// otherwise (ARMv6-M, RISC-V without Zbb, other compilers, or SL_NO_INTRINSICS) a de
/// Bruijn multiply and a 32-byte table, which libgcc's __ctzsi2 would not beat there.
#if !defined(SL_NO_INTRINSICS) && defined(__GNUC__) &&                                        \
    (defined(__x86_64__) || defined(__i386__) || defined(__aarch64__) || defined(__s390x__) || \
     (defined(__ARM_ARCH) && __ARM_ARCH >= 7 && !defined(__ARM_ARCH_6M__)))
#define SL_BITS_CTZ_BUILTIN 1
#endif

static inline uint32_t sl_bits_ctz32(uint32_t v)
{
#ifdef SL_BITS_CTZ_BUILTIN
    return (uint32_t)__builtin_ctz(v);
#else
    static const uint8_t tab[32] = {0,  1,  28, 2,  29, 14, 24, 3,  30, 22, 20,
                                    15, 25, 17, 4,  8,  31, 27, 13, 23, 21, 19,
                                    16, 7,  26, 12, 18, 6,  11, 5,  10, 9};
    return tab[((v & (0U - v)) * 0x077CB531U) >> 27];
#endif
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
