// SPDX-License-Identifier: MIT
// fuzz_proto: libFuzzer entry point for the Colossus decoder + scan assembly.
//
// Input layout: 4 control bytes, then the stream.
//   ctl[0] & 3     chunking: 0 = 1 byte at a time, 1 = 1..16, 2 = 1..4096, 3 = 1..65536
//   ctl[1], ctl[2] chunking PRNG seed
//   ctl[3] & 7     reassembly buffer size: 0, 22, 64, 512, 4096, 8192, 16384, 65536
//   ctl[3] >> 3 & 3 max_payload_bytes: 0 (= buffer), 100, 3804, 1000000
//   ctl[3] >> 5 & 3 scan: 0 wait for a Configuration, 1 preset 400 x 5600, 2 preset 8 x 5600,
//                   3 preset 400 x 5600 with a 16-bit shift of 4 and ignore_sweep
// Shorter inputs use zero control bytes.
//
// Invariants (SECURITY.md): for every input
//  - no crash, no sanitizer report (ASan + UBSan in the libFuzzer build);
//  - the decoder's events (id, payload, stream offset) and counters are identical whether
//    the stream is fed whole or in the fuzzer-chosen chunks;
//  - after every feed: bytes_in == bytes_delivered + bytes_skipped + buffered; after
//    sl_proto_finish: buffered == 0;
//  - every payload view lies inside the chunk being fed (zero copy) or the reassembly buffer
//    and is no longer than the limits; zero_copy + reassembled == messages;
//  - scan: each completed frame's valid + missing == azimuths, flags / bins / zero rows are
//    consistent, and fft == azimuths + duplicates + late_dropped + bad_azimuth + no_config.
//
// The same file builds two ways:
//  - with -DSL_FUZZ_LIBFUZZER and -fsanitize=fuzzer: the `fuzz_proto` libFuzzer binary;
//  - without: `fuzz_proto_replay [--mutations N] <file|dir>...`, a plain program that runs
//    every corpus file plus N deterministic mutations of each (the `fuzz_proto_corpus` ctest).
#define _POSIX_C_SOURCE 200809L
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_scan.h"

#define CHECK(c)                                                                             \
    do {                                                                                     \
        if (!(c)) {                                                                          \
            fprintf(stderr, "fuzz_proto: invariant failed: %s (%s:%d)\n", #c, __FILE__,      \
                    __LINE__);                                                               \
            abort();                                                                         \
        }                                                                                    \
    } while (0)

static const size_t k_reasm_sizes[8] = {0, 22, 64, 512, 4096, 8192, 16384, 65536};
static const uint32_t k_max_payload[4] = {0, 100, 3804, 1000000};

typedef struct run {
    sl_proto_t p;
    uint8_t *reasm;
    size_t reasm_size;
    uint32_t limit;        // effective payload limit
    uint64_t digest;       // FNV-1a over every event
    const uint8_t *chunk;  // chunk being fed
    size_t chunk_len;
    sl_scan_t *scan;       // NULL: decoder only
} run_t;

static uint64_t fnv(uint64_t h, const uint8_t *d, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        h ^= d[i];
        h *= 0x100000001b3ULL;
    }
    return h;
}

static void on_msg(void *ctx, const sl_proto_msg_t *m)
{
    run_t *r = ctx;
    CHECK(m->payload.size <= r->limit);
    if (m->payload.size == 0) {
        CHECK(m->payload.data == NULL);
    } else if (m->zero_copy) {
        CHECK(m->payload.data >= r->chunk && m->payload.data + m->payload.size <= r->chunk + r->chunk_len);
    } else {
        CHECK(m->payload.data >= r->reasm && m->payload.data + m->payload.size <= r->reasm + r->reasm_size);
    }
    uint8_t h[13] = {m->id};
    const uint64_t sz = m->payload.size, off = m->stream_offset;
    for (int i = 0; i < 4; i++) {
        h[1 + i] = (uint8_t)(sz >> (8 * i));
    }
    for (int i = 0; i < 8; i++) {
        h[5 + i] = (uint8_t)(off >> (8 * i));
    }
    r->digest = fnv(r->digest, h, sizeof h);
    r->digest = fnv(r->digest, m->payload.data, m->payload.size);
    if (r->scan != NULL) {
        (void)sl_scan_on_msg(r->scan, m);
    }
}

static void check_accounting(const sl_proto_t *p)
{
    CHECK(p->stats.bytes_in == p->stats.bytes_delivered + p->stats.bytes_skipped + sl_proto_buffered(p));
    CHECK(p->stats.zero_copy + p->stats.reassembled == p->stats.messages);
    CHECK(p->stats.keep_alive + p->stats.configuration + p->stats.fft8 + p->stats.fft16 +
              p->stats.health + p->stats.other ==
          p->stats.messages);
}

// ---- scan invariants
static sl_scan_frame_t g_frames[2];
static uint64_t g_frame_valid_sum;

static void on_frame(void *ctx, const sl_scan_frame_t *f)
{
    (void)ctx;
    CHECK(f->azimuths >= 1 && f->azimuths <= SL_CFG_MAX_AZIMUTHS);
    uint32_t valid = 0;
    uint32_t nshort = 0;
    for (uint32_t i = 0; i < f->azimuths; i++) {
        if (f->flags[i] & SL_SCAN_AZ_VALID) {
            valid++;
            CHECK(f->bins[i] <= f->roi_bins);
            CHECK(((f->flags[i] & SL_SCAN_AZ_SHORT) != 0) == (f->bins[i] < f->roi_bins));
            nshort += (f->flags[i] & SL_SCAN_AZ_SHORT) ? 1U : 0U;
            for (uint32_t b = f->bins[i]; b < f->roi_bins; b++) {
                CHECK(f->power[i][b] == 0);
            }
        } else {
            CHECK(f->flags[i] == 0 && f->bins[i] == 0 && f->t_us[i] == 0);
            for (uint32_t b = 0; b < f->roi_bins; b++) {
                CHECK(f->power[i][b] == 0);
            }
        }
    }
    CHECK(valid == f->stats.valid);
    CHECK(valid >= 1);
    CHECK((uint32_t)f->stats.valid + f->stats.missing == f->azimuths);
    CHECK(nshort == f->stats.short_azimuths);
    CHECK(f->t_first_us <= f->t_last_us);
    g_frame_valid_sum += valid;
}

static void on_azimuth(void *ctx, const sl_scan_frame_t *f, uint16_t idx)
{
    (void)ctx;
    CHECK(idx < f->azimuths);
    CHECK((f->flags[idx] & SL_SCAN_AZ_VALID) != 0);
}

static void run_init(run_t *r, uint8_t ctl3, sl_scan_t *scan)
{
    memset(r, 0, sizeof *r);
    r->reasm_size = k_reasm_sizes[ctl3 & 7U];
    r->reasm = malloc(r->reasm_size ? r->reasm_size : 1);
    CHECK(r->reasm != NULL);
    const uint32_t maxp = k_max_payload[(ctl3 >> 3) & 3U];
    r->limit = (uint32_t)r->reasm_size;
    if (maxp != 0 && maxp < r->limit) {
        r->limit = maxp;
    }
    r->digest = 0xcbf29ce484222325ULL;
    r->scan = scan;
    sl_proto_cfg_t c = {.reasm_buf = r->reasm, .reasm_size = r->reasm_size,
                        .max_payload_bytes = maxp, .on_msg = on_msg, .ctx = r};
    CHECK(sl_proto_init(&r->p, &c) == SL_OK);
}

static void run_feed(run_t *r, const uint8_t *d, size_t n)
{
    // An exact-size copy, so ASan sees any read beyond the chunk.
    uint8_t *copy = malloc(n ? n : 1);
    CHECK(copy != NULL);
    if (n) {
        memcpy(copy, d, n);
    }
    r->chunk = copy;
    r->chunk_len = n;
    CHECK(sl_proto_feed(&r->p, copy, n, 0) == SL_OK);
    r->chunk = NULL;
    r->chunk_len = 0;
    free(copy);
    check_accounting(&r->p);
}

static void run_finish(run_t *r)
{
    CHECK(sl_proto_finish(&r->p) == SL_OK);
    CHECK(sl_proto_buffered(&r->p) == 0);
    check_accounting(&r->p);
    CHECK(r->p.stats.bytes_in == r->p.stats.bytes_delivered + r->p.stats.bytes_skipped);
}

static void same_stats(const sl_proto_stats_t *a, const sl_proto_stats_t *b)
{
    CHECK(a->bytes_in == b->bytes_in);
    CHECK(a->bytes_delivered == b->bytes_delivered);
    CHECK(a->bytes_skipped == b->bytes_skipped);
    CHECK(a->resyncs == b->resyncs);
    CHECK(a->bad_version == b->bad_version);
    CHECK(a->oversize == b->oversize);
    CHECK(a->too_big == b->too_big);
    CHECK(a->truncated == b->truncated);
    CHECK(a->messages == b->messages);
    CHECK(a->fft8 == b->fft8 && a->fft16 == b->fft16 && a->configuration == b->configuration);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint8_t ctl[4] = {0, 0, 0, 0};
    if (size >= 4) {
        memcpy(ctl, data, 4);
        data += 4;
        size -= 4;
    }
    // Run A: the whole stream in one call, decoder only.
    run_t a;
    run_init(&a, ctl[3], NULL);
    run_feed(&a, data, size);
    run_finish(&a);

    // Run B: fuzzer-chosen chunks, through scan assembly.
    static sl_scan_t scan;
    const unsigned smode = (ctl[3] >> 5) & 3U;
    sl_scan_cfg_t sc = {.roi_bins = 64, .pow16_shift = smode == 3 ? 4 : 8,
                        .azimuths = smode == 0 ? 0 : (smode == 2 ? 8 : 400),
                        .encoder_size = smode == 0 ? 0 : 5600, .ignore_sweep = smode == 3,
                        .on_azimuth = on_azimuth, .on_frame = on_frame};
    CHECK(sl_scan_init(&scan, &sc, &g_frames[0], &g_frames[1]) == SL_OK);
    g_frame_valid_sum = 0;
    run_t b;
    run_init(&b, ctl[3], &scan);
    uint32_t rng = ((uint32_t)ctl[1] << 8 | ctl[2]) * 2654435761U + 1U;
    static const size_t k_max_chunk[4] = {1, 16, 4096, 65536};
    const size_t maxc = k_max_chunk[ctl[0] & 3U];
    size_t i = 0;
    while (i < size) {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        size_t c = 1 + rng % maxc;
        if (c > size - i) {
            c = size - i;
        }
        run_feed(&b, data + i, c);
        i += c;
    }
    run_finish(&b);
    sl_scan_flush(&scan);

    CHECK(a.digest == b.digest);
    same_stats(&a.p.stats, &b.p.stats);
    const sl_scan_stats_t *ss = &scan.stats;
    CHECK(ss->fft == ss->azimuths + ss->duplicates + ss->late_dropped + ss->bad_azimuth + ss->no_config +
          ss->empty_rows);
    CHECK(g_frame_valid_sum == ss->azimuths);
    CHECK(ss->out_of_order <= ss->azimuths);
    CHECK(ss->fft <= b.p.stats.fft8 + b.p.stats.fft16);
    free(a.reasm);
    free(b.reasm);
    return 0;
}

#ifndef SL_FUZZ_LIBFUZZER
// ------------------------------------------------------------------------ corpus replay
#include "replay_files.h"

static unsigned long g_inputs;
static unsigned g_mutations;

static uint64_t xs64(uint64_t *s)
{
    uint64_t x = *s;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *s = x;
}

// Deterministic structure-aware-ish mutations: flip, insert junk / signature fragments,
// delete, duplicate, truncate, rechunk.
static void run_mutations(const uint8_t *d, size_t n, uint64_t seed)
{
    static const uint8_t sig[16] = {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                                    0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE};
    uint8_t *m = malloc(2 * n + 256);
    CHECK(m != NULL);
    for (unsigned k = 0; k < g_mutations; k++) {
        uint64_t s = seed * 0x9E3779B97F4A7C15ULL + k + 1;
        memcpy(m, d, n);
        size_t len = n;
        const unsigned ops = 1 + (unsigned)(xs64(&s) % 4);
        for (unsigned o = 0; o < ops && len > 0; o++) {
            const uint64_t r = xs64(&s);
            const size_t at = (size_t)(xs64(&s) % len);
            switch (r % 7) {
            case 0: m[at] ^= (uint8_t)(1U << (r >> 8) % 8); break;
            case 1: m[at] = (uint8_t)(r >> 16); break;
            case 2: { // insert a signature fragment
                const size_t k2 = 1 + (r >> 8) % 16;
                if (len + k2 <= 2 * n + 256) {
                    memmove(m + at + k2, m + at, len - at);
                    memcpy(m + at, sig, k2);
                    len += k2;
                }
                break;
            }
            case 3: { // delete a range
                const size_t k2 = 1 + (r >> 8) % 64;
                const size_t e = (at + k2 > len) ? len : at + k2;
                memmove(m + at, m + e, len - e);
                len -= e - at;
                break;
            }
            case 4: len = at; break; // truncate
            case 5: { // duplicate a range
                const size_t k2 = 1 + (r >> 8) % 256;
                const size_t e = (at + k2 > len) ? len : at + k2;
                if (len + (e - at) <= 2 * n + 256) {
                    memmove(m + e + (e - at), m + e, len - e);
                    memcpy(m + e, m + at, e - at);
                    len += e - at;
                }
                break;
            }
            default: if (len >= 4) { m[(r >> 8) % 4] = (uint8_t)(r >> 24); } break; // rechunk
            }
        }
        (void)LLVMFuzzerTestOneInput(m, len);
        g_inputs++;
    }
    free(m);
}

static int run_file(const char *path, uint64_t seed)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "fuzz_proto_replay: cannot open %s\n", path);
        return 1;
    }
    size_t cap = 1 << 16, n = 0;
    uint8_t *d = malloc(cap);
    CHECK(d != NULL);
    size_t got;
    while ((got = fread(d + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            cap *= 2;
            d = realloc(d, cap);
            CHECK(d != NULL);
        }
    }
    fclose(f);
    (void)LLVMFuzzerTestOneInput(d, n);
    g_inputs++;
    run_mutations(d, n, seed);
    free(d);
    return 0;
}

// A directory entry's mutations are seeded by its name, a file argument's by its position.
static int replay_one(const char *path, const char *name, unsigned long index)
{
    return run_file(path, name != NULL ? fnv(0, (const uint8_t *)name, strlen(name)) : index);
}

int main(int argc, char **argv)
{
    int bad = 0;
    unsigned long files = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--mutations") == 0 && i + 1 < argc) {
            g_mutations = (unsigned)strtoul(argv[++i], NULL, 10);
            continue;
        }
        const int r = replay_path(argv[i], &files, replay_one);
        if (r < 0) {
            fprintf(stderr, "fuzz_proto_replay: no such path %s\n", argv[i]);
            return 1;
        }
        bad |= r;
    }
    if (files == 0) {
        fprintf(stderr, "usage: fuzz_proto_replay [--mutations N] <file|dir>...\n");
        return 1;
    }
    printf("fuzz_proto_replay: %lu files, %lu inputs, all invariants held\n", files, g_inputs);
    return bad;
}
#endif
