// SPDX-License-Identifier: MIT
// CRC-8 SAE J1850 (poly 0x1D, init 0xFF, xorout 0xFF, no reflection) and the E2E CRC of
// sl_can.h. Bitwise, no table: 8 bytes per frame make a 256-byte table not worth its flash.
#include "shadowlean/sl_can.h"

static uint8_t crc_add(uint8_t reg, uint8_t byte)
{
    reg ^= byte;
    for (unsigned i = 0; i < 8U; i++) {
        reg = (uint8_t)(((reg & 0x80U) != 0U) ? ((unsigned)reg << 1) ^ 0x1DU : (unsigned)reg << 1);
    }
    return reg;
}

uint8_t sl_can_crc8_j1850(const uint8_t *data, size_t len)
{
    uint8_t reg = 0xFFU;
    for (size_t i = 0; i < len; i++) {
        reg = crc_add(reg, data[i]);
    }
    return (uint8_t)(reg ^ 0xFFU);
}

uint8_t sl_can_e2e_crc(uint8_t data_id, const uint8_t data[8])
{
    // One run over [data_id, data[1..7]]: the Data ID is mixed in first, the CRC slot
    // (byte 0) is skipped.
    uint8_t reg = crc_add(0xFFU, data_id);
    for (size_t i = 1; i < 8U; i++) {
        reg = crc_add(reg, data[i]);
    }
    return (uint8_t)(reg ^ 0xFFU);
}
