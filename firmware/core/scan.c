// SPDX-License-Identifier: MIT
// Scan assembly (sl_scan.h): FFT messages -> rows of one rotation, with gap, duplicate and
// reorder bookkeeping. Rows are written exactly once per rotation: on arrival (ROI copy +
// zero fill of a short row) or, for rows never received, zero-filled at completion.
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_scan.h"

int32_t sl_scan_az_index(uint16_t azimuths, uint16_t encoder_size, uint16_t ticks)
{
    if (azimuths == 0U || encoder_size == 0U || ticks >= encoder_size) {
        return -1;
    }
    // The cell containing the encoder value (round down). Exact in 32 bits:
    // (2^16-1)^2 < 2^32, and ticks < encoder_size makes the quotient < azimuths.
    const uint32_t idx = ((uint32_t)ticks * azimuths) / encoder_size;
    return (int32_t)idx;
}

// sl_scan_az_index_geo(): sl_scan_az_index() without a division, for the per-azimuth path:
// the reciprocal recip = floor(az 2^16 / enc) is set with the geometry (az <= enc).
// est = ticks recip / 2^16 is idx or idx - 1 (recip is low by < 1, times ticks / 2^16 < 1),
// and one compare fixes it. All products < 2^32: ticks < 2^16, recip <= 2^16 when
// az <= enc, idx < az <= 4096.
int32_t sl_scan_az_index_geo(const sl_scan_t *s, uint16_t ticks)
{
    SL_ASSERT(s != NULL);
    if (s->azimuths == 0U) {
        return -1;
    }
    if (s->az_recip == 0U) {
        return sl_scan_az_index(s->azimuths, s->encoder_size, ticks);
    }
    if (ticks >= s->encoder_size) {
        return -1;
    }
    uint32_t est = ((uint32_t)ticks * s->az_recip) >> 16;
    if ((est + 1U) * s->encoder_size <= (uint32_t)ticks * s->azimuths) {
        est++;
    }
    return (int32_t)est;
}

static void frame_clear(sl_scan_frame_t *f)
{
    memset(f, 0, sizeof *f);
}

// Frame mode: copy the bookkeeping header into the filling frame (its per-azimuth arrays
// are written as rows arrive).
static void frame_sync(sl_scan_frame_t *f, const sl_scan_rot_t *r)
{
    f->rotation = r->rotation;
    f->azimuths = r->azimuths;
    f->encoder_size = r->encoder_size;
    f->roi_bins = r->roi_bins;
    f->end = r->end;
    f->head = r->head;
    f->head_sweep = r->head_sweep;
    f->t_first_us = r->t_first_us;
    f->t_last_us = r->t_last_us;
    f->stats = r->stats;
}

static void frame_start(sl_scan_t *s)
{
    sl_scan_rot_t *r = &s->rot;
    const uint16_t n = s->azimuths;
    r->rotation = s->rotation;
    r->azimuths = n;
    r->encoder_size = s->encoder_size;
    r->roi_bins = s->cfg.roi_bins;
    r->end = SL_SCAN_END_WRAP;
    r->head = 0;
    r->head_sweep = 0;
    r->t_first_us = UINT64_MAX;
    r->t_last_us = 0;
    memset(&r->stats, 0, sizeof r->stats);
    memset(r->flags, 0, n);
    if (s->fill != NULL) {
        frame_sync(s->fill, r);
        memset(s->fill->flags, 0, n);
    }
    s->in_frame = true;
}

static void frame_complete(sl_scan_t *s, sl_scan_end_t why)
{
    sl_scan_rot_t *r = &s->rot;
    sl_scan_frame_t *f = s->fill;
    const uint16_t n = r->azimuths;
    if (f != NULL) {
        const size_t roi = r->roi_bins;
        for (uint16_t i = 0; i < n; i++) {
            if ((r->flags[i] & SL_SCAN_AZ_VALID) == 0U) {
                memset(f->power[i], 0, roi);
                f->flags[i] = 0;
                f->bins[i] = 0;
                f->ticks[i] = 0;
                f->sweep[i] = 0;
                f->t_us[i] = 0;
            }
        }
    }
    for (uint16_t i = 0; i < n; i++) {
        if ((r->flags[i] & SL_SCAN_AZ_VALID) == 0U) {
            r->flags[i] = 0; // a missing row keeps no DUP/LATE marks
        }
    }
    if (r->stats.valid == 0U) {
        r->t_first_us = 0;
    }
    r->stats.missing = (uint16_t)(n - r->stats.valid);
    r->end = (uint8_t)why;
    s->stats.frames++;
    s->stats.missing += r->stats.missing;
    s->rotation++;
    s->in_frame = false;
    if (f != NULL) {
        frame_sync(f, r);
        if (s->cfg.on_frame != NULL) {
            s->cfg.on_frame(s->cfg.ctx, f);
        }
    }
    if (s->cfg.on_rot != NULL) {
        s->cfg.on_rot(s->cfg.ctx, r);
    }
    if (f != NULL && s->done != NULL) {
        s->fill = s->done;
        s->done = f;
        s->done_valid = true;
    }
}

static sl_err_t check_geometry(const sl_scan_t *s, uint16_t azimuths, uint16_t encoder_size)
{
    if (azimuths == 0U || azimuths > SL_CFG_MAX_AZIMUTHS || encoder_size == 0U ||
        (s->cfg.expect_azimuths != 0U && azimuths != s->cfg.expect_azimuths) ||
        (s->cfg.expect_encoder_size != 0U && encoder_size != s->cfg.expect_encoder_size)) {
        return SL_ERR_RANGE;
    }
    return SL_OK;
}

// Geometry already checked. Completes the current frame when the geometry changes.
static void apply_geometry(sl_scan_t *s, uint16_t azimuths, uint16_t encoder_size)
{
    if (azimuths == s->azimuths && encoder_size == s->encoder_size) {
        return;
    }
    if (s->azimuths != 0U) {
        s->stats.config_changes++;
    }
    if (s->in_frame) {
        frame_complete(s, SL_SCAN_END_CONFIG);
    }
    s->azimuths = azimuths;
    s->encoder_size = encoder_size;
    s->az_recip = (azimuths <= encoder_size)
                      ? (uint32_t)(((uint32_t)azimuths << 16) / encoder_size)
                      : 0U;
    uint16_t w = (s->cfg.reorder_azimuths != 0U) ? s->cfg.reorder_azimuths
                                                 : (uint16_t)(azimuths / 8U);
    const uint16_t wmax = (uint16_t)((azimuths - 1U) / 2U);
    s->window = (w > wmax) ? wmax : w;
    s->have_sweep = false;
}

sl_err_t sl_scan_init(sl_scan_t *s, const sl_scan_cfg_t *cfg, sl_scan_frame_t *fill,
                      sl_scan_frame_t *spare)
{
    if (s == NULL || cfg == NULL || (fill != NULL && fill == spare) || cfg->roi_bins == 0U ||
        cfg->roi_bins > SL_CFG_ROI_BINS || cfg->pow16_shift > 15U ||
        (fill == NULL && (spare != NULL || cfg->row_buf == NULL ||
                          cfg->row_buf_size < cfg->roi_bins))) {
        return SL_ERR_ARG;
    }
    memset(s, 0, sizeof *s);
    s->cfg = *cfg;
    s->fill = fill;
    s->done = spare;
    if (fill != NULL) {
        frame_clear(fill);
    }
    if (spare != NULL) {
        frame_clear(spare);
    }
    if (cfg->azimuths != 0U || cfg->encoder_size != 0U) {
        if (check_geometry(s, cfg->azimuths, cfg->encoder_size) != SL_OK) {
            return SL_ERR_RANGE;
        }
        apply_geometry(s, cfg->azimuths, cfg->encoder_size);
    }
    return SL_OK;
}

sl_err_t sl_scan_set_geometry(sl_scan_t *s, uint16_t azimuths, uint16_t encoder_size)
{
    if (s == NULL) {
        return SL_ERR_ARG;
    }
    if (check_geometry(s, azimuths, encoder_size) != SL_OK) {
        s->stats.config_rejected++;
        return SL_ERR_RANGE;
    }
    apply_geometry(s, azimuths, encoder_size);
    return SL_OK;
}

sl_err_t sl_scan_on_config(sl_scan_t *s, const sl_proto_config_t *c)
{
    if (s == NULL || c == NULL) {
        return SL_ERR_ARG;
    }
    if (check_geometry(s, c->azimuths, c->encoder_size) != SL_OK) {
        s->stats.config_rejected++;
        return SL_ERR_RANGE;
    }
    s->stats.configs++;
    apply_geometry(s, c->azimuths, c->encoder_size);
    return SL_OK;
}

// 8 wire bytes as a little-endian 64-bit word (compilers emit one load on little-endian
// targets; the assembly keeps the result endian-independent).
static inline uint64_t ld64le(const uint8_t *p)
{
    return (uint64_t)p[0] | ((uint64_t)p[1] << 8) | ((uint64_t)p[2] << 16) |
           ((uint64_t)p[3] << 24) | ((uint64_t)p[4] << 32) | ((uint64_t)p[5] << 40) |
           ((uint64_t)p[6] << 48) | ((uint64_t)p[7] << 56);
}

// High bytes of four little-endian 16-bit lanes of w, packed: v0 | v1 << 8 | v2 << 16 | v3 << 24.
static inline uint32_t high_bytes4(uint64_t w)
{
    uint64_t x = (w >> 8) & 0x00FF00FF00FF00FFULL;
    x = (x | (x >> 8)) & 0x0000FFFF0000FFFFULL;
    return (uint32_t)(x | (x >> 16));
}

// 16-bit little-endian wire bins -> uint8 power, p = min(255, v >> shift). Shift 8 (the
// default: the high byte, never saturates) packs 8 bins per step with 64-bit SWAR; other
// shifts use blocks of 32 bins with a constant trip count so that compilers can vectorise
// them at -O2. Tails are done bin by bin.
#define R16_BLOCK 32U
static void reduce16(uint8_t *restrict row, const uint8_t *restrict b, uint32_t n, unsigned shift,
                     uint32_t *saturated)
{
    size_t i = 0;
    if (shift == 8U) {
        for (; i + 8U <= n; i += 8U) {
            const uint64_t v = (uint64_t)high_bytes4(ld64le(b + 2U * i)) |
                               ((uint64_t)high_bytes4(ld64le(b + 2U * i + 8U)) << 32);
            uint8_t *d = row + i;
            // Byte stores of one value: merged into one 64-bit store on little-endian targets.
            d[0] = (uint8_t)v;
            d[1] = (uint8_t)(v >> 8);
            d[2] = (uint8_t)(v >> 16);
            d[3] = (uint8_t)(v >> 24);
            d[4] = (uint8_t)(v >> 32);
            d[5] = (uint8_t)(v >> 40);
            d[6] = (uint8_t)(v >> 48);
            d[7] = (uint8_t)(v >> 56);
        }
        for (; i < n; i++) {
            row[i] = b[2U * i + 1U];
        }
        return;
    }
    uint32_t sat = 0;
    for (; i + R16_BLOCK <= n; i += R16_BLOCK) {
        const uint8_t *restrict src = b + 2U * i;
        uint8_t *restrict dst = row + i;
        for (size_t j = 0; j < R16_BLOCK; j++) {
            const uint32_t v = ((uint32_t)src[2U * j] | ((uint32_t)src[2U * j + 1U] << 8)) >> shift;
            sat += (v > 255U) ? 1U : 0U;
            dst[j] = (uint8_t)((v > 255U) ? 255U : v);
        }
    }
    for (; i < n; i++) {
        const uint32_t v = ((uint32_t)b[2U * i] | ((uint32_t)b[2U * i + 1U] << 8)) >> shift;
        sat += (v > 255U) ? 1U : 0U;
        row[i] = (uint8_t)((v > 255U) ? 255U : v);
    }
    *saturated += sat;
}

// Store one message as row idx (frame mode: copy into the frame; frame-less: a view of the
// message or of the row buffer) and report it.
static void store(sl_scan_t *s, const sl_proto_fft_t *f, uint16_t idx, uint8_t extra_flags)
{
    sl_scan_rot_t *r = &s->rot;
    sl_scan_frame_t *fr = s->fill;
    const uint32_t roi = s->cfg.roi_bins;
    const uint32_t n = (f->bins < roi) ? f->bins : roi;
    uint8_t flags = (uint8_t)(SL_SCAN_AZ_VALID | extra_flags);
    const uint8_t *view;
    if (fr == NULL && f->bytes_per_bin == 1U && n == roi) {
        view = f->bin_data; // frame-less, complete 8-bit row: no copy at all
    } else {
        uint8_t *row = (fr != NULL) ? fr->power[idx] : s->cfg.row_buf;
        if (f->bytes_per_bin == 1U) {
            memcpy(row, f->bin_data, n);
        } else {
            reduce16(row, f->bin_data, n, s->cfg.pow16_shift, &s->stats.saturated16);
        }
        if (n < roi) {
            memset(row + n, 0, roi - n);
        }
        view = row;
    }
    if (f->bytes_per_bin != 1U) {
        flags |= SL_SCAN_AZ_16BIT;
        r->stats.wide_azimuths++;
        s->stats.wide_azimuths++;
    }
    if (n < roi) {
        flags |= SL_SCAN_AZ_SHORT;
        r->stats.short_azimuths++;
        s->stats.short_azimuths++;
    }
    r->flags[idx] = flags;
    const uint64_t t = sl_proto_fft_time_us(f);
    if (t < r->t_first_us) {
        r->t_first_us = t;
    }
    if (t > r->t_last_us) {
        r->t_last_us = t;
    }
    r->stats.valid++;
    s->stats.azimuths++;
    if (fr != NULL) {
        fr->flags[idx] = flags;
        fr->bins[idx] = (uint16_t)n;
        fr->ticks[idx] = f->azimuth_ticks;
        fr->sweep[idx] = f->sweep_counter;
        fr->t_us[idx] = t;
        frame_sync(fr, r);
        if (s->cfg.on_azimuth != NULL) {
            s->cfg.on_azimuth(s->cfg.ctx, fr, idx);
        }
    }
    if (s->cfg.on_row != NULL) {
        const sl_scan_row_t row = {.rotation = r->rotation, .idx = idx, .bins = (uint16_t)n,
                                   .ticks = f->azimuth_ticks, .sweep = f->sweep_counter,
                                   .flags = flags, .t_us = t, .power = view, .fft = f};
        s->cfg.on_row(s->cfg.ctx, &row);
    }
}

static void duplicate(sl_scan_t *s, uint16_t idx)
{
    s->rot.flags[idx] |= SL_SCAN_AZ_DUP;
    s->rot.stats.duplicates++;
    s->stats.duplicates++;
    if (s->fill != NULL) {
        s->fill->flags[idx] |= SL_SCAN_AZ_DUP;
        s->fill->stats = s->rot.stats;
    }
}

// An FFT message that gave no row (encoder value out of range, no bins, malformed). A
// whole rotation's worth of them in a row is a rotation the radar sent and nobody saw:
// its azimuths count as missing (stats.missing, stats.blind_rotations) even though no frame
// was opened for it.
static void unusable(sl_scan_t *s)
{
    if (s->azimuths == 0U) {
        return;
    }
    s->unusable_run++;
    if (s->unusable_run >= s->azimuths) {
        s->unusable_run = 0;
        s->stats.blind_rotations++;
        s->stats.missing += s->azimuths;
    }
}

sl_err_t sl_scan_on_fft(sl_scan_t *s, const sl_proto_fft_t *f)
{
    if (s == NULL || f == NULL || (f->bytes_per_bin != 1U && f->bytes_per_bin != 2U) ||
        (f->bin_data == NULL && f->bins != 0U)) {
        return SL_ERR_ARG;
    }
    s->stats.fft++;
    if (s->azimuths == 0U) {
        s->stats.no_config++;
        return SL_ERR_STATE;
    }
    const int32_t sidx = sl_scan_az_index_geo(s, f->azimuth_ticks);
    if (sidx < 0) {
        s->stats.bad_azimuth++;
        unusable(s);
        return SL_ERR_RANGE;
    }
    const uint16_t idx = (uint16_t)sidx;
    const uint16_t n = s->azimuths;
    if (f->bins == 0U) {
        s->stats.empty_rows++; // no range bin: not an azimuth (it stays missing)
        unusable(s);
        return SL_ERR_MALFORMED;
    }
    s->unusable_run = 0;
    if (s->have_sweep && f->sweep_counter != (uint16_t)(s->last_sweep + 1U)) {
        s->stats.sweep_gaps++;
    }
    s->have_sweep = true;
    s->last_sweep = f->sweep_counter;

    if (s->in_frame) {
        sl_scan_rot_t *fr = &s->rot;
        const uint16_t du = (uint16_t)(f->sweep_counter - fr->head_sweep);
        const int32_t dsweep = (du < 0x8000U) ? (int32_t)du : (int32_t)du - 0x10000;
        const bool sweep = !s->cfg.ignore_sweep;
        if (sweep && dsweep >= (int32_t)n) {
            frame_complete(s, SL_SCAN_END_SWEEP_GAP);
        } else {
            const uint16_t head = fr->head;
            const uint32_t fwd = (idx >= head) ? (uint32_t)idx - head : (uint32_t)idx + n - head;
            const bool filled = (fr->flags[idx] & SL_SCAN_AZ_VALID) != 0U;
            // Sent more than half a rotation of messages after the head (sweep counters
            // usable): a message for an already stored azimuth is then the next rotation's,
            // not a duplicate (a jittered encoder value one message later stays a duplicate).
            const bool newer = sweep && dsweep > (int32_t)(n / 2U);
            if (fwd == 0U) {
                if (!newer) {
                    duplicate(s, idx);
                    return SL_OK;
                }
                frame_complete(s, SL_SCAN_END_WRAP);
            } else if (fwd >= (uint32_t)(n - s->window) && !(idx > head && sweep && dsweep > 0)) {
                // A small step backwards: a late message. (Just above the head but sent after
                // it, by the sweep counters, it is this rotation's: a forward step below.)
                if (idx > head) {
                    s->stats.late_dropped++; // its rotation was already completed
                    return SL_OK;
                }
                if (!filled) {
                    fr->stats.out_of_order++;
                    s->stats.out_of_order++;
                    s->behind_head++;
                    store(s, f, idx, SL_SCAN_AZ_LATE); // syncs the frame's stats
                    return SL_OK;
                }
                if (!newer) {
                    duplicate(s, idx);
                    return SL_OK;
                }
                frame_complete(s, SL_SCAN_END_WRAP);
            } else if (idx < head) {
                // A step back beyond the reorder window. It starts the next rotation when
                // the sweep counters moved forward by about `fwd` messages (in order across
                // index 0, with or without a gap), or when this azimuth was already stored
                // in this rotation (whatever the sweep counter says: it restarts with the
                // radar).
                // Otherwise it is DISORDER: stored into its empty slot and counted, and the
                // rotation stays open (a shuffled rotation is one rotation, not many).
                // (Only when at most W rows were stored behind the head since it was set:
                // a reversed rotation matches the sweep arithmetic half way round.)
                const bool wrap_by_sweep = sweep && dsweep > 0 && s->behind_head <= s->window &&
                                           (uint32_t)dsweep + s->window >= fwd &&
                                           (uint32_t)dsweep <= fwd + s->window;
                if (!wrap_by_sweep && !filled) {
                    fr->stats.disorder++;
                    s->stats.disorder++;
                    s->behind_head++;
                    store(s, f, idx, SL_SCAN_AZ_LATE);
                    return SL_OK;
                }
                frame_complete(s, SL_SCAN_END_WRAP);
            }
        }
    }
    if (!s->in_frame) {
        frame_start(s);
    }
    s->rot.head = idx;
    s->rot.head_sweep = f->sweep_counter;
    s->behind_head = 0;
    store(s, f, idx, 0);
    return SL_OK;
}

sl_err_t sl_scan_on_msg(sl_scan_t *s, const sl_proto_msg_t *msg)
{
    if (s == NULL || msg == NULL) {
        return SL_ERR_ARG;
    }
    switch (msg->id) {
    case SL_PROTO_ID_CONFIGURATION: {
        sl_proto_config_t c;
        if (sl_proto_parse_config(msg, &c) != SL_OK) {
            s->stats.malformed++;
            return SL_ERR_MALFORMED;
        }
        return sl_scan_on_config(s, &c);
    }
    case SL_PROTO_ID_FFT_DATA:
    case SL_PROTO_ID_FFT_DATA_16: {
        sl_proto_fft_t f;
        if (sl_proto_parse_fft(msg, &f) != SL_OK) {
            s->stats.malformed++;
            unusable(s);
            return SL_ERR_MALFORMED;
        }
        return sl_scan_on_fft(s, &f);
    }
    default:
        return SL_OK;
    }
}

void sl_scan_proto_sink(void *ctx, const sl_proto_msg_t *msg)
{
    (void)sl_scan_on_msg((sl_scan_t *)ctx, msg);
}

void sl_scan_flush(sl_scan_t *s)
{
    if (s != NULL && s->in_frame) {
        frame_complete(s, SL_SCAN_END_FLUSH);
    }
}

const sl_scan_frame_t *sl_scan_last_frame(const sl_scan_t *s)
{
    return (s != NULL && s->done_valid) ? s->done : NULL;
}
