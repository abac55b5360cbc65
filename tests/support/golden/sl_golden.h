// SPDX-License-Identifier: MIT
/// @file sl_golden.h
/// @brief Deterministic Colossus streams for tests, fuzz seeds and benchmarks.
///
/// Builds a stream with the core's own encoders: one Configuration (with a protobuf holding
/// datawidth and rangeresolutionmetres), then `rotations` x `azimuths` FFT messages (id 30 or
/// 31), optionally interleaved with keep-alives and Health messages. Every value is a pure
/// function of the parameters, so a test can check a decoded row with sl_golden_power*()
/// instead of keeping a copy. Test/host code only (not part of the core).
#ifndef SL_GOLDEN_H
#define SL_GOLDEN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sl_golden_params {
    uint16_t azimuths;         ///< azimuths per rotation (400)
    uint16_t encoder_size;     ///< encoder ticks per rotation (5600)
    uint16_t range_bins;       ///< bins per azimuth (3768)
    uint16_t rotations;        ///< whole rotations of FFT messages
    uint16_t tick_offset;      ///< encoder value of azimuth i: i*enc/az + offset (Oxford: 13)
    uint8_t bytes_per_bin;     ///< 1 (id 30) or 2 (id 31)
    uint16_t keep_alive_every; ///< a keep-alive after every n-th FFT message (0 = none)
    uint16_t health_every;     ///< a Health message (id 40, 37 bytes) after every n-th (0 = none)
    uint16_t contour_bins;     ///< 0, or: odd azimuths carry only this many bins (contoured)
    uint32_t seed;             ///< content seed
    uint32_t t0_s;             ///< UNIX seconds of the first azimuth
} sl_golden_params_t;

/// CTS350-X-like defaults (400 x 5600, 3768 bins, 8-bit, tick offset 13, 4 Hz).
sl_golden_params_t sl_golden_defaults(void);

/// Exact size in bytes of the stream sl_golden_build() writes.
size_t sl_golden_size(const sl_golden_params_t *p);

/// Writes the stream into buf (cap >= sl_golden_size). Returns bytes written, 0 on error.
size_t sl_golden_build(uint8_t *buf, size_t cap, const sl_golden_params_t *p);

/// Bins carried by azimuth `az` (contour rule above).
uint32_t sl_golden_bins(const sl_golden_params_t *p, uint32_t az);

/// Encoder ticks of azimuth `az` (0..azimuths-1).
uint16_t sl_golden_ticks(const sl_golden_params_t *p, uint32_t az);

/// Sweep counter of FFT message number k (0-based over the whole stream).
uint16_t sl_golden_sweep(const sl_golden_params_t *p, uint32_t k);

/// Timestamp of FFT message number k: seconds and nanoseconds (4 Hz rotation, 1600 Hz).
void sl_golden_time(const sl_golden_params_t *p, uint32_t k, uint32_t *sec, uint32_t *ns);

/// 8-bit power of (rotation, azimuth, bin): noise around 40-70 plus a few strong returns.
uint8_t sl_golden_power8(const sl_golden_params_t *p, uint32_t rot, uint32_t az, uint32_t bin);

/// 16-bit power of (rotation, azimuth, bin) (used when bytes_per_bin == 2).
uint16_t sl_golden_power16(const sl_golden_params_t *p, uint32_t rot, uint32_t az, uint32_t bin);

/// FNV-1a 64 of bytes (event fingerprints in tests).
uint64_t sl_golden_fnv1a(const uint8_t *d, size_t n, uint64_t h);
#define SL_GOLDEN_FNV_INIT 0xcbf29ce484222325ULL

#ifdef __cplusplus
}
#endif

#endif // SL_GOLDEN_H
