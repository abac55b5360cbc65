// SPDX-License-Identifier: MIT
// make_seeds: writes the committed seed corpus of fuzz_proto (tests/core/fuzz/corpus/).
// Usage: fuzz_make_seeds <dir>. Deterministic; re-run only when the input layout of
// fuzz_proto.c changes. Each file = 4 control bytes (see fuzz_proto.c) + a stream.
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_proto.h"
#include "sl_golden.h"

static const char *g_dir;

static void put(const char *name, const uint8_t ctl[4], const uint8_t *d, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    FILE *f = fopen(path, "wb");
    if (f == NULL || fwrite(ctl, 1, 4, f) != 4 || fwrite(d, 1, n, f) != n || fclose(f) != 0) {
        fprintf(stderr, "make_seeds: cannot write %s\n", path);
        exit(1);
    }
    printf("%s: %zu bytes\n", path, n + 4);
}

static uint8_t *golden(const sl_golden_params_t *g, size_t *n)
{
    *n = sl_golden_size(g);
    uint8_t *d = malloc(*n + 4096);
    if (d == NULL || sl_golden_build(d, *n, g) != *n) {
        exit(1);
    }
    return d;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: fuzz_make_seeds <dir>\n");
        return 2;
    }
    g_dir = argv[1];
    sl_golden_params_t g = sl_golden_defaults();
    g.azimuths = 8;
    g.range_bins = 64;
    g.rotations = 2;
    g.keep_alive_every = 5;
    g.health_every = 7;
    g.contour_bins = 20;
    size_t n;
    uint8_t *d = golden(&g, &n);
    // ctl: chunk mode 2 (recv-sized), seed, reasm 4096 (idx 4), max = buffer, scan waits.
    const uint8_t ctl_whole[4] = {2, 0x12, 0x34, 4};
    put("golden_8bit.bin", ctl_whole, d, n);
    const uint8_t ctl_bytes[4] = {0, 0, 0, 4};
    put("golden_8bit_bytewise.bin", ctl_bytes, d, n);
    // Truncated in the middle of the 5th message.
    put("truncated.bin", ctl_whole, d, n / 2 + 3);
    // Junk-prefixed, with a partial signature and a bad-version header in the junk.
    {
        uint8_t *j = malloc(n + 128);
        size_t o = 0;
        const char *txt = "HTTP/1.1 200 OK\r\n";
        memcpy(j + o, txt, strlen(txt));
        o += strlen(txt);
        memcpy(j + o, sl_proto_signature, 9);
        o += 9;
        memcpy(j + o, sl_proto_signature, 16);
        j[o + 16] = 2; // bad version
        memset(j + o + 17, 0, 5);
        o += 22;
        memcpy(j + o, d, n);
        o += n;
        const uint8_t ctl[4] = {1, 0x55, 0xAA, 4 | (1 << 3)};
        put("junk_prefixed.bin", ctl, j, o);
        free(j);
    }
    free(d);
    // 16-bit data, preset geometry 8 x 5600 (scan mode 2), shift-4 variant (mode 3).
    g.bytes_per_bin = 2;
    d = golden(&g, &n);
    const uint8_t ctl16[4] = {3, 1, 2, 4 | (2 << 5)};
    put("golden_16bit.bin", ctl16, d, n);
    free(d);
    // Oxford-like: 400 azimuths, ticks 13 + 14 i, 4 bins, one rotation and a bit, preset
    // geometry (scan mode 1) so it also works without the config.
    g = sl_golden_defaults();
    g.range_bins = 4;
    g.rotations = 2;
    d = golden(&g, &n);
    const uint8_t ctlox[4] = {2, 9, 9, 4 | (1 << 5)};
    put("oxford_like.bin", ctlox, d, n);
    free(d);
    return 0;
}
