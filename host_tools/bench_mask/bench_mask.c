// SPDX-License-Identifier: MIT
// sl-bench-mask: cost of threshold + consistency mask + detection + tracking on synthetic
// CTS350-X-like rotations (400 azimuths x 512 ROI bins), for the n this variant was built
// with (SL_CFG_MASK_FRAMES_MAX, one executable per n; see CMakeLists.txt).
//
// Prints the RAM of each stage (sizeof) and wall-clock nanoseconds per azimuth. Instruction
// counts: run under callgrind with --collect-atstart=no and `--collect STAGE`; the program
// then switches collection on around that stage only, for the measured rotations only
// (after a warm-up of n + 4 rotations so the mask is stable and detection sees targets).
// host_tools/bench_mask/callgrind.sh does that for every stage and variant.
//
// Scene (deterministic): a bright near-field band (bins 0..35, REAL_SCANS.md s.2), a dark
// shadow ring with exact zeros and rare transient speckle, flickering clutter beyond the
// shadow edge (bin 134 on paper-sim), stable walls outside the shadow, and 6 slender poles
// inside the shadow (3 azimuths each).
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sl_cli.h"
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_detect.h"
#include "shadowlean/sl_mask.h"
#include "shadowlean/sl_thresh.h"
#include "shadowlean/sl_track.h"

#ifdef SL_HAVE_CALLGRIND_H
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_TOGGLE_COLLECT
#endif

#define NAZ 400U
#define NBINS 512U
#define NW (NBINS / 32U)

#if SL_CFG_MAX_AZIMUTHS < 400 || SL_CFG_ROI_BINS < 512
#error "the bench needs 400 azimuths x 512 bins"
#endif

static sl_mask_t mask;
static sl_detect_t det;
static sl_tracker_t trk;
static uint32_t bits[NAZ][NW];
static uint8_t *power; // rotations x NAZ x NBINS
static const sl_board_t *board;
static uint32_t nbins = NBINS; // bins thresholded and masked (--detect-bins: only those read)

enum { C_NONE, C_THRESH, C_MASK, C_DETECT, C_TRACK, C_ALL };

static uint64_t rng = 0x2545F4914F6CDD1DULL;
static uint32_t rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 11);
}

#define SL_STR2(x) #x
#define SL_STR(x) SL_STR2(x)
#define PROG "sl-bench-mask-n" SL_STR(SL_CFG_MASK_FRAMES_MAX)

static void usage(FILE *out)
{
    fprintf(out, "usage: " PROG " [--board NAME] [--rotations MEASURED] [--detect-bins] "
                 "[--collect thresh|mask|detect|track|all]\n");
}

static const struct {
    uint16_t az, first, last;
} poles[6] = {{30, 68, 83}, {95, 60, 72}, {150, 80, 100}, {210, 70, 79}, {300, 66, 90},
              {370, 75, 88}};

static void make_scene(uint32_t rotations)
{
    power = malloc((size_t)rotations * NAZ * NBINS);
    if (power == NULL) {
        fprintf(stderr, PROG ": out of memory\n");
        exit(SL_EXIT_ERROR);
    }
    for (uint32_t r = 0; r < rotations; r++) {
        for (uint32_t a = 0; a < NAZ; a++) {
            uint8_t *row = power + ((size_t)r * NAZ + a) * NBINS;
            for (uint32_t k = 0; k < NBINS; k++) {
                const uint32_t u = rnd();
                uint8_t v;
                if (k < 36U) {
                    v = (uint8_t)((u % 100U) < 3U ? 30U : 45U + u % 40U); // band, 3% dips
                } else if (k < 134U) {
                    v = (uint8_t)((u % 100U) < 60U ? 0U : 6U + (u >> 8) % 20U);
                    if ((u >> 20) % 1000U < 3U) {
                        v = 55; // transient speckle
                    }
                } else {
                    v = (uint8_t)((u % 100U) < 35U ? 0U : 6U + (u >> 8) % 56U); // flicker
                }
                if ((a >= 40U && a < 80U && k >= 250U && k < 262U) ||
                    (a >= 200U && a < 260U && k >= 400U && k < 410U) ||
                    (a >= 330U && a < 345U && k >= 150U && k < 170U)) {
                    v = 90; // walls
                }
                for (uint32_t p = 0; p < 6U; p++) {
                    const uint32_t pa = poles[p].az;
                    if (a + 1U >= pa && a <= pa + 1U && k >= poles[p].first && k <= poles[p].last) {
                        v = 100;
                    }
                }
                row[k] = v;
            }
        }
    }
}

// The measured stages; noinline so profiles attribute them cleanly.
__attribute__((noinline)) void bench_thresh(uint32_t r);
__attribute__((noinline)) void bench_mask(void);
__attribute__((noinline)) sl_ssize_t bench_detect(void);
__attribute__((noinline)) void bench_track(uint32_t n, uint64_t now_us);

void bench_thresh(uint32_t r)
{
    const uint8_t *rot = power + (size_t)r * NAZ * NBINS;
    for (uint32_t a = 0; a < NAZ; a++) {
        sl_thresh_u8(rot + (size_t)a * NBINS, nbins, board->threshold, bits[a]);
    }
}

void bench_mask(void)
{
    for (uint32_t a = 0; a < NAZ; a++) {
        (void)sl_mask_update(&mask, (uint16_t)a, bits[a], NULL, NULL);
    }
    sl_mask_end_rotation(&mask);
}

sl_ssize_t bench_detect(void)
{
    return sl_detect_rotation_from_mask(&det, &mask);
}

void bench_track(uint32_t n, uint64_t now_us)
{
    sl_track_update(&trk, det.targets, n, now_us);
}

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    const char *board_name = "paper-sim";
    int collect = C_NONE;
    uint32_t measured = 16;
    int detect_bins = 0;
    const int info = sl_cli_info(argc, argv, PROG, usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; i++) {
        const int has_value = i + 1 < argc;
        if ((strcmp(argv[i], "--board") == 0 || strcmp(argv[i], "--rotations") == 0 ||
             strcmp(argv[i], "--collect") == 0) &&
            !has_value) {
            return sl_cli_bad_value(PROG, argv[i], "needs a value", usage);
        }
        if (strcmp(argv[i], "--board") == 0 && i + 1 < argc) {
            board_name = argv[++i];
        } else if (strcmp(argv[i], "--rotations") == 0 && i + 1 < argc) {
            measured = (uint32_t)strtoul(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--detect-bins") == 0) {
            detect_bins = 1;
        } else if (strcmp(argv[i], "--collect") == 0 && i + 1 < argc) {
            const char *s = argv[++i];
            collect = strcmp(s, "thresh") == 0   ? C_THRESH
                      : strcmp(s, "mask") == 0   ? C_MASK
                      : strcmp(s, "detect") == 0 ? C_DETECT
                      : strcmp(s, "track") == 0  ? C_TRACK
                      : strcmp(s, "all") == 0    ? C_ALL
                                                 : -1;
            if (collect < 0) {
                return sl_cli_bad_value(PROG, "--collect", "must be thresh|mask|detect|track|all",
                                        usage);
            }
        } else {
            return sl_cli_unknown(PROG, argv[i], usage);
        }
    }
    board = sl_board_find(board_name);
    if (board == NULL || board->azimuths != NAZ || board->roi_bins < NBINS) {
        fprintf(stderr, PROG ": --board: board '%s' missing or not 400 x >= 512\n", board_name);
        return SL_EXIT_USAGE;
    }
    const uint8_t n = SL_CFG_MASK_FRAMES_MAX;
    const uint32_t warmup = n + 4U;
    const uint32_t rotations = warmup + measured;
    make_scene(rotations);
    if (sl_detect_init(&det, board, NULL) != SL_OK || sl_track_init(&trk, board, NULL) != SL_OK) {
        fprintf(stderr, PROG ": init failed\n");
        return SL_EXIT_ERROR;
    }
    if (detect_bins) {
        nbins = SL_BITS_WORDS(sl_detect_bins_needed(&det)) * 32U;
    }
    if (sl_mask_init(&mask, NAZ, (uint16_t)nbins, n, SL_MASK_MAX_MISSED_DEFAULT) != SL_OK) {
        fprintf(stderr, PROG ": mask init failed\n");
        return SL_EXIT_ERROR;
    }
    double t_th = 0, t_mk = 0, t_dt = 0, t_tr = 0;
    sl_ssize_t targets = 0;
    uint64_t now_us = 0;
    for (uint32_t r = 0; r < rotations; r++) {
        const int m = r >= warmup;
        double t0 = now_ns();
        if (m && (collect == C_THRESH || collect == C_ALL)) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        bench_thresh(r);
        if (m && collect == C_THRESH) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        double t1 = now_ns();
        if (m && collect == C_MASK) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        bench_mask();
        if (m && collect == C_MASK) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        double t2 = now_ns();
        if (m && collect == C_DETECT) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        targets = bench_detect();
        if (m && collect == C_DETECT) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        double t3 = now_ns();
        if (m && collect == C_TRACK) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        bench_track((uint32_t)targets, now_us);
        if (m && (collect == C_TRACK || collect == C_ALL)) {
            CALLGRIND_TOGGLE_COLLECT;
        }
        double t4 = now_ns();
        now_us += 250000U;
        if (m) {
            t_th += t1 - t0;
            t_mk += t2 - t1;
            t_dt += t3 - t2;
            t_tr += t4 - t3;
        }
    }
    const double az = (double)measured * NAZ;
    printf("sl-bench-mask: n=%u (SL_CFG_MASK_FRAMES_MAX=%d, %d counter planes + 1), board %s, "
           "%u x %u bins (%u thresholded and masked), %u warm-up + %u measured rotations\n",
           (unsigned)n, SL_CFG_MASK_FRAMES_MAX, SL_MASK_COUNTER_PLANES, board->name,
           (unsigned)NAZ, (unsigned)NBINS, (unsigned)nbins, (unsigned)warmup, (unsigned)measured);
    printf("sizeof: sl_mask_t %zu  sl_detect_t %zu  sl_tracker_t %zu  (naive %u planes: %zu)\n",
           sizeof(sl_mask_t), sizeof(sl_detect_t), sizeof(sl_tracker_t), (unsigned)n,
           (size_t)n * SL_CFG_MAX_AZIMUTHS * SL_ROI_WORDS * 4U);
    printf("targets: %d (scene has 6 poles)  tracks: %u  rejected near/shadow/wide/broken: "
           "%u/%u/%u/%u per %u rotations\n",
           (int)targets, (unsigned)trk.live, (unsigned)det.stats.rejected[0],
           (unsigned)det.stats.rejected[1], (unsigned)det.stats.rejected[2],
           (unsigned)det.stats.rejected[3], (unsigned)det.stats.rotations);
    printf("wall ns/azimuth: thresh %.1f  mask %.1f  detect %.1f  track %.1f  total %.1f\n",
           t_th / az, t_mk / az, t_dt / az, t_tr / az, (t_th + t_mk + t_dt + t_tr) / az);
    printf("azimuths: %.0f\n", az);
    free(power);
    return targets == 6 ? 0 : 1;
}
