// SPDX-License-Identifier: MIT
/// @file sl_proto.h
/// @brief Navtech Colossus TCP protocol: incremental decoder, typed parsers, encoders.
///
/// Wire format (NAVTECH_PROTOCOL.md s.2): every message is a 22-byte header
/// (16-byte signature `00 01 03 03 07 07 0F 0F 1F 1F 3F 3F 7F 7F FE FE`, version = 1,
/// message id, uint32 big-endian payload length) followed by the payload.
///
/// ## Decoder model
/// `sl_proto_feed()` takes ANY chunking of the byte stream (1 byte at a time up to whole
/// capture files) and emits exactly the same sequence of message events for every chunking
/// (same id, payload bytes, stream offset). The only things that depend on the chunking are
/// `msg->zero_copy`, `msg->rx_us` and the `zero_copy` / `reassembled` counters.
///
/// - **Zero copy**: when a message's whole payload lies in the buffer passed to one
///   `sl_proto_feed()` call, the event's payload view points into that buffer; nothing is
///   copied. Only the 22 header bytes are examined (bytewise), never the payload.
/// - **Reassembly**: otherwise the payload is accumulated in a caller-owned buffer
///   (`cfg.reasm_buf`, `cfg.reasm_size`), mbedTLS `mps_reader` style. The buffer is borrowed
///   from `sl_proto_init()` until the decoder is re-initialised or abandoned.
/// - **Limits** (checked on the header, independent of chunking so that events do not depend
///   on it): version must be 1; payload length must be <= `max_payload_bytes` (the board's
///   `max_message_bytes`); payload length must be <= `reasm_size` (a message that could
///   not be reassembled is rejected even when it happens to arrive in one piece).
/// - **Truncation** (`cfg.truncate_long`, for consumers that read only the start of a
///   payload, e.g. a detection pipeline that needs the first few hundred range bins of a
///   3.8 KB FFT message): a payload longer than `reasm_size` (but within
///   `max_payload_bytes`) is accepted; only its first `reasm_size` bytes are kept and
///   delivered (`msg->truncated`, `msg->wire_bytes` = the length field), the rest is
///   consumed without being copied, and the message is delivered once its last byte has
///   been consumed (so events stay independent of the chunking). Counted in `stats.cut`;
///   the whole message counts as delivered in the accounting invariant. With truncate_long
///   (and reasm_size <= 1 KiB) the fast path also issues cache prefetch hints
///   (`__builtin_prefetch`, a no-op where unavailable) for the header and kept prefix of the
///   message three ahead, assuming the current length (the prefixes are ~3.8 KB apart;
///   ~1.4x on cache-resident captures in sl-bench). No effect on behaviour.
/// - **Resync**: on junk or a rejected header the decoder looks for the next signature
///   starting at the byte after the rejected signature's first byte (events identical to a
///   byte-at-a-time search: a signature split across chunks or preceded by a partial
///   signature inside junk is found). Within a chunk it does not re-test every offset: a
///   Horspool search over 16-byte windows keyed on the window's last byte (and byte 13 when
///   that is 0xFE) skips up to 16 bytes per step; only the last < 16 bytes of a chunk are
///   matched bytewise (a possible signature start). Nothing is ever asserted on stream bytes.
/// - **EOF**: `sl_proto_finish()` declares the end of a stream (peer closed, end of file,
///   reconnect). A partly received message is counted as `truncated` and dropped; the next
///   byte fed starts a new stream.
///
/// ## Accounting invariant (checked by the fuzz target, SECURITY.md)
/// At every point between calls:
/// `stats.bytes_in == stats.bytes_delivered + stats.bytes_skipped + sl_proto_buffered(p)`,
/// where `bytes_delivered` counts whole messages (22 + payload) handed to the callback.
///
/// ## Cost
/// - `sl_proto_feed()`: O(len) worst case; for well-formed data O(messages) when each
///   payload is whole in the chunk (header check + one callback per message), plus one
///   memcpy of each payload byte that must be reassembled.
/// - **Junk bound** (per call): at most one O(1) window step per junk byte plus at most one
///   14-byte compare per byte that starts a window ending in `7F FE`, plus <= 15 bytewise
///   steps at the chunk's end and 6 per rejected header: work <= c * len + 15 * c' per call,
///   whatever the bytes (measured per junk kind: docs/PERFORMANCE.md, "Core modules");
///   ctest `bench_junk_cost` fails above 4 instructions per byte for zero, random and
///   prefixes. The Linux port
///   (radar_client.c) feeds at most SL_RADAR_RX_CHUNK bytes per call and SL_RADAR_RX_BUDGET
///   bytes per poll wake-up, so the decoder's work per wake-up is bounded by those sizes.
/// - Stack: < 128 bytes plus the callback's. RAM: `sizeof(sl_proto_t)` (160 bytes on x86-64,
///   asserted <= 192) plus the caller's reassembly buffer. No allocation, no float, no OS.
/// - Per message O(1) when whole in the chunk, O(payload) when it straddles chunks and is
///   copied (measured per chunk size: docs/PERFORMANCE.md, "Core modules").
/// - Context: task context; one decoder per stream; not reentrant (the callback must not
///   call `sl_proto_feed()` / `sl_proto_finish()` / `sl_proto_init()` on the same decoder).
#ifndef SHADOWLEAN_SL_PROTO_H
#define SHADOWLEAN_SL_PROTO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Bytes in every Colossus header (signature 16 + version 1 + id 1 + length 4).
#define SL_PROTO_HEADER_BYTES 22U
/// Bytes in the header's signature.
#define SL_PROTO_SIGNATURE_BYTES 16U
/// The only protocol version accepted and produced.
#define SL_PROTO_VERSION 1U
/// Fixed part of an FFT data payload (offset, sweep, azimuth, seconds, split seconds).
#define SL_PROTO_FFT_FIXED_BYTES 14U
/// Fixed part of a Configuration payload (before the protobuf).
#define SL_PROTO_CONFIG_FIXED_BYTES 20U

/// The 16 signature bytes, in wire order.
extern const uint8_t sl_proto_signature[SL_PROTO_SIGNATURE_BYTES];

/// Message ids used by this project (NAVTECH_PROTOCOL.md s.3). The decoder delivers every
/// id 0..255; these are the ones with a parser, an encoder or a counter.
typedef enum sl_proto_id {
    SL_PROTO_ID_KEEP_ALIVE = 1,             ///< radar -> client, no payload
    SL_PROTO_ID_CONFIGURATION = 10,         ///< radar -> client, see sl_proto_config_t
    SL_PROTO_ID_CONFIG_REQUEST = 20,        ///< client -> radar, no payload
    SL_PROTO_ID_START_FFT = 21,             ///< client -> radar, no payload
    SL_PROTO_ID_STOP_FFT = 22,              ///< client -> radar, no payload
    SL_PROTO_ID_FFT_DATA = 30,              ///< radar -> client, 8-bit bins
    SL_PROTO_ID_FFT_DATA_16 = 31,           ///< radar -> client, 16-bit little-endian bins
    SL_PROTO_ID_HEALTH = 40,                ///< radar -> client, protobuf (not parsed)
    SL_PROTO_ID_START_NONCONTOUR_FFT = 140, ///< client -> radar, no payload
} sl_proto_id_t;

/// One decoded message, handed to the callback.
///
/// Lifetime: the struct and the bytes `payload` points to are valid only until the callback
/// returns. `payload.data` points either into the buffer of the `sl_proto_feed()` call that
/// completed the message (`zero_copy`) or into the reassembly buffer; copy what you keep.
/// `payload.data` is NULL when `payload.size == 0`.
typedef struct sl_proto_msg {
    uint8_t id;                ///< message id (sl_proto_id_t or any other 0..255)
    bool zero_copy;            ///< payload viewed in the caller's chunk (informational)
    sl_bytes_t payload;        ///< payload bytes, `payload.size` == header length field
    uint64_t stream_offset;    ///< offset of the signature's first byte in the fed bytes
                               ///< (counts every byte fed since sl_proto_init, all streams)
    uint64_t rx_us;            ///< `now_us` of the sl_proto_feed() call that completed it
    bool truncated;            ///< payload cut to reasm_size (cfg.truncate_long)
    uint32_t wire_bytes;       ///< payload length on the wire (== payload.size unless truncated)
} sl_proto_msg_t;

/// Message callback. `ctx` is `cfg.ctx`. Must not re-enter the decoder.
typedef void (*sl_proto_on_msg_fn)(void *ctx, const sl_proto_msg_t *msg);

/// Decoder configuration (copied by sl_proto_init; the buffer is borrowed).
typedef struct sl_proto_cfg {
    uint8_t *reasm_buf;         ///< caller-owned reassembly buffer (may be NULL if size 0)
    size_t reasm_size;          ///< its size in bytes: the largest payload that is accepted
    uint32_t max_payload_bytes; ///< board's max_message_bytes; 0 = use reasm_size
                                ///< (with truncate_long: 0 = no limit)
    bool truncate_long;         ///< deliver longer payloads cut to reasm_size (see above)
    sl_proto_on_msg_fn on_msg;  ///< required
    void *ctx;                  ///< passed to on_msg
} sl_proto_cfg_t;

/// Decoder counters. Monotonic since sl_proto_init (never reset by sl_proto_finish).
typedef struct sl_proto_stats {
    uint64_t bytes_in;        ///< every byte passed to sl_proto_feed
    uint64_t bytes_delivered; ///< header + payload bytes of delivered messages
    uint64_t bytes_skipped;   ///< junk, rejected headers, bytes dropped at EOF
    uint32_t resyncs;         ///< times the decoder lost sync (start of a run of skipped bytes)
    uint32_t bad_version;     ///< headers rejected: version != 1
    uint32_t oversize;        ///< headers rejected: payload > max_payload_bytes
    uint32_t too_big;         ///< headers rejected: payload > reasm_size (<= max_payload_bytes)
    uint32_t cut;             ///< messages delivered truncated to reasm_size (truncate_long)
    uint32_t truncated;       ///< sl_proto_finish() with a partial message (or signature) held
    uint32_t messages;        ///< messages delivered (all ids)
    uint32_t keep_alive;      ///< ... of which id 1
    uint32_t configuration;   ///< ... of which id 10
    uint32_t fft8;            ///< ... of which id 30
    uint32_t fft16;           ///< ... of which id 31
    uint32_t health;          ///< ... of which id 40
    uint32_t other;           ///< ... of which any other id
    uint32_t zero_copy;       ///< delivered as a view into the caller's chunk (depends on chunking)
    uint32_t reassembled;     ///< delivered from the reassembly buffer (depends on chunking)
} sl_proto_stats_t;

/// Decoder instance. Caller-allocated (static is fine); fields read-only to the application
/// except `stats`, which it may read at any time.
typedef struct sl_proto {
    sl_proto_cfg_t cfg;         ///< copy of the configuration
    uint32_t max_payload;       ///< effective limit: min(max_payload_bytes, reasm_size), or
                                ///< max_payload_bytes (0: none) with truncate_long
    uint32_t payload_bytes;     ///< length field of the message being received
    uint32_t payload_got;       ///< payload bytes already copied to the reassembly buffer
    uint64_t msg_offset;        ///< stream offset of the message being received
    uint8_t state;              ///< internal: 0 signature, 1 header tail, 2 payload
    uint8_t sig_got;            ///< signature bytes matched so far (0..16)
    uint8_t hdr_got;            ///< header tail bytes held (0..6)
    uint8_t hdr[6];             ///< version, id, length (big-endian)
    bool hunting;               ///< discarding bytes since the last valid header
    sl_proto_stats_t stats;     ///< counters
} sl_proto_t;

#if defined(__cplusplus)
static_assert(sizeof(sl_proto_t) <= 192, "sl_proto_t RAM budget");
#else
_Static_assert(sizeof(sl_proto_t) <= 192, "sl_proto_t RAM budget");
#endif

/// Initialise (or completely reset) a decoder: state cleared, counters zeroed.
/// @return SL_OK, or SL_ERR_ARG (NULL p/cfg/on_msg, NULL reasm_buf with reasm_size > 0).
/// Cost: O(1).
sl_err_t sl_proto_init(sl_proto_t *p, const sl_proto_cfg_t *cfg);

/// Feed `len` stream bytes (any chunk size, including 0). Calls `on_msg` for every message
/// completed by these bytes, in stream order. Malformed input is counted and skipped.
/// @param now_us caller's clock, copied into `msg->rx_us` (never interpreted).
/// @return SL_OK, or SL_ERR_ARG (NULL p, NULL data with len > 0; nothing consumed).
sl_err_t sl_proto_feed(sl_proto_t *p, const uint8_t *data, size_t len, uint64_t now_us);

/// End of stream (EOF, peer closed, before reconnecting). Bytes still held (a partial
/// message or partial signature) are dropped: `truncated` += 1 and `bytes_skipped` += held.
/// The decoder then expects a fresh stream; counters are kept. Cost: O(1).
/// @return SL_OK or SL_ERR_ARG.
sl_err_t sl_proto_finish(sl_proto_t *p);

/// Bytes currently held in the decoder (partial signature, header or payload). O(1).
uint64_t sl_proto_buffered(const sl_proto_t *p);

// ------------------------------------------------------------------------------------------
// Typed parsers. Input: a delivered message (or one built by hand). Output views point into
// `msg->payload`, so they share its lifetime. Cost: O(1) except the protobuf walk, O(size).

/// Configuration (id 10). Big-endian fixed part; the two float32 fields are kept as raw
/// IEEE-754 bit patterns (no float in the core); fields 9 and 10 are read from the protobuf.
typedef struct sl_proto_config {
    uint16_t azimuths;          ///< azimuth samples per rotation (CTS350-X: 400)
    uint16_t bin_size_100um;    ///< bin size in 0.1 mm units (438 -> 0.0438 m)
    uint16_t range_bins;        ///< bins per azimuth without contour (3768)
    uint16_t encoder_size;      ///< encoder ticks per rotation (5600)
    uint16_t rotation_mhz;      ///< rotation speed, milli-hertz (4000 = 4 Hz)
    uint16_t packet_rate;       ///< FFT packets (azimuths) per second (1600)
    uint32_t range_gain_f32;    ///< float32 bit pattern (decoded from big-endian)
    uint32_t range_offset_f32;  ///< float32 bit pattern, metres
    bool has_data_width;        ///< protobuf field 9 present
    bool has_range_res;         ///< protobuf field 10 present
    bool protobuf_malformed;    ///< protobuf walk stopped at malformed data (fields found
                                ///< before that point are kept; the config is still valid)
    int32_t data_width;         ///< field 9: 1 = 8-bit, 2 = 16-bit (0 when absent)
    uint32_t range_res_m_f32;   ///< field 10 rangeresolutionmetres, float32 bit pattern
    sl_bytes_t protobuf;        ///< the raw protobuf part (may be empty)
} sl_proto_config_t;

/// Parse a Configuration payload. Empty or malformed protobuf is tolerated
/// (`protobuf_malformed`).
/// @return SL_OK; SL_ERR_ARG (NULL, or id != 10); SL_ERR_MALFORMED (payload < 20 bytes).
sl_err_t sl_proto_parse_config(const sl_proto_msg_t *msg, sl_proto_config_t *out);

/// Range bin size in micrometres from a parsed config: `rangeresolutionmetres` when present,
/// finite and in (0, 4294 m], else `bin_size_100um * 100`. Integer float decoding, rounded
/// to nearest. Cost: O(1), no float.
uint32_t sl_proto_config_bin_size_um(const sl_proto_config_t *c);

/// FFT data (ids 30 and 31), NAVTECH_PROTOCOL.md s.4.
typedef struct sl_proto_fft {
    uint8_t id;                 ///< 30 (8-bit) or 31 (16-bit)
    uint8_t bytes_per_bin;      ///< 1 or 2
    uint16_t data_offset;       ///< payload offset of the bins (14 in this protocol version)
    uint16_t sweep_counter;     ///< +1 per FFT packet, wraps
    uint16_t azimuth_ticks;     ///< encoder ticks 0 .. encoder_size-1 (not validated here)
    uint32_t seconds;           ///< little-endian on the wire; UNIX seconds
    uint32_t split_ns;          ///< little-endian on the wire; nanoseconds in the second
    uint32_t bins;              ///< bin count = (payload - data_offset) / bytes_per_bin
    const uint8_t *bin_data;    ///< view of the bins in wire format (16-bit: little-endian)
} sl_proto_fft_t;

/// Parse an FFT payload. Bins start at `data_offset` (read from the payload, not assumed).
/// @return SL_OK; SL_ERR_ARG (NULL, or id not 30/31); SL_ERR_MALFORMED (payload < 14,
/// data_offset < 14 or > payload size, 16-bit data with an odd byte count AS SENT: checked on
/// `wire_bytes` for a truncated message, so the result never depends on the reassembly size;
/// a truncated prefix with an odd byte count gives its whole bins only).
sl_err_t sl_proto_parse_fft(const sl_proto_msg_t *msg, sl_proto_fft_t *out);

/// Bin `i` of a 16-bit FFT message (little-endian on the wire). No bounds check. O(1).
static inline uint16_t sl_proto_fft_bin16(const sl_proto_fft_t *f, uint32_t i)
{
    return (uint16_t)((uint16_t)f->bin_data[2U * i] | (uint16_t)(f->bin_data[2U * i + 1U] << 8));
}

/// 32 x 32 -> 64-bit product. ARMv6-M has no widening multiply and the compiler calls the
/// 64 x 64 library helper (__aeabi_lmul, ~45 instructions); there it is formed from four
/// 16 x 16 products (exact: each < 2^32, the middle sum < 2^18 + 2 x 2^16 before its shift).
static inline uint64_t sl_mul_u32_wide(uint32_t a, uint32_t b)
{
#if defined(__ARM_ARCH_6M__)
    const uint32_t al = a & 0xFFFFU, ah = a >> 16, bl = b & 0xFFFFU, bh = b >> 16;
    const uint32_t ll = al * bl, lh = al * bh, hl = ah * bl, hh = ah * bh;
    const uint32_t mid = (ll >> 16) + (lh & 0xFFFFU) + (hl & 0xFFFFU);
    const uint32_t hi = hh + (lh >> 16) + (hl >> 16) + (mid >> 16);
    const uint32_t lo = (mid << 16) | (ll & 0xFFFFU);
    return ((uint64_t)hi << 32) | lo;
#else
    return (uint64_t)a * b;
#endif
}

/// FFT timestamp as UNIX microseconds: seconds * 1e6 + split_ns / 1000 (truncated). O(1).
static inline uint64_t sl_proto_fft_time_us(const sl_proto_fft_t *f)
{
    // split_ns / 1000 as a multiply (once per azimuth; no division helper on ARMv6-M):
    // m = ceil(2^38 / 1000) = 274877907, m x 1000 - 2^38 = 56 and 56 x 2^32 < 2^38, so
    // (x m) >> 38 == x / 1000 for every 32-bit x.
    return sl_mul_u32_wide(f->seconds, 1000000U) +
           (sl_mul_u32_wide(f->split_ns, 274877907U) >> 38);
}

// ------------------------------------------------------------------------------------------
// Encoders. Each writes a complete message into `buf` and returns its length in bytes
// (> 0), or SL_ERR_ARG (NULL, bad id), SL_ERR_FULL (buf too small; nothing useful written),
// SL_ERR_RANGE (message longer than INT32_MAX). Cost: O(message length).

/// A 22-byte header for `id` announcing `payload_bytes`. Returns 22.
sl_ssize_t sl_proto_encode_header(uint8_t *buf, size_t size, uint8_t id, uint32_t payload_bytes);

/// A header-only client command: SL_PROTO_ID_CONFIG_REQUEST, _START_FFT, _STOP_FFT,
/// _START_NONCONTOUR_FFT (any id is accepted: commands are bare headers). Returns 22.
sl_ssize_t sl_proto_encode_command(uint8_t *buf, size_t size, uint8_t id);

/// Keep-alive (id 1, radar -> client). Returns 22.
sl_ssize_t sl_proto_encode_keep_alive(uint8_t *buf, size_t size);

/// Configuration (id 10): the 20-byte fixed part from `c`, then a protobuf with field 9
/// (varint) when `c->has_data_width` and field 10 (fixed32) when `c->has_range_res`, then
/// `extra_protobuf` verbatim (may be {NULL, 0}). `c->protobuf` and `protobuf_malformed` are
/// ignored.
sl_ssize_t sl_proto_encode_config(uint8_t *buf, size_t size, const sl_proto_config_t *c,
                                  sl_bytes_t extra_protobuf);

/// Header + 14-byte FFT fixed part for `f->bins` bins of `f->id` (30 or 31; data_offset is
/// written as 14 whatever `f->data_offset` says). The caller writes the bins after the
/// returned 36 bytes (lets a simulator generate bins in place). Returns 36.
sl_ssize_t sl_proto_encode_fft_head(uint8_t *buf, size_t size, const sl_proto_fft_t *f);

/// Whole 8-bit FFT message (id 30, whatever f->id says) with `f->bins` bins from `bins8`.
sl_ssize_t sl_proto_encode_fft8(uint8_t *buf, size_t size, const sl_proto_fft_t *f,
                                const uint8_t *bins8);

/// Whole 16-bit FFT message (id 31, whatever f->id says), bins written little-endian.
sl_ssize_t sl_proto_encode_fft16(uint8_t *buf, size_t size, const sl_proto_fft_t *f,
                                 const uint16_t *bins16);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_PROTO_H
