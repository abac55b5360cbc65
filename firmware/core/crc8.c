// SPDX-License-Identifier: MIT
// CRC-8 with polynomial 0x1D and the AUTOSAR E2E Profile 11 CRC of sl_can.h. Bitwise, no
// table: 9 bytes per frame make a 256-byte table not worth its flash.
#include "shadowlean/sl_can.h"

uint8_t sl_can_crc8_0x1d(uint8_t crc, const uint8_t *data, size_t len)
{
    uint8_t reg = crc;
    for (size_t i = 0; i < len; i++) {
        reg ^= data[i];
        for (unsigned b = 0; b < 8U; b++) {
            reg = (uint8_t)(((reg & 0x80U) != 0U) ? ((unsigned)reg << 1) ^ 0x1DU
                                                  : (unsigned)reg << 1);
        }
    }
    return reg;
}

uint8_t sl_can_e2e_crc(const sl_can_e2e_cfg_t *cfg, const uint8_t data[8])
{
    if (cfg == NULL) {
        return 0U;
    }
    // Profile 11: start value 0x00, no final XOR; the Data ID's low byte first, then its
    // high byte (11A) or 0x00 (11C), then every data byte but the CRC slot (byte 0).
    const uint8_t id[2] = {
        (uint8_t)(cfg->data_id & 0xFFU),
        (cfg->mode == (uint8_t)SL_CAN_E2E_MODE_NIBBLE) ? 0U : (uint8_t)(cfg->data_id >> 8),
    };
    const uint8_t reg = sl_can_crc8_0x1d(0x00U, id, sizeof id);
    return sl_can_crc8_0x1d(reg, &data[1], 7U);
}
