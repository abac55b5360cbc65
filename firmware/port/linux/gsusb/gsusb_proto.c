// SPDX-License-Identifier: MIT
// gs_usb protocol layer and driver logic (no libusb: see gsusb_proto.h).
#include "gsusb_proto.h"

#include "shadowlean/sl_bytes.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

// ---------------------------------------------------------------------------------------
// Identity

static const slp_gsusb_usb_id_t known_ids[] = {
    {0x1d50, 0x606f, "candleLight_fw default / Geschwister Schneider USB2CAN"},
    {0x1209, 0x2323, "candleLight (pid.codes)"},
    {0x1cd2, 0x606f, "CES CANext FD"},
    {0x16d0, 0x10b8, "ABE CANdebugger FD"},
    {0x16d0, 0x0f30, "Xylanta SAINT3"},
    {0x1209, 0xca01, "CANnectivity (Zephyr)"},
};

const slp_gsusb_usb_id_t *slp_gsusb_known_ids(size_t *n)
{
    if (n != NULL) {
        *n = sizeof known_ids / sizeof known_ids[0];
    }
    return known_ids;
}

bool slp_gsusb_is_known_id(uint16_t vid, uint16_t pid)
{
    for (size_t i = 0; i < sizeof known_ids / sizeof known_ids[0]; i++) {
        if (known_ids[i].vid == vid && known_ids[i].pid == pid) {
            return true;
        }
    }
    return false;
}

const char *slp_gsusb_breq_name(uint8_t breq)
{
    switch (breq) {
    case SLP_GSUSB_BREQ_HOST_FORMAT: return "HOST_FORMAT";
    case SLP_GSUSB_BREQ_BITTIMING: return "BITTIMING";
    case SLP_GSUSB_BREQ_MODE: return "MODE";
    case SLP_GSUSB_BREQ_BERR: return "BERR";
    case SLP_GSUSB_BREQ_BT_CONST: return "BT_CONST";
    case SLP_GSUSB_BREQ_DEVICE_CONFIG: return "DEVICE_CONFIG";
    case SLP_GSUSB_BREQ_TIMESTAMP: return "TIMESTAMP";
    case SLP_GSUSB_BREQ_IDENTIFY: return "IDENTIFY";
    case SLP_GSUSB_BREQ_DATA_BITTIMING: return "DATA_BITTIMING";
    case SLP_GSUSB_BREQ_BT_CONST_EXT: return "BT_CONST_EXT";
    case SLP_GSUSB_BREQ_SET_TERMINATION: return "SET_TERMINATION";
    case SLP_GSUSB_BREQ_GET_TERMINATION: return "GET_TERMINATION";
    case SLP_GSUSB_BREQ_GET_STATE: return "GET_STATE";
    default: return "REQ?";
    }
}

const char *slp_gsusb_io_name(slp_gsusb_io_t io)
{
    switch (io) {
    case SLP_GSUSB_IO_OK: return "OK";
    case SLP_GSUSB_IO_TIMEOUT: return "TIMEOUT";
    case SLP_GSUSB_IO_STALL: return "STALL";
    case SLP_GSUSB_IO_NO_DEVICE: return "NO_DEVICE";
    case SLP_GSUSB_IO_OVERFLOW: return "OVERFLOW";
    case SLP_GSUSB_IO_ERROR: return "ERROR";
    default: return "IO?";
    }
}

// ---------------------------------------------------------------------------------------
// Request payloads

void slp_gsusb_encode_host_format(uint8_t out[SLP_GSUSB_HOST_FORMAT_BYTES])
{
    sl_put_le32(out, (uint32_t)SLP_GSUSB_HOST_FORMAT_WORD);
}

void slp_gsusb_encode_bittiming(const slp_gsusb_bittiming_t *bt, uint8_t out[SLP_GSUSB_BITTIMING_BYTES])
{
    sl_put_le32(out + 0, bt->prop_seg);
    sl_put_le32(out + 4, bt->phase_seg1);
    sl_put_le32(out + 8, bt->phase_seg2);
    sl_put_le32(out + 12, bt->sjw);
    sl_put_le32(out + 16, bt->brp);
}

void slp_gsusb_encode_mode(uint32_t mode, uint32_t flags, uint8_t out[SLP_GSUSB_MODE_BYTES])
{
    sl_put_le32(out + 0, mode);
    sl_put_le32(out + 4, flags);
}

sl_err_t slp_gsusb_decode_device_config(const uint8_t *buf, size_t len, slp_gsusb_device_config_t *out)
{
    if (buf == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    if (len < SLP_GSUSB_DEVICE_CONFIG_BYTES) {
        return SL_ERR_MALFORMED;
    }
    out->icount = buf[3];
    out->sw_version = sl_get_le32(buf + 4);
    out->hw_version = sl_get_le32(buf + 8);
    return SL_OK;
}

sl_err_t slp_gsusb_decode_bt_const(const uint8_t *buf, size_t len, slp_gsusb_bt_const_t *out)
{
    if (buf == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    if (len < SLP_GSUSB_BT_CONST_BYTES) {
        return SL_ERR_MALFORMED;
    }
    out->feature = sl_get_le32(buf + 0);
    out->fclk_hz = sl_get_le32(buf + 4);
    out->tseg1_min = sl_get_le32(buf + 8);
    out->tseg1_max = sl_get_le32(buf + 12);
    out->tseg2_min = sl_get_le32(buf + 16);
    out->tseg2_max = sl_get_le32(buf + 20);
    out->sjw_max = sl_get_le32(buf + 24);
    out->brp_min = sl_get_le32(buf + 28);
    out->brp_max = sl_get_le32(buf + 32);
    out->brp_inc = sl_get_le32(buf + 36);
    return SL_OK;
}

sl_err_t slp_gsusb_decode_bittiming(const uint8_t *buf, size_t len, slp_gsusb_bittiming_t *out)
{
    if (buf == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    if (len < SLP_GSUSB_BITTIMING_BYTES) {
        return SL_ERR_MALFORMED;
    }
    out->prop_seg = sl_get_le32(buf + 0);
    out->phase_seg1 = sl_get_le32(buf + 4);
    out->phase_seg2 = sl_get_le32(buf + 8);
    out->sjw = sl_get_le32(buf + 12);
    out->brp = sl_get_le32(buf + 16);
    return SL_OK;
}

sl_err_t slp_gsusb_decode_state(const uint8_t *buf, size_t len, slp_gsusb_can_state_t *out)
{
    if (buf == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    if (len < SLP_GSUSB_STATE_BYTES) {
        return SL_ERR_MALFORMED;
    }
    out->state = sl_get_le32(buf + 0);
    out->rxerr = sl_get_le32(buf + 4);
    out->txerr = sl_get_le32(buf + 8);
    return SL_OK;
}

sl_err_t slp_gsusb_bt_const_check(const slp_gsusb_bt_const_t *c)
{
    if (c == NULL) {
        return SL_ERR_ARG;
    }
    if (c->fclk_hz == 0U || c->brp_inc == 0U || c->brp_max == 0U || c->tseg2_max == 0U ||
        c->tseg1_max == 0U || c->tseg1_min > c->tseg1_max || c->tseg2_min > c->tseg2_max ||
        c->brp_min > c->brp_max || c->tseg1_max > SLP_GSUSB_TSEG_LIMIT ||
        c->tseg2_max > SLP_GSUSB_TSEG_LIMIT) {
        return SL_ERR_MALFORMED;
    }
    return SL_OK;
}

// ---------------------------------------------------------------------------------------
// Bit timing (Linux can_calc_bittiming(), drivers/net/can/dev/calc_bittiming.c, 6.1)

uint16_t slp_gsusb_default_sample_point(uint32_t bitrate)
{
    if (bitrate > 800000U) {
        return 750U;
    }
    if (bitrate > 500000U) {
        return 800U;
    }
    return 875U;
}

uint32_t slp_gsusb_bittiming_rate(const slp_gsusb_bittiming_t *bt, uint32_t fclk_hz)
{
    if (bt == NULL || bt->brp == 0U) {
        return 0U;
    }
    uint64_t tq = 1U + (uint64_t)bt->prop_seg + bt->phase_seg1 + bt->phase_seg2;
    return (uint32_t)((uint64_t)fclk_hz / ((uint64_t)bt->brp * tq));
}

static uint64_t absdiff_u64(uint64_t a, uint64_t b)
{
    return a > b ? a - b : b - a;
}

// For `tseg` = tseg1 + tseg2 time quanta (plus the sync quantum), split it so the sample
// point is as close as possible to, but not above, the nominal one. Returns false when no
// split fits the limits.
static bool split_tseg(const slp_gsusb_bt_const_t *c, uint32_t sp_nominal, int64_t tseg,
                       int64_t *tseg1_out, int64_t *tseg2_out, uint32_t *sp_err_out)
{
    uint32_t best_err = UINT32_MAX;
    int64_t all = tseg + 1;
    for (int64_t i = 0; i <= 1; i++) {
        int64_t tseg2 = all - ((int64_t)sp_nominal * all) / 1000 - i;
        if (tseg2 < (int64_t)c->tseg2_min) {
            tseg2 = (int64_t)c->tseg2_min;
        }
        if (tseg2 > (int64_t)c->tseg2_max) {
            tseg2 = (int64_t)c->tseg2_max;
        }
        int64_t tseg1 = tseg - tseg2;
        if (tseg1 > (int64_t)c->tseg1_max) {
            tseg1 = (int64_t)c->tseg1_max;
            tseg2 = tseg - tseg1;
        }
        if (tseg1 < (int64_t)c->tseg1_min || tseg2 < (int64_t)c->tseg2_min ||
            tseg2 > (int64_t)c->tseg2_max || tseg2 < 1) {
            continue;
        }
        int64_t sp = (1000 * (all - tseg2)) / all;
        uint32_t err = (uint32_t)(sp > (int64_t)sp_nominal ? sp - (int64_t)sp_nominal
                                                            : (int64_t)sp_nominal - sp);
        if (sp <= (int64_t)sp_nominal && err < best_err) {
            best_err = err;
            *tseg1_out = tseg1;
            *tseg2_out = tseg2;
        }
    }
    *sp_err_out = best_err;
    return best_err != UINT32_MAX;
}

sl_err_t slp_gsusb_bittiming_calc(const slp_gsusb_bt_const_t *c, uint32_t bitrate,
                                 uint16_t sample_point_permille, slp_gsusb_bt_result_t *out)
{
    if (c == NULL || out == NULL || bitrate == 0U || sample_point_permille >= 1000U) {
        return SL_ERR_ARG;
    }
    memset(out, 0, sizeof *out);
    uint32_t sp_nominal =
        sample_point_permille != 0U ? sample_point_permille : slp_gsusb_default_sample_point(bitrate);
    out->sample_point_nominal = (uint16_t)sp_nominal;
    if (slp_gsusb_bt_const_check(c) != SL_OK) {
        return SL_ERR_MALFORMED;
    }

    uint64_t best_rate_err = UINT64_MAX;
    uint32_t best_sp_err = UINT32_MAX;
    int64_t best_tseg1 = 0;
    int64_t best_tseg2 = 0;
    uint64_t best_brp = 0;
    int64_t lo = 2 * ((int64_t)c->tseg1_min + (int64_t)c->tseg2_min);
    if (lo < 2) {
        lo = 2; // at least one quantum besides the sync quantum
    }
    // tseg even = round the prescaler down, odd = round it up (as Linux).
    for (int64_t tseg = 2 * ((int64_t)c->tseg1_max + (int64_t)c->tseg2_max) + 1; tseg >= lo; tseg--) {
        uint64_t tsegall = 1U + (uint64_t)(tseg / 2);
        uint64_t brp = (uint64_t)c->fclk_hz / (tsegall * bitrate) + (uint64_t)(tseg % 2);
        brp = (brp / c->brp_inc) * c->brp_inc;
        if (brp < c->brp_min || brp > c->brp_max || brp == 0U) {
            continue;
        }
        uint64_t rate = (uint64_t)c->fclk_hz / (brp * tsegall);
        uint64_t rate_err = absdiff_u64(bitrate, rate);
        if (rate_err > best_rate_err) {
            continue;
        }
        if (rate_err < best_rate_err) {
            best_sp_err = UINT32_MAX; // a better rate resets the sample-point race
        }
        int64_t tseg1 = 0;
        int64_t tseg2 = 0;
        uint32_t sp_err = UINT32_MAX;
        if (!split_tseg(c, sp_nominal, tseg / 2, &tseg1, &tseg2, &sp_err)) {
            continue;
        }
        if (sp_err >= best_sp_err) {
            continue;
        }
        best_sp_err = sp_err;
        best_rate_err = rate_err;
        best_tseg1 = tseg1;
        best_tseg2 = tseg2;
        best_brp = brp;
        if (rate_err == 0U && sp_err == 0U) {
            break;
        }
    }
    if (best_brp == 0U) {
        return SL_ERR_RANGE; // no prescaler in [brp_min, brp_max] reaches this rate
    }
    uint64_t tq = 1U + (uint64_t)best_tseg1 + (uint64_t)best_tseg2;
    out->bt.prop_seg = (uint32_t)(best_tseg1 / 2);
    out->bt.phase_seg1 = (uint32_t)best_tseg1 - out->bt.prop_seg;
    out->bt.phase_seg2 = (uint32_t)best_tseg2;
    out->bt.sjw = 1U; // Linux 6.1 default; always <= sjw_max (>= 1) and <= phase_seg2
    out->bt.brp = (uint32_t)best_brp;
    out->tq_per_bit = (uint16_t)tq;
    out->bitrate = (uint32_t)((uint64_t)c->fclk_hz / (best_brp * tq));
    out->error_ppm = (uint32_t)((absdiff_u64(bitrate, out->bitrate) * 1000000U) / bitrate);
    out->sample_point_permille = (uint16_t)((1000U * (1U + (uint64_t)best_tseg1)) / tq);
    if (bitrate > SLP_GSUSB_MAX_BITRATE || out->error_ppm > SLP_GSUSB_MAX_RATE_ERROR_PPM) {
        return SL_ERR_RANGE;
    }
    return SL_OK;
}

// ---------------------------------------------------------------------------------------
// Bulk frames

size_t slp_gsusb_frame_size(unsigned fmt)
{
    if ((fmt & SLP_GSUSB_FMT_TIMESTAMP) != 0U) {
        return SLP_GSUSB_FRAME_TS_BYTES;
    }
    if ((fmt & SLP_GSUSB_FMT_QUIRK) != 0U) {
        return SLP_GSUSB_FRAME_QUIRK_BYTES;
    }
    return SLP_GSUSB_FRAME_BYTES;
}

sl_ssize_t slp_gsusb_frame_encode(const slp_gsusb_host_frame_t *hf, unsigned fmt, uint8_t *buf,
                                 size_t cap)
{
    if (hf == NULL || buf == NULL ||
        (fmt & (SLP_GSUSB_FMT_TIMESTAMP | SLP_GSUSB_FMT_QUIRK)) ==
            (SLP_GSUSB_FMT_TIMESTAMP | SLP_GSUSB_FMT_QUIRK)) {
        return SL_ERR_ARG;
    }
    size_t n = slp_gsusb_frame_size(fmt);
    if (cap < n) {
        return SL_ERR_FULL;
    }
    sl_put_le32(buf + 0, hf->echo_id);
    sl_put_le32(buf + 4, hf->can_id);
    buf[8] = hf->can_dlc;
    buf[9] = hf->channel;
    buf[10] = hf->flags;
    buf[11] = hf->reserved;
    memcpy(buf + 12, hf->data, 8);
    if ((fmt & SLP_GSUSB_FMT_TIMESTAMP) != 0U) {
        sl_put_le32(buf + 20, hf->timestamp_us);
    } else if ((fmt & SLP_GSUSB_FMT_QUIRK) != 0U) {
        buf[20] = 0U;
    }
    return (sl_ssize_t)n;
}

sl_err_t slp_gsusb_frame_decode(const uint8_t *buf, size_t len, unsigned fmt, slp_gsusb_host_frame_t *out)
{
    if (buf == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    bool ts = (fmt & SLP_GSUSB_FMT_TIMESTAMP) != 0U;
    if (len < (ts ? SLP_GSUSB_FRAME_TS_BYTES : SLP_GSUSB_FRAME_BYTES)) {
        return SL_ERR_MALFORMED;
    }
    out->echo_id = sl_get_le32(buf + 0);
    out->can_id = sl_get_le32(buf + 4);
    out->can_dlc = buf[8];
    out->channel = buf[9];
    out->flags = buf[10];
    out->reserved = buf[11];
    memcpy(out->data, buf + 12, 8);
    out->timestamp_us = ts ? sl_get_le32(buf + 20) : 0U;
    return SL_OK;
}

sl_err_t slp_gsusb_frame_from_can(const sl_can_frame_t *f, uint32_t echo_id, uint8_t channel,
                                 slp_gsusb_host_frame_t *out)
{
    if (f == NULL || out == NULL || f->dlc > 8U || (f->flags & SL_CAN_FLAG_ERR) != 0U) {
        return SL_ERR_ARG;
    }
    bool eff = (f->flags & SL_CAN_FLAG_EFF) != 0U;
    bool rtr = (f->flags & SL_CAN_FLAG_RTR) != 0U;
    if (f->id > (eff ? SL_CAN_EFF_MASK : SL_CAN_SFF_MASK)) {
        return SL_ERR_ARG;
    }
    memset(out, 0, sizeof *out);
    out->echo_id = echo_id;
    out->can_id = f->id | (eff ? (uint32_t)SLP_GSUSB_CAN_EFF_FLAG : 0U) |
                  (rtr ? (uint32_t)SLP_GSUSB_CAN_RTR_FLAG : 0U);
    out->can_dlc = f->dlc;
    out->channel = channel;
    if (!rtr) {
        memcpy(out->data, f->data, f->dlc);
    }
    return SL_OK;
}

sl_err_t slp_gsusb_frame_to_can(const slp_gsusb_host_frame_t *hf, sl_can_frame_t *out)
{
    if (hf == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    if ((hf->flags & SLP_GSUSB_FRAME_FLAG_FD) != 0U || hf->can_dlc > 8U) {
        return SL_ERR_MALFORMED;
    }
    bool eff = (hf->can_id & SLP_GSUSB_CAN_EFF_FLAG) != 0U;
    bool rtr = (hf->can_id & SLP_GSUSB_CAN_RTR_FLAG) != 0U;
    bool err = (hf->can_id & SLP_GSUSB_CAN_ERR_FLAG) != 0U;
    if (err && rtr) {
        return SL_ERR_MALFORMED;
    }
    memset(out, 0, sizeof *out);
    out->dlc = hf->can_dlc;
    if (err) {
        out->id = hf->can_id & (uint32_t)SLP_GSUSB_CAN_ERR_MASK;
        out->flags = SL_CAN_FLAG_ERR;
        memcpy(out->data, hf->data, hf->can_dlc);
        return SL_OK;
    }
    out->id = hf->can_id & (uint32_t)(eff ? SL_CAN_EFF_MASK : SL_CAN_SFF_MASK);
    out->flags = (uint8_t)((eff ? SL_CAN_FLAG_EFF : 0U) | (rtr ? SL_CAN_FLAG_RTR : 0U));
    if (!rtr) {
        memcpy(out->data, hf->data, hf->can_dlc);
    }
    return SL_OK;
}

// ---------------------------------------------------------------------------------------
// Echo ids

sl_err_t slp_gsusb_echo_init(slp_gsusb_echo_t *e, uint8_t capacity)
{
    if (e == NULL || capacity > SLP_GSUSB_MAX_IN_FLIGHT) {
        return SL_ERR_ARG;
    }
    memset(e, 0, sizeof *e);
    e->capacity = capacity != 0U ? capacity : (uint8_t)SLP_GSUSB_DEFAULT_IN_FLIGHT;
    return SL_OK;
}

sl_ssize_t slp_gsusb_echo_alloc(slp_gsusb_echo_t *e, const sl_can_frame_t *frame, uint32_t tag,
                               uint64_t now_us)
{
    if (e == NULL || frame == NULL) {
        return SL_ERR_ARG;
    }
    for (uint8_t k = 0; k < e->capacity; k++) {
        uint8_t id = (uint8_t)((e->next + k) % e->capacity);
        slp_gsusb_echo_slot_t *s = &e->slot[id];
        if (!s->in_use) {
            s->in_use = true;
            s->tag = tag;
            s->sent_us = now_us;
            s->frame = *frame;
            e->next = (uint8_t)((id + 1U) % e->capacity);
            e->in_flight++;
            e->stats.allocated++;
            if (e->in_flight > e->stats.max_in_flight) {
                e->stats.max_in_flight = e->in_flight;
            }
            return (sl_ssize_t)id;
        }
    }
    e->stats.full++;
    return SL_ERR_FULL;
}

sl_err_t slp_gsusb_echo_release(slp_gsusb_echo_t *e, uint32_t echo_id)
{
    if (e == NULL || echo_id >= e->capacity || !e->slot[echo_id].in_use) {
        return SL_ERR_ARG;
    }
    e->slot[echo_id].in_use = false;
    e->in_flight--;
    e->stats.allocated--;
    // Give the id back to the round-robin search first: it was never used on the wire.
    e->next = (uint8_t)echo_id;
    return SL_OK;
}

const slp_gsusb_echo_slot_t *slp_gsusb_echo_peek(const slp_gsusb_echo_t *e, uint32_t echo_id)
{
    if (e == NULL || echo_id >= e->capacity || !e->slot[echo_id].in_use) {
        return NULL;
    }
    return &e->slot[echo_id];
}

sl_err_t slp_gsusb_echo_confirm(slp_gsusb_echo_t *e, uint32_t echo_id, slp_gsusb_echo_slot_t *done)
{
    if (e == NULL) {
        return SL_ERR_ARG;
    }
    if (echo_id >= e->capacity || !e->slot[echo_id].in_use) {
        e->stats.unknown++;
        return SL_ERR_MALFORMED;
    }
    if (done != NULL) {
        *done = e->slot[echo_id];
    }
    e->slot[echo_id].in_use = false;
    e->in_flight--;
    e->stats.confirmed++;
    return SL_OK;
}

size_t slp_gsusb_echo_expire(slp_gsusb_echo_t *e, uint64_t now_us, uint64_t timeout_us,
                            slp_gsusb_echo_done_fn cb, void *ctx)
{
    size_t n = 0;
    if (e == NULL) {
        return 0;
    }
    for (uint8_t id = 0; id < e->capacity; id++) {
        slp_gsusb_echo_slot_t *s = &e->slot[id];
        if (s->in_use && now_us >= s->sent_us && now_us - s->sent_us >= timeout_us) {
            slp_gsusb_echo_slot_t copy = *s;
            s->in_use = false;
            e->in_flight--;
            e->stats.timeouts++;
            n++;
            if (cb != NULL) {
                cb(ctx, id, &copy, SLP_GSUSB_TX_TIMEOUT);
            }
        }
    }
    return n;
}

size_t slp_gsusb_echo_drop_all(slp_gsusb_echo_t *e, slp_gsusb_echo_done_fn cb, void *ctx)
{
    size_t n = 0;
    if (e == NULL) {
        return 0;
    }
    for (uint8_t id = 0; id < e->capacity; id++) {
        slp_gsusb_echo_slot_t *s = &e->slot[id];
        if (s->in_use) {
            slp_gsusb_echo_slot_t copy = *s;
            s->in_use = false;
            e->in_flight--;
            e->stats.dropped++;
            n++;
            if (cb != NULL) {
                cb(ctx, id, &copy, SLP_GSUSB_TX_DROPPED);
            }
        }
    }
    return n;
}

uint64_t slp_gsusb_echo_deadline(const slp_gsusb_echo_t *e, uint64_t timeout_us)
{
    uint64_t best = UINT64_MAX;
    if (e == NULL) {
        return best;
    }
    for (uint8_t id = 0; id < e->capacity; id++) {
        if (e->slot[id].in_use && e->slot[id].sent_us + timeout_us < best) {
            best = e->slot[id].sent_us + timeout_us;
        }
    }
    return best;
}

// ---------------------------------------------------------------------------------------
// Driver

void slp_gsusb_cfg_defaults(slp_gsusb_cfg_t *cfg)
{
    if (cfg == NULL) {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    cfg->bitrate = 500000U;
    cfg->reset_first = true;
    cfg->max_in_flight = (uint8_t)SLP_GSUSB_DEFAULT_IN_FLIGHT;
    cfg->echo_timeout_ms = 1000U;
    cfg->control_timeout_ms = 1000U;
    cfg->bulk_out_timeout_ms = 100U;
    cfg->rx_budget = 64U;
    cfg->io_error_limit = 3U;
}

sl_err_t slp_gsusb_init(slp_gsusb_t *d, const slp_gsusb_cfg_t *cfg, const slp_gsusb_transport_t *tr)
{
    if (d == NULL || cfg == NULL || tr == NULL || tr->ops == NULL || tr->ops->control_out == NULL ||
        tr->ops->control_in == NULL || tr->ops->bulk_out == NULL || tr->ops->bulk_in == NULL ||
        cfg->bitrate == 0U || cfg->max_in_flight > SLP_GSUSB_MAX_IN_FLIGHT ||
        (cfg->mode_flags & ~(uint32_t)SLP_GSUSB_MODE_FLAGS_ALLOWED) != 0U ||
        cfg->sample_point_permille >= 1000U) {
        return SL_ERR_ARG;
    }
    memset(d, 0, sizeof *d);
    d->cfg = *cfg;
    if (d->cfg.max_in_flight == 0U) {
        d->cfg.max_in_flight = (uint8_t)SLP_GSUSB_DEFAULT_IN_FLIGHT;
    }
    if (d->cfg.echo_timeout_ms == 0U) {
        d->cfg.echo_timeout_ms = 1000U;
    }
    if (d->cfg.control_timeout_ms == 0U) {
        d->cfg.control_timeout_ms = 1000U;
    }
    if (d->cfg.bulk_out_timeout_ms == 0U) {
        d->cfg.bulk_out_timeout_ms = 100U;
    }
    if (d->cfg.rx_budget == 0U) {
        d->cfg.rx_budget = 64U;
    }
    if (d->cfg.io_error_limit == 0U) {
        d->cfg.io_error_limit = 3U;
    }
    d->tr = *tr;
    d->state = SLP_GSUSB_CLOSED;
    (void)slp_gsusb_echo_init(&d->echo, d->cfg.max_in_flight);
    return SL_OK;
}

void slp_gsusb_set_transport(slp_gsusb_t *d, const slp_gsusb_transport_t *tr)
{
    if (d != NULL && tr != NULL) {
        d->tr = *tr;
    }
}

// printf-style into last_error; keeps the first message of a start-up.
static void set_error(slp_gsusb_t *d, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_error(slp_gsusb_t *d, const char *fmt, ...)
{
    if (d->last_error[0] != '\0') {
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(d->last_error, sizeof d->last_error, fmt, ap);
    va_end(ap);
}

static void echo_done_cb(void *ctx, uint32_t echo_id, const slp_gsusb_echo_slot_t *slot,
                         slp_gsusb_tx_result_t result)
{
    slp_gsusb_t *d = ctx;
    (void)echo_id;
    if (result == SLP_GSUSB_TX_TIMEOUT) {
        d->stats.tx_unconfirmed++;
    } else if (result == SLP_GSUSB_TX_DROPPED) {
        d->stats.tx_dropped++;
    }
    if (d->cfg.on_tx_done != NULL) {
        d->cfg.on_tx_done(d->cfg.ctx, &slot->frame, slot->tag, result, 0U);
    }
}

void slp_gsusb_mark_down(slp_gsusb_t *d)
{
    if (d == NULL) {
        return;
    }
    if (d->state != SLP_GSUSB_DOWN) {
        d->stats.vanished++;
    }
    d->state = SLP_GSUSB_DOWN;
    d->io_errors_in_row = 0;
    (void)slp_gsusb_echo_drop_all(&d->echo, echo_done_cb, d);
}

// Why a control request failed, for last_error.
static const char *io_reason(slp_gsusb_io_t io)
{
    switch (io) {
    case SLP_GSUSB_IO_STALL: return "refused by the device (control request stalled)";
    case SLP_GSUSB_IO_TIMEOUT: return "timed out";
    case SLP_GSUSB_IO_NO_DEVICE: return "failed: the device vanished";
    case SLP_GSUSB_IO_OVERFLOW: return "failed: answer overflow";
    case SLP_GSUSB_IO_OK:
    case SLP_GSUSB_IO_ERROR:
    default: return "failed (USB error)";
    }
}

static sl_err_t ctrl_fail(slp_gsusb_t *d, uint8_t breq, slp_gsusb_io_t io)
{
    if (io == SLP_GSUSB_IO_STALL) {
        d->stats.ctrl_stalls++;
    } else {
        d->stats.ctrl_errors++;
    }
    set_error(d, "%s %s", slp_gsusb_breq_name(breq), io_reason(io));
    if (io == SLP_GSUSB_IO_NO_DEVICE) {
        slp_gsusb_mark_down(d);
    }
    return SL_ERR_PORT;
}

static sl_err_t ctrl_out(slp_gsusb_t *d, uint8_t breq, uint16_t wvalue, uint16_t windex,
                         const uint8_t *data, uint16_t len, slp_gsusb_io_t *io_out)
{
    size_t n = 0;
    slp_gsusb_io_t io = d->tr.ops->control_out(d->tr.ctx, (uint8_t)SLP_GSUSB_RT_OUT, breq, wvalue,
                                              windex, data, len, d->cfg.control_timeout_ms, &n);
    if (io_out != NULL) {
        *io_out = io;
    }
    if (io == SLP_GSUSB_IO_OK && n != len) {
        io = SLP_GSUSB_IO_ERROR;
    }
    return io == SLP_GSUSB_IO_OK ? SL_OK : ctrl_fail(d, breq, io);
}

static sl_err_t ctrl_in(slp_gsusb_t *d, uint8_t breq, uint16_t wvalue, uint16_t windex,
                        uint8_t *data, uint16_t len)
{
    size_t n = 0;
    slp_gsusb_io_t io = d->tr.ops->control_in(d->tr.ctx, (uint8_t)SLP_GSUSB_RT_IN, breq, wvalue,
                                             windex, data, len, d->cfg.control_timeout_ms, &n);
    if (io != SLP_GSUSB_IO_OK) {
        return ctrl_fail(d, breq, io);
    }
    if (n < len) {
        d->stats.ctrl_errors++;
        set_error(d, "%s answer too short (%zu of %u bytes)", slp_gsusb_breq_name(breq), n,
                  (unsigned)len);
        return SL_ERR_MALFORMED;
    }
    return SL_OK;
}

static sl_err_t start_sequence(slp_gsusb_t *d)
{
    uint8_t buf[SLP_GSUSB_BT_CONST_BYTES];
    sl_err_t rc;
    uint16_t ch = d->cfg.channel;

    // 1. HOST_FORMAT (per device: wValue 1, wIndex = interface number)
    slp_gsusb_encode_host_format(buf);
    rc = ctrl_out(d, SLP_GSUSB_BREQ_HOST_FORMAT, 1U, SLP_GSUSB_INTERFACE, buf,
                  SLP_GSUSB_HOST_FORMAT_BYTES, NULL);
    if (rc != SL_OK) {
        return rc;
    }
    // 2. DEVICE_CONFIG
    memset(buf, 0, sizeof buf);
    rc = ctrl_in(d, SLP_GSUSB_BREQ_DEVICE_CONFIG, 1U, SLP_GSUSB_INTERFACE, buf,
                 SLP_GSUSB_DEVICE_CONFIG_BYTES);
    if (rc != SL_OK) {
        return rc;
    }
    (void)slp_gsusb_decode_device_config(buf, SLP_GSUSB_DEVICE_CONFIG_BYTES, &d->dev_cfg);
    if ((unsigned)d->cfg.channel > d->dev_cfg.icount) {
        set_error(d, "channel %u not present (the device has %u)", (unsigned)d->cfg.channel,
                  (unsigned)d->dev_cfg.icount + 1U);
        return SL_ERR_ARG;
    }
    // 3. BT_CONST (per channel: wValue = channel, wIndex 0)
    memset(buf, 0, sizeof buf);
    rc = ctrl_in(d, SLP_GSUSB_BREQ_BT_CONST, ch, 0U, buf, SLP_GSUSB_BT_CONST_BYTES);
    if (rc != SL_OK) {
        return rc;
    }
    (void)slp_gsusb_decode_bt_const(buf, SLP_GSUSB_BT_CONST_BYTES, &d->bt_const);
    const slp_gsusb_bt_const_t *c = &d->bt_const;
    if (slp_gsusb_bt_const_check(c) != SL_OK) {
        set_error(d,
                  "BT_CONST reports implausible limits (fclk %lu Hz, tseg1 %lu..%lu, tseg2 "
                  "%lu..%lu, brp %lu..%lu step %lu)",
                  (unsigned long)c->fclk_hz, (unsigned long)c->tseg1_min,
                  (unsigned long)c->tseg1_max, (unsigned long)c->tseg2_min,
                  (unsigned long)c->tseg2_max, (unsigned long)c->brp_min,
                  (unsigned long)c->brp_max, (unsigned long)c->brp_inc);
        return SL_ERR_MALFORMED;
    }
    if ((d->cfg.mode_flags & ~c->feature) != 0U) {
        set_error(d, "the device does not offer mode flags 0x%lx (features 0x%lx)",
                  (unsigned long)(d->cfg.mode_flags & ~c->feature), (unsigned long)c->feature);
        return SL_ERR_ARG;
    }
    d->rx_fmt = (d->cfg.hw_timestamp && (c->feature & SLP_GSUSB_FEAT_HW_TIMESTAMP) != 0U)
                    ? SLP_GSUSB_FMT_TIMESTAMP
                    : 0U;
    d->tx_fmt = (c->feature & SLP_GSUSB_FEAT_QUIRK_LPC546XX) != 0U ? SLP_GSUSB_FMT_QUIRK : 0U;

    // 4. bit timing from the clock and limits
    rc = slp_gsusb_bittiming_calc(c, d->cfg.bitrate, d->cfg.sample_point_permille, &d->timing);
    if (rc != SL_OK) {
        if (d->timing.tq_per_bit == 0U) {
            set_error(d,
                      "bitrate %lu bit/s cannot be produced from the %lu Hz clock: no prescaler "
                      "in %lu..%lu (step %lu) fits tseg1 %lu..%lu + tseg2 %lu..%lu",
                      (unsigned long)d->cfg.bitrate, (unsigned long)c->fclk_hz,
                      (unsigned long)c->brp_min, (unsigned long)c->brp_max,
                      (unsigned long)c->brp_inc, (unsigned long)c->tseg1_min,
                      (unsigned long)c->tseg1_max, (unsigned long)c->tseg2_min,
                      (unsigned long)c->tseg2_max);
        } else if (d->cfg.bitrate > SLP_GSUSB_MAX_BITRATE) {
            set_error(d, "bitrate %lu bit/s is above the classic CAN maximum of %lu bit/s",
                      (unsigned long)d->cfg.bitrate, (unsigned long)SLP_GSUSB_MAX_BITRATE);
        } else {
            set_error(d,
                      "bitrate %lu bit/s cannot be produced from the %lu Hz clock: closest is "
                      "%lu bit/s (brp %lu, %u tq), error %lu.%02lu %% > %u.%02u %%",
                      (unsigned long)d->cfg.bitrate, (unsigned long)c->fclk_hz,
                      (unsigned long)d->timing.bitrate, (unsigned long)d->timing.bt.brp,
                      (unsigned)d->timing.tq_per_bit, (unsigned long)(d->timing.error_ppm / 10000U),
                      (unsigned long)((d->timing.error_ppm / 100U) % 100U),
                      SLP_GSUSB_MAX_RATE_ERROR_PPM / 10000U,
                      (SLP_GSUSB_MAX_RATE_ERROR_PPM / 100U) % 100U);
        }
        return rc;
    }

    // 5. MODE RESET first (a channel left running), tolerated when refused
    if (d->cfg.reset_first) {
        slp_gsusb_io_t io = SLP_GSUSB_IO_OK;
        slp_gsusb_encode_mode(SLP_GSUSB_MODE_RESET, 0U, buf);
        rc = ctrl_out(d, SLP_GSUSB_BREQ_MODE, ch, 0U, buf, SLP_GSUSB_MODE_BYTES, &io);
        if (rc != SL_OK) {
            if (io != SLP_GSUSB_IO_STALL) {
                return rc;
            }
            d->last_error[0] = '\0'; // a refused RESET of a stopped channel is harmless
        }
    }
    // 6. BITTIMING
    slp_gsusb_encode_bittiming(&d->timing.bt, buf);
    rc = ctrl_out(d, SLP_GSUSB_BREQ_BITTIMING, ch, 0U, buf, SLP_GSUSB_BITTIMING_BYTES, NULL);
    if (rc != SL_OK) {
        return rc;
    }
    // 7. MODE START
    d->mode_flags_sent = d->cfg.mode_flags | (d->rx_fmt != 0U ? (uint32_t)SLP_GSUSB_FEAT_HW_TIMESTAMP : 0U);
    slp_gsusb_encode_mode(SLP_GSUSB_MODE_START, d->mode_flags_sent, buf);
    return ctrl_out(d, SLP_GSUSB_BREQ_MODE, ch, 0U, buf, SLP_GSUSB_MODE_BYTES, NULL);
}

sl_err_t slp_gsusb_start(slp_gsusb_t *d, uint64_t now_us)
{
    (void)now_us;
    if (d == NULL) {
        return SL_ERR_ARG;
    }
    if (d->state == SLP_GSUSB_RUNNING) {
        return SL_ERR_STATE;
    }
    (void)slp_gsusb_echo_drop_all(&d->echo, echo_done_cb, d);
    d->last_error[0] = '\0';
    d->io_errors_in_row = 0;
    slp_gsusb_state_t before = d->state;
    sl_err_t rc = start_sequence(d);
    if (rc != SL_OK) {
        d->stats.start_failures++;
        if (d->state != SLP_GSUSB_DOWN) {
            d->state = before == SLP_GSUSB_DOWN ? SLP_GSUSB_DOWN : SLP_GSUSB_CLOSED;
        }
        return rc;
    }
    d->state = SLP_GSUSB_RUNNING;
    d->stats.starts++;
    return SL_OK;
}

// Count a transfer error; too many in a row means the device is as good as gone.
static void io_error(slp_gsusb_t *d)
{
    if (++d->io_errors_in_row >= d->cfg.io_error_limit) {
        slp_gsusb_mark_down(d);
    }
}

static bool clear_halt(slp_gsusb_t *d, bool in)
{
    if (d->tr.ops->clear_halt == NULL) {
        d->stats.clear_halt_failures++;
        return false;
    }
    slp_gsusb_io_t io = d->tr.ops->clear_halt(d->tr.ctx, in);
    if (io == SLP_GSUSB_IO_OK) {
        d->stats.clear_halts++;
        return true;
    }
    d->stats.clear_halt_failures++;
    if (io == SLP_GSUSB_IO_NO_DEVICE) {
        slp_gsusb_mark_down(d);
    }
    return false;
}

static uint64_t echo_timeout_us(const slp_gsusb_t *d)
{
    return (uint64_t)d->cfg.echo_timeout_ms * 1000U;
}

sl_err_t slp_gsusb_send(slp_gsusb_t *d, const sl_can_frame_t *f, uint32_t tag, uint64_t now_us)
{
    if (d == NULL || f == NULL) {
        return SL_ERR_ARG;
    }
    if (d->state != SLP_GSUSB_RUNNING) {
        return SL_ERR_STATE;
    }
    slp_gsusb_host_frame_t hf;
    if (slp_gsusb_frame_from_can(f, 0U, d->cfg.channel, &hf) != SL_OK) {
        return SL_ERR_ARG;
    }
    (void)slp_gsusb_echo_expire(&d->echo, now_us, echo_timeout_us(d), echo_done_cb, d);
    sl_ssize_t id = slp_gsusb_echo_alloc(&d->echo, f, tag, now_us);
    if (id < 0) {
        d->stats.tx_window_full++;
        return SL_ERR_BUSY;
    }
    hf.echo_id = (uint32_t)id;
    uint8_t buf[SLP_GSUSB_FRAME_MAX_BYTES];
    sl_ssize_t len = slp_gsusb_frame_encode(&hf, d->tx_fmt, buf, sizeof buf);
    SL_ASSERT(len > 0);

    for (int attempt = 0; attempt < 2; attempt++) {
        size_t n = 0;
        slp_gsusb_io_t io = d->tr.ops->bulk_out(d->tr.ctx, buf, (size_t)len,
                                               d->cfg.bulk_out_timeout_ms, &n);
        if (n == (size_t)len && (io == SLP_GSUSB_IO_OK || io == SLP_GSUSB_IO_TIMEOUT)) {
            d->stats.tx_frames++;
            d->io_errors_in_row = 0;
            return SL_OK;
        }
        switch (io) {
        case SLP_GSUSB_IO_STALL:
            d->stats.stalls_out++;
            if (attempt == 0 && clear_halt(d, false)) {
                d->stats.tx_retries++;
                continue;
            }
            (void)slp_gsusb_echo_release(&d->echo, (uint32_t)id);
            d->stats.tx_errors++;
            return SL_ERR_PORT;
        case SLP_GSUSB_IO_TIMEOUT:
            (void)slp_gsusb_echo_release(&d->echo, (uint32_t)id);
            d->stats.tx_timeouts++;
            return SL_ERR_BUSY;
        case SLP_GSUSB_IO_NO_DEVICE:
            (void)slp_gsusb_echo_release(&d->echo, (uint32_t)id);
            d->stats.tx_errors++;
            slp_gsusb_mark_down(d);
            return SL_ERR_PORT;
        case SLP_GSUSB_IO_OK: // short write
        case SLP_GSUSB_IO_OVERFLOW:
        case SLP_GSUSB_IO_ERROR:
        default:
            (void)slp_gsusb_echo_release(&d->echo, (uint32_t)id);
            d->stats.tx_errors++;
            io_error(d);
            return SL_ERR_PORT;
        }
    }
    // Unreachable: the second attempt returns in every branch.
    (void)slp_gsusb_echo_release(&d->echo, (uint32_t)id);
    d->stats.tx_errors++;
    return SL_ERR_PORT;
}

static void handle_error_frame(slp_gsusb_t *d, const sl_can_frame_t *f)
{
    d->stats.rx_error_frames++;
    if ((f->id & SLP_GSUSB_ERR_BUSOFF) != 0U) {
        d->stats.bus_off++;
    }
    if ((f->id & SLP_GSUSB_ERR_CRTL) != 0U && f->dlc >= 2U) {
        uint8_t st = f->data[1];
        if ((st & (SLP_GSUSB_ERR_CRTL_RX_PASSIVE | SLP_GSUSB_ERR_CRTL_TX_PASSIVE)) != 0U) {
            d->stats.err_passive++;
        }
        if ((st & (SLP_GSUSB_ERR_CRTL_RX_WARNING | SLP_GSUSB_ERR_CRTL_TX_WARNING)) != 0U) {
            d->stats.err_warning++;
        }
    }
}

static void handle_packet(slp_gsusb_t *d, const uint8_t *pkt, size_t len, uint64_t now_us)
{
    slp_gsusb_host_frame_t hf;
    if (slp_gsusb_frame_decode(pkt, len, d->rx_fmt, &hf) != SL_OK) {
        d->stats.rx_malformed++;
        return;
    }
    if (hf.echo_id != (uint32_t)SLP_GSUSB_ECHO_ID_RX) {
        const slp_gsusb_echo_slot_t *slot = slp_gsusb_echo_peek(&d->echo, hf.echo_id);
        if (slot == NULL) {
            d->echo.stats.unknown++;
            d->stats.echo_unknown++;
            return;
        }
        slp_gsusb_host_frame_t sent;
        (void)slp_gsusb_frame_from_can(&slot->frame, hf.echo_id, d->cfg.channel, &sent);
        bool rtr = (sent.can_id & SLP_GSUSB_CAN_RTR_FLAG) != 0U;
        if (sent.can_id != hf.can_id || sent.can_dlc != hf.can_dlc ||
            (!rtr && memcmp(sent.data, hf.data, sent.can_dlc) != 0)) {
            d->stats.echo_mismatch++; // late echo of an earlier user of this id, or bogus
            return;
        }
        slp_gsusb_echo_slot_t done;
        (void)slp_gsusb_echo_confirm(&d->echo, hf.echo_id, &done);
        d->stats.tx_confirmed++;
        if (d->cfg.on_tx_done != NULL) {
            uint64_t lat = now_us >= done.sent_us ? now_us - done.sent_us : 0U;
            d->cfg.on_tx_done(d->cfg.ctx, &done.frame, done.tag, SLP_GSUSB_TX_CONFIRMED, lat);
        }
        return;
    }
    if (hf.channel != d->cfg.channel) {
        d->stats.rx_other_channel++;
        return;
    }
    sl_can_frame_t f;
    if (slp_gsusb_frame_to_can(&hf, &f) != SL_OK) {
        d->stats.rx_malformed++;
        return;
    }
    slp_gsusb_rx_info_t info = {
        .now_us = now_us,
        .timestamp_us = hf.timestamp_us,
        .has_timestamp = d->rx_fmt != 0U,
        .overflow = (hf.flags & SLP_GSUSB_FRAME_FLAG_OVERFLOW) != 0U,
    };
    if (info.overflow) {
        d->stats.rx_overflows++;
    }
    if ((f.flags & SL_CAN_FLAG_ERR) != 0U) {
        handle_error_frame(d, &f);
    } else {
        d->stats.rx_frames++;
    }
    if (d->cfg.on_rx != NULL) {
        d->cfg.on_rx(d->cfg.ctx, &f, &info);
    }
}

sl_ssize_t slp_gsusb_poll(slp_gsusb_t *d, uint32_t timeout_ms, uint64_t now_us)
{
    if (d == NULL) {
        return SL_ERR_ARG;
    }
    if (d->state != SLP_GSUSB_RUNNING) {
        return SL_ERR_STATE;
    }
    sl_ssize_t handled = 0;
    uint8_t pkt[512];
    uint32_t wait = timeout_ms;
    if (d->tr.ops->out_stalled != NULL && d->tr.ops->out_stalled(d->tr.ctx)) {
        d->stats.stalls_out++;
        (void)clear_halt(d, false);
        if (d->state != SLP_GSUSB_RUNNING) {
            return SL_ERR_PORT;
        }
    }
    for (uint16_t k = 0; k < d->cfg.rx_budget; k++) {
        size_t n = 0;
        slp_gsusb_io_t io = d->tr.ops->bulk_in(d->tr.ctx, pkt, sizeof pkt, wait, &n);
        wait = 0;
        if (io == SLP_GSUSB_IO_OK) {
            d->io_errors_in_row = 0;
            handle_packet(d, pkt, n, now_us);
            handled++;
            continue;
        }
        if (io == SLP_GSUSB_IO_TIMEOUT) {
            break;
        }
        if (io == SLP_GSUSB_IO_STALL) {
            d->stats.stalls_in++;
            (void)clear_halt(d, true);
            break;
        }
        if (io == SLP_GSUSB_IO_NO_DEVICE) {
            slp_gsusb_mark_down(d);
            break;
        }
        if (io == SLP_GSUSB_IO_OVERFLOW) {
            d->stats.rx_malformed++;
            continue;
        }
        d->stats.rx_io_errors++;
        io_error(d);
        break;
    }
    if (d->state != SLP_GSUSB_RUNNING) {
        return SL_ERR_PORT;
    }
    (void)slp_gsusb_echo_expire(&d->echo, now_us, echo_timeout_us(d), echo_done_cb, d);
    return handled;
}

sl_err_t slp_gsusb_get_state(slp_gsusb_t *d, slp_gsusb_can_state_t *out)
{
    if (d == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    if (d->state != SLP_GSUSB_RUNNING || (d->bt_const.feature & SLP_GSUSB_FEAT_GET_STATE) == 0U) {
        return SL_ERR_STATE;
    }
    uint8_t buf[SLP_GSUSB_STATE_BYTES];
    sl_err_t rc = ctrl_in(d, SLP_GSUSB_BREQ_GET_STATE, d->cfg.channel, 0U, buf, SLP_GSUSB_STATE_BYTES);
    if (rc != SL_OK) {
        return rc;
    }
    return slp_gsusb_decode_state(buf, sizeof buf, out);
}

void slp_gsusb_stop(slp_gsusb_t *d)
{
    if (d == NULL) {
        return;
    }
    if (d->state == SLP_GSUSB_RUNNING) {
        uint8_t buf[SLP_GSUSB_MODE_BYTES];
        size_t n = 0;
        slp_gsusb_encode_mode(SLP_GSUSB_MODE_RESET, 0U, buf);
        slp_gsusb_io_t io = d->tr.ops->control_out(d->tr.ctx, (uint8_t)SLP_GSUSB_RT_OUT,
                                                  SLP_GSUSB_BREQ_MODE, d->cfg.channel, 0U, buf,
                                                  SLP_GSUSB_MODE_BYTES, d->cfg.control_timeout_ms, &n);
        if (io != SLP_GSUSB_IO_OK) {
            d->stats.ctrl_errors++;
        }
    }
    (void)slp_gsusb_echo_drop_all(&d->echo, echo_done_cb, d);
    d->state = SLP_GSUSB_CLOSED;
}

uint8_t slp_gsusb_in_flight(const slp_gsusb_t *d)
{
    return d != NULL ? d->echo.in_flight : 0U;
}

int slp_gsusb_next_timeout_ms(const slp_gsusb_t *d, uint64_t now_us)
{
    if (d == NULL) {
        return -1;
    }
    uint64_t dl = slp_gsusb_echo_deadline(&d->echo, echo_timeout_us(d));
    if (dl == UINT64_MAX) {
        return -1;
    }
    if (dl <= now_us) {
        return 0;
    }
    uint64_t ms = (dl - now_us + 999U) / 1000U;
    return ms > (uint64_t)INT32_MAX ? INT32_MAX : (int)ms;
}
