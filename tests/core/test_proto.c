// SPDX-License-Identifier: MIT
// Unit tests for sl_proto.h: incremental decoder (chunking invariance, resync, limits,
// EOF, accounting), typed parsers (wire layout checked against hand-written bytes) and
// encoders. Streams are built in the test with the encoders (tests/support/golden/sl_golden.c).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_proto.h"
#include "sl_golden.h"

// ------------------------------------------------------------------------------ recorder

typedef struct ev {
    uint8_t id;
    uint32_t size;
    uint64_t offset;
    uint64_t hash;
} ev_t;

typedef struct rec {
    ev_t *ev;
    size_t n, cap;
    const uint8_t *chunk_lo, *chunk_hi; // the feed buffer (for zero-copy checks)
    const uint8_t *reasm_lo, *reasm_hi;
    unsigned zc_inside, reasm_inside, bad_view;
} rec_t;

static void rec_on_msg(void *ctx, const sl_proto_msg_t *m)
{
    rec_t *r = ctx;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 64;
        r->ev = realloc(r->ev, r->cap * sizeof *r->ev);
        assert_non_null(r->ev);
    }
    ev_t *e = &r->ev[r->n++];
    e->id = m->id;
    e->size = (uint32_t)m->payload.size;
    e->offset = m->stream_offset;
    e->hash = sl_golden_fnv1a(m->payload.data, m->payload.size, SL_GOLDEN_FNV_INIT);
    if (m->payload.size == 0) {
        if (m->payload.data != NULL) {
            r->bad_view++;
        }
        return;
    }
    const uint8_t *lo = m->payload.data, *hi = lo + m->payload.size;
    if (m->zero_copy) {
        if (r->chunk_lo && lo >= r->chunk_lo && hi <= r->chunk_hi) {
            r->zc_inside++;
        } else {
            r->bad_view++;
        }
    } else {
        if (lo >= r->reasm_lo && hi <= r->reasm_hi) {
            r->reasm_inside++;
        } else {
            r->bad_view++;
        }
    }
}

static void rec_free(rec_t *r)
{
    free(r->ev);
    memset(r, 0, sizeof *r);
}

// A decoder with its own reassembly buffer, recording into rec.
typedef struct dec {
    sl_proto_t p;
    uint8_t *buf;
    size_t size;
    rec_t rec;
} dec_t;

static void dec_init(dec_t *d, size_t reasm, uint32_t max_payload)
{
    memset(d, 0, sizeof *d);
    d->buf = malloc(reasm ? reasm : 1);
    d->size = reasm;
    d->rec.reasm_lo = d->buf;
    d->rec.reasm_hi = d->buf + reasm;
    sl_proto_cfg_t c = {.reasm_buf = d->buf, .reasm_size = reasm, .max_payload_bytes = max_payload,
                        .on_msg = rec_on_msg, .ctx = &d->rec};
    assert_int_equal(sl_proto_init(&d->p, &c), SL_OK);
}

static void dec_free(dec_t *d)
{
    free(d->buf);
    rec_free(&d->rec);
}

static void assert_accounted(const sl_proto_t *p)
{
    assert_int_equal(p->stats.bytes_in,
                     p->stats.bytes_delivered + p->stats.bytes_skipped + sl_proto_buffered(p));
}

static void feed(dec_t *d, const uint8_t *data, size_t n)
{
    d->rec.chunk_lo = data;
    d->rec.chunk_hi = data + n;
    assert_int_equal(sl_proto_feed(&d->p, data, n, 1234), SL_OK);
    d->rec.chunk_lo = d->rec.chunk_hi = NULL;
    assert_accounted(&d->p);
}

// Feed in chunks chosen by a PRNG. Mix of tiny, recv-sized and huge chunks. Each chunk is
// copied to a fresh heap block so zero-copy views are checked against the exact chunk.
static uint64_t rng_next(uint64_t *s)
{
    uint64_t x = *s;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *s = x;
}

static void feed_random_chunks(dec_t *d, const uint8_t *data, size_t n, uint64_t seed)
{
    uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 1;
    size_t i = 0;
    while (i < n) {
        const uint64_t r = rng_next(&s);
        size_t c;
        switch (r % 4) {
        case 0: c = 1 + (r >> 8) % 8; break;        // tiny
        case 1: c = 1 + (r >> 8) % 64; break;       // small
        case 2: c = 1 + (r >> 8) % 4096; break;     // recv-sized
        default: c = 1 + (r >> 8) % 20000; break;   // several messages
        }
        if (c > n - i) {
            c = n - i;
        }
        uint8_t *copy = malloc(c);
        memcpy(copy, data + i, c);
        feed(d, copy, c);
        free(copy);
        i += c;
    }
}

static void assert_same_events(const rec_t *a, const rec_t *b)
{
    assert_int_equal(a->n, b->n);
    for (size_t i = 0; i < a->n; i++) {
        assert_int_equal(a->ev[i].id, b->ev[i].id);
        assert_int_equal(a->ev[i].size, b->ev[i].size);
        assert_int_equal(a->ev[i].offset, b->ev[i].offset);
        assert_true(a->ev[i].hash == b->ev[i].hash);
    }
}

static void assert_same_stats(const sl_proto_stats_t *a, const sl_proto_stats_t *b)
{
    assert_int_equal(a->bytes_in, b->bytes_in);
    assert_int_equal(a->bytes_delivered, b->bytes_delivered);
    assert_int_equal(a->bytes_skipped, b->bytes_skipped);
    assert_int_equal(a->resyncs, b->resyncs);
    assert_int_equal(a->bad_version, b->bad_version);
    assert_int_equal(a->oversize, b->oversize);
    assert_int_equal(a->too_big, b->too_big);
    assert_int_equal(a->truncated, b->truncated);
    assert_int_equal(a->messages, b->messages);
    assert_int_equal(a->keep_alive, b->keep_alive);
    assert_int_equal(a->configuration, b->configuration);
    assert_int_equal(a->fft8, b->fft8);
    assert_int_equal(a->fft16, b->fft16);
    assert_int_equal(a->health, b->health);
    assert_int_equal(a->other, b->other);
    assert_int_equal(a->zero_copy + a->reassembled, a->messages);
    assert_int_equal(b->zero_copy + b->reassembled, b->messages);
}

// A small golden stream: config, 2 rotations of 16 azimuths x 300 bins, keep-alives every
// 5th FFT, Health every 7th, contoured odd azimuths. ~21 KB.
static sl_golden_params_t small_params(void)
{
    sl_golden_params_t g = sl_golden_defaults();
    g.azimuths = 16;
    g.encoder_size = 5600;
    g.range_bins = 300;
    g.rotations = 2;
    g.keep_alive_every = 5;
    g.health_every = 7;
    g.contour_bins = 120;
    return g;
}

static uint8_t *build(const sl_golden_params_t *g, size_t *n)
{
    *n = sl_golden_size(g);
    uint8_t *s = malloc(*n);
    assert_int_equal(sl_golden_build(s, *n, g), *n);
    return s;
}

// Reference events from the golden parameters alone (independent of the decoder).
static size_t expected_events(const sl_golden_params_t *g, const uint8_t *s, ev_t *out)
{
    size_t n = 0, o = 0;
    // Walk the stream by its own headers (built by our encoders, so well-formed).
    size_t total = sl_golden_size(g);
    while (o < total) {
        const uint32_t len = ((uint32_t)s[o + 18] << 24) | ((uint32_t)s[o + 19] << 16) |
                             ((uint32_t)s[o + 20] << 8) | s[o + 21];
        out[n].id = s[o + 17];
        out[n].size = len;
        out[n].offset = o;
        out[n].hash = sl_golden_fnv1a(s + o + 22, len, SL_GOLDEN_FNV_INIT);
        n++;
        o += 22 + len;
    }
    assert_int_equal(o, total);
    return n;
}

// ---------------------------------------------------------------------------------- tests

static void test_proto_encodes_commands_as_bare_22_byte_headers(void **state)
{
    (void)state;
    uint8_t b[32];
    static const uint8_t want[22] = {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                                     0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE,
                                     0x01, 21,   0,    0,    0,    0};
    assert_int_equal(sl_proto_encode_command(b, sizeof b, SL_PROTO_ID_START_FFT), 22);
    assert_memory_equal(b, want, 22);
    assert_int_equal(sl_proto_encode_command(b, sizeof b, SL_PROTO_ID_START_NONCONTOUR_FFT), 22);
    assert_int_equal(b[17], 140);
    assert_int_equal(sl_proto_encode_command(b, sizeof b, SL_PROTO_ID_STOP_FFT), 22);
    assert_int_equal(b[17], 22);
    assert_int_equal(sl_proto_encode_command(b, sizeof b, SL_PROTO_ID_CONFIG_REQUEST), 22);
    assert_int_equal(b[17], 20);
    assert_int_equal(sl_proto_encode_keep_alive(b, sizeof b), 22);
    assert_int_equal(b[17], 1);
    assert_int_equal(sl_proto_encode_header(b, sizeof b, 99, 0x01020304), 22);
    assert_int_equal(b[18], 1);
    assert_int_equal(b[19], 2);
    assert_int_equal(b[20], 3);
    assert_int_equal(b[21], 4);
}

static void test_proto_encoders_refuse_small_buffers(void **state)
{
    (void)state;
    uint8_t b[64];
    assert_int_equal(sl_proto_encode_command(b, 21, 21), SL_ERR_FULL);
    assert_int_equal(sl_proto_encode_command(NULL, 64, 21), SL_ERR_ARG);
    sl_proto_fft_t f = {.id = 30, .bins = 29};
    uint8_t bins[29] = {0};
    assert_int_equal(sl_proto_encode_fft8(b, 64, &f, bins), SL_ERR_FULL);
    f.bins = 28;
    assert_int_equal(sl_proto_encode_fft8(b, 64, &f, bins), 64);
    f.id = 7;
    assert_int_equal(sl_proto_encode_fft_head(b, 64, &f), SL_ERR_ARG);
    sl_proto_config_t c = {0};
    assert_int_equal(sl_proto_encode_config(b, 41, &c, (sl_bytes_t){NULL, 0}), SL_ERR_FULL);
    assert_int_equal(sl_proto_encode_config(b, 42, &c, (sl_bytes_t){NULL, 0}), 42);
}

static void test_proto_init_rejects_bad_arguments(void **state)
{
    (void)state;
    sl_proto_t p;
    uint8_t buf[8];
    rec_t r = {0};
    sl_proto_cfg_t c = {.reasm_buf = buf, .reasm_size = 8, .on_msg = rec_on_msg, .ctx = &r};
    assert_int_equal(sl_proto_init(NULL, &c), SL_ERR_ARG);
    assert_int_equal(sl_proto_init(&p, NULL), SL_ERR_ARG);
    c.on_msg = NULL;
    assert_int_equal(sl_proto_init(&p, &c), SL_ERR_ARG);
    c.on_msg = rec_on_msg;
    c.reasm_buf = NULL;
    assert_int_equal(sl_proto_init(&p, &c), SL_ERR_ARG);
    c.reasm_size = 0;
    assert_int_equal(sl_proto_init(&p, &c), SL_OK); // header-only messages are still fine
    assert_int_equal(sl_proto_feed(&p, NULL, 3, 0), SL_ERR_ARG);
    assert_int_equal(sl_proto_feed(&p, NULL, 0, 0), SL_OK);
    assert_int_equal(sl_proto_finish(NULL), SL_ERR_ARG);
}

static void test_proto_decodes_a_golden_stream_fed_whole_without_copying(void **state)
{
    (void)state;
    const sl_golden_params_t g = small_params();
    size_t n;
    uint8_t *s = build(&g, &n);
    ev_t *want = calloc(4096, sizeof *want);
    const size_t nw = expected_events(&g, s, want);
    dec_t d;
    dec_init(&d, 4096, 4096);
    feed(&d, s, n);
    assert_int_equal(d.rec.n, nw);
    for (size_t i = 0; i < nw; i++) {
        assert_int_equal(d.rec.ev[i].id, want[i].id);
        assert_int_equal(d.rec.ev[i].size, want[i].size);
        assert_int_equal(d.rec.ev[i].offset, want[i].offset);
        assert_true(d.rec.ev[i].hash == want[i].hash);
    }
    assert_int_equal(d.p.stats.configuration, 1);
    assert_int_equal(d.p.stats.fft8, 32);
    assert_int_equal(d.p.stats.keep_alive, 6);
    assert_int_equal(d.p.stats.health, 4);
    assert_int_equal(d.p.stats.bytes_skipped, 0);
    assert_int_equal(d.p.stats.resyncs, 0);
    assert_int_equal(d.p.stats.bytes_delivered, n);
    // Whole in the caller's buffer: every payload is a view into it, none copied.
    assert_int_equal(d.p.stats.reassembled, 0);
    assert_int_equal(d.rec.zc_inside, d.p.stats.messages - d.p.stats.keep_alive);
    assert_int_equal(d.rec.bad_view, 0);
    free(want);
    free(s);
    dec_free(&d);
}

static void test_proto_gives_identical_events_when_fed_one_byte_at_a_time(void **state)
{
    (void)state;
    const sl_golden_params_t g = small_params();
    size_t n;
    uint8_t *s = build(&g, &n);
    dec_t whole, bytes;
    dec_init(&whole, 4096, 0);
    dec_init(&bytes, 4096, 0);
    feed(&whole, s, n);
    for (size_t i = 0; i < n; i++) {
        feed(&bytes, s + i, 1);
    }
    assert_same_events(&whole.rec, &bytes.rec);
    assert_same_stats(&whole.p.stats, &bytes.p.stats);
    // One byte at a time: every non-empty payload went through the reassembly buffer.
    assert_int_equal(bytes.rec.reasm_inside, bytes.p.stats.messages - bytes.p.stats.keep_alive);
    assert_int_equal(bytes.rec.bad_view, 0);
    free(s);
    dec_free(&whole);
    dec_free(&bytes);
}

static void test_proto_gives_identical_events_for_random_chunkings(void **state)
{
    (void)state;
    sl_golden_params_t g = small_params();
    g.bytes_per_bin = 2; // 16-bit too
    size_t n;
    uint8_t *s = build(&g, &n);
    dec_t whole;
    dec_init(&whole, 4096, 0);
    feed(&whole, s, n);
    assert_int_equal(whole.p.stats.fft16, 32);
    for (uint64_t seed = 1; seed <= 150; seed++) {
        dec_t d;
        dec_init(&d, 4096, 0);
        feed_random_chunks(&d, s, n, seed);
        assert_same_events(&whole.rec, &d.rec);
        assert_same_stats(&whole.p.stats, &d.p.stats);
        assert_int_equal(d.rec.bad_view, 0);
        dec_free(&d);
    }
    free(s);
    dec_free(&whole);
}

static void test_proto_gives_identical_events_for_every_two_chunk_split(void **state)
{
    (void)state;
    sl_golden_params_t g = small_params();
    g.rotations = 1;
    g.azimuths = 4;
    size_t n;
    uint8_t *s = build(&g, &n);
    dec_t whole;
    dec_init(&whole, 4096, 0);
    feed(&whole, s, n);
    for (size_t cut = 0; cut <= n; cut++) {
        dec_t d;
        dec_init(&d, 4096, 0);
        feed(&d, s, cut);
        feed(&d, s + cut, n - cut);
        assert_same_events(&whole.rec, &d.rec);
        assert_same_stats(&whole.p.stats, &d.p.stats);
        dec_free(&d);
    }
    free(s);
    dec_free(&whole);
}

// Junk that contains the hardest cases: partial signatures, 0x00 runs, full signatures with
// bad versions / lengths, and random bytes. Same events for every chunking is the property.
static size_t make_nasty_junk(uint8_t *out, size_t cap, uint64_t seed)
{
    uint64_t s = seed * 0x2545F4914F6CDD1DULL + 7;
    size_t o = 0;
    const size_t want = 20 + rng_next(&s) % 200;
    while (o < want && o + 64 < cap) {
        const uint64_t r = rng_next(&s);
        switch (r % 6) {
        case 0: { // partial signature of length 1..15
            const size_t k = 1 + (r >> 8) % 15;
            memcpy(out + o, sl_proto_signature, k);
            o += k;
            break;
        }
        case 1: // zeros
            for (size_t k = 0; k < 1 + (r >> 8) % 4; k++) {
                out[o++] = 0;
            }
            break;
        case 2: { // signature + bad version
            memcpy(out + o, sl_proto_signature, 16);
            out[o + 16] = (uint8_t)(2 + (r >> 8) % 250);
            out[o + 17] = 30;
            memset(out + o + 18, 0, 4);
            o += 22;
            break;
        }
        case 3: { // signature + version 1 + absurd length
            memcpy(out + o, sl_proto_signature, 16);
            out[o + 16] = 1;
            out[o + 17] = 30;
            out[o + 18] = 0x7F;
            out[o + 19] = (uint8_t)(r >> 16);
            out[o + 20] = 0;
            out[o + 21] = 0;
            o += 22;
            break;
        }
        case 4: { // signature + version 0 + tail that begins another signature
            memcpy(out + o, sl_proto_signature, 16);
            memcpy(out + o + 16, sl_proto_signature, 6);
            o += 22;
            break;
        }
        default: // random bytes
            for (size_t k = 0; k < 1 + (r >> 8) % 8; k++) {
                out[o++] = (uint8_t)rng_next(&s);
            }
            break;
        }
    }
    return o;
}

static void test_proto_resyncs_after_nasty_junk_for_every_chunking(void **state)
{
    (void)state;
    sl_golden_params_t g = small_params();
    g.rotations = 1;
    size_t n;
    uint8_t *s = build(&g, &n);
    ev_t *want = calloc(4096, sizeof *want);
    const size_t nw = expected_events(&g, s, want);
    // Interleave: junk, message, junk, message, ... (junk before every message).
    uint8_t *mix = malloc(n + nw * 512 + 512);
    size_t *junk_before = calloc(nw + 1, sizeof *junk_before);
    size_t o = 0, total_junk = 0;
    for (size_t i = 0; i < nw; i++) {
        const size_t j = make_nasty_junk(mix + o, 512, 1000 + i);
        o += j;
        total_junk += j;
        junk_before[i] = total_junk;
        memcpy(mix + o, s + want[i].offset, 22 + want[i].size);
        o += 22 + want[i].size;
    }
    dec_t whole;
    dec_init(&whole, 4096, 4096);
    feed(&whole, mix, o);
    // Every message is found, at its shifted offset, with its content.
    assert_int_equal(whole.rec.n, nw);
    for (size_t i = 0; i < nw; i++) {
        assert_int_equal(whole.rec.ev[i].offset, want[i].offset + junk_before[i]);
        assert_true(whole.rec.ev[i].hash == want[i].hash);
    }
    assert_int_equal(whole.p.stats.bytes_skipped, total_junk);
    assert_int_equal(whole.p.stats.resyncs, nw); // one run of junk before each message
    assert_true(whole.p.stats.bad_version > 0);
    assert_true(whole.p.stats.oversize > 0);
    dec_t bytes;
    dec_init(&bytes, 4096, 4096);
    for (size_t i = 0; i < o; i++) {
        feed(&bytes, mix + i, 1);
    }
    assert_same_events(&whole.rec, &bytes.rec);
    assert_same_stats(&whole.p.stats, &bytes.p.stats);
    for (uint64_t seed = 1; seed <= 60; seed++) {
        dec_t d;
        dec_init(&d, 4096, 4096);
        feed_random_chunks(&d, mix, o, seed);
        assert_same_events(&whole.rec, &d.rec);
        assert_same_stats(&whole.p.stats, &d.p.stats);
        dec_free(&d);
    }
    dec_free(&bytes);
    dec_free(&whole);
    free(junk_before);
    free(mix);
    free(want);
    free(s);
}

// Long runs of the junk the fast resync skips by windows (zero fill, 0xFE runs, repeated
// signature prefixes of every length 1..15, random bytes, signatures with bad headers) before
// every message: the events and counters are those of the byte-at-a-time decoder for every
// chunk size 1..70 and random chunkings, and every message is found at its offset.
static size_t make_long_junk(uint8_t *out, unsigned kind, uint64_t seed)
{
    uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 3;
    size_t o = 0;
    const size_t want = 300 + rng_next(&s) % 700;
    while (o < want) {
        switch (kind % 5) {
        case 0: out[o++] = 0x00; break;
        case 1: out[o++] = 0xFE; break;
        case 2: { // prefix of length 1..15, repeated
            const size_t k = 1 + (kind / 5) % 15;
            memcpy(out + o, sl_proto_signature, k);
            o += k;
            break;
        }
        case 3: out[o++] = (uint8_t)rng_next(&s); break;
        default: // whole signature, version 0, then the same again
            memcpy(out + o, sl_proto_signature, 16);
            memset(out + o + 16, 0, 6);
            o += 22;
            break;
        }
    }
    return o;
}

static void test_proto_long_junk_runs_same_events_for_every_chunking(void **state)
{
    (void)state;
    sl_golden_params_t g = small_params();
    g.rotations = 1;
    g.azimuths = 8;
    size_t n;
    uint8_t *s = build(&g, &n);
    ev_t *want = calloc(4096, sizeof *want);
    const size_t nw = expected_events(&g, s, want);
    uint8_t *mix = malloc(n + nw * 1100 + 1100);
    size_t *junk_before = calloc(nw + 1, sizeof *junk_before);
    size_t o = 0, total_junk = 0;
    for (size_t i = 0; i < nw; i++) {
        const size_t j = make_long_junk(mix + o, (unsigned)i, 77 + i);
        o += j;
        total_junk += j;
        junk_before[i] = total_junk;
        memcpy(mix + o, s + want[i].offset, 22 + want[i].size);
        o += 22 + want[i].size;
    }
    const size_t tail = make_long_junk(mix + o, 2, 5); // trailing partial signatures
    o += tail;
    dec_t bytes;
    dec_init(&bytes, 4096, 4096);
    for (size_t i = 0; i < o; i++) {
        feed(&bytes, mix + i, 1);
    }
    assert_int_equal(bytes.rec.n, nw);
    for (size_t i = 0; i < nw; i++) {
        assert_int_equal(bytes.rec.ev[i].offset, want[i].offset + junk_before[i]);
        assert_true(bytes.rec.ev[i].hash == want[i].hash);
    }
    for (size_t chunk = 2; chunk <= 70; chunk++) {
        dec_t d;
        dec_init(&d, 4096, 4096);
        for (size_t i = 0; i < o; i += chunk) {
            feed(&d, mix + i, (o - i < chunk) ? o - i : chunk);
        }
        assert_same_events(&bytes.rec, &d.rec);
        assert_same_stats(&bytes.p.stats, &d.p.stats);
        assert_int_equal(sl_proto_buffered(&d.p), sl_proto_buffered(&bytes.p));
        dec_free(&d);
    }
    for (uint64_t seed = 1; seed <= 30; seed++) {
        dec_t d;
        dec_init(&d, 4096, 4096);
        feed_random_chunks(&d, mix, o, seed);
        assert_same_events(&bytes.rec, &d.rec);
        assert_same_stats(&bytes.p.stats, &d.p.stats);
        dec_free(&d);
    }
    dec_t whole;
    dec_init(&whole, 4096, 4096);
    feed(&whole, mix, o);
    assert_same_events(&bytes.rec, &whole.rec);
    assert_same_stats(&bytes.p.stats, &whole.p.stats);
    assert_int_equal(whole.p.stats.bytes_skipped + sl_proto_buffered(&whole.p), total_junk + tail);
    dec_free(&whole);
    dec_free(&bytes);
    free(junk_before);
    free(mix);
    free(want);
    free(s);
}

// An odd-length 16-bit FFT message is malformed whatever the reassembly size it is
// truncated to (odd or even, longer or shorter than the message), and an even one is
// accepted in every case: the verdict depends on the message as sent only.
// What the decoder delivers for a reassembly size `reasm` (payload cut to reasm bytes when
// longer), built by hand, then parsed.
static sl_err_t parse16_with(const uint8_t *m, size_t n, size_t reasm, sl_proto_fft_t *out)
{
    sl_proto_msg_t got;
    memset(&got, 0, sizeof got);
    const uint32_t wire = (uint32_t)(n - SL_PROTO_HEADER_BYTES);
    got.id = m[17];
    got.truncated = wire > reasm;
    got.wire_bytes = wire;
    got.payload.data = m + SL_PROTO_HEADER_BYTES;
    got.payload.size = got.truncated ? reasm : wire;
    return sl_proto_parse_fft(&got, out);
}

static uint32_t g_odd_seen;
static sl_err_t g_odd_err[2];
static void odd_on_msg(void *ctx, const sl_proto_msg_t *m)
{
    (void)ctx;
    sl_proto_fft_t f;
    if (g_odd_seen < 2) {
        g_odd_err[g_odd_seen] = sl_proto_parse_fft(m, &f);
    }
    g_odd_seen++;
}

static void test_proto_odd_16_bit_fft_is_malformed_for_every_reassembly_size(void **state)
{
    (void)state;
    static uint16_t bins[300];
    for (int odd = 0; odd < 2; odd++) {
        uint8_t m[22 + 14 + 600 + 1];
        const sl_proto_fft_t f = {.sweep_counter = 1, .azimuth_ticks = 14, .bins = 300};
        sl_ssize_t k = sl_proto_encode_fft16(m, sizeof m, &f, bins);
        assert_true(k > 0);
        size_t n = (size_t)k;
        if (odd) {
            m[n++] = 0xAB; // one stray byte: 601 bin bytes
            const uint32_t len = (uint32_t)(n - 22);
            m[18] = (uint8_t)(len >> 24);
            m[19] = (uint8_t)(len >> 16);
            m[20] = (uint8_t)(len >> 8);
            m[21] = (uint8_t)len;
        }
        for (size_t reasm = 15; reasm <= 700; reasm += 1) {
            sl_proto_fft_t out;
            const sl_err_t e = parse16_with(m, n, reasm, &out);
            assert_int_equal(e, odd ? SL_ERR_MALFORMED : SL_OK);
            if (!odd) {
                assert_true(out.bins <= 300);
            }
        }
        // Through the decoder itself, whole and truncated.
        for (size_t reasm = 64; reasm <= 1024; reasm += 61) {
            uint8_t *buf = malloc(reasm);
            sl_proto_t p;
            const sl_proto_cfg_t c = {.reasm_buf = buf, .reasm_size = reasm,
                                      .truncate_long = true, .on_msg = odd_on_msg};
            assert_int_equal(sl_proto_init(&p, &c), SL_OK);
            g_odd_seen = 0;
            assert_int_equal(sl_proto_feed(&p, m, n, 0), SL_OK);
            assert_int_equal(g_odd_seen, 1);
            assert_int_equal(g_odd_err[0], odd ? SL_ERR_MALFORMED : SL_OK);
            free(buf);
        }
    }
}

static size_t keep_alive_at(uint8_t *b)
{
    return (size_t)sl_proto_encode_keep_alive(b, 22);
}

static void test_proto_finds_a_signature_split_across_chunks(void **state)
{
    (void)state;
    uint8_t m[40];
    size_t n = 0;
    m[n++] = 0x55; // junk
    m[n++] = 0x00;
    n += keep_alive_at(m + n);
    for (size_t cut = 0; cut <= n; cut++) {
        dec_t d;
        dec_init(&d, 16, 0);
        feed(&d, m, cut);
        feed(&d, m + cut, n - cut);
        assert_int_equal(d.rec.n, 1);
        assert_int_equal(d.rec.ev[0].id, 1);
        assert_int_equal(d.rec.ev[0].offset, 2);
        assert_int_equal(d.p.stats.bytes_skipped, 2);
        assert_int_equal(d.p.stats.resyncs, 1);
        dec_free(&d);
    }
}

static void test_proto_finds_a_signature_right_after_a_partial_signature(void **state)
{
    (void)state;
    for (size_t k = 1; k < 16; k++) {
        uint8_t m[64];
        memcpy(m, sl_proto_signature, k); // partial signature in junk
        size_t n = k;
        n += keep_alive_at(m + n);
        dec_t whole, bytes;
        dec_init(&whole, 16, 0);
        dec_init(&bytes, 16, 0);
        feed(&whole, m, n);
        for (size_t i = 0; i < n; i++) {
            feed(&bytes, m + i, 1);
        }
        assert_int_equal(whole.rec.n, 1);
        assert_int_equal(whole.rec.ev[0].offset, k);
        assert_int_equal(whole.p.stats.bytes_skipped, k);
        assert_same_events(&whole.rec, &bytes.rec);
        assert_same_stats(&whole.p.stats, &bytes.p.stats);
        dec_free(&whole);
        dec_free(&bytes);
    }
}

static void test_proto_rejects_a_wrong_version_and_finds_a_message_inside_its_header(void **state)
{
    (void)state;
    // A signature with version 0 whose 6 header bytes are the start of a real message.
    uint8_t m[64];
    memcpy(m, sl_proto_signature, 16);
    const size_t ka = 16;
    (void)keep_alive_at(m + ka); // real message starts at 16: its bytes 0..5 are the tail
    const size_t n = ka + 22;
    dec_t whole, bytes;
    dec_init(&whole, 16, 0);
    dec_init(&bytes, 16, 0);
    feed(&whole, m, n);
    for (size_t i = 0; i < n; i++) {
        feed(&bytes, m + i, 1);
    }
    assert_int_equal(whole.p.stats.bad_version, 1);
    assert_int_equal(whole.rec.n, 1);
    assert_int_equal(whole.rec.ev[0].offset, 16);
    assert_int_equal(whole.p.stats.bytes_skipped, 16);
    assert_same_events(&whole.rec, &bytes.rec);
    assert_same_stats(&whole.p.stats, &bytes.p.stats);
    // Versions 2 and 255 are rejected too.
    for (unsigned v = 2; v <= 255; v += 253) {
        dec_t d;
        dec_init(&d, 16, 0);
        uint8_t h[44];
        (void)keep_alive_at(h);
        h[16] = (uint8_t)v;
        (void)keep_alive_at(h + 22);
        feed(&d, h, 44);
        assert_int_equal(d.p.stats.bad_version, 1);
        assert_int_equal(d.rec.n, 1);
        assert_int_equal(d.rec.ev[0].offset, 22);
        dec_free(&d);
    }
    dec_free(&whole);
    dec_free(&bytes);
}

static void test_proto_rejects_payloads_above_the_configured_maximum(void **state)
{
    (void)state;
    uint8_t m[200];
    size_t n = (size_t)sl_proto_encode_header(m, sizeof m, 30, 101); // 101 > max 100
    memset(m + n, 0xAA, 101);
    n += 101;
    n += keep_alive_at(m + n);
    for (int mode = 0; mode < 2; mode++) {
        dec_t d;
        dec_init(&d, 4096, 100);
        if (mode == 0) {
            feed(&d, m, n);
        } else {
            for (size_t i = 0; i < n; i++) {
                feed(&d, m + i, 1);
            }
        }
        assert_int_equal(d.p.stats.oversize, 1);
        assert_int_equal(d.p.stats.too_big, 0);
        assert_int_equal(d.rec.n, 1);
        assert_int_equal(d.rec.ev[0].id, 1);
        assert_int_equal(d.rec.ev[0].offset, 22 + 101);
        assert_int_equal(d.p.stats.bytes_skipped, 22 + 101);
        dec_free(&d);
    }
    // Exactly the maximum is accepted.
    dec_t d;
    dec_init(&d, 4096, 101);
    feed(&d, m, n);
    assert_int_equal(d.rec.n, 2);
    assert_int_equal(d.p.stats.oversize, 0);
    dec_free(&d);
}

static void test_proto_rejects_payloads_beyond_the_reassembly_buffer_even_when_whole(void **state)
{
    (void)state;
    uint8_t m[200];
    size_t n = (size_t)sl_proto_encode_header(m, sizeof m, 30, 65);
    memset(m + n, 0x11, 65);
    n += 65;
    n += keep_alive_at(m + n);
    dec_t d;
    dec_init(&d, 64, 1000); // max allows it, the buffer does not
    feed(&d, m, n);         // whole: could have been zero-copy, still rejected
    assert_int_equal(d.p.stats.too_big, 1);
    assert_int_equal(d.p.stats.oversize, 0);
    assert_int_equal(d.rec.n, 1);
    assert_int_equal(d.rec.ev[0].id, 1);
    dec_free(&d);
}

// truncate_long: a decoder with a 100-byte buffer delivers the first 100 payload bytes of
// every longer message (same events for every chunking), consumes the rest uncopied, keeps
// the accounting invariant and still rejects what exceeds max_payload_bytes.
static void dec_init_cut(dec_t *d, size_t reasm, uint32_t max_payload)
{
    memset(d, 0, sizeof *d);
    d->buf = malloc(reasm ? reasm : 1);
    d->size = reasm;
    d->rec.reasm_lo = d->buf;
    d->rec.reasm_hi = d->buf + reasm;
    sl_proto_cfg_t c = {.reasm_buf = d->buf, .reasm_size = reasm, .max_payload_bytes = max_payload,
                        .truncate_long = true, .on_msg = rec_on_msg, .ctx = &d->rec};
    assert_int_equal(sl_proto_init(&d->p, &c), SL_OK);
}

static uint32_t cut_seen, cut_wire_ok;
static void cut_on_msg(void *ctx, const sl_proto_msg_t *m)
{
    rec_on_msg(ctx, m);
    if (m->truncated) {
        cut_seen++;
    }
    if ((m->truncated && m->payload.size == 100U && m->wire_bytes > 100U) ||
        (!m->truncated && m->payload.size == m->wire_bytes)) {
        cut_wire_ok++;
    }
}

static void test_proto_truncates_long_payloads_to_the_buffer_for_every_chunking(void **state)
{
    (void)state;
    sl_golden_params_t g = small_params(); // FFT payloads 14 + 300 or 14 + 120 bytes
    size_t n;
    uint8_t *s = build(&g, &n);
    ev_t *want = calloc(4096, sizeof *want);
    const size_t nw = expected_events(&g, s, want);
    // The expected events: sizes capped at 100, hashes of the first 100 bytes.
    size_t o = 0;
    uint32_t n_long = 0;
    for (size_t i = 0; i < nw; i++) {
        if (want[i].size > 100U) {
            want[i].hash = sl_golden_fnv1a(s + o + 22, 100, SL_GOLDEN_FNV_INIT);
            want[i].size = 100;
            n_long++;
        }
        o += 22U + (((uint32_t)s[o + 18] << 24) | ((uint32_t)s[o + 19] << 16) |
                    ((uint32_t)s[o + 20] << 8) | s[o + 21]);
    }
    assert_true(n_long >= 32U);
    for (uint64_t seed = 0; seed <= 60; seed++) {
        dec_t d;
        dec_init_cut(&d, 100, 0);
        d.p.cfg.on_msg = cut_on_msg;
        cut_seen = cut_wire_ok = 0;
        if (seed == 0) {
            feed(&d, s, n);
            assert_int_equal(d.p.stats.reassembled, 0); // whole: views, even when cut
        } else if (seed == 1) {
            for (size_t i = 0; i < n; i++) {
                feed(&d, s + i, 1);
            }
        } else {
            feed_random_chunks(&d, s, n, seed);
        }
        assert_int_equal(d.rec.n, nw);
        for (size_t i = 0; i < nw; i++) {
            assert_int_equal(d.rec.ev[i].id, want[i].id);
            assert_int_equal(d.rec.ev[i].size, want[i].size);
            assert_int_equal(d.rec.ev[i].offset, want[i].offset);
            assert_true(d.rec.ev[i].hash == want[i].hash);
        }
        assert_int_equal(d.p.stats.cut, n_long);
        assert_int_equal(cut_seen, n_long);
        assert_int_equal(cut_wire_ok, nw);
        assert_int_equal(d.p.stats.bytes_delivered, n); // whole messages consumed
        assert_int_equal(d.p.stats.bytes_skipped, 0);
        assert_int_equal(d.p.stats.too_big, 0);
        assert_int_equal(d.rec.bad_view, 0);
        dec_free(&d);
    }
    // max_payload_bytes still rejects; without truncate_long the same message is too_big.
    dec_t d;
    dec_init_cut(&d, 100, 200);
    feed(&d, s, n);
    assert_int_equal(d.p.stats.oversize, 16); // the 16 full-length (314-byte) FFT messages
    assert_int_equal(d.p.stats.cut, n_long - 16);
    dec_free(&d);
    dec_init(&d, 100, 0);
    feed(&d, s, n);
    assert_int_equal(d.p.stats.cut, 0);
    assert_int_equal(d.p.stats.too_big, n_long);
    dec_free(&d);
    free(want);
    free(s);
}

static void test_proto_counts_a_message_truncated_at_eof_and_restarts_cleanly(void **state)
{
    (void)state;
    const sl_golden_params_t g = small_params();
    size_t n;
    uint8_t *s = build(&g, &n);
    ev_t *want = calloc(4096, sizeof *want);
    const size_t nw = expected_events(&g, s, want);
    // Cut inside the third message (first FFT after config is message 1).
    const size_t cut = (size_t)want[2].offset + 22 + 7;
    dec_t d;
    dec_init(&d, 4096, 0);
    feed(&d, s, cut);
    assert_int_equal(d.rec.n, 2);
    assert_int_equal(sl_proto_buffered(&d.p), 29);
    assert_int_equal(sl_proto_finish(&d.p), SL_OK);
    assert_accounted(&d.p);
    assert_int_equal(d.p.stats.truncated, 1);
    assert_int_equal(d.p.stats.bytes_skipped, 29);
    assert_int_equal(sl_proto_buffered(&d.p), 0);
    // Reconnect: the new stream is decoded from its first byte, no resync needed.
    feed(&d, s, n);
    assert_int_equal(d.rec.n, 2 + nw);
    assert_int_equal(d.rec.ev[2].offset, cut); // stream offsets keep counting across streams
    assert_int_equal(d.p.stats.resyncs, 0);
    // EOF inside a header and inside a signature count too; EOF between messages does not.
    assert_int_equal(sl_proto_finish(&d.p), SL_OK);
    assert_int_equal(d.p.stats.truncated, 1);
    feed(&d, s, 19);
    assert_int_equal(sl_proto_finish(&d.p), SL_OK);
    assert_int_equal(d.p.stats.truncated, 2);
    feed(&d, s, 3);
    assert_int_equal(sl_proto_finish(&d.p), SL_OK);
    assert_int_equal(d.p.stats.truncated, 3);
    assert_accounted(&d.p);
    free(want);
    free(s);
    dec_free(&d);
}

static void test_proto_recovers_after_a_message_cut_short_mid_stream(void **state)
{
    (void)state;
    // A radar that restarts without closing the connection: a half-sent FFT is directly
    // followed by a new config + data. The half message swallows bytes as its payload
    // (lengths can not be second-guessed); the decoder must then resync and deliver every
    // message that starts after the swallowed span.
    sl_golden_params_t g = small_params();
    g.keep_alive_every = 0;
    g.health_every = 0;
    size_t n;
    uint8_t *s = build(&g, &n);
    ev_t *want = calloc(4096, sizeof *want);
    const size_t nw = expected_events(&g, s, want);
    const size_t cut = (size_t)want[3].offset + 22 + 100; // inside message 3's payload
    uint8_t *m = malloc(cut + n);
    memcpy(m, s, cut);
    memcpy(m + cut, s, n); // the restarted radar's stream: config, FFTs...
    dec_t d;
    dec_init(&d, 4096, 0);
    feed(&d, m, cut + n);
    const size_t swallowed_end = (size_t)want[3].offset + 22 + want[3].size;
    size_t first_after = 0;
    while (first_after < nw && cut + want[first_after].offset < swallowed_end) {
        first_after++;
    }
    // Messages 0..2, the bogus message 3 (its payload is other messages' bytes), then every
    // restarted message that begins after the swallowed span.
    assert_int_equal(d.rec.n, 4 + (nw - first_after));
    for (size_t i = first_after; i < nw; i++) {
        const ev_t *e = &d.rec.ev[4 + i - first_after];
        assert_int_equal(e->offset, cut + want[i].offset);
        assert_true(e->hash == want[i].hash);
    }
    assert_accounted(&d.p);
    free(m);
    free(want);
    free(s);
    dec_free(&d);
}

static void test_proto_delivers_interleaved_keep_alives_and_unknown_ids(void **state)
{
    (void)state;
    uint8_t m[256];
    size_t n = 0;
    n += keep_alive_at(m + n);
    n += (size_t)sl_proto_encode_header(m + n, 40, 200, 3);
    m[n++] = 1;
    m[n++] = 2;
    m[n++] = 3;
    n += keep_alive_at(m + n);
    n += (size_t)sl_proto_encode_header(m + n, 22, 0, 0); // id 0, empty
    dec_t d;
    dec_init(&d, 16, 0);
    feed(&d, m, n);
    assert_int_equal(d.rec.n, 4);
    assert_int_equal(d.p.stats.keep_alive, 2);
    assert_int_equal(d.p.stats.other, 2);
    assert_int_equal(d.rec.ev[1].id, 200);
    assert_int_equal(d.rec.ev[1].size, 3);
    assert_int_equal(d.rec.ev[3].id, 0);
    assert_int_equal(d.rec.bad_view, 0); // empty payloads have NULL data
    dec_free(&d);
}

static void test_proto_accounts_for_every_byte_of_random_garbage(void **state)
{
    (void)state;
    uint64_t s = 42;
    uint8_t *g = malloc(50000);
    for (size_t i = 0; i < 50000; i++) {
        const uint64_t r = rng_next(&s);
        // Mostly signature bytes and zeros, so partial matches are frequent.
        g[i] = (r % 3 == 0) ? (uint8_t)(r >> 8) : sl_proto_signature[(r >> 16) % 16];
    }
    dec_t whole;
    dec_init(&whole, 128, 0);
    feed(&whole, g, 50000);
    for (uint64_t seed = 1; seed <= 20; seed++) {
        dec_t d;
        dec_init(&d, 128, 0);
        feed_random_chunks(&d, g, 50000, seed);
        assert_same_events(&whole.rec, &d.rec);
        assert_same_stats(&whole.p.stats, &d.p.stats);
        assert_int_equal(sl_proto_finish(&d.p), SL_OK);
        assert_accounted(&d.p);
        assert_int_equal(d.p.stats.bytes_in, d.p.stats.bytes_delivered + d.p.stats.bytes_skipped);
        dec_free(&d);
    }
    assert_true(whole.p.stats.bytes_skipped > 40000);
    dec_free(&whole);
    free(g);
}

// ------------------------------------------------------------------------------- parsers

static sl_proto_msg_t msg_of(uint8_t id, const uint8_t *p, size_t n)
{
    sl_proto_msg_t m = {.id = id, .payload = {p, n}};
    return m;
}

static void test_proto_parses_fft_fields_big_endian_and_time_little_endian(void **state)
{
    (void)state;
    // Hand-written payload (NAVTECH_PROTOCOL.md s.4), independent of the encoders.
    static const uint8_t pl[] = {
        0x00, 0x0E,             // offset 14 (BE)
        0x12, 0x34,             // sweep 0x1234 (BE)
        0x15, 0xDF,             // azimuth 5599 (BE)
        0x78, 0x56, 0x34, 0x12, // seconds 0x12345678 (LE)
        0x40, 0x42, 0x0F, 0x00, // ns 1000000 (LE)
        9, 8, 7,                // 3 bins
    };
    sl_proto_msg_t m = msg_of(30, pl, sizeof pl);
    sl_proto_fft_t f;
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_OK);
    assert_int_equal(f.data_offset, 14);
    assert_int_equal(f.sweep_counter, 0x1234);
    assert_int_equal(f.azimuth_ticks, 5599);
    assert_int_equal(f.seconds, 0x12345678);
    assert_int_equal(f.split_ns, 1000000);
    assert_int_equal(f.bins, 3);
    assert_int_equal(f.bytes_per_bin, 1);
    assert_ptr_equal(f.bin_data, pl + 14);
    assert_int_equal(sl_proto_fft_time_us(&f), (uint64_t)0x12345678 * 1000000 + 1000);
    // The encoder writes the same bytes.
    uint8_t b[64];
    uint8_t bins[3] = {9, 8, 7};
    f.id = 30;
    assert_int_equal(sl_proto_encode_fft8(b, sizeof b, &f, bins), 22 + sizeof pl);
    assert_memory_equal(b + 22, pl, sizeof pl);
    assert_int_equal(b[17], 30);
}

static void test_proto_parses_16_bit_bins_little_endian(void **state)
{
    (void)state;
    static const uint8_t pl[] = {0, 14, 0, 1, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0,
                                 0x34, 0x12, 0xFF, 0x00, 0x00, 0xFF};
    sl_proto_msg_t m = msg_of(31, pl, sizeof pl);
    sl_proto_fft_t f;
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_OK);
    assert_int_equal(f.bins, 3);
    assert_int_equal(f.bytes_per_bin, 2);
    assert_int_equal(sl_proto_fft_bin16(&f, 0), 0x1234);
    assert_int_equal(sl_proto_fft_bin16(&f, 1), 0x00FF);
    assert_int_equal(sl_proto_fft_bin16(&f, 2), 0xFF00);
    const uint16_t v[3] = {0x1234, 0x00FF, 0xFF00};
    uint8_t b[64];
    assert_int_equal(sl_proto_encode_fft16(b, sizeof b, &f, v), 22 + sizeof pl);
    assert_memory_equal(b + 22 + 14, pl + 14, 6);
    assert_int_equal(b[17], 31);
    // An odd number of 16-bit data bytes is malformed.
    m.payload.size = sizeof pl - 1;
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_ERR_MALFORMED);
}

static void test_proto_rejects_fft_offsets_outside_the_payload(void **state)
{
    (void)state;
    uint8_t pl[20] = {0};
    sl_proto_fft_t f;
    sl_proto_msg_t m = msg_of(30, pl, sizeof pl);
    pl[1] = 13; // < 14
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_ERR_MALFORMED);
    pl[1] = 21; // > payload size 20
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_ERR_MALFORMED);
    pl[0] = 0xFF;
    pl[1] = 0xFF;
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_ERR_MALFORMED);
    pl[0] = 0;
    pl[1] = 20; // == payload size: no bins, accepted
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_OK);
    assert_int_equal(f.bins, 0);
    pl[1] = 16; // a longer fixed part: bins start at 16, not 14
    pl[16] = 0x5A;
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_OK);
    assert_int_equal(f.bins, 4);
    assert_int_equal(f.bin_data[0], 0x5A);
    m.payload.size = 13; // shorter than the fixed part
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_ERR_MALFORMED);
    m.payload.size = 0;
    m.payload.data = NULL;
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_ERR_MALFORMED);
    m.id = 10;
    assert_int_equal(sl_proto_parse_fft(&m, &f), SL_ERR_ARG);
}

static uint32_t f32_bits(float v)
{
    uint32_t b;
    memcpy(&b, &v, 4);
    return b;
}

static void test_proto_parses_configuration_fixed_part_and_protobuf_fields(void **state)
{
    (void)state;
    // Hand-written payload: 400, 438, 3768, 5600, 4000, 1600, gain 1.0f, offset -0.31f (BE),
    // then protobuf: field 2 string "ab", field 9 = 2, field 1 nested {1: 5}, field 10 = 0.0438f
    uint8_t pl[64];
    size_t n = 0;
    const uint8_t fixed[20] = {0x01, 0x90, 0x01, 0xB6, 0x0E, 0xB8, 0x15, 0xE0, 0x0F, 0xA0,
                               0x06, 0x40, 0x3F, 0x80, 0x00, 0x00, 0xBE, 0x9E, 0xB8, 0x52};
    memcpy(pl, fixed, 20);
    n = 20;
    const uint32_t rr = f32_bits(0.0438f);
    const uint8_t pb[] = {0x12, 2, 'a', 'b', 0x48, 2, 0x0A, 2, 0x08, 5, 0x55,
                          (uint8_t)rr, (uint8_t)(rr >> 8), (uint8_t)(rr >> 16), (uint8_t)(rr >> 24)};
    memcpy(pl + n, pb, sizeof pb);
    n += sizeof pb;
    sl_proto_msg_t m = msg_of(10, pl, n);
    sl_proto_config_t c;
    assert_int_equal(sl_proto_parse_config(&m, &c), SL_OK);
    assert_int_equal(c.azimuths, 400);
    assert_int_equal(c.bin_size_100um, 438);
    assert_int_equal(c.range_bins, 3768);
    assert_int_equal(c.encoder_size, 5600);
    assert_int_equal(c.rotation_mhz, 4000);
    assert_int_equal(c.packet_rate, 1600);
    assert_int_equal(c.range_gain_f32, f32_bits(1.0f));
    assert_int_equal(c.range_offset_f32, f32_bits(-0.31f));
    assert_true(c.has_data_width);
    assert_int_equal(c.data_width, 2);
    assert_true(c.has_range_res);
    assert_int_equal(c.range_res_m_f32, rr);
    assert_false(c.protobuf_malformed);
    assert_int_equal(c.protobuf.size, sizeof pb);
    assert_int_equal(sl_proto_config_bin_size_um(&c), 43800);
    // Round trip through the encoder (which writes fields 9 and 10 only).
    uint8_t b[128];
    const sl_ssize_t w = sl_proto_encode_config(b, sizeof b, &c, (sl_bytes_t){NULL, 0});
    assert_int_equal(w, 22 + 20 + 2 + 5);
    assert_memory_equal(b + 22, fixed, 20);
    sl_proto_config_t c2;
    sl_proto_msg_t m2 = msg_of(10, b + 22, (size_t)w - 22);
    assert_int_equal(sl_proto_parse_config(&m2, &c2), SL_OK);
    assert_int_equal(c2.data_width, 2);
    assert_int_equal(c2.range_res_m_f32, rr);
}

static void test_proto_tolerates_empty_and_malformed_configuration_protobuf(void **state)
{
    (void)state;
    uint8_t pl[64] = {0x01, 0x90, 0, 0, 0, 0, 0x15, 0xE0};
    pl[2] = 0x01;
    pl[3] = 0xB6; // 438
    sl_proto_config_t c;
    sl_proto_msg_t m = msg_of(10, pl, 20);
    assert_int_equal(sl_proto_parse_config(&m, &c), SL_OK); // empty protobuf
    assert_false(c.has_data_width);
    assert_false(c.has_range_res);
    assert_false(c.protobuf_malformed);
    assert_int_equal(c.protobuf.size, 0);
    assert_int_equal(sl_proto_config_bin_size_um(&c), 43800); // from the fixed part
    // field 9 = 1, then a truncated varint
    const uint8_t bad1[] = {0x48, 1, 0x50, 0x80};
    memcpy(pl + 20, bad1, sizeof bad1);
    m.payload.size = 20 + sizeof bad1;
    assert_int_equal(sl_proto_parse_config(&m, &c), SL_OK);
    assert_true(c.protobuf_malformed);
    assert_true(c.has_data_width);
    assert_int_equal(c.data_width, 1);
    // A length beyond the end, a group wire type, field number 0, a short fixed32.
    const uint8_t bad[][3] = {{0x12, 0x7F, 0}, {0x0B, 0, 0}, {0x00, 1, 0}, {0x55, 1, 2}};
    for (size_t i = 0; i < 4; i++) {
        memcpy(pl + 20, bad[i], 3);
        m.payload.size = 23;
        assert_int_equal(sl_proto_parse_config(&m, &c), SL_OK);
        assert_true(c.protobuf_malformed);
        assert_false(c.has_range_res);
    }
    // A negative data width (10-byte varint) and a fixed64 field are walked correctly.
    const uint8_t neg[] = {0x19, 1, 2, 3, 4, 5, 6, 7, 8, 0x48, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,
                           0xFF, 0xFF, 0xFF, 0xFF, 0x01};
    memcpy(pl + 20, neg, sizeof neg);
    m.payload.size = 20 + sizeof neg;
    assert_int_equal(sl_proto_parse_config(&m, &c), SL_OK);
    assert_false(c.protobuf_malformed);
    assert_int_equal(c.data_width, -1);
    // Shorter than the fixed part.
    m.payload.size = 19;
    assert_int_equal(sl_proto_parse_config(&m, &c), SL_ERR_MALFORMED);
}

static void test_proto_bin_size_prefers_range_resolution_metres_when_sane(void **state)
{
    (void)state;
    sl_proto_config_t c = {.bin_size_100um = 438, .has_range_res = true};
    c.range_res_m_f32 = f32_bits(0.0432f);
    assert_int_equal(sl_proto_config_bin_size_um(&c), 43200);
    c.range_res_m_f32 = f32_bits(0.0596f);
    assert_int_equal(sl_proto_config_bin_size_um(&c), 59600);
    c.range_res_m_f32 = f32_bits(1.0f);
    assert_int_equal(sl_proto_config_bin_size_um(&c), 1000000);
    c.range_res_m_f32 = f32_bits(4000.0f);
    assert_int_equal(sl_proto_config_bin_size_um(&c), 4000000000u);
    c.range_res_m_f32 = f32_bits(0.0000004f); // 0.4 um rounds to 0: fall back
    assert_int_equal(sl_proto_config_bin_size_um(&c), 43800);
    c.range_res_m_f32 = f32_bits(-0.0438f);
    assert_int_equal(sl_proto_config_bin_size_um(&c), 43800);
    c.range_res_m_f32 = 0x7FC00000u; // NaN
    assert_int_equal(sl_proto_config_bin_size_um(&c), 43800);
    c.range_res_m_f32 = f32_bits(5000.0f); // > 4294 m
    assert_int_equal(sl_proto_config_bin_size_um(&c), 43800);
    // Exhaustive-ish: the integer conversion matches double rounding over a sweep.
    for (uint32_t um = 1; um < 2000000; um = um * 3 / 2 + 1) {
        const float v = (float)um / 1e6f;
        c.range_res_m_f32 = f32_bits(v);
        const double ref = (double)v * 1e6;
        const uint32_t got = sl_proto_config_bin_size_um(&c);
        assert_true((double)got - ref <= 0.5 && ref - (double)got <= 0.5);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_proto_encodes_commands_as_bare_22_byte_headers),
        cmocka_unit_test(test_proto_encoders_refuse_small_buffers),
        cmocka_unit_test(test_proto_init_rejects_bad_arguments),
        cmocka_unit_test(test_proto_decodes_a_golden_stream_fed_whole_without_copying),
        cmocka_unit_test(test_proto_gives_identical_events_when_fed_one_byte_at_a_time),
        cmocka_unit_test(test_proto_gives_identical_events_for_random_chunkings),
        cmocka_unit_test(test_proto_gives_identical_events_for_every_two_chunk_split),
        cmocka_unit_test(test_proto_resyncs_after_nasty_junk_for_every_chunking),
        cmocka_unit_test(test_proto_long_junk_runs_same_events_for_every_chunking),
        cmocka_unit_test(test_proto_odd_16_bit_fft_is_malformed_for_every_reassembly_size),
        cmocka_unit_test(test_proto_finds_a_signature_split_across_chunks),
        cmocka_unit_test(test_proto_finds_a_signature_right_after_a_partial_signature),
        cmocka_unit_test(test_proto_rejects_a_wrong_version_and_finds_a_message_inside_its_header),
        cmocka_unit_test(test_proto_rejects_payloads_above_the_configured_maximum),
        cmocka_unit_test(test_proto_rejects_payloads_beyond_the_reassembly_buffer_even_when_whole),
        cmocka_unit_test(test_proto_truncates_long_payloads_to_the_buffer_for_every_chunking),
        cmocka_unit_test(test_proto_counts_a_message_truncated_at_eof_and_restarts_cleanly),
        cmocka_unit_test(test_proto_recovers_after_a_message_cut_short_mid_stream),
        cmocka_unit_test(test_proto_delivers_interleaved_keep_alives_and_unknown_ids),
        cmocka_unit_test(test_proto_accounts_for_every_byte_of_random_garbage),
        cmocka_unit_test(test_proto_parses_fft_fields_big_endian_and_time_little_endian),
        cmocka_unit_test(test_proto_parses_16_bit_bins_little_endian),
        cmocka_unit_test(test_proto_rejects_fft_offsets_outside_the_payload),
        cmocka_unit_test(test_proto_parses_configuration_fixed_part_and_protobuf_fields),
        cmocka_unit_test(test_proto_tolerates_empty_and_malformed_configuration_protobuf),
        cmocka_unit_test(test_proto_bin_size_prefers_range_resolution_metres_when_sane),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
