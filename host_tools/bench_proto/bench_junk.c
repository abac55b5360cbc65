// SPDX-License-Identifier: MIT
// sl-bench-junk: instructions per junk byte of the Colossus decoder's resynchronisation.
//
//   sl-bench-junk KIND [BYTES [CHUNK]]
//
// KIND: zero (0x00 fill), fe (0xFE fill, the worst byte for the window search), random
// (xorshift, fixed seed), prefixK (the first K = 1..15 signature bytes, repeated),
// badsig (whole signatures with version 0, repeated). BYTES defaults to 1 MiB, CHUNK (bytes
// per sl_proto_feed call) to 65536. The decoder (firmware/core/proto.c) is compiled into this
// program with -O2 whatever the build type, so callgrind counts are those of an optimised
// build; junk_cost.sh runs it under `valgrind --tool=callgrind --toggle-collect=
// sl_bench_junk_run` (only the feed loop is counted) and divides by the "bytes:" line.
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sl_cli.h"
#include "shadowlean/sl_proto.h"

static uint8_t g_reasm[4096];
static sl_proto_t g_p;
static uint64_t g_msgs;

static void on_msg(void *ctx, const sl_proto_msg_t *m)
{
    (void)ctx;
    (void)m;
    g_msgs++;
}

__attribute__((noinline)) void sl_bench_junk_run(const uint8_t *d, size_t n, size_t chunk);
__attribute__((noinline)) void sl_bench_junk_run(const uint8_t *d, size_t n, size_t chunk)
{
    for (size_t i = 0; i < n; i += chunk) {
        const size_t k = (n - i < chunk) ? n - i : chunk;
        (void)sl_proto_feed(&g_p, d + i, k, 0);
    }
}

static int fill(uint8_t *b, size_t n, const char *kind)
{
    if (strcmp(kind, "zero") == 0) {
        memset(b, 0x00, n);
    } else if (strcmp(kind, "fe") == 0) {
        memset(b, 0xFE, n);
    } else if (strcmp(kind, "random") == 0) {
        uint64_t x = 0x9E3779B97F4A7C15ULL;
        for (size_t i = 0; i < n; i++) {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            b[i] = (uint8_t)(x >> 24);
        }
    } else if (strncmp(kind, "prefix", 6) == 0) {
        const long k = strtol(kind + 6, NULL, 10);
        if (k < 1 || k > 15) {
            return -1;
        }
        for (size_t i = 0; i < n; i++) {
            b[i] = sl_proto_signature[i % (size_t)k];
        }
    } else if (strcmp(kind, "badsig") == 0) {
        for (size_t i = 0; i < n; i++) {
            const size_t o = i % SL_PROTO_HEADER_BYTES;
            b[i] = (o < SL_PROTO_SIGNATURE_BYTES) ? sl_proto_signature[o] : 0x00U;
        }
    } else {
        return -1;
    }
    return 0;
}

static void usage(FILE *out)
{
    fprintf(out, "usage: sl-bench-junk zero|fe|random|prefix1..prefix15|badsig [BYTES [CHUNK]]\n");
}

int main(int argc, char **argv)
{
    const int info = sl_cli_info(argc, argv, "sl-bench-junk", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; i++) {
        if (argv[i][0] == '-') {
            return sl_cli_unknown("sl-bench-junk", argv[i], usage);
        }
    }
    if (argc < 2) {
        return sl_cli_usage_error("sl-bench-junk", "missing KIND", usage);
    }
    if (argc > 4) {
        return sl_cli_unknown("sl-bench-junk", argv[4], usage);
    }
    const size_t n = (argc > 2) ? (size_t)strtoull(argv[2], NULL, 10) : ((size_t)1 << 20);
    const size_t chunk = (argc > 3) ? (size_t)strtoull(argv[3], NULL, 10) : 65536U;
    uint8_t *b = malloc(n ? n : 1);
    if (b == NULL) {
        fprintf(stderr, "sl-bench-junk: out of memory\n");
        return SL_EXIT_ERROR;
    }
    if (chunk == 0) {
        free(b);
        return sl_cli_bad_value("sl-bench-junk", "CHUNK", "must be at least 1", usage);
    }
    if (fill(b, n, argv[1]) != 0) {
        free(b);
        return sl_cli_bad_value("sl-bench-junk", "KIND", "unknown kind", usage);
    }
    const sl_proto_cfg_t cfg = {.reasm_buf = g_reasm, .reasm_size = sizeof g_reasm,
                                .max_payload_bytes = sizeof g_reasm, .on_msg = on_msg};
    if (sl_proto_init(&g_p, &cfg) != SL_OK) {
        free(b);
        return SL_EXIT_ERROR;
    }
    sl_bench_junk_run(b, n, chunk);
    printf("kind: %s\nchunk: %zu\nbytes: %zu\nskipped: %llu\nbuffered: %llu\nmessages: %llu\n",
           argv[1], chunk, n, (unsigned long long)g_p.stats.bytes_skipped,
           (unsigned long long)sl_proto_buffered(&g_p), (unsigned long long)g_msgs);
    free(b);
    // Junk must be consumed without a message, every byte accounted for.
    return (g_msgs == 0 && g_p.stats.bytes_skipped + sl_proto_buffered(&g_p) == n) ? 0 : 1;
}
