// SPDX-License-Identifier: MIT
// fuzz_rfit: libFuzzer entry point for the sensor model and the forward-model fit
// (sl_response.h, sl_rfit.h).
//
// The fit is fixed-point arithmetic on 64-bit intermediates over whatever profile a radar
// and a response hand it: any powers (0 to 2^32 - 1, floors from 1), any plausible or
// implausible response shape, any window length, looks and density. It must never overflow
// (undefined behaviour under UBSan), crash, loop without bound, or return a result out of
// its documented range; the learner must accept any row.
//
// Input (read front to back; missing bytes read as 0):
//   u8 n (8 + n % (SL_RFIT_MAX_N - 7)), u8 looks (1 + looks, as Q8 x 256), u8 shape (bit 0),
//   u8 origin (bins, 0 means 1), u8 floor exponent (floor = 1 << (e % 28) | low bits);
//   SL_RESP_TAPS x u8: the response's drops (value x 32 Q8, the centre forced to 0; an
//   implausible shape falls back to the prior, as sl_response_set refuses it);
//   n x u8 exponent + u8 mantissa: y_k = (256 + m) << (e % 24) >> 8, or 0 when e = 255;
//   the rest: one row for the learner (up to 1,024 bytes).
// Invariants: SL_OK; a quality of sl_rfit_quality_t; a and b inside the window with
// b >= a; the evaluations bounded by the iteration and halving limits; |corr| <= 32767;
// NO_SIGNAL only when no power lies above the floor; the learner returns >= 0 and its
// response stays plausible (its drops 0 at the centre).
//
// The same file builds two ways (as fuzz_proto.c):
//  - -DSL_FUZZ_LIBFUZZER -fsanitize=fuzzer: the `fuzz_rfit` libFuzzer binary;
//  - without: `fuzz_rfit_replay [--random N] [file|dir]...` (the `fuzz_rfit_random` ctest).
#define _POSIX_C_SOURCE 200809L
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_response.h"
#include "shadowlean/sl_rfit.h"

#define CHECK(c)                                                                             \
    do {                                                                                     \
        if (!(c)) {                                                                          \
            fprintf(stderr, "fuzz_rfit: invariant failed: %s (%s:%d)\n", #c, __FILE__,       \
                    __LINE__);                                                               \
            abort();                                                                         \
        }                                                                                    \
    } while (0)

typedef struct reader {
    const uint8_t *p;
    size_t n, i;
} reader_t;

static uint8_t u8(reader_t *r)
{
    return (r->i < r->n) ? r->p[r->i++] : 0U;
}

static unsigned long g_fits, g_ok, g_oom, g_nosig, g_nconv, g_peaks;

static void run_one(const uint8_t *data, size_t size)
{
    reader_t rd = {data, size, 0};
    const uint16_t n = (uint16_t)(8U + u8(&rd) % (SL_RFIT_MAX_N - 7U));
    const uint16_t looks_q8 = (uint16_t)(256U * (1U + u8(&rd) % 64U));
    const uint8_t shape = (uint8_t)(u8(&rd) & 1U);
    const uint8_t org = u8(&rd);
    const uint8_t fe = u8(&rd);
    const uint32_t floor_p = (1U << (fe % 28U)) | (uint32_t)(fe >> 5);
    static const sl_vscale_t cts = SL_VSCALE_CTS350X;
    sl_response_t r;
    CHECK(sl_response_init(&r, &cts, NULL, NULL) == SL_OK);
    uint16_t d[SL_RESP_TAPS];
    for (int i = 0; i < SL_RESP_TAPS; i++) {
        d[i] = (uint16_t)(u8(&rd) * 32U);
    }
    d[SL_CFG_RESP_HALF] = 0;
    const sl_err_t se = sl_response_set(&r, d, SL_RESPONSE_CALIBRATED);
    CHECK(se == SL_OK || se == SL_ERR_ARG);
    uint32_t y[SL_RFIT_MAX_N];
    bool above = false;
    for (uint16_t k = 0; k < n; k++) {
        const uint8_t e = u8(&rd);
        const uint8_t m = u8(&rd);
        y[k] = (e == 255U) ? 0U : (uint32_t)(((uint64_t)(256U + m) << (e % 24U)) >> 8);
        above = above || y[k] > floor_p;
    }
    sl_rfit_in_t in;
    memset(&in, 0, sizeof(in));
    in.y = y;
    in.floor = floor_p;
    in.n = n;
    in.looks_q8 = looks_q8;
    in.shape = shape;
    in.origin_q8 = (uint32_t)(org == 0U ? 1U : org) * 256U;
    sl_rfit_out_t out;
    CHECK(sl_rfit(&r, &in, &out) == SL_OK);
    g_fits++;
    CHECK(out.quality <= (uint8_t)SL_RFIT_NOT_CONVERGED);
    CHECK(out.iters <= SL_RFIT_ITERS);
    CHECK(out.evals <= 1U + SL_RFIT_ITERS * (SL_RFIT_HALVINGS + 1U));
    CHECK(out.corr_q15 <= 32767 && out.corr_q15 >= -32767);
    switch (out.quality) {
    case SL_RFIT_NO_SIGNAL:
        g_nosig++;
        break;
    case SL_RFIT_OUT_OF_MODEL:
        g_oom++;
        break;
    case SL_RFIT_NOT_CONVERGED:
        g_nconv++;
        break;
    default:
        g_ok++;
        break;
    }
    if (out.quality != (uint8_t)SL_RFIT_NO_SIGNAL) {
        CHECK(above);
        CHECK(out.a_q8 >= 0 && out.b_q8 >= out.a_q8 && out.b_q8 <= (int32_t)(n - 1U) * 256);
    }
    // the rest: a row for the learner
    const size_t left = (rd.i < rd.n) ? rd.n - rd.i : 0U;
    const uint32_t bins = (uint32_t)((left > 1024U) ? 1024U : left);
    if (bins >= 2U) {
        const int got = sl_response_learn_row(&r, rd.p + rd.i, bins, 0, bins);
        CHECK(got >= 0);
        g_peaks += (unsigned long)got;
        (void)sl_response_update(&r);
        CHECK(r.drop_q8[SL_CFG_RESP_HALF] == 0U);
    }
}

#ifdef SL_FUZZ_LIBFUZZER
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    run_one(data, size);
    return 0;
}
#else
#include "replay_files.h"

static unsigned long g_inputs;

static int run_file(const char *path, const char *name, unsigned long index)
{
    (void)name;
    (void)index;
    static uint8_t buf[1U << 16];
    size_t n = 0;
    if (replay_read("fuzz_rfit_replay", path, buf, sizeof buf, &n) != 0) {
        return 1;
    }
    run_one(buf, n);
    g_inputs++;
    return 0;
}

static uint64_t g_rng = 0x2545F4914F6CDD1DULL;
static uint8_t rnd(void)
{
    return replay_rnd(&g_rng);
}

// Pseudo-random inputs: half of them a plausible return (a Gaussian-like lobe over a floor,
// a smooth response), half unconstrained bytes.
static void run_random(unsigned long count, const char *write_dir)
{
    static uint8_t buf[2048];
    for (unsigned long k = 0; k < count; k++) {
        size_t len = 0;
        const bool wild = (k & 1U) != 0U;
        const uint8_t n = rnd();
        buf[len++] = n;
        buf[len++] = rnd();
        buf[len++] = rnd();
        buf[len++] = (uint8_t)(40U + rnd() % 60U);
        buf[len++] = wild ? rnd() : (uint8_t)(4U + rnd() % 8U);
        for (int i = 0; i < SL_RESP_TAPS; i++) {
            const int o = i - SL_CFG_RESP_HALF;
            const unsigned w = 2U + rnd() % 6U;
            const unsigned drop = (unsigned)(o * o) * 8U / (w * w);
            buf[len++] = wild ? rnd() : (uint8_t)(drop > 255U ? 255U : drop);
        }
        const unsigned nn = 8U + n % (SL_RFIT_MAX_N - 7U);
        const unsigned c = rnd() % nn;
        const unsigned amp = 8U + rnd() % 16U;
        for (unsigned i = 0; i < nn; i++) {
            const int dd = (int)i - (int)c;
            const int e = (int)amp - dd * dd / 8;
            const unsigned ev = (e < 6) ? 6U + rnd() % 2U : (unsigned)e;
            buf[len++] = wild ? rnd() : (uint8_t)ev;
            buf[len++] = rnd();
        }
        const unsigned row = rnd() % 4U == 0U ? 0U : 200U + rnd() % 800U;
        for (unsigned i = 0; i < row && len < sizeof buf; i++) {
            buf[len++] = (i % 97U == 50U) ? 120U : (uint8_t)(rnd() % 16U);
        }
        if (write_dir != NULL) { // keep it as a libFuzzer run's seed
            replay_write(write_dir, k, buf, len);
        }
        run_one(buf, len);
        g_inputs++;
    }
}

int main(int argc, char **argv)
{
    replay_args_t a;
    if (replay_args(argc, argv, "fuzz_rfit_replay", run_file, &a) != 0) {
        return 1;
    }
    const unsigned long files = a.files;
    const int bad = a.bad;
    run_random(a.random_n, a.write_dir);
    printf("fuzz_rfit_replay: %lu inputs (%lu files), all invariants held; %lu fits: OK %lu, "
           "OUT_OF_MODEL %lu, NO_SIGNAL %lu, NOT_CONVERGED %lu; %lu peaks learned\n",
           g_inputs, files, g_fits, g_ok, g_oom, g_nosig, g_nconv, g_peaks);
    return bad;
}
#endif
