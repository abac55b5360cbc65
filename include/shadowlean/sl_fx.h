// SPDX-License-Identifier: MIT
/// @file sl_fx.h
/// @brief Fixed-point types and the only narrowing helpers the core uses.
///
/// Formats are in the type name:
/// - `sl_q15_t`   int16, Q1.15 (range [-1, 1)).
/// - `sl_q30_t`   int32, Q2.30 (range [-2, 2)); trigonometric table values.
/// - `sl_uq4_28_t` uint32, UQ4.28 (range [0, 16)); range ratios rho = r2 / r1.
/// - `sl_bam32_t` uint32 binary angle: 2^32 = one turn, so it wraps for free; as a signed
///   int32 it covers [-180, 180) degrees. Resolution 8.4e-8 deg.
/// - `sl_bam16_t` uint16 binary angle: 65536 = one turn.
/// - Plain integers carry their unit in the name: `_um`, `_cdeg` (0.01 deg), `_us`.
///
/// Rounding happens in exactly three places (house style): the host generator when it
/// writes a table; these narrowing helpers (round half up, then saturate); CAN encoding.
/// Module code never writes an ad-hoc `>>` on a signed value: it calls these.
///
/// Cost: every helper is O(1), a handful of instructions, no stack beyond registers.
#ifndef SHADOWLEAN_SL_FX_H
#define SHADOWLEAN_SL_FX_H

#include <limits.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef int16_t sl_q15_t;
typedef int32_t sl_q30_t;
typedef uint32_t sl_uq4_28_t;
typedef uint32_t sl_bam32_t;
typedef uint16_t sl_bam16_t;

#define SL_Q30_ONE ((sl_q30_t)1 << 30)
#define SL_UQ4_28_ONE ((sl_uq4_28_t)1 << 28)

// The narrowing helpers rely on arithmetic right shift of negative values (implementation
// defined in C11, arithmetic on every compiler and target we support). Checked here.
#if defined(__cplusplus)
static_assert((-8 >> 1) == -4, "signed right shift must be arithmetic");
#else
_Static_assert((-8 >> 1) == -4, "signed right shift must be arithmetic");
#endif

/// Round half up and shift right: round(x / 2^n). `n` in [1, 62]. No overflow for any
/// x below INT64_MAX - 2^(n-1).
static inline int64_t sl_fx_rshift_round64(int64_t x, unsigned n)
{
    return (x + ((int64_t)1 << (n - 1U))) >> n;
}

/// Unsigned variant: round(x / 2^n), `n` in [1, 63]; saturates instead of wrapping.
static inline uint64_t sl_fx_urshift_round64(uint64_t x, unsigned n)
{
    const uint64_t half = (uint64_t)1 << (n - 1U);
    return (x > UINT64_MAX - half) ? (UINT64_MAX >> n) + 1U : (x + half) >> n;
}

/// Saturate a 64-bit value to int32.
static inline int32_t sl_fx_sat32(int64_t x)
{
    return (x > INT32_MAX) ? INT32_MAX : (x < INT32_MIN) ? INT32_MIN : (int32_t)x;
}

/// Saturate a 64-bit value to uint32.
static inline uint32_t sl_fx_usat32(int64_t x)
{
    return (x > (int64_t)UINT32_MAX) ? UINT32_MAX : (x < 0) ? 0U : (uint32_t)x;
}

/// Saturate a 32-bit value to int16 (Q15 and other 16-bit signals).
static inline int16_t sl_fx_sat16(int32_t x)
{
    return (x > INT16_MAX) ? INT16_MAX : (x < INT16_MIN) ? INT16_MIN : (int16_t)x;
}

/// Q30 x Q30 -> Q30, rounded and saturated.
static inline sl_q30_t sl_fx_mul_q30(sl_q30_t a, sl_q30_t b)
{
    return sl_fx_sat32(sl_fx_rshift_round64((int64_t)a * (int64_t)b, 30U));
}

/// |x| for int32 with the most negative value saturated to INT32_MAX (CMSIS style).
static inline int32_t sl_fx_abs32(int32_t x)
{
    return (x == INT32_MIN) ? INT32_MAX : (x < 0 ? -x : x);
}

/// floor(sqrt(x)) for a 64-bit unsigned value; exact. Cost: 32 iterations, no division.
uint32_t sl_fx_isqrt64(uint64_t x);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_FX_H
