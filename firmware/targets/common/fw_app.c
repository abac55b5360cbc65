// SPDX-License-Identifier: MIT
// The example firmware's application (see fw_app.h).
#include "fw_app.h"

#include <string.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_pipeline.h"

// Frames and rotations are copied to these buffers by the port callbacks (cheap, inside
// the measured feed) and printed after the feed returns (outside it).
#define FW_MAX_FRAMES 64U
#define FW_MAX_ROTS 4U

typedef struct fw_rot {
    uint32_t rotation;
    uint16_t valid, missing, n_targets;
    uint8_t level;
} fw_rot_t;

typedef struct fw_state {
    sl_can_frame_t frames[FW_MAX_FRAMES];
    uint32_t frame_rot[FW_MAX_FRAMES];
    uint32_t n_frames;
    fw_rot_t rots[FW_MAX_ROTS];
    uint32_t n_rots;
    uint32_t rotation;   // rotations completed so far
    fw_result_t *res;
} fw_state_t;

static sl_pipeline_t g_pipeline; // the whole RAM of the module (sizeof: docs/PERFORMANCE.md)
static fw_state_t g_state;

static sl_err_t port_can_tx(void *ctx, const sl_can_frame_t *f)
{
    fw_state_t *s = (fw_state_t *)ctx;
    if (s->n_frames >= FW_MAX_FRAMES) {
        s->res->frames_lost++;
        return SL_OK;
    }
    s->frames[s->n_frames] = *f;
    s->frame_rot[s->n_frames] = s->rotation;
    s->n_frames++;
    return SL_OK;
}

static void port_on_rotation(void *ctx, const sl_pipeline_rotation_t *r)
{
    fw_state_t *s = (fw_state_t *)ctx;
    // on_rotation comes before this rotation's frames (sl_pipeline.h): number them by it.
    s->rotation = r->rotation;
    if (s->n_rots < FW_MAX_ROTS) {
        fw_rot_t *o = &s->rots[s->n_rots++];
        o->rotation = r->rotation;
        o->valid = r->valid;
        o->missing = r->missing;
        o->n_targets = r->n_targets;
        o->level = r->level;
    }
    s->res->rotations++;
    s->res->targets += r->n_targets;
}

char *fw_u64(char *buf, uint64_t v)
{
    char tmp[21];
    size_t n = 0;
    do {
        tmp[n++] = (char)('0' + (int)(v % 10U));
        v /= 10U;
    } while (v != 0U);
    for (size_t i = 0; i < n; i++) {
        buf[i] = tmp[n - 1U - i];
    }
    buf[n] = '\0';
    return buf;
}

static char *put(char *o, const char *s)
{
    while (*s != '\0') {
        *o++ = *s++;
    }
    return o;
}

static char *put_u(char *o, uint64_t v)
{
    char b[21];
    return put(o, fw_u64(b, v));
}

static char *put_hex(char *o, uint32_t v, int digits)
{
    static const char hx[] = "0123456789abcdef";
    for (int i = digits - 1; i >= 0; i--) {
        *o++ = hx[(v >> (4 * i)) & 0xFU];
    }
    return o;
}

static void flush(const fw_platform_t *pf, fw_state_t *s)
{
    char line[96];
    for (uint32_t i = 0; i < s->n_rots; i++) {
        const fw_rot_t *r = &s->rots[i];
        char *o = put(line, "rotation ");
        o = put_u(o, r->rotation);
        o = put(o, " valid ");
        o = put_u(o, r->valid);
        o = put(o, " missing ");
        o = put_u(o, r->missing);
        o = put(o, " targets ");
        o = put_u(o, r->n_targets);
        o = put(o, " level ");
        o = put_u(o, r->level);
        o = put(o, "\n");
        *o = '\0';
        pf->write(line);
    }
    for (uint32_t i = 0; i < s->n_frames; i++) {
        const sl_can_frame_t *f = &s->frames[i];
        char *o = put(line, "frame ");
        o = put_u(o, s->frame_rot[i]);
        o = put(o, " ");
        o = put_hex(o, f->id, 3);
        o = put(o, " ");
        o = put_u(o, f->dlc);
        o = put(o, " ");
        for (uint32_t k = 0; k < f->dlc && k < 8U; k++) {
            o = put_hex(o, f->data[k], 2);
        }
        o = put(o, "\n");
        *o = '\0';
        pf->write(line);
    }
    s->res->frames += s->n_frames;
    s->n_frames = 0;
    s->n_rots = 0;
}

sl_err_t fw_app_run(const fw_platform_t *pf, const char *board_name, const uint8_t *cap,
                    size_t len, size_t chunk, fw_result_t *res)
{
    const sl_board_t *board = board_name != NULL ? sl_board_find(board_name) : sl_board_at(0);
    if (board == NULL || chunk == 0U || res == NULL || pf == NULL) {
        return SL_ERR_ARG;
    }
    memset(res, 0, sizeof *res);
    memset(&g_state, 0, sizeof g_state);
    g_state.res = res;
    sl_pipeline_cfg_t cfg;
    sl_pipeline_cfg_default(&cfg, board);
#if SL_CFG_GROUND
    // The host's run of this application (tests/core/thumb/host_frames.c) is the firmware
    // configuration's reference, which has no ground: its frames (GroundPlane) stay off.
    cfg.ground = false;
#endif
    cfg.port.can_tx = port_can_tx;
    cfg.port.on_rotation = port_on_rotation;
    cfg.port.ctx = &g_state;
    const sl_err_t e = sl_pipeline_init(&g_pipeline, board, &cfg);
    if (e != SL_OK) {
        return e;
    }
    sl_pipeline_set_link_state(&g_pipeline, SL_CAN_LINK_STREAMING);
    uint64_t now_us = 0;
    for (size_t off = 0; off < len; off += chunk) {
        const size_t n = (len - off) < chunk ? (len - off) : chunk;
        now_us += 1000U;
        const uint32_t t0 = pf->ticks != NULL ? pf->ticks() : 0U;
        (void)sl_pipeline_feed(&g_pipeline, cap + off, n, now_us);
        const uint32_t t1 = pf->ticks != NULL ? pf->ticks() : 0U;
        res->ticks += (uint64_t)((t1 - t0) & pf->tick_mask);
        flush(pf, &g_state);
    }
    // End of stream: finish() completes the last rotation (timed like a feed).
    const uint32_t t0 = pf->ticks != NULL ? pf->ticks() : 0U;
    (void)sl_pipeline_finish(&g_pipeline, now_us + 1000U);
    const uint32_t t1 = pf->ticks != NULL ? pf->ticks() : 0U;
    res->ticks += (uint64_t)((t1 - t0) & pf->tick_mask);
    flush(pf, &g_state);
    res->azimuths = g_pipeline.stats.azimuths;
    return SL_OK;
}
