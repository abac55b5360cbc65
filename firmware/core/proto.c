// SPDX-License-Identifier: MIT
// Colossus protocol: incremental decoder, typed parsers and encoders (sl_proto.h).
//
// Decoder: a three-state machine (signature, header tail, payload). The signature is
// matched incrementally; because 0x00 occurs only as its first byte, a mismatch restarts
// the match at 1 (byte is 0x00) or 0 (any other byte), which is exactly byte-wise resync
// without keeping the matched bytes. A rejected header discards the signature (none of
// signature bytes 1..15 can start a signature) and rescans the 6 header-tail bytes.
// A fast path handles the common case (aligned stream, whole header and payload in the
// chunk) without touching the state machine; it is behaviourally identical (the property
// tests feed every chunking and compare).
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_proto.h"

#include "shadowlean/sl_bytes.h"

const uint8_t sl_proto_signature[SL_PROTO_SIGNATURE_BYTES] = {
    0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
    0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE,
};

enum { ST_SIG = 0, ST_HDR = 1, ST_PAY = 2 };

// A whole signature at d (16 readable bytes), compared a word at a time: the aligned
// stream's per-message check, which a byte-wise library memcmp makes ~120 instructions
// on Cortex-M (once per azimuth). Words assembled from bytes: alignment-safe, one load
// where the target has unaligned loads (forced inline: -Os otherwise calls it).
#if defined(__GNUC__)
#define SL_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define SL_ALWAYS_INLINE inline
#endif
static SL_ALWAYS_INLINE uint32_t word_at(const uint8_t *b)
{
    return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) |
           ((uint32_t)b[3] << 24);
}

// The per-message field reads (header length, FFT timestamp): sl_get_be32/le32 forced
// inline here, where -Os on Cortex-M otherwise calls them (~4 calls per azimuth).
static SL_ALWAYS_INLINE uint32_t msg_be32(const uint8_t *b)
{
    return ((uint32_t)b[0] << 24) | ((uint32_t)b[1] << 16) | ((uint32_t)b[2] << 8) | (uint32_t)b[3];
}

// The signature as little-endian words (the table above, bytes 0-3, 4-7, 8-11, 12-15):
// literals, so they are not re-read byte by byte from the table.
// Hosts whose compilers expand a 16-byte memcmp inline (x86-64 GCC: two 8-byte compares)
// keep it.
static bool sig_at(const uint8_t *d)
{
#if defined(__arm__) || defined(__thumb__)
    return ((word_at(d) ^ 0x03030100U) | (word_at(d + 4) ^ 0x0F0F0707U) |
            (word_at(d + 8) ^ 0x3F3F1F1FU) | (word_at(d + 12) ^ 0xFEFE7F7FU)) == 0U;
#else
    return memcmp(d, sl_proto_signature, SL_PROTO_SIGNATURE_BYTES) == 0;
#endif
}

enum { HDR_OK = 0, HDR_BAD_VERSION, HDR_OVERSIZE, HDR_TOO_BIG };

// ---------------------------------------------------------------------------------- decoder

// Cache prefetch hint (a compiler builtin, no library call; a no-op elsewhere). A consumer
// that reads only a prefix of each message touches a few lines every ~3.8 KB; hinting them
// a few messages ahead measured ~1.4x faster on an L3-resident capture (sl-bench, x86-64),
// and no change on a 535 MB one.
#if defined(__GNUC__) || defined(__clang__)
#define SL_PREFETCH(a) __builtin_prefetch(a)
#else
#define SL_PREFETCH(a) ((void)(a))
#endif

// Messages ahead to prefetch, assuming they have the length of the current one.
#define PREFETCH_MSGS 3U

// With truncate_long the consumer reads at most the header and reasm_size payload bytes of
// each message: hint the CPU to fetch those of the next PREFETCH_MSGS messages (only the
// lines inside the caller's buffer). Pure performance; no effect on behaviour.
static inline void prefetch_ahead(const sl_proto_t *p, const uint8_t *data, size_t len,
                                  size_t next, uint32_t plen)
{
    if (!p->cfg.truncate_long || p->cfg.reasm_size > 1024U) {
        return;
    }
    // Only the message PREFETCH_MSGS ahead: the nearer ones were hinted by earlier calls.
    const size_t keep = SL_PROTO_HEADER_BYTES + p->cfg.reasm_size;
    const size_t at = next + (PREFETCH_MSGS - 1U) * (SL_PROTO_HEADER_BYTES + (size_t)plen);
    for (size_t o = 0; o < keep && at + o < len; o += 64U) {
        SL_PREFETCH(data + at + o);
    }
}

// Horspool bad-character shift on the last byte of a 16-byte window: 15 - (last position of
// the byte among signature bytes 0..14), 16 for a byte not in the signature.
static const uint8_t sig_shift[256] = {
    15, 14, 16, 12, 16, 16, 16, 10, 16, 16, 16, 16, 16, 16, 16,  8,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,  6,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,  4,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,  2,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,
    16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16, 16,  1, 16,
};

// First position s >= from at which a whole signature lies in d[0..len), or, when there is
// none, the first position at which one could still begin (a partial signature at the end,
// s >= len - 15, or s == from when fewer than 16 bytes remain); *found tells which.
// Horspool over 16-byte windows keyed on the window's last byte: zero fill advances 15
// bytes per step, bytes not in the signature 16; a window ending in 0xFE is also keyed on
// its byte 13 (a run of 0xFE advances 14). Each step is O(1): the full compare runs only
// when the window ends in 7F FE and starts with 0x00.
static size_t sig_search(const uint8_t *d, size_t from, size_t len, bool *found)
{
    size_t s = from;
    if (len - from >= SL_PROTO_SIGNATURE_BYTES) {
        const size_t last = len - SL_PROTO_SIGNATURE_BYTES;
        while (s <= last) {
            const uint8_t b = d[s + (SL_PROTO_SIGNATURE_BYTES - 1U)];
            if (b != 0xFEU) {
                s += sig_shift[b];
                continue;
            }
            // Last byte matches: key on byte 13 (0x7F in a signature) as well. Shifted by
            // k >= 1 it would sit at signature index 13 - k <= 12: 0xFE never does (skip
            // 14), 0x7F at 12 (skip 1), any other byte as the last-byte table less 2.
            const uint8_t c = d[s + 13U];
            if (c == 0x7FU) {
                if (d[s] == 0x00U &&
                    memcmp(d + s + 1U, sl_proto_signature + 1U, SL_PROTO_SIGNATURE_BYTES - 2U) == 0) {
                    *found = true;
                    return s;
                }
                s += 1U;
            } else {
                s += (c == 0xFEU) ? 14U : (size_t)sig_shift[c] - 2U;
            }
        }
    }
    *found = false;
    return s;
}

static void skip(sl_proto_t *p, uint64_t n)
{
    if (n != 0U) {
        p->stats.bytes_skipped += n;
        if (!p->hunting) {
            p->hunting = true;
            p->stats.resyncs++;
        }
    }
}

// One byte while matching the signature.
static void sig_byte(sl_proto_t *p, uint8_t b)
{
    const uint8_t k = p->sig_got;
    if (b == sl_proto_signature[k]) {
        p->sig_got = (uint8_t)(k + 1U);
        if (p->sig_got == SL_PROTO_SIGNATURE_BYTES) {
            p->state = ST_HDR;
            p->hdr_got = 0;
        }
    } else if (b == 0x00U) {
        // k >= 1 here (signature[0] is 0x00): drop the k matched bytes, this one starts anew.
        skip(p, k);
        p->sig_got = 1;
    } else {
        skip(p, (uint64_t)k + 1U);
        p->sig_got = 0;
    }
}

// Header tail = version, id, length (BE). Counts the rejection reason.
static int check_header(sl_proto_t *p, const uint8_t *tail)
{
    const uint32_t len = msg_be32(tail + 2);
    if (tail[0] != SL_PROTO_VERSION) {
        p->stats.bad_version++;
        return HDR_BAD_VERSION;
    }
    if (p->cfg.max_payload_bytes != 0U && len > p->cfg.max_payload_bytes) {
        p->stats.oversize++;
        return HDR_OVERSIZE;
    }
    if ((uint64_t)len > (uint64_t)p->cfg.reasm_size && !p->cfg.truncate_long) {
        p->stats.too_big++;
        return HDR_TOO_BIG;
    }
    return HDR_OK;
}

// `wire` = the payload length field; only its first reasm_size bytes are delivered when it
// is longer (truncate_long: check_header rejects it otherwise).
static void deliver(sl_proto_t *p, uint8_t id, const uint8_t *data, uint32_t wire, bool zc,
                    uint64_t now_us)
{
    sl_proto_stats_t *st = &p->stats;
    const bool cut = (uint64_t)wire > (uint64_t)p->cfg.reasm_size;
    const uint32_t size = cut ? (uint32_t)p->cfg.reasm_size : wire;
    if (cut) {
        st->cut++;
    }
    st->messages++;
    switch (id) {
    case SL_PROTO_ID_KEEP_ALIVE: st->keep_alive++; break;
    case SL_PROTO_ID_CONFIGURATION: st->configuration++; break;
    case SL_PROTO_ID_FFT_DATA: st->fft8++; break;
    case SL_PROTO_ID_FFT_DATA_16: st->fft16++; break;
    case SL_PROTO_ID_HEALTH: st->health++; break;
    default: st->other++; break;
    }
    if (zc) {
        st->zero_copy++;
    } else {
        st->reassembled++;
    }
    st->bytes_delivered += (uint64_t)SL_PROTO_HEADER_BYTES + wire;
    p->state = ST_SIG;
    p->sig_got = 0;
    p->hdr_got = 0;
    p->payload_got = 0;
    sl_proto_msg_t m;
    m.id = id;
    m.zero_copy = zc;
    m.payload.data = (size != 0U) ? data : NULL;
    m.payload.size = size;
    m.stream_offset = p->msg_offset;
    m.rx_us = now_us;
    m.truncated = cut;
    m.wire_bytes = wire;
    p->cfg.on_msg(p->cfg.ctx, &m);
}

sl_err_t sl_proto_init(sl_proto_t *p, const sl_proto_cfg_t *cfg)
{
    if (p == NULL || cfg == NULL || cfg->on_msg == NULL ||
        (cfg->reasm_buf == NULL && cfg->reasm_size != 0U)) {
        return SL_ERR_ARG;
    }
    memset(p, 0, sizeof *p);
    p->cfg = *cfg;
    uint64_t lim = cfg->truncate_long ? (uint64_t)UINT32_MAX : (uint64_t)cfg->reasm_size;
    if (cfg->max_payload_bytes != 0U && cfg->max_payload_bytes < lim) {
        lim = cfg->max_payload_bytes;
    }
    p->max_payload = (lim > UINT32_MAX) ? UINT32_MAX : (uint32_t)lim;
    return SL_OK;
}

uint64_t sl_proto_buffered(const sl_proto_t *p)
{
    switch (p->state) {
    case ST_SIG: return p->sig_got;
    case ST_HDR: return (uint64_t)SL_PROTO_SIGNATURE_BYTES + p->hdr_got;
    default: return (uint64_t)SL_PROTO_HEADER_BYTES + p->payload_got;
    }
}

sl_err_t sl_proto_finish(sl_proto_t *p)
{
    if (p == NULL) {
        return SL_ERR_ARG;
    }
    const uint64_t held = sl_proto_buffered(p);
    if (held != 0U) {
        p->stats.truncated++;
        p->stats.bytes_skipped += held;
    }
    p->state = ST_SIG;
    p->sig_got = 0;
    p->hdr_got = 0;
    p->payload_got = 0;
    p->payload_bytes = 0;
    p->hunting = false;
    return SL_OK;
}

sl_err_t sl_proto_feed(sl_proto_t *p, const uint8_t *data, size_t len, uint64_t now_us)
{
    if (p == NULL || (data == NULL && len != 0U)) {
        return SL_ERR_ARG;
    }
    const uint64_t base = p->stats.bytes_in;
    p->stats.bytes_in += len;
    size_t i = 0;
    while (i < len) {
        if (p->state == ST_SIG && p->sig_got <= i && len - (i - p->sig_got) >= SL_PROTO_SIGNATURE_BYTES) {
            // Fast resync. A held partial signature that lies in this chunk is given back
            // (it is re-examined as part of a window), then the Horspool search rules out
            // every start position before the next whole signature. The rewind happens
            // only while 16 bytes remain, and the search then either finds a signature
            // (state leaves ST_SIG or a message is delivered) or leaves i >= len - 15, so
            // it cannot repeat without progress.
            i -= p->sig_got;
            p->sig_got = 0;
            bool found = true;
            size_t j = i;
            // Aligned stream (the common case): the signature is right here.
            if (data[i] != 0x00U || !sig_at(data + i)) {
                j = sig_search(data, i, len, &found);
            }
            skip(p, j - i);
            i = j;
            if (!found) {
                if (i == len) {
                    break;
                }
            } else if (len - i >= SL_PROTO_HEADER_BYTES) {
                const uint8_t *tail = data + i + SL_PROTO_SIGNATURE_BYTES;
                if (check_header(p, tail) != HDR_OK) {
                    // Same as the slow path: drop the signature's first byte, rescan after it.
                    skip(p, 1);
                    i++;
                    continue;
                }
                const uint32_t plen = msg_be32(tail + 2);
                p->hunting = false;
                p->msg_offset = base + i;
                p->payload_bytes = plen;
                i += SL_PROTO_HEADER_BYTES;
                if (len - i >= plen) {
                    prefetch_ahead(p, data, len, i + plen, plen);
                    deliver(p, tail[1], data + i, plen, true, now_us);
                    i += plen;
                } else {
                    p->hdr[1] = tail[1];
                    p->state = ST_PAY;
                    p->payload_got = 0;
                }
                continue;
            } else {
                // Whole signature, header tail beyond this chunk: as if matched bytewise.
                i += SL_PROTO_SIGNATURE_BYTES;
                p->state = ST_HDR;
                p->sig_got = (uint8_t)SL_PROTO_SIGNATURE_BYTES;
                p->hdr_got = 0;
                continue;
            }
        }
        switch (p->state) {
        case ST_SIG:
            sig_byte(p, data[i]);
            i++;
            break;
        case ST_HDR:
            p->hdr[p->hdr_got] = data[i];
            p->hdr_got++;
            i++;
            if (p->hdr_got == 6U) {
                if (check_header(p, p->hdr) != HDR_OK) {
                    uint8_t tail[6];
                    memcpy(tail, p->hdr, sizeof tail);
                    p->state = ST_SIG;
                    p->sig_got = 0;
                    p->hdr_got = 0;
                    skip(p, SL_PROTO_SIGNATURE_BYTES);
                    for (size_t k = 0; k < sizeof tail; k++) {
                        sig_byte(p, tail[k]);
                    }
                } else {
                    p->hunting = false;
                    p->msg_offset = base + i - SL_PROTO_HEADER_BYTES;
                    p->payload_bytes = sl_get_be32(p->hdr + 2);
                    p->payload_got = 0;
                    p->state = ST_PAY;
                    if (p->payload_bytes == 0U) {
                        deliver(p, p->hdr[1], NULL, 0, true, now_us);
                    } else if (len - i >= p->payload_bytes) {
                        deliver(p, p->hdr[1], data + i, p->payload_bytes, true, now_us);
                        i += p->payload_bytes;
                    }
                }
            }
            break;
        default: { // ST_PAY, payload_got < payload_bytes, never zero-copy here
            const uint32_t need = p->payload_bytes - p->payload_got;
            const size_t avail = len - i;
            const uint32_t n = (avail < need) ? (uint32_t)avail : need;
            if ((uint64_t)p->payload_got < (uint64_t)p->cfg.reasm_size) {
                // Only the part that fits is kept (all of it unless truncate_long).
                const uint64_t room = (uint64_t)p->cfg.reasm_size - p->payload_got;
                const uint32_t c = ((uint64_t)n < room) ? n : (uint32_t)room;
                memcpy(p->cfg.reasm_buf + p->payload_got, data + i, c);
            }
            p->payload_got += n;
            i += n;
            if (p->payload_got == p->payload_bytes) {
                deliver(p, p->hdr[1], p->cfg.reasm_buf, p->payload_bytes, false, now_us);
            }
            break;
        }
        }
    }
    return SL_OK;
}

// ---------------------------------------------------------------------------------- parsers

// Protobuf varint (up to 10 bytes). False when truncated or longer than 10 bytes.
static bool pb_varint(const uint8_t *d, size_t n, size_t *pos, uint64_t *out)
{
    uint64_t v = 0;
    for (unsigned shift = 0; shift < 70U; shift += 7U) {
        if (*pos >= n) {
            return false;
        }
        const uint8_t b = d[*pos];
        (*pos)++;
        if (shift < 64U) {
            v |= (uint64_t)(b & 0x7FU) << shift;
        }
        if ((b & 0x80U) == 0U) {
            *out = v;
            return true;
        }
    }
    return false;
}

static int32_t to_int32(uint64_t v)
{
    // proto int32: the low 32 bits, two's complement (negative values use 10 varint bytes).
    const uint32_t u = (uint32_t)(v & 0xFFFFFFFFU);
    return (u <= (uint32_t)INT32_MAX) ? (int32_t)u : -(int32_t)(~u) - 1;
}

// Walk the ConfigurationData protobuf for fields 9 (datawidth) and 10 (rangeresolutionmetres).
static bool pb_walk(const uint8_t *d, size_t n, sl_proto_config_t *c)
{
    size_t pos = 0;
    while (pos < n) {
        uint64_t key;
        uint64_t v;
        if (!pb_varint(d, n, &pos, &key)) {
            return false;
        }
        const uint64_t field = key >> 3;
        if (field == 0U) {
            return false;
        }
        switch ((unsigned)(key & 7U)) {
        case 0: // varint
            if (!pb_varint(d, n, &pos, &v)) {
                return false;
            }
            if (field == 9U) {
                c->has_data_width = true;
                c->data_width = to_int32(v);
            }
            break;
        case 1: // fixed64
            if (n - pos < 8U) {
                return false;
            }
            pos += 8U;
            break;
        case 2: // length-delimited
            if (!pb_varint(d, n, &pos, &v) || v > (uint64_t)(n - pos)) {
                return false;
            }
            pos += (size_t)v;
            break;
        case 5: // fixed32, little-endian
            if (n - pos < 4U) {
                return false;
            }
            if (field == 10U) {
                c->has_range_res = true;
                c->range_res_m_f32 = sl_get_le32(d + pos);
            }
            pos += 4U;
            break;
        default: // groups (3, 4) and reserved wire types: not in this schema
            return false;
        }
    }
    return true;
}

sl_err_t sl_proto_parse_config(const sl_proto_msg_t *msg, sl_proto_config_t *out)
{
    if (msg == NULL || out == NULL || msg->id != SL_PROTO_ID_CONFIGURATION ||
        (msg->payload.data == NULL && msg->payload.size != 0U)) {
        return SL_ERR_ARG;
    }
    if (msg->payload.size < SL_PROTO_CONFIG_FIXED_BYTES) {
        return SL_ERR_MALFORMED;
    }
    const uint8_t *d = msg->payload.data;
    memset(out, 0, sizeof *out);
    out->azimuths = sl_get_be16(d + 0);
    out->bin_size_100um = sl_get_be16(d + 2);
    out->range_bins = sl_get_be16(d + 4);
    out->encoder_size = sl_get_be16(d + 6);
    out->rotation_mhz = sl_get_be16(d + 8);
    out->packet_rate = sl_get_be16(d + 10);
    out->range_gain_f32 = sl_get_be32(d + 12);
    out->range_offset_f32 = sl_get_be32(d + 16);
    out->protobuf.data = d + SL_PROTO_CONFIG_FIXED_BYTES;
    out->protobuf.size = msg->payload.size - SL_PROTO_CONFIG_FIXED_BYTES;
    out->protobuf_malformed = !pb_walk(out->protobuf.data, out->protobuf.size, out);
    if (out->protobuf.size == 0U) {
        out->protobuf.data = NULL;
    }
    return SL_OK;
}

// float32 bit pattern (metres) -> micrometres, round to nearest; false when not finite,
// not positive or out of (0, UINT32_MAX] um.
static bool f32_m_to_um(uint32_t bits, uint32_t *um)
{
    const uint32_t exp = (bits >> 23) & 0xFFU;
    const uint32_t man = bits & 0x7FFFFFU;
    if ((bits >> 31) != 0U || exp == 0xFFU || exp == 0U) {
        return false; // negative, inf/nan, zero or subnormal (< 1e-38 m rounds to 0 um)
    }
    uint64_t x = (uint64_t)(man | 0x800000U) * 1000000U; // value * 1e6 * 2^(150 - exp)
    if (exp >= 150U) {
        const uint32_t sh = exp - 150U;
        if (sh > 20U) {
            return false;
        }
        x <<= sh;
    } else {
        const uint32_t sh = 150U - exp;
        x = (sh >= 64U) ? 0U : (x + ((uint64_t)1 << (sh - 1U))) >> sh;
    }
    if (x == 0U || x > UINT32_MAX) {
        return false;
    }
    *um = (uint32_t)x;
    return true;
}

uint32_t sl_proto_config_bin_size_um(const sl_proto_config_t *c)
{
    if (c == NULL) {
        return 0;
    }
    uint32_t um;
    if (c->has_range_res && f32_m_to_um(c->range_res_m_f32, &um)) {
        return um;
    }
    return (uint32_t)c->bin_size_100um * 100U;
}

sl_err_t sl_proto_parse_fft(const sl_proto_msg_t *msg, sl_proto_fft_t *out)
{
    if (msg == NULL || out == NULL ||
        (msg->id != SL_PROTO_ID_FFT_DATA && msg->id != SL_PROTO_ID_FFT_DATA_16) ||
        (msg->payload.data == NULL && msg->payload.size != 0U)) {
        return SL_ERR_ARG;
    }
    const size_t size = msg->payload.size;
    if (size < SL_PROTO_FFT_FIXED_BYTES) {
        return SL_ERR_MALFORMED;
    }
#if SIZE_MAX > UINT32_MAX
    if (size > UINT32_MAX) {
        return SL_ERR_MALFORMED; // only for hand-built messages: the decoder caps at uint32
    }
#endif
    const uint8_t *d = msg->payload.data;
    const uint16_t off = sl_get_be16(d);
    if (off < SL_PROTO_FFT_FIXED_BYTES || off > size) {
        return SL_ERR_MALFORMED;
    }
    const uint8_t bpb = (msg->id == SL_PROTO_ID_FFT_DATA_16) ? 2U : 1U;
    // Parity of the message as sent, not of the prefix kept: an odd-length 16-bit message
    // is malformed whatever the reassembly size it was truncated to. bpb is 1 or 2: masks
    // and shifts, not divisions (this runs once per azimuth).
    const uint32_t bpb_log2 = (uint32_t)bpb - 1U;
    const size_t wire = (msg->truncated && msg->wire_bytes > size) ? msg->wire_bytes : size;
    if (((wire - off) & (size_t)bpb_log2) != 0U) {
        return SL_ERR_MALFORMED;
    }
    // A truncated 16-bit message may have kept an odd prefix: whole bins only.
    const size_t nbytes = (size - off) & ~(size_t)bpb_log2;
    out->id = msg->id;
    out->bytes_per_bin = bpb;
    out->data_offset = off;
    out->sweep_counter = sl_get_be16(d + 2);
    out->azimuth_ticks = sl_get_be16(d + 4);
    out->seconds = word_at(d + 6);
    out->split_ns = word_at(d + 10);
    out->bins = (uint32_t)(nbytes >> bpb_log2);
    out->bin_data = d + off;
    return SL_OK;
}

// --------------------------------------------------------------------------------- encoders

sl_ssize_t sl_proto_encode_header(uint8_t *buf, size_t size, uint8_t id, uint32_t payload_bytes)
{
    if (buf == NULL) {
        return SL_ERR_ARG;
    }
    if (size < SL_PROTO_HEADER_BYTES) {
        return SL_ERR_FULL;
    }
    memcpy(buf, sl_proto_signature, SL_PROTO_SIGNATURE_BYTES);
    buf[16] = SL_PROTO_VERSION;
    buf[17] = id;
    sl_put_be32(buf + 18, payload_bytes);
    return (sl_ssize_t)SL_PROTO_HEADER_BYTES;
}

sl_ssize_t sl_proto_encode_command(uint8_t *buf, size_t size, uint8_t id)
{
    return sl_proto_encode_header(buf, size, id, 0);
}

sl_ssize_t sl_proto_encode_keep_alive(uint8_t *buf, size_t size)
{
    return sl_proto_encode_header(buf, size, SL_PROTO_ID_KEEP_ALIVE, 0);
}

// Protobuf varint; returns bytes written (<= 10).
static size_t pb_put_varint(uint8_t *b, uint64_t v)
{
    size_t n = 0;
    while (v >= 0x80U) {
        b[n++] = (uint8_t)((v & 0x7FU) | 0x80U);
        v >>= 7;
    }
    b[n++] = (uint8_t)v;
    return n;
}

sl_ssize_t sl_proto_encode_config(uint8_t *buf, size_t size, const sl_proto_config_t *c,
                                  sl_bytes_t extra_protobuf)
{
    if (buf == NULL || c == NULL || (extra_protobuf.data == NULL && extra_protobuf.size != 0U)) {
        return SL_ERR_ARG;
    }
    uint8_t pb[16];
    size_t pbn = 0;
    if (c->has_data_width) {
        pb[pbn++] = (uint8_t)((9U << 3) | 0U);
        // int32 negative values are sign-extended to 64 bits (10-byte varint), as protobuf does.
        pbn += pb_put_varint(pb + pbn, (uint64_t)(int64_t)c->data_width);
    }
    if (c->has_range_res) {
        pb[pbn++] = (uint8_t)((10U << 3) | 5U);
        sl_put_le32(pb + pbn, c->range_res_m_f32);
        pbn += 4U;
    }
    const uint64_t payload = (uint64_t)SL_PROTO_CONFIG_FIXED_BYTES + pbn + extra_protobuf.size;
    const uint64_t total = SL_PROTO_HEADER_BYTES + payload;
    if (total > (uint64_t)INT32_MAX) {
        return SL_ERR_RANGE;
    }
    if (total > size) {
        return SL_ERR_FULL;
    }
    (void)sl_proto_encode_header(buf, size, SL_PROTO_ID_CONFIGURATION, (uint32_t)payload);
    uint8_t *d = buf + SL_PROTO_HEADER_BYTES;
    sl_put_be16(d + 0, c->azimuths);
    sl_put_be16(d + 2, c->bin_size_100um);
    sl_put_be16(d + 4, c->range_bins);
    sl_put_be16(d + 6, c->encoder_size);
    sl_put_be16(d + 8, c->rotation_mhz);
    sl_put_be16(d + 10, c->packet_rate);
    sl_put_be32(d + 12, c->range_gain_f32);
    sl_put_be32(d + 16, c->range_offset_f32);
    memcpy(d + SL_PROTO_CONFIG_FIXED_BYTES, pb, pbn);
    if (extra_protobuf.size != 0U) {
        memcpy(d + SL_PROTO_CONFIG_FIXED_BYTES + pbn, extra_protobuf.data, extra_protobuf.size);
    }
    return (sl_ssize_t)total;
}

static sl_ssize_t fft_head(uint8_t *buf, size_t size, const sl_proto_fft_t *f, uint8_t id)
{
    const uint8_t bpb = (id == SL_PROTO_ID_FFT_DATA_16) ? 2U : 1U;
    const uint64_t payload = (uint64_t)SL_PROTO_FFT_FIXED_BYTES + (uint64_t)f->bins * bpb;
    const uint64_t total = SL_PROTO_HEADER_BYTES + payload;
    if (total > (uint64_t)INT32_MAX) {
        return SL_ERR_RANGE;
    }
    if (total > size) {
        return SL_ERR_FULL;
    }
    (void)sl_proto_encode_header(buf, size, id, (uint32_t)payload);
    uint8_t *d = buf + SL_PROTO_HEADER_BYTES;
    sl_put_be16(d + 0, (uint16_t)SL_PROTO_FFT_FIXED_BYTES);
    sl_put_be16(d + 2, f->sweep_counter);
    sl_put_be16(d + 4, f->azimuth_ticks);
    sl_put_le32(d + 6, f->seconds);
    sl_put_le32(d + 10, f->split_ns);
    return (sl_ssize_t)total;
}

sl_ssize_t sl_proto_encode_fft_head(uint8_t *buf, size_t size, const sl_proto_fft_t *f)
{
    if (buf == NULL || f == NULL ||
        (f->id != SL_PROTO_ID_FFT_DATA && f->id != SL_PROTO_ID_FFT_DATA_16)) {
        return SL_ERR_ARG;
    }
    const sl_ssize_t r = fft_head(buf, size, f, f->id);
    return (r < 0) ? r : (sl_ssize_t)(SL_PROTO_HEADER_BYTES + SL_PROTO_FFT_FIXED_BYTES);
}

sl_ssize_t sl_proto_encode_fft8(uint8_t *buf, size_t size, const sl_proto_fft_t *f,
                                const uint8_t *bins8)
{
    if (buf == NULL || f == NULL || (bins8 == NULL && f->bins != 0U)) {
        return SL_ERR_ARG;
    }
    const sl_ssize_t r = fft_head(buf, size, f, SL_PROTO_ID_FFT_DATA);
    if (r > 0 && f->bins != 0U) {
        memcpy(buf + SL_PROTO_HEADER_BYTES + SL_PROTO_FFT_FIXED_BYTES, bins8, f->bins);
    }
    return r;
}

sl_ssize_t sl_proto_encode_fft16(uint8_t *buf, size_t size, const sl_proto_fft_t *f,
                                 const uint16_t *bins16)
{
    if (buf == NULL || f == NULL || (bins16 == NULL && f->bins != 0U)) {
        return SL_ERR_ARG;
    }
    const sl_ssize_t r = fft_head(buf, size, f, SL_PROTO_ID_FFT_DATA_16);
    if (r > 0) {
        uint8_t *d = buf + SL_PROTO_HEADER_BYTES + SL_PROTO_FFT_FIXED_BYTES;
        for (uint32_t i = 0; i < f->bins; i++) {
            d[2U * i] = (uint8_t)bins16[i];
            d[2U * i + 1U] = (uint8_t)(bins16[i] >> 8);
        }
    }
    return r;
}
