// SPDX-License-Identifier: MIT
// host_frames CAPTURE [BOARD]: the example firmware's application (firmware/targets/common/
// fw_app.c) on the host, over a capture file: the same text lines the Thumb images print
// under qemu-system-arm, for run_thumb.sh to compare.
#include <stdio.h>
#include <stdlib.h>

#include "fw_app.h"

static void write_stdout(const char *s) { fputs(s, stdout); }

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: host_frames CAPTURE [BOARD]\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "rb");
    if (f == NULL) {
        perror(argv[1]);
        return 2;
    }
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc(n > 0 ? (size_t)n : 1U);
    if (buf == NULL || fread(buf, 1, (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "%s: read error\n", argv[1]);
        return 2;
    }
    fclose(f);
    const fw_platform_t pf = {write_stdout, NULL, 0U};
    fw_result_t res;
    const sl_err_t e = fw_app_run(&pf, argc > 2 ? argv[2] : NULL, buf, (size_t)n, 1460U, &res);
    free(buf);
    if (e != SL_OK) {
        fprintf(stderr, "fw_app_run: %s\n", sl_err_str(e));
        return 1;
    }
    printf("azimuths %u\nrotations %u\ntargets %u\nframes %u\n", res.azimuths, res.rotations,
           res.targets, res.frames);
    return res.frames_lost == 0U ? 0 : 1;
}
