// SPDX-License-Identifier: MIT
// make_stream.c: writes a deterministic Colossus stream (tests/support/golden/sl_golden.c) to a
// file: make_stream OUT ROTATIONS. CTS350-X geometry (400 azimuths, 5600 ticks, 3768 bins).
#include <stdio.h>
#include <stdlib.h>

#include "sl_golden.h"

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: make_stream OUT ROTATIONS\n");
        return 2;
    }
    sl_golden_params_t gp = sl_golden_defaults();
    gp.rotations = (uint16_t)atoi(argv[2]);
    gp.keep_alive_every = 97;
    const size_t n = sl_golden_size(&gp);
    unsigned char *b = malloc(n);
    FILE *f = fopen(argv[1], "wb");
    if (b == NULL || f == NULL || sl_golden_build(b, n, &gp) != n || fwrite(b, 1, n, f) != n || fclose(f) != 0) {
        fprintf(stderr, "make_stream: %s: failed\n", argv[1]);
        return 1;
    }
    free(b);
    return 0;
}
