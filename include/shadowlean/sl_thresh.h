// SPDX-License-Identifier: MIT
/// @file sl_thresh.h
/// @brief Thresholding of one azimuth's region of interest into one bit per range bin.
///
/// **Bit layout (used by every bit row in the core: sl_mask.h, sl_detect.h).** A bit row
/// of `bins` range bins is an array of `SL_BITS_WORDS(bins)` `uint32_t` words; bin `k` is
/// bit `k % 32` (value `1u << (k % 32)`) of word `k / 32`. Bit 0 of word 0 is bin 0, the
/// nearest bin. Bits at or beyond `bins` in the last word are always written as 0. The
/// layout is defined on `uint32_t` values, not on bytes, so it is the same on little- and
/// big-endian targets (never reinterpret a bit row as bytes).
///
/// **Occupied** means `power >= threshold`. With the board's `threshold` (8-bit scale):
/// 0 marks every bin occupied, 256 or more marks none (8-bit rows).
///
/// Implementation: SWAR, portable C11 (no intrinsics). A carry-free byte compare on
/// 8 (64-bit lanes, SL_CFG_SWAR_BITS = 64) or 4 bytes at a time: for t <= 128,
/// x >= t == top bit of (x | ((x & 0x7F) + 128 - t)); for t > 128, of
/// (x & ((x & 0x7F) + 256 - t)). 64-bit lanes gather 64 flags with shifts and one 8x8 bit
/// transpose; 32-bit lanes gather 4 flags with one 32-bit multiply. Loads are assembled
/// byte by byte (compilers turn that into one load), so the result is endian-independent.
///
/// Cost: O(bins), 32 bins per word; tails (bins % 32) one bin at a time (measured per bin:
/// docs/PERFORMANCE.md, "Core modules"). Stack: a few words. No state: reentrant, callable from any context. RAM: none
/// (the caller owns the input and output rows).
///
/// Errors: none at run time; NULL pointers with `bins > 0` are caller bugs (SL_ASSERT).
#ifndef SHADOWLEAN_SL_THRESH_H
#define SHADOWLEAN_SL_THRESH_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_config.h"

#ifdef __cplusplus
extern "C" {
#endif

/// SWAR lane width used by the core's bit kernels (thresholds, mask): 64 on targets with
/// 64-bit pointers, else 32 (a 64-bit multiply or shift would be a library call there).
/// Override with -DSL_CFG_SWAR_BITS=32 to test the 32-bit kernels on a 64-bit host.
#ifndef SL_CFG_SWAR_BITS
#if UINTPTR_MAX > 0xFFFFFFFFU
#define SL_CFG_SWAR_BITS 64
#else
#define SL_CFG_SWAR_BITS 32
#endif
#endif
#if SL_CFG_SWAR_BITS != 32 && SL_CFG_SWAR_BITS != 64
#error "SL_CFG_SWAR_BITS must be 32 or 64"
#endif

/// Words of a bit row holding `nbins` bins (rounded up).
#define SL_BITS_WORDS(nbins) (((uint32_t)(nbins) + 31U) / 32U)

/// Words of a full region-of-interest bit row (SL_CFG_ROI_BINS is a multiple of 32).
#define SL_ROI_WORDS (SL_CFG_ROI_BINS / 32)

/// Bin `bin` of a bit row. O(1). No bounds check.
static inline bool sl_bits_get(const uint32_t *bits, uint32_t bin)
{
    return ((bits[bin >> 5] >> (bin & 31U)) & 1U) != 0U;
}

/// Set bin `bin` of a bit row to `v`. O(1). No bounds check.
static inline void sl_bits_put(uint32_t *bits, uint32_t bin, bool v)
{
    const uint32_t m = (uint32_t)1U << (bin & 31U);
    bits[bin >> 5] = v ? (bits[bin >> 5] | m) : (bits[bin >> 5] & ~m);
}

/// Threshold an 8-bit row with one threshold: bit k = (row[k] >= threshold).
///
/// @param row        `bins` power values (8-bit scale), borrowed for the call
/// @param bins       number of bins (0 allowed: writes nothing)
/// @param threshold  0..65535; 0 = every bin occupied, >= 256 = none
/// @param bits       out: SL_BITS_WORDS(bins) words (layout above); must not alias `row`
void sl_thresh_u8(const uint8_t *row, uint32_t bins, uint16_t threshold, uint32_t *bits);

/// Threshold an 8-bit row with a per-range threshold table: bit k = (row[k] >= table[k]).
/// A table entry 0 marks its bin always occupied; no entry can mark a bin never occupied
/// (255 still accepts 255). Use it for range-dependent thresholds (e.g. a higher one over
/// the near-field band). Same parameters as sl_thresh_u8(); `table` has `bins` entries.
void sl_thresh_u8_table(const uint8_t *row, uint32_t bins, const uint8_t *table,
                        uint32_t *bits);

/// Threshold a 16-bit row (radars configured for 16-bit power): bit k = (row[k] >=
/// threshold). `row` holds host-order `uint16_t` values (the decoder assembles wire bytes).
/// threshold 0 = every bin occupied, >= 65536 = none. Cost about 4 instructions per bin.
void sl_thresh_u16(const uint16_t *row, uint32_t bins, uint32_t threshold, uint32_t *bits);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_THRESH_H
