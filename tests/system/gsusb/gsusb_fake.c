// SPDX-License-Identifier: MIT
// In-process fake candleLight (see gsusb_fake.h).
#include "gsusb_fake.h"

#include <string.h>

#include "shadowlean/sl_bytes.h"

void gsusb_fake_init(gsusb_fake_t *f)
{
    memset(f, 0, sizeof *f);
    f->dev_cfg.icount = 0;
    f->dev_cfg.sw_version = 2;
    f->dev_cfg.hw_version = 1;
    f->bt_const.feature = SLP_GSUSB_FEAT_LISTEN_ONLY | SLP_GSUSB_FEAT_LOOP_BACK |
                          SLP_GSUSB_FEAT_ONE_SHOT | SLP_GSUSB_FEAT_GET_STATE;
    f->bt_const.fclk_hz = 48000000U;
    f->bt_const.tseg1_min = 1;
    f->bt_const.tseg1_max = 16;
    f->bt_const.tseg2_min = 1;
    f->bt_const.tseg2_max = 8;
    f->bt_const.sjw_max = 4;
    f->bt_const.brp_min = 1;
    f->bt_const.brp_max = 1024;
    f->bt_const.brp_inc = 1;
    f->can_state.state = 0;
    f->vanish_after_frames = -1;
    f->echo_limit = -1;
    f->stall_out_at = -1;
    f->stall_in_after = -1;
}

void gsusb_fake_push_in(gsusb_fake_t *f, const uint8_t *pkt, size_t len)
{
    if (f->inq_count >= FAKE_INQ || len > sizeof f->inq[0]) {
        return;
    }
    size_t slot = (f->inq_head + f->inq_count) % FAKE_INQ;
    memcpy(f->inq[slot], pkt, len);
    f->inq_len[slot] = len;
    f->inq_count++;
}

static unsigned fake_fmt(const gsusb_fake_t *f)
{
    return (f->mode_flags & SLP_GSUSB_FEAT_HW_TIMESTAMP) != 0U ? SLP_GSUSB_FMT_TIMESTAMP : 0U;
}

static void push_frame(gsusb_fake_t *f, const slp_gsusb_host_frame_t *hf)
{
    uint8_t buf[SLP_GSUSB_FRAME_MAX_BYTES];
    slp_gsusb_host_frame_t copy = *hf;
    f->clock_us += 100U;
    copy.timestamp_us = f->clock_us;
    sl_ssize_t n = slp_gsusb_frame_encode(&copy, fake_fmt(f), buf, sizeof buf);
    if (n > 0) {
        gsusb_fake_push_in(f, buf, (size_t)n);
    }
}

void gsusb_fake_push_rx(gsusb_fake_t *f, uint32_t can_id, uint8_t dlc, const uint8_t *data,
                        uint8_t flags, uint8_t channel)
{
    slp_gsusb_host_frame_t hf;
    memset(&hf, 0, sizeof hf);
    hf.echo_id = (uint32_t)SLP_GSUSB_ECHO_ID_RX;
    hf.can_id = can_id;
    hf.can_dlc = dlc;
    hf.channel = channel;
    hf.flags = flags;
    if (data != NULL) {
        memcpy(hf.data, data, dlc > 8U ? 8U : dlc);
    }
    push_frame(f, &hf);
}

int gsusb_fake_find_req(const gsusb_fake_t *f, uint8_t breq, size_t from)
{
    for (size_t i = from; i < f->n_reqs; i++) {
        if (f->reqs[i].breq == breq) {
            return (int)i;
        }
    }
    return -1;
}

static void record(gsusb_fake_t *f, uint8_t rt, uint8_t breq, uint16_t wvalue, uint16_t windex,
                   const uint8_t *data, uint16_t len)
{
    if (f->n_reqs >= FAKE_MAX_REQS) {
        return;
    }
    fake_req_t *r = &f->reqs[f->n_reqs++];
    memset(r, 0, sizeof *r);
    r->rt = rt;
    r->breq = breq;
    r->wvalue = wvalue;
    r->windex = windex;
    r->len = len;
    if (data != NULL) {
        memcpy(r->data, data, len > sizeof r->data ? sizeof r->data : len);
    }
}

static slp_gsusb_io_t fake_control_out(void *ctx, uint8_t rt, uint8_t breq, uint16_t wvalue,
                                      uint16_t windex, const uint8_t *data, uint16_t len,
                                      uint32_t timeout_ms, size_t *transferred)
{
    gsusb_fake_t *f = ctx;
    (void)timeout_ms;
    *transferred = 0;
    if (f->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    record(f, rt, breq, wvalue, windex, data, len);
    if (breq < 32U && (f->refuse_mask & (1UL << breq)) != 0U) {
        return SLP_GSUSB_IO_STALL;
    }
    if (breq < 32U && (f->timeout_mask & (1UL << breq)) != 0U) {
        return SLP_GSUSB_IO_TIMEOUT;
    }
    switch (breq) {
    case SLP_GSUSB_BREQ_HOST_FORMAT:
        break;
    case SLP_GSUSB_BREQ_BITTIMING:
        if (slp_gsusb_decode_bittiming(data, len, &f->bt) != SL_OK) {
            return SLP_GSUSB_IO_STALL;
        }
        f->bt_set = true;
        break;
    case SLP_GSUSB_BREQ_MODE:
        if (len < 8U) {
            return SLP_GSUSB_IO_STALL;
        }
        f->started = data[0] == 1U;
        f->mode_flags = (uint32_t)data[4] | ((uint32_t)data[5] << 8) | ((uint32_t)data[6] << 16) |
                        ((uint32_t)data[7] << 24);
        if (!f->started) {
            f->mode_flags = 0;
        }
        break;
    default:
        return SLP_GSUSB_IO_STALL;
    }
    *transferred = len;
    return SLP_GSUSB_IO_OK;
}

static slp_gsusb_io_t fake_control_in(void *ctx, uint8_t rt, uint8_t breq, uint16_t wvalue,
                                     uint16_t windex, uint8_t *data, uint16_t len,
                                     uint32_t timeout_ms, size_t *transferred)
{
    gsusb_fake_t *f = ctx;
    uint8_t ans[40];
    size_t n = 0;
    (void)timeout_ms;
    *transferred = 0;
    if (f->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    record(f, rt, breq, wvalue, windex, NULL, len);
    if (breq < 32U && (f->refuse_mask & (1UL << breq)) != 0U) {
        return SLP_GSUSB_IO_STALL;
    }
    if (breq < 32U && (f->timeout_mask & (1UL << breq)) != 0U) {
        return SLP_GSUSB_IO_TIMEOUT;
    }
    memset(ans, 0, sizeof ans);
    switch (breq) {
    case SLP_GSUSB_BREQ_DEVICE_CONFIG:
        ans[3] = f->dev_cfg.icount;
        sl_put_le32(ans + 4, f->dev_cfg.sw_version);
        sl_put_le32(ans + 8, f->dev_cfg.hw_version);
        n = 12;
        break;
    case SLP_GSUSB_BREQ_BT_CONST: {
        const slp_gsusb_bt_const_t *c = &f->bt_const;
        const uint32_t v[10] = {c->feature, c->fclk_hz,  c->tseg1_min, c->tseg1_max, c->tseg2_min,
                                c->tseg2_max, c->sjw_max, c->brp_min,  c->brp_max,   c->brp_inc};
        for (size_t i = 0; i < 10; i++) {
            sl_put_le32(ans + 4 * i, v[i]);
        }
        n = 40;
        break;
    }
    case SLP_GSUSB_BREQ_GET_STATE:
        if ((f->bt_const.feature & SLP_GSUSB_FEAT_GET_STATE) == 0U) {
            return SLP_GSUSB_IO_STALL;
        }
        sl_put_le32(ans + 0, f->can_state.state);
        sl_put_le32(ans + 4, f->can_state.rxerr);
        sl_put_le32(ans + 8, f->can_state.txerr);
        n = 12;
        break;
    default:
        return SLP_GSUSB_IO_STALL;
    }
    if (breq < 32U && (f->short_mask & (1UL << breq)) != 0U) {
        n -= 2U;
    }
    if (n > len) {
        n = len;
    }
    memcpy(data, ans, n);
    *transferred = n;
    return SLP_GSUSB_IO_OK;
}

static slp_gsusb_io_t fake_bulk_out(void *ctx, const uint8_t *data, size_t len, uint32_t timeout_ms,
                                   size_t *transferred)
{
    gsusb_fake_t *f = ctx;
    (void)timeout_ms;
    *transferred = 0;
    f->bulk_out_calls++;
    if (f->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    if (f->out_halted) {
        return SLP_GSUSB_IO_STALL;
    }
    if (f->stall_out_at >= 0 && (size_t)f->stall_out_at == f->n_frames) {
        f->stall_out_at = -1;
        f->out_halted = true;
        return SLP_GSUSB_IO_STALL;
    }
    if (f->out_busy) {
        return SLP_GSUSB_IO_TIMEOUT;
    }
    if (f->out_error_count > 0) {
        f->out_error_count--;
        return SLP_GSUSB_IO_ERROR;
    }
    slp_gsusb_host_frame_t hf;
    if (slp_gsusb_frame_decode(data, len, 0U, &hf) != SL_OK || f->n_frames >= FAKE_MAX_FRAMES) {
        return SLP_GSUSB_IO_ERROR;
    }
    size_t idx = f->n_frames++;
    f->frames[idx] = hf;
    f->frame_len[idx] = len;
    *transferred = len;
    if (f->vanish_after_frames >= 0 && f->n_frames >= (size_t)f->vanish_after_frames) {
        f->gone = true; // accepted, then unplugged before the echo
        return SLP_GSUSB_IO_OK;
    }
    if (f->echo_limit < 0 || f->n_echoed < (size_t)f->echo_limit) {
        f->n_echoed++;
        push_frame(f, &hf);
    }
    if (f->inject_reply) {
        bool eff = (hf.can_id & SLP_GSUSB_CAN_EFF_FLAG) != 0U;
        uint32_t id = hf.can_id & (eff ? SL_CAN_EFF_MASK : SL_CAN_SFF_MASK);
        uint32_t reply = ((id + 1U) & (eff ? SL_CAN_EFF_MASK : SL_CAN_SFF_MASK)) |
                         (hf.can_id & SLP_GSUSB_CAN_EFF_FLAG);
        gsusb_fake_push_rx(f, reply, hf.can_dlc, hf.data, 0U, hf.channel);
    }
    if (f->stall_in_after >= 0 && (size_t)f->stall_in_after == idx) {
        f->stall_in_after = -1;
        f->in_halted = true;
    }
    return SLP_GSUSB_IO_OK;
}

static slp_gsusb_io_t fake_bulk_in(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms,
                                  size_t *transferred)
{
    gsusb_fake_t *f = ctx;
    (void)timeout_ms;
    *transferred = 0;
    if (f->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    if (f->in_halted) {
        return SLP_GSUSB_IO_STALL;
    }
    if (f->in_error_count > 0) {
        f->in_error_count--;
        return SLP_GSUSB_IO_ERROR;
    }
    if (f->inq_count == 0U) {
        return SLP_GSUSB_IO_TIMEOUT;
    }
    size_t slot = f->inq_head;
    f->inq_head = (f->inq_head + 1U) % FAKE_INQ;
    f->inq_count--;
    if (f->inq_len[slot] > cap) {
        return SLP_GSUSB_IO_OVERFLOW;
    }
    memcpy(buf, f->inq[slot], f->inq_len[slot]);
    *transferred = f->inq_len[slot];
    return SLP_GSUSB_IO_OK;
}

static slp_gsusb_io_t fake_clear_halt(void *ctx, bool in)
{
    gsusb_fake_t *f = ctx;
    if (f->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    if (f->clear_halt_fails) {
        return SLP_GSUSB_IO_ERROR;
    }
    if (in) {
        f->in_halted = false;
        f->clear_halts_in++;
    } else {
        f->out_halted = false;
        f->clear_halts_out++;
    }
    return SLP_GSUSB_IO_OK;
}

static const slp_gsusb_transport_ops_t fake_ops = {
    .control_out = fake_control_out,
    .control_in = fake_control_in,
    .bulk_out = fake_bulk_out,
    .bulk_in = fake_bulk_in,
    .clear_halt = fake_clear_halt,
};

slp_gsusb_transport_t gsusb_fake_transport(gsusb_fake_t *f)
{
    slp_gsusb_transport_t t = {&fake_ops, f};
    return t;
}
