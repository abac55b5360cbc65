// SPDX-License-Identifier: MIT
// Deterministic Colossus streams (sl_golden.h), built with the core's encoders.
#include "sl_golden.h"

#include <string.h>

#include "shadowlean/sl_proto.h"

// 0.0438 m as an IEEE-754 float32 bit pattern (bin size of the CTS350-X Oxford data).
#define GOLDEN_RANGE_RES_F32 0x3D3367A1U
#define GOLDEN_ONE_F32 0x3F800000U
#define HEALTH_BYTES 37U

sl_golden_params_t sl_golden_defaults(void)
{
    sl_golden_params_t p;
    memset(&p, 0, sizeof p);
    p.azimuths = 400;
    p.encoder_size = 5600;
    p.range_bins = 3768;
    p.rotations = 1;
    p.tick_offset = 13;
    p.bytes_per_bin = 1;
    p.seed = 1;
    p.t0_s = 1547131046U; // an Oxford-era UNIX time
    return p;
}

static uint32_t mix32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

uint32_t sl_golden_bins(const sl_golden_params_t *p, uint32_t az)
{
    return (p->contour_bins != 0U && (az & 1U) != 0U && p->contour_bins < p->range_bins)
               ? p->contour_bins
               : p->range_bins;
}

uint16_t sl_golden_ticks(const sl_golden_params_t *p, uint32_t az)
{
    return (uint16_t)(((uint64_t)az * p->encoder_size / p->azimuths + p->tick_offset) %
                      p->encoder_size);
}

uint16_t sl_golden_sweep(const sl_golden_params_t *p, uint32_t k)
{
    return (uint16_t)(k + p->seed * 977U);
}

void sl_golden_time(const sl_golden_params_t *p, uint32_t k, uint32_t *sec, uint32_t *ns)
{
    // 1600 azimuths per second: 625 us apart, plus a small deterministic jitter.
    const uint64_t t_ns = (uint64_t)k * 625000U + (mix32(k ^ p->seed) % 1000U);
    *sec = p->t0_s + (uint32_t)(t_ns / 1000000000U);
    *ns = (uint32_t)(t_ns % 1000000000U);
}

uint8_t sl_golden_power8(const sl_golden_params_t *p, uint32_t rot, uint32_t az, uint32_t bin)
{
    const uint32_t h = mix32(p->seed * 0x9E3779B9U ^ rot * 0x85EBCA6BU ^ az * 0xC2B2AE35U ^ bin);
    uint32_t v = 40U + (h & 31U); // noise floor 40..71
    if (bin >= 20U && bin < 26U && (az % 50U) < 3U) {
        v = 200U + (h >> 27); // a pole-like return
    }
    if (bin < 4U) {
        v = 250U; // near-field leakage
    }
    return (uint8_t)v;
}

uint16_t sl_golden_power16(const sl_golden_params_t *p, uint32_t rot, uint32_t az, uint32_t bin)
{
    const uint32_t h = mix32(p->seed * 0x27D4EB2FU ^ rot * 0x165667B1U ^ az * 0xD3A2646CU ^ bin);
    return (uint16_t)(((uint32_t)sl_golden_power8(p, rot, az, bin) << 8) | (h & 0xFFU));
}

uint64_t sl_golden_fnv1a(const uint8_t *d, size_t n, uint64_t h)
{
    for (size_t i = 0; i < n; i++) {
        h ^= d[i];
        h *= 0x100000001b3ULL;
    }
    return h;
}

static size_t config_bytes(void)
{
    // 22 + 20 + field 9 (2 bytes) + field 10 (5 bytes)
    return SL_PROTO_HEADER_BYTES + SL_PROTO_CONFIG_FIXED_BYTES + 2U + 5U;
}

static size_t fft_bytes(const sl_golden_params_t *p, uint32_t az)
{
    return SL_PROTO_HEADER_BYTES + SL_PROTO_FFT_FIXED_BYTES +
           (size_t)sl_golden_bins(p, az) * p->bytes_per_bin;
}

size_t sl_golden_size(const sl_golden_params_t *p)
{
    size_t n = config_bytes();
    uint32_t k = 0;
    for (uint32_t r = 0; r < p->rotations; r++) {
        for (uint32_t a = 0; a < p->azimuths; a++, k++) {
            n += fft_bytes(p, a);
            if (p->keep_alive_every != 0U && (k + 1U) % p->keep_alive_every == 0U) {
                n += SL_PROTO_HEADER_BYTES;
            }
            if (p->health_every != 0U && (k + 1U) % p->health_every == 0U) {
                n += SL_PROTO_HEADER_BYTES + HEALTH_BYTES;
            }
        }
    }
    return n;
}

size_t sl_golden_build(uint8_t *buf, size_t cap, const sl_golden_params_t *p)
{
    if (p->azimuths == 0U || p->encoder_size == 0U ||
        (p->bytes_per_bin != 1U && p->bytes_per_bin != 2U) || cap < sl_golden_size(p)) {
        return 0;
    }
    size_t o = 0;
    sl_proto_config_t c;
    memset(&c, 0, sizeof c);
    c.azimuths = p->azimuths;
    c.bin_size_100um = 438;
    c.range_bins = p->range_bins;
    c.encoder_size = p->encoder_size;
    c.rotation_mhz = 4000;
    c.packet_rate = (uint16_t)(p->azimuths * 4U);
    c.range_gain_f32 = GOLDEN_ONE_F32;
    c.range_offset_f32 = 0;
    c.has_data_width = true;
    c.data_width = p->bytes_per_bin;
    c.has_range_res = true;
    c.range_res_m_f32 = GOLDEN_RANGE_RES_F32;
    const sl_bytes_t none = {NULL, 0};
    sl_ssize_t w = sl_proto_encode_config(buf + o, cap - o, &c, none);
    if (w <= 0) {
        return 0;
    }
    o += (size_t)w;
    uint32_t k = 0;
    for (uint32_t r = 0; r < p->rotations; r++) {
        for (uint32_t a = 0; a < p->azimuths; a++, k++) {
            sl_proto_fft_t f;
            memset(&f, 0, sizeof f);
            f.id = (p->bytes_per_bin == 2U) ? SL_PROTO_ID_FFT_DATA_16 : SL_PROTO_ID_FFT_DATA;
            f.sweep_counter = sl_golden_sweep(p, k);
            f.azimuth_ticks = sl_golden_ticks(p, a);
            sl_golden_time(p, k, &f.seconds, &f.split_ns);
            f.bins = sl_golden_bins(p, a);
            w = sl_proto_encode_fft_head(buf + o, cap - o, &f);
            if (w <= 0) {
                return 0;
            }
            uint8_t *d = buf + o + (size_t)w;
            if (p->bytes_per_bin == 1U) {
                for (uint32_t b = 0; b < f.bins; b++) {
                    d[b] = sl_golden_power8(p, r, a, b);
                }
            } else {
                for (uint32_t b = 0; b < f.bins; b++) {
                    const uint16_t v = sl_golden_power16(p, r, a, b);
                    d[2U * b] = (uint8_t)v;
                    d[2U * b + 1U] = (uint8_t)(v >> 8);
                }
            }
            o += fft_bytes(p, a);
            if (p->keep_alive_every != 0U && (k + 1U) % p->keep_alive_every == 0U) {
                o += (size_t)sl_proto_encode_keep_alive(buf + o, cap - o);
            }
            if (p->health_every != 0U && (k + 1U) % p->health_every == 0U) {
                o += (size_t)sl_proto_encode_header(buf + o, cap - o, SL_PROTO_ID_HEALTH, HEALTH_BYTES);
                for (uint32_t b = 0; b < HEALTH_BYTES; b++) {
                    // protobuf-ish bytes that include signature fragments (00 01 03 ...)
                    buf[o + b] = (b % 9U == 0U) ? 0x00U : sl_proto_signature[b % 16U];
                }
                o += HEALTH_BYTES;
            }
        }
    }
    return o;
}
