# SPDX-License-Identifier: MIT
"""AUTOSAR E2E Profile 11 protection for test frames, written the way the AUTOSAR E2E
library chains the AUTOSAR CRC library (Crc_CalculateCRC8: SAE J1850, start value 0xFF
on the first call, the previous result XOR 0xFF on later calls, final XOR 0xFF), not with
the project's own code: E2E_P11Protect runs Crc_CalculateCRC8 over the Data ID's low
byte (start value 0xFF, not a first call), then its high byte (11A) or 0x00 (11C), then
the data bytes after the CRC byte, and XORs the result with 0xFF. The check below pins it
to the published Profile 11 vectors (8 zero bytes, Data ID 0x123: 0xCC / 0x91 in 11A,
0x2A with byte 1 = 0x10 in 11C)."""


def crc_calculate_crc8(data, start, first_call):
    """AUTOSAR Crc_CalculateCRC8 (SAE J1850: poly 0x1D, initial value 0xFF, XOR 0xFF)."""
    crc = 0xFF if first_call else (start ^ 0xFF)
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


def p11_protect(data, data_id, counter, nibble=False):
    """8 bytes with Counter in bits 8..11, (11C) the Data ID nibble in bits 12..15, CRC in byte 0."""
    d = bytearray(data)
    d[1] = (d[1] & 0xF0) | (counter & 0x0F)
    if nibble:
        d[1] = (d[1] & 0x0F) | (((data_id >> 8) & 0x0F) << 4)
    crc = crc_calculate_crc8(bytes([data_id & 0xFF]), 0xFF, False)
    crc = crc_calculate_crc8(bytes([0 if nibble else (data_id >> 8) & 0xFF]), crc, False)
    crc = crc_calculate_crc8(bytes(d[1:]), crc, False)
    d[0] = crc ^ 0xFF
    return bytes(d)


assert p11_protect(bytes(8), 0x123, 0) == bytes.fromhex("cc00000000000000")
assert p11_protect(bytes(8), 0x123, 1) == bytes.fromhex("9101000000000000")
assert p11_protect(bytes(8), 0x123, 0, nibble=True) == bytes.fromhex("2a10000000000000")
