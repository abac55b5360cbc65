// SPDX-License-Identifier: MIT
// Thresholding into bit rows (sl_thresh.h): SWAR byte compares, multiply gather.
#include <stdint.h>

#include "shadowlean/sl_err.h"
#include "shadowlean/sl_thresh.h"

// The SWAR kernels are specialised on `low` (threshold <= 128) by inlining with a constant.
#if defined(__GNUC__)
#define FORCE_INLINE static inline __attribute__((always_inline))
#else
#define FORCE_INLINE static inline
#endif

// Lane = the widest integer the target handles natively (a 64-bit multiply on a 32-bit
// core would be a library call). All lane arithmetic below is per-byte carry-free.
#if SL_CFG_SWAR_BITS == 64
typedef uint64_t lane_t;
#define LANE_BYTES 8U
#define ONES8 ((lane_t)0x0101010101010101U)
// Byte k's flag at bit 8k -> bit 56 + k: the multiplier has bits 56 - 7k (k = 0..7); no
// two partial products land on the same bit, so there are no carries.
#define GATHER8 ((lane_t)0x0102040810204080U)
#define GATHER8_SHIFT 56U
#define ONES16 ((lane_t)0x0001000100010001U)
// Halfword k's flag at bit 16k -> bit 60 + k: multiplier bits 60 - 15k (k = 0..3).
#define GATHER16 ((lane_t)0x1000200040008000U)
#define GATHER16_SHIFT 60U
#else
typedef uint32_t lane_t;
#define LANE_BYTES 4U
#define ONES8 ((lane_t)0x01010101U)
#define GATHER8 ((lane_t)0x01020408U) // bits 24 - 7k, k = 0..3 -> bits 24..27
#define GATHER8_SHIFT 24U
#define ONES16 ((lane_t)0x00010001U)
#define GATHER16 ((lane_t)0x40008000U) // bits 30 - 15k, k = 0..1 -> bits 30..31
#define GATHER16_SHIFT 30U
#endif

#define H8 (ONES8 * 0x80U)
#define L8 (ONES8 * 0x7FU)
#define H16 (ONES16 * 0x8000U)
#define L16 (ONES16 * 0x7FFFU)
#define LANE_HALVES (LANE_BYTES / 2U)

// Bytes p[0..LANE_BYTES) with p[i] in bits 8i.. (endian-independent; one load on LE).
FORCE_INLINE lane_t ld8(const uint8_t *p)
{
#if SL_CFG_SWAR_BITS == 64
    return (lane_t)p[0] | ((lane_t)p[1] << 8) | ((lane_t)p[2] << 16) | ((lane_t)p[3] << 24) |
           ((lane_t)p[4] << 32) | ((lane_t)p[5] << 40) | ((lane_t)p[6] << 48) |
           ((lane_t)p[7] << 56);
#else
    return (lane_t)p[0] | ((lane_t)p[1] << 8) | ((lane_t)p[2] << 16) | ((lane_t)p[3] << 24);
#endif
}

FORCE_INLINE lane_t ld16(const uint16_t *p)
{
#if SL_CFG_SWAR_BITS == 64
    return (lane_t)p[0] | ((lane_t)p[1] << 16) | ((lane_t)p[2] << 32) | ((lane_t)p[3] << 48);
#else
    return (lane_t)p[0] | ((lane_t)p[1] << 16);
#endif
}

// Flags in the top bit of each byte -> LANE_BYTES bits, byte k -> bit k.
FORCE_INLINE uint32_t gather8(lane_t msb)
{
    return (uint32_t)(((msb >> 7) * GATHER8) >> GATHER8_SHIFT);
}

FORCE_INLINE uint32_t gather16(lane_t msb)
{
    return (uint32_t)(((msb >> 15) * GATHER16) >> GATHER16_SHIFT);
}

// x >= t per byte with one threshold. For 1 <= t <= 128, c = 128 - t: (x & 0x7F) + c
// stays below 256 and has its top bit set iff (x & 0x7F) >= t; x >= t iff that or x >= 128.
// For 129 <= t <= 255, c = 256 - t: x >= t iff x >= 128 and (x & 0x7F) >= t - 128.
FORCE_INLINE lane_t ge8(lane_t x, lane_t c, bool low)
{
    const lane_t s = (x & L8) + c;
    return (low ? (x | s) : (x & s)) & H8;
}

#if SL_CFG_SWAR_BITS == 64
// 64-bit lanes: 64 bins at a time without multiplies. Lane j (bins 8j..8j+7) contributes
// its byte flags shifted to bit j of every byte: acc byte k bit j = bin 8j + k. An 8x8 bit
// transpose (Hacker's Delight 7-3: element (r, c) at bit 8r + c) turns that into byte j
// bit k = bit 8j + k = bin 8j + k.
FORCE_INLINE uint64_t transpose8(uint64_t x)
{
    uint64_t t = (x ^ (x >> 7)) & 0x00AA00AA00AA00AAU;
    x = x ^ t ^ (t << 7);
    t = (x ^ (x >> 14)) & 0x0000CCCC0000CCCCU;
    x = x ^ t ^ (t << 14);
    t = (x ^ (x >> 28)) & 0x00000000F0F0F0F0U;
    return x ^ t ^ (t << 28);
}

FORCE_INLINE void block64(const uint8_t *p, lane_t c, bool low, uint32_t *out)
{
    // Horner: after lane j the earlier lanes moved one bit down; lane j ends at bit j.
#define H(j) acc = (acc >> 1) | ge8(ld8(p + 8U * (j)), c, low)
    uint64_t acc = ge8(ld8(p), c, low);
    H(1U);
    H(2U);
    H(3U);
    H(4U);
    H(5U);
    H(6U);
    H(7U);
#undef H
    const uint64_t bitsv = transpose8(acc);
    out[0] = (uint32_t)bitsv;
    out[1] = (uint32_t)(bitsv >> 32);
}
#endif

// One output word: 32 bins (multiply gather), unrolled.
FORCE_INLINE uint32_t word8(const uint8_t *p, lane_t c, bool low)
{
#define G8(j) (gather8(ge8(ld8(p + (j) * LANE_BYTES), c, low)) << ((j) * LANE_BYTES))
#if SL_CFG_SWAR_BITS == 64
    return G8(0U) | G8(1U) | G8(2U) | G8(3U);
#else
    return G8(0U) | G8(1U) | G8(2U) | G8(3U) | G8(4U) | G8(5U) | G8(6U) | G8(7U);
#endif
#undef G8
}

FORCE_INLINE void thresh8_rows(const uint8_t *row, uint32_t bins, uint8_t t, uint32_t *bits,
                               bool low)
{
    const lane_t c = ONES8 * (lane_t)(low ? 128U - t : 256U - t);
    const uint32_t full = bins / 32U;
    uint32_t w = 0;
#if SL_CFG_SWAR_BITS == 64
    for (; w + 2U <= full; w += 2U) {
        block64(row + 32U * w, c, low, &bits[w]);
    }
#endif
    for (; w < full; w++) {
        bits[w] = word8(row + 32U * w, c, low);
    }
    const uint32_t rem = bins % 32U;
    if (rem != 0U) {
        const uint8_t *p = row + 32U * full;
        uint32_t acc = 0;
        for (uint32_t k = 0; k < rem; k++) {
            acc |= (uint32_t)(p[k] >= t) << k;
        }
        bits[full] = acc;
    }
}

static void fill(uint32_t *bits, uint32_t bins, bool all)
{
    const uint32_t words = SL_BITS_WORDS(bins);
    for (uint32_t w = 0; w < words; w++) {
        bits[w] = all ? UINT32_MAX : 0U;
    }
    if (all && (bins % 32U) != 0U) {
        bits[words - 1U] = ((uint32_t)1U << (bins % 32U)) - 1U;
    }
}

void sl_thresh_u8(const uint8_t *row, uint32_t bins, uint16_t threshold, uint32_t *bits)
{
    if (bins == 0U) {
        return;
    }
    SL_ASSERT(row != NULL && bits != NULL);
    if (threshold == 0U || threshold > 255U) {
        fill(bits, bins, threshold == 0U);
    } else if (threshold <= 128U) {
        thresh8_rows(row, bins, (uint8_t)threshold, bits, true);
    } else {
        thresh8_rows(row, bins, (uint8_t)threshold, bits, false);
    }
}

void sl_thresh_u8_table(const uint8_t *row, uint32_t bins, const uint8_t *table,
                        uint32_t *bits)
{
    if (bins == 0U) {
        return;
    }
    SL_ASSERT(row != NULL && table != NULL && bits != NULL);
    const uint32_t full = bins / 32U;
    for (uint32_t w = 0; w < full; w++) {
        uint32_t acc = 0;
        for (uint32_t j = 0; j < 32U / LANE_BYTES; j++) {
            const uint32_t o = 32U * w + j * LANE_BYTES;
            const lane_t x = ld8(row + o);
            const lane_t y = ld8(table + o);
            // Top bit of d: (x & 0x7F) >= (y & 0x7F), no borrow between bytes; then the
            // top bits decide unless they are equal (Hacker's Delight, unsigned compare).
            const lane_t d = (x | H8) - (y & L8);
            const lane_t ge = ((x & ~y) | (~(x ^ y) & d)) & H8;
            acc |= gather8(ge) << (j * LANE_BYTES);
        }
        bits[w] = acc;
    }
    const uint32_t rem = bins % 32U;
    if (rem != 0U) {
        uint32_t acc = 0;
        for (uint32_t k = 0; k < rem; k++) {
            acc |= (uint32_t)(row[32U * full + k] >= table[32U * full + k]) << k;
        }
        bits[full] = acc;
    }
}

// Same scheme as ge8 on 16-bit lanes.
FORCE_INLINE lane_t ge16(lane_t x, lane_t c, bool low)
{
    const lane_t s = (x & L16) + c;
    return (low ? (x | s) : (x & s)) & H16;
}

FORCE_INLINE void thresh16_rows(const uint16_t *row, uint32_t bins, uint32_t t,
                                 uint32_t *bits, bool low)
{
    const lane_t c = ONES16 * (lane_t)(low ? 32768U - t : 65536U - t);
    const uint32_t full = bins / 32U;
    for (uint32_t w = 0; w < full; w++) {
        const uint16_t *p = row + 32U * w;
        uint32_t acc = 0;
        for (uint32_t j = 0; j < 32U / LANE_HALVES; j++) {
            acc |= gather16(ge16(ld16(p + j * LANE_HALVES), c, low)) << (j * LANE_HALVES);
        }
        bits[w] = acc;
    }
    const uint32_t rem = bins % 32U;
    if (rem != 0U) {
        const uint16_t *p = row + 32U * full;
        uint32_t acc = 0;
        for (uint32_t k = 0; k < rem; k++) {
            acc |= (uint32_t)(p[k] >= t) << k;
        }
        bits[full] = acc;
    }
}

void sl_thresh_u16(const uint16_t *row, uint32_t bins, uint32_t threshold, uint32_t *bits)
{
    if (bins == 0U) {
        return;
    }
    SL_ASSERT(row != NULL && bits != NULL);
    if (threshold == 0U || threshold > 65535U) {
        fill(bits, bins, threshold == 0U);
    } else if (threshold <= 32768U) {
        thresh16_rows(row, bins, threshold, bits, true);
    } else {
        thresh16_rows(row, bins, threshold, bits, false);
    }
}
