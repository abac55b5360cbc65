// SPDX-License-Identifier: MIT
// Unit tests for sl_pipeline_on_msg() (decode once): a caller's own decoder handing every
// message to the pipeline gives the same rotations and the same CAN frames, byte for byte,
// as sl_pipeline_feed() on the same bytes: a CTS350-X-like stream (tests/support/golden/sl_golden.c,
// robotcar-leaf geometry) with keep-alives, Health messages and junk cut into a message, fed
// in odd chunks; Status reports the caller's decoder resyncs (sl_pipeline_set_decoder_stats).
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_pipeline.h"
#include "sl_golden.h"

#define MAX_FRAMES 4096

typedef struct rec {
    sl_can_frame_t f[MAX_FRAMES];
    size_t n;
    uint32_t rotations, targets;
} rec_t;

static sl_err_t rec_tx(void *ctx, const sl_can_frame_t *f)
{
    rec_t *r = ctx;
    if (r->n < MAX_FRAMES) {
        r->f[r->n++] = *f;
    }
    return SL_OK;
}

static void rec_rot(void *ctx, const sl_pipeline_rotation_t *rot)
{
    rec_t *r = ctx;
    r->rotations++;
    r->targets += rot->n_targets;
}

static sl_pipeline_t pa, pb;
static rec_t ra, rb;

typedef struct caller {
    sl_pipeline_t *p;
    uint64_t now;
} caller_t;

static void caller_on_msg(void *ctx, const sl_proto_msg_t *m)
{
    caller_t *c = ctx;
    assert_int_equal(sl_pipeline_on_msg(c->p, m, c->now), SL_OK);
}

static uint8_t *stream(size_t *n)
{
    sl_golden_params_t gp = sl_golden_defaults();
    gp.rotations = 20;
    gp.keep_alive_every = 53;
    gp.health_every = 211;
    const size_t g = sl_golden_size(&gp);
    static const uint8_t junk[37] = {0x00, 0x01, 0x03, 0x03, 0x07, 0x77, 0x12, 0x00, 0x01};
    uint8_t *b = malloc(g + sizeof junk);
    assert_non_null(b);
    assert_int_equal(sl_golden_build(b, g, &gp), g);
    // junk cut into the middle of a message a third of the way in: a truncated message and
    // a resync for both decoders
    const size_t at = g / 3;
    memmove(b + at + sizeof junk, b + at, g - at);
    memcpy(b + at, junk, sizeof junk);
    *n = g + sizeof junk;
    return b;
}

static void init_pipe(sl_pipeline_t *p, rec_t *r, const sl_board_t *board)
{
    sl_pipeline_cfg_t cfg;
    sl_pipeline_cfg_default(&cfg, board);
    cfg.port.can_tx = rec_tx;
    cfg.port.on_rotation = rec_rot;
    cfg.port.ctx = r;
    memset(r, 0, sizeof *r);
    assert_int_equal(sl_pipeline_init(p, board, &cfg), SL_OK);
}

static void test_pipeline_on_msg_gives_the_frames_of_feed(void **state)
{
    (void)state;
    const sl_board_t *board = sl_board_find("robotcar-leaf");
    assert_non_null(board);
    size_t n;
    uint8_t *b = stream(&n);
    init_pipe(&pa, &ra, board);
    init_pipe(&pb, &rb, board);

    // The caller's decoder: whole payloads (1 MiB reassembly), as the Linux port runs it.
    const size_t reasm_size = 1u << 20;
    uint8_t *reasm = malloc(reasm_size);
    assert_non_null(reasm);
    caller_t caller = {&pb, 0};
    const sl_proto_cfg_t pc = {.reasm_buf = reasm, .reasm_size = reasm_size,
                               .max_payload_bytes = (uint32_t)reasm_size, .truncate_long = false,
                               .on_msg = caller_on_msg, .ctx = &caller};
    sl_proto_t dec;
    assert_int_equal(sl_proto_init(&dec, &pc), SL_OK);
    sl_pipeline_set_decoder_stats(&pb, &dec.stats);

    uint64_t now = 1000;
    for (size_t i = 0; i < n;) {
        const size_t k = n - i < 7777 ? n - i : 7777; // odd chunks: messages span calls
        assert_int_equal(sl_pipeline_feed(&pa, b + i, k, now), SL_OK);
        caller.now = now;
        assert_int_equal(sl_proto_feed(&dec, b + i, k, now), SL_OK);
        i += k;
        now += 250;
    }
    assert_int_equal(sl_pipeline_finish(&pa, now), SL_OK);
    (void)sl_proto_finish(&dec);
    assert_int_equal(sl_pipeline_finish(&pb, now), SL_OK);

    assert_true(ra.rotations >= 19);
    assert_int_equal(rb.rotations, ra.rotations);
    assert_int_equal(rb.targets, ra.targets);
    assert_true(ra.n >= 2 * 19); // LeanWarning + Status per rotation at least
    assert_int_equal(rb.n, ra.n);
    for (size_t i = 0; i < ra.n; i++) {
        assert_int_equal(rb.f[i].id, ra.f[i].id);
        assert_int_equal(rb.f[i].dlc, ra.f[i].dlc);
        assert_memory_equal(rb.f[i].data, ra.f[i].data, 8);
    }
    // the junk was seen by both decoders and reported through the caller's counters
    assert_true(pa.proto.stats.resyncs > 0);
    assert_int_equal(dec.stats.resyncs, pa.proto.stats.resyncs);
    assert_int_equal(pb.proto.stats.messages, 0); // the pipeline's own decoder never ran
    assert_int_equal(pb.stats.rotations, pa.stats.rotations);
    free(reasm);
    free(b);
}

static void test_pipeline_on_msg_rejects_null_and_uninitialised(void **state)
{
    (void)state;
    static sl_pipeline_t raw; // zeroed: not initialised
    const sl_proto_msg_t m = {0};
    assert_int_equal(sl_pipeline_on_msg(NULL, &m, 0), SL_ERR_ARG);
    assert_int_equal(sl_pipeline_on_msg(&raw, &m, 0), SL_ERR_ARG);
    const sl_board_t *board = sl_board_find("robotcar-leaf");
    init_pipe(&pa, &ra, board);
    assert_int_equal(sl_pipeline_on_msg(&pa, NULL, 0), SL_ERR_ARG);
    // NULL stats: back to the pipeline's own decoder
    sl_proto_stats_t other = {0};
    sl_pipeline_set_decoder_stats(&pa, &other);
    assert_ptr_equal(pa.decoder_stats, &other);
    sl_pipeline_set_decoder_stats(&pa, NULL);
    assert_ptr_equal(pa.decoder_stats, &pa.proto.stats);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pipeline_on_msg_gives_the_frames_of_feed),
        cmocka_unit_test(test_pipeline_on_msg_rejects_null_and_uninitialised),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
