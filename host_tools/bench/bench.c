// SPDX-License-Identifier: MIT
// sl-bench: the whole detection pipeline (sl_pipeline_feed) over a capture file.
//
//   sl-bench CAPTURE [--board NAME] [--chunk BYTES] [--repeat N] [--loop N] [--n N]
//                    [--beam-cdeg N] [--threshold T] [--speed-mm-s V] [--no-profile] [--no-learn]
//                    [--fit]
//                    [--callgrind run|latency] [--quiet]
//
// CAPTURE is a raw Colossus stream (`.colossus`: sl-sim, `sl-replay from-oxford`,
// `sl-replay record`). It is read whole into memory first (then `--loop N` concatenates N
// copies: more rotations from a short capture), so the timing is the pipeline from the
// page cache / RAM, not the disk. The pipeline is then fed in `--chunk` byte pieces
// (default 65536) exactly as the daemon feeds it, with `now_us` advancing 250 ms per
// rotation's worth of bytes.
//
// Printed (one `key: value` per line, parsed by callgrind.sh / compare.sh):
//   - the pipeline's static RAM: sizeof(sl_pipeline_t) for this build's SL_CFG_* (sl-bench is
//     built in the firmware configuration, sl-bench-host in the host default);
//   - bytes, messages, azimuths, rotations, targets of one run; the 3D tilt history's
//     observations and fits (only with --speed-mm-s: a motion input) and its RAM;
//   - wall-clock MB/s (best of --repeat runs, one thread, one core; 1 MB = 1e6 bytes);
//   - latency: wall-clock microseconds from the start of the sl_pipeline_feed() call that
//     hands over the message completing a rotation (the next rotation's first azimuth) to
//     the on_rotation callback with that rotation's targets. For this the capture is fed one
//     message per call (message boundaries from a pre-pass over the headers).
//
// Instruction counts (no timing in tests: these come from valgrind only):
//   --callgrind run      collection is toggled on around the feed loop of one run only
//                        (init, file reading and the pre-pass excluded); divide the total by
//                        the azimuths / rotations printed here.
//   --callgrind latency  collection is toggled on just before feeding each rotation-completing
//                        message and off inside on_rotation: total / rotations = instructions
//                        of the latency path.
// Run under `valgrind --tool=callgrind --collect-atstart=no`; host_tools/bench/callgrind.sh
// does it and prints the per-azimuth / per-rotation numbers.
#define _POSIX_C_SOURCE 200809L
#include <inttypes.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sl_cli.h"
#include "shadowlean/sl_pipeline.h"

#ifdef SL_HAVE_CALLGRIND_H
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_TOGGLE_COLLECT
#endif

static sl_pipeline_t g_pl; // static, as in firmware

typedef struct bench {
    uint64_t rotations, targets, frames;
    // latency bookkeeping
    bool timing;            // wall-clock latency measurement active
    bool cg_latency;        // callgrind latency mode
    bool armed;             // a rotation-completing message is being fed
    struct timespec t0;
    double lat_sum_us, lat_max_us;
    uint64_t lat_n;
    uint64_t *complete_msg; // message index that completed each rotation (pre-pass)
    uint64_t n_complete, cap_complete;
    uint64_t cur_msg;       // index of the message being fed (latency modes)
} bench_t;
static bench_t g_b;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void on_rotation(void *ctx, const sl_pipeline_rotation_t *r)
{
    bench_t *b = ctx;
    if (b->armed) {
        if (b->cg_latency) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        if (b->timing) {
            struct timespec t1;
            clock_gettime(CLOCK_MONOTONIC, &t1);
            const double us = (double)(t1.tv_sec - b->t0.tv_sec) * 1e6 +
                              (double)(t1.tv_nsec - b->t0.tv_nsec) * 1e-3;
            b->lat_sum_us += us;
            b->lat_max_us = us > b->lat_max_us ? us : b->lat_max_us;
            b->lat_n++;
        }
        b->armed = false;
    }
    if (b->complete_msg != NULL) {
        if (b->n_complete == b->cap_complete) {
            b->cap_complete = b->cap_complete ? 2 * b->cap_complete : 256;
            b->complete_msg = realloc(b->complete_msg, b->cap_complete * sizeof *b->complete_msg);
            if (b->complete_msg == NULL) {
                abort();
            }
        }
        b->complete_msg[b->n_complete++] = b->cur_msg;
    }
    b->rotations++;
    b->targets += r->n_targets;
}

static sl_err_t can_tx(void *ctx, const sl_can_frame_t *f)
{
    bench_t *b = ctx;
    (void)f;
    b->frames++;
    return SL_OK;
}

typedef struct opts {
    const char *capture, *board, *callgrind;
    size_t chunk;
    int repeat, loop, n, beam_cdeg, threshold;
    long speed_mm_s;
    int no_profile;
    int no_learn;
    int fit;
    bool quiet;
} opts_t;

// sl-bench and sl-bench-host are the same source: each names itself.
#ifndef SL_BENCH_PROG
#define SL_BENCH_PROG "sl-bench"
#endif

static void usage(FILE *out)
{
    fprintf(out, "usage: " SL_BENCH_PROG " CAPTURE [--board NAME] [--chunk BYTES] [--repeat N] "
                 "[--loop N] [--n N] [--beam-cdeg N] [--threshold T] [--speed-mm-s V] [--no-profile] [--no-learn] "
                 "[--fit] [--callgrind run|latency] [--quiet]\n");
}

static bool takes_value(const char *a)
{
    static const char *const with_value[] = {"--board", "--chunk", "--repeat", "--loop", "--n",
                                             "--beam-cdeg", "--threshold", "--speed-mm-s",
                                             "--callgrind"};
    for (size_t k = 0; k < sizeof with_value / sizeof with_value[0]; k++) {
        if (strcmp(a, with_value[k]) == 0) {
            return true;
        }
    }
    return false;
}

static uint8_t *read_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return NULL;
    }
    size_t cap = 1u << 20, len = 0;
    uint8_t *buf = malloc(cap);
    for (;;) {
        if (len == cap) {
            cap *= 2;
            buf = realloc(buf, cap);
        }
        if (buf == NULL) {
            fclose(f);
            return NULL;
        }
        const size_t k = fread(buf + len, 1, cap - len, f);
        len += k;
        if (k == 0) {
            break;
        }
    }
    fclose(f);
    *n = len;
    return buf;
}

// Message boundaries (offsets of each header) by walking the well-formed stream; junk
// between messages is skipped byte by byte. Returns the count; offs[count] = end.
static size_t message_offsets(const uint8_t *d, size_t n, size_t **out)
{
    size_t cap = 4096, k = 0, i = 0;
    size_t *o = malloc(cap * sizeof *o);
    while (i + SL_PROTO_HEADER_BYTES <= n && o != NULL) {
        if (memcmp(d + i, sl_proto_signature, SL_PROTO_SIGNATURE_BYTES) != 0) {
            i++;
            continue;
        }
        const uint32_t len = ((uint32_t)d[i + 18] << 24) | ((uint32_t)d[i + 19] << 16) |
                             ((uint32_t)d[i + 20] << 8) | d[i + 21];
        if (k + 2 > cap) {
            cap *= 2;
            o = realloc(o, cap * sizeof *o);
            if (o == NULL) {
                break;
            }
        }
        o[k++] = i;
        i += SL_PROTO_HEADER_BYTES + (size_t)len;
    }
    if (o != NULL) {
        o[k] = n;
    }
    *out = o;
    return k;
}

static int init_pipeline(const opts_t *o, const sl_board_t *board)
{
    sl_pipeline_cfg_t c;
    sl_pipeline_cfg_default(&c, board);
    c.port.can_tx = can_tx;
    c.port.on_rotation = on_rotation;
    c.port.ctx = &g_b;
    if (o->n > 0) {
        c.mask_frames = (uint8_t)o->n;
    }
    if (o->beam_cdeg > 0) {
        c.detect.beam_width_cdeg = (uint16_t)o->beam_cdeg;
    }
    if (o->no_learn) {
        c.learn = false; // the board's prior, no floor: detection at the threshold
    }
    if (o->no_profile) {
        c.profile = false; // the mask's bounds and the board's d(r) (sl_profile.h off)
    }
    if (o->fit) {
        c.fit = true; // bounds from the sensor model's fit (SL_CFG_FIT builds: sl-bench-host)
    }
    if (o->threshold >= 0) {
        c.threshold = (uint16_t)o->threshold;
    }
    const sl_err_t e = sl_pipeline_init(&g_pl, board, &c);
    if (e != SL_OK) {
        fprintf(stderr, "sl-bench: sl_pipeline_init: %s (%s)\n", sl_err_str(e),
                g_pl.last_err_msg != NULL ? g_pl.last_err_msg : "?");
        return 1;
    }
    sl_pipeline_set_link_state(&g_pl, SL_CAN_LINK_STREAMING);
    return 0;
}

static uint64_t now_for(size_t off, size_t total, uint64_t rotations_est)
{
    // 250 ms per rotation's worth of bytes (the core only compares times).
    return 1000000U + (uint64_t)((double)off / (double)total * (double)rotations_est * 250000.0);
}

static void set_motion(const opts_t *o, uint64_t now)
{
    if (o->speed_mm_s >= 0) {
        sl_pipeline_set_motion(&g_pl, (int32_t)o->speed_mm_s, true, 0, true, now);
    }
}

int main(int argc, char **argv)
{
    opts_t o = {.board = "paper-sim", .chunk = 65536, .repeat = 5, .loop = 1, .threshold = -1,
                .speed_mm_s = -1};
    const int info = sl_cli_info(argc, argv, SL_BENCH_PROG, usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--board") == 0 && v) {
            o.board = v, i++;
        } else if (strcmp(a, "--chunk") == 0 && v) {
            o.chunk = (size_t)strtoull(v, NULL, 10), i++;
        } else if (strcmp(a, "--repeat") == 0 && v) {
            o.repeat = atoi(v), i++;
        } else if (strcmp(a, "--loop") == 0 && v) {
            o.loop = atoi(v), i++;
        } else if (strcmp(a, "--n") == 0 && v) {
            o.n = atoi(v), i++;
        } else if (strcmp(a, "--beam-cdeg") == 0 && v) {
            o.beam_cdeg = atoi(v), i++;
        } else if (strcmp(a, "--no-profile") == 0) {
            o.no_profile = 1;
        } else if (strcmp(a, "--no-learn") == 0) {
            o.no_learn = 1;
        } else if (strcmp(a, "--fit") == 0) {
            o.fit = 1;
        } else if (strcmp(a, "--threshold") == 0 && v) {
            o.threshold = atoi(v), i++;
        } else if (strcmp(a, "--speed-mm-s") == 0 && v) {
            o.speed_mm_s = atol(v), i++;
        } else if (strcmp(a, "--callgrind") == 0 && v) {
            o.callgrind = v, i++;
        } else if (strcmp(a, "--quiet") == 0) {
            o.quiet = true;
        } else if (takes_value(a) && v == NULL) {
            return sl_cli_bad_value(SL_BENCH_PROG, a, "needs a value", usage);
        } else if (a[0] == '-' || o.capture != NULL) {
            return sl_cli_unknown(SL_BENCH_PROG, a, usage);
        } else {
            o.capture = a;
        }
    }
    if (o.capture == NULL) {
        return sl_cli_usage_error(SL_BENCH_PROG, "missing CAPTURE", usage);
    }
    if (o.chunk == 0) {
        return sl_cli_bad_value(SL_BENCH_PROG, "--chunk", "must be at least 1", usage);
    }
    if (o.repeat < 1) {
        return sl_cli_bad_value(SL_BENCH_PROG, "--repeat", "must be at least 1", usage);
    }
    if (o.loop < 1) {
        return sl_cli_bad_value(SL_BENCH_PROG, "--loop", "must be at least 1", usage);
    }
    const sl_board_t *board = sl_board_find(o.board);
    if (board == NULL) {
        fprintf(stderr, "sl-bench: board %s is not linked in\n", o.board);
        return 2;
    }
    size_t n1 = 0;
    uint8_t *one = read_file(o.capture, &n1);
    if (one == NULL || n1 == 0) {
        fprintf(stderr, "sl-bench: cannot read %s\n", o.capture);
        return 1;
    }
    const size_t n = n1 * (size_t)o.loop;
    uint8_t *data = malloc(n);
    if (data == NULL) {
        fprintf(stderr, "sl-bench: out of memory\n");
        return 1;
    }
    for (int k = 0; k < o.loop; k++) {
        memcpy(data + (size_t)k * n1, one, n1);
    }
    free(one);
    size_t *offs = NULL;
    const size_t msgs = message_offsets(data, n, &offs);
    if (offs == NULL) {
        fprintf(stderr, "sl-bench: out of memory\n");
        return 1;
    }
    const uint64_t rot_est = msgs / board->azimuths + 1U;

    printf("capture: %s (x%d)\n", o.capture, o.loop);
    printf("board: %s\n", board->name);
    printf("config: SL_CFG_MAX_AZIMUTHS %d SL_CFG_ROI_BINS %d SL_CFG_MASK_BINS %d "
           "SL_CFG_MASK_FRAMES_MAX %d SL_CFG_MAX_TARGETS %d\n",
           SL_CFG_MAX_AZIMUTHS, SL_CFG_ROI_BINS, SL_CFG_MASK_BINS, SL_CFG_MASK_FRAMES_MAX,
           SL_CFG_MAX_TARGETS);
    printf("sizeof_pipeline: %zu\n", sizeof(sl_pipeline_t));
    printf("sizeof_parts: mask %zu detect %zu tracker %zu scan %zu proto %zu reasm %zu\n",
           sizeof(sl_mask_t), sizeof(sl_detect_t), sizeof(sl_tracker_t), sizeof(sl_scan_t),
           sizeof(sl_proto_t), (size_t)SL_PIPELINE_REASM_BYTES);
    printf("bytes: %zu\n", n);
    printf("messages: %zu\n", msgs);
    printf("chunk: %zu\n", o.chunk);

    const bool cg_run = o.callgrind != NULL && strcmp(o.callgrind, "run") == 0;
    const bool cg_lat = o.callgrind != NULL && strcmp(o.callgrind, "latency") == 0;
    if (o.callgrind != NULL && !cg_run && !cg_lat) {
        return sl_cli_bad_value(SL_BENCH_PROG, "--callgrind", "must be run or latency", usage);
    }

    // --- throughput: whole capture in chunks
    double best = 1e30;
    const int runs = (cg_run || cg_lat) ? 1 : o.repeat;
    for (int r = 0; r < (cg_lat ? 0 : runs); r++) {
        memset(&g_b, 0, sizeof g_b);
        if (init_pipeline(&o, board) != 0) {
            return 1;
        }
        set_motion(&o, 1000000U);
        const double t0 = now_s();
        if (cg_run) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        for (size_t i = 0; i < n; i += o.chunk) {
            const size_t k = n - i < o.chunk ? n - i : o.chunk;
            const uint64_t now = now_for(i, n, rot_est);
            set_motion(&o, now); // the vehicle bus refreshes it (VehicleMotion: 50 Hz)
            (void)sl_pipeline_feed(&g_pl, data + i, k, now);
        }
        (void)sl_pipeline_finish(&g_pl, now_for(n, n, rot_est));
        if (cg_run) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        const double dt = now_s() - t0;
        best = dt < best ? dt : best;
    }
    if (!cg_lat) {
        printf("azimuths: %" PRIu32 "\n", g_pl.stats.azimuths);
        printf("rotations: %" PRIu64 "\n", g_b.rotations);
        printf("targets: %" PRIu64 "\n", g_b.targets);
        printf("can_frames: %" PRIu64 "\n", g_b.frames);
        printf("missing: %" PRIu32 " resyncs: %" PRIu32 " cut: %" PRIu32 " mask_bins: %u n: %u\n",
               g_pl.stats.azimuths_missing, g_pl.proto.stats.resyncs, g_pl.proto.stats.cut,
               (unsigned)g_pl.mask_bins, (unsigned)g_pl.mask.frames);
        const sl_detect_stats_t *ds = &g_pl.detect.stats;
        printf("detect: runs %" PRIu32 " groups %" PRIu32 " targets %" PRIu32
               " rejected near %" PRIu32 " shadow %" PRIu32 " wide %" PRIu32 " broken %" PRIu32
               " short %" PRIu32 " rho %" PRIu32 " weak %" PRIu32 "\n",
               ds->runs, ds->groups, ds->targets, ds->rejected[SL_DETECT_REJ_NEAR],
               ds->rejected[SL_DETECT_REJ_SHADOW], ds->rejected[SL_DETECT_REJ_WIDE],
               ds->rejected[SL_DETECT_REJ_BROKEN], ds->rejected[SL_DETECT_REJ_SHORT],
               ds->rejected[SL_DETECT_REJ_RHO], ds->rejected[SL_DETECT_REJ_WEAK]);
        uint32_t win_max = 0;
        for (uint32_t a = 0; a < g_pl.detect.azimuths; a++) {
            win_max = g_pl.detect.win_bins[a] > win_max ? g_pl.detect.win_bins[a] : win_max;
        }
        const sl_tiltobs_stats_t *ts = &g_pl.tilt.stats;
        printf("tilt: observations %" PRIu32 " fits %" PRIu32 " resets %" PRIu32
               " no_ring %" PRIu32 " sizeof %zu\n",
               ts->observations, ts->fits, ts->resets, ts->no_ring, sizeof(sl_tiltobs_t));
        printf("detect_window: near %u win_max %u\n", (unsigned)g_pl.detect.near_bins,
               (unsigned)win_max);
        const sl_response_t *rs = &g_pl.resp;
        printf("model: response %s peaks %" PRIu32 " half_power_bins %.2f floor_dB/threshold",
               rs->source == SL_RESPONSE_LEARNED      ? "learned"
               : rs->source == SL_RESPONSE_CALIBRATED ? "calibrated"
                                                      : "prior",
               rs->learn_n, sl_response_hpw_q8(rs) / 256.0);
        for (uint32_t b = 0; b * SL_RESP_FLOOR_BAND < g_pl.mask_bins; b++) {
            const int32_t fl = sl_response_floor_lp(rs, b * SL_RESP_FLOOR_BAND);
            if (fl == INT32_MIN) {
                printf(" -/%u", (unsigned)g_pl.thr_band[b]);
            } else {
                printf(" %.1f/%u", fl * 3.0103 / 256.0, (unsigned)g_pl.thr_band[b]);
            }
        }
        printf("\n");
        printf("wall_s: %.6f\n", best);
        printf("MB_per_s: %.1f\n", (double)n / best / 1e6);
        printf("us_per_azimuth: %.4f\n",
               g_pl.stats.azimuths ? best * 1e6 / g_pl.stats.azimuths : 0.0);
    }
    if (cg_run) {
        free(offs);
        free(data);
        return 0;
    }

    // --- latency: one message per call; pre-pass to find the rotation-completing messages
    memset(&g_b, 0, sizeof g_b);
    g_b.complete_msg = malloc(256 * sizeof *g_b.complete_msg);
    g_b.cap_complete = 256;
    if (init_pipeline(&o, board) != 0) {
        return 1;
    }
    set_motion(&o, 1000000U);
    for (size_t m = 0; m < msgs; m++) {
        g_b.cur_msg = m;
        const uint64_t now = now_for(offs[m], n, rot_est);
        set_motion(&o, now);
        (void)sl_pipeline_feed(&g_pl, data + offs[m], offs[m + 1] - offs[m], now);
    }
    // (the last rotation completes at EOF, not on a message: not a latency sample)
    uint64_t *done = g_b.complete_msg;
    const uint64_t nd = g_b.n_complete;
    for (int rep = 0; rep < (cg_lat ? 1 : o.repeat); rep++) {
        const uint64_t *keep = done;
        memset(&g_b, 0, sizeof g_b);
        g_b.timing = !cg_lat;
        g_b.cg_latency = cg_lat;
        if (init_pipeline(&o, board) != 0) {
            return 1;
        }
        set_motion(&o, 1000000U);
        uint64_t next = 0;
        for (size_t m = 0; m < msgs; m++) {
            const bool arm = next < nd && keep[next] == m;
            const uint64_t now = now_for(offs[m], n, rot_est);
            set_motion(&o, now);
            if (arm) {
                next++;
                g_b.armed = true;
                if (cg_lat) {
                    CALLGRIND_TOGGLE_COLLECT;
                }
                clock_gettime(CLOCK_MONOTONIC, &g_b.t0);
            }
            (void)sl_pipeline_feed(&g_pl, data + offs[m], offs[m + 1] - offs[m], now);
            if (g_b.armed) { // no rotation after all (cannot happen: same input, same state)
                g_b.armed = false;
                if (cg_lat) {
                    CALLGRIND_TOGGLE_COLLECT;
                }
            }
        }
        if (!cg_lat && g_b.lat_n > 0 && rep == o.repeat - 1) {
            printf("latency_rotations: %" PRIu64 "\n", g_b.lat_n);
            printf("latency_us_mean: %.3f\n", g_b.lat_sum_us / (double)g_b.lat_n);
            printf("latency_us_max: %.3f\n", g_b.lat_max_us);
        }
        if (cg_lat) {
            printf("latency_rotations: %" PRIu64 "\n", nd);
        }
    }
    free(done);
    free(offs);
    free(data);
    return 0;
}
