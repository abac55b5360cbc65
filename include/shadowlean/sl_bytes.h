// SPDX-License-Identifier: MIT
/// @file sl_bytes.h
/// @brief Wire byte order, byte by byte: the one set of helpers every encoder and parser
/// uses (Colossus is big-endian with little-endian timestamps; gs_usb and CAN signals are
/// little-endian). Assembling bytes explicitly keeps the code endian-clean (the unit tests
/// run on big-endian s390x) and free of alignment traps. Cost: a few instructions each.
#ifndef SHADOWLEAN_SL_BYTES_H
#define SHADOWLEAN_SL_BYTES_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

static inline uint16_t sl_get_be16(const uint8_t *b)
{
    return (uint16_t)(((uint32_t)b[0] << 8) | (uint32_t)b[1]);
}

static inline uint32_t sl_get_be32(const uint8_t *b)
{
    return ((uint32_t)b[0] << 24) | ((uint32_t)b[1] << 16) | ((uint32_t)b[2] << 8) | (uint32_t)b[3];
}

static inline uint32_t sl_get_le32(const uint8_t *b)
{
    return ((uint32_t)b[3] << 24) | ((uint32_t)b[2] << 16) | ((uint32_t)b[1] << 8) | (uint32_t)b[0];
}

static inline void sl_put_be16(uint8_t *b, uint16_t v)
{
    b[0] = (uint8_t)(v >> 8);
    b[1] = (uint8_t)v;
}

static inline void sl_put_be32(uint8_t *b, uint32_t v)
{
    b[0] = (uint8_t)(v >> 24);
    b[1] = (uint8_t)(v >> 16);
    b[2] = (uint8_t)(v >> 8);
    b[3] = (uint8_t)v;
}

static inline void sl_put_le32(uint8_t *b, uint32_t v)
{
    b[0] = (uint8_t)v;
    b[1] = (uint8_t)(v >> 8);
    b[2] = (uint8_t)(v >> 16);
    b[3] = (uint8_t)(v >> 24);
}

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_BYTES_H
