// SPDX-License-Identifier: MIT
// gs_usb CAN sink: libusb transport + driver + queue + reopen (see gsusb_sink.h).
#include "gsusb_sink.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "port_clock.h"

slp_gsusb_sink_cfg_t slp_gsusb_sink_default_cfg(void)
{
    slp_gsusb_sink_cfg_t c;
    memset(&c, 0, sizeof c);
    slp_gsusb_cfg_defaults(&c.can);
    c.queue_cap = 32U;
    c.max_age_us = 200000U;
    c.reopen_interval_us = 1000000U;
    return c;
}

static void on_rx(void *ctx, const sl_can_frame_t *f, const slp_gsusb_rx_info_t *info)
{
    slp_gsusb_sink_t *s = ctx;
    if ((f->flags & SL_CAN_FLAG_ERR) != 0U) {
        s->stats.rx_error_frames++;
    } else {
        s->stats.rx_frames++;
    }
    if (s->cfg.on_rx != NULL) {
        s->cfg.on_rx(s->cfg.user, f, info);
    }
}

static void on_tx_done(void *ctx, const sl_can_frame_t *f, uint32_t tag, slp_gsusb_tx_result_t r,
                       uint64_t latency_us)
{
    slp_gsusb_sink_t *s = ctx;
    switch (r) {
    case SLP_GSUSB_TX_CONFIRMED: s->stats.confirmed++; break;
    case SLP_GSUSB_TX_TIMEOUT: s->stats.unconfirmed++; break;
    case SLP_GSUSB_TX_DROPPED:
    default: s->stats.dropped_in_flight++; break;
    }
    if (s->cfg.on_tx_done != NULL) {
        s->cfg.on_tx_done(s->cfg.user, f, tag, r, latency_us);
    }
}

static void drop_queue(slp_gsusb_sink_t *s, uint32_t *counter)
{
    *counter += s->q_len;
    s->q_head = 0;
    s->q_len = 0;
}

static void go_down(slp_gsusb_sink_t *s, uint64_t t_us, const char *why)
{
    if (!s->up) {
        return;
    }
    s->up = false;
    s->stats.down_events++;
    (void)snprintf(s->last_error, sizeof s->last_error, "%s", why);
    drop_queue(s, &s->stats.dropped_down);
    slp_gsusb_mark_down(&s->drv); // in-flight frames -> on_tx_done(DROPPED)
    slp_gsusb_usb_close(&s->usb);
    s->next_reopen_us = t_us + s->cfg.reopen_interval_us;
}

// Open the USB device and run the start-up sequence.
static sl_err_t bring_up(slp_gsusb_sink_t *s, uint64_t t_us)
{
    if (slp_gsusb_usb_is_open(&s->usb)) {
        slp_gsusb_usb_close(&s->usb);
    }
    sl_err_t rc = slp_gsusb_usb_open(&s->usb, &s->sel);
    if (rc != SL_OK) {
        (void)snprintf(s->last_error, sizeof s->last_error, "%s", s->usb.err);
        s->stats.open_failures++;
        s->next_reopen_us = t_us + s->cfg.reopen_interval_us;
        return rc;
    }
    slp_gsusb_transport_t tr = slp_gsusb_usb_transport(&s->usb);
    slp_gsusb_set_transport(&s->drv, &tr);
    rc = slp_gsusb_start(&s->drv, t_us);
    if (rc != SL_OK) {
        (void)snprintf(s->last_error, sizeof s->last_error, "%04x:%04x at %s: %s",
                       (unsigned)s->usb.vid, (unsigned)s->usb.pid, s->usb.where,
                       s->drv.last_error);
        s->stats.open_failures++;
        slp_gsusb_usb_close(&s->usb); // gives the device back to the kernel driver
        s->next_reopen_us = t_us + s->cfg.reopen_interval_us;
        return rc;
    }
    s->last_error[0] = '\0';
    if (s->ever_up) {
        s->stats.reopens++;
    }
    s->ever_up = true;
    s->up = true;
    return SL_OK;
}

sl_err_t slp_gsusb_sink_open(slp_gsusb_sink_t *s, const slp_gsusb_sink_cfg_t *cfg, uint64_t t_us)
{
    if (s == NULL || cfg == NULL || cfg->queue_cap > SLP_GSUSB_SINK_QUEUE_MAX ||
        (cfg->selector != NULL && strlen(cfg->selector) >= sizeof s->selector)) {
        return SL_ERR_ARG;
    }
    memset(s, 0, sizeof *s);
    s->cfg = *cfg;
    if (cfg->selector != NULL) {
        (void)snprintf(s->selector, sizeof s->selector, "%s", cfg->selector);
    }
    s->cfg.selector = s->selector;
    if (s->cfg.reopen_interval_us == 0U) {
        s->cfg.reopen_interval_us = 1000000U;
    }
    if (slp_gsusb_usb_parse_selector(s->selector, &s->sel) != SL_OK) {
        (void)snprintf(s->last_error, sizeof s->last_error,
                       "bad adapter selector '%s' (want VID:PID like 1d50:606f or BUS-PORT like 1-1.4)",
                       s->selector);
        return SL_ERR_ARG;
    }
    slp_gsusb_cfg_t dc = cfg->can;
    dc.on_rx = on_rx;
    dc.on_tx_done = on_tx_done;
    dc.ctx = s;
    // The driver talks to the transport only after a successful USB open; until then it
    // holds an empty transport that it never calls (state CLOSED).
    slp_gsusb_transport_t tr = slp_gsusb_usb_transport(&s->usb);
    if (slp_gsusb_init(&s->drv, &dc, &tr) != SL_OK) {
        (void)snprintf(s->last_error, sizeof s->last_error, "invalid CAN configuration");
        return SL_ERR_ARG;
    }
    if (slp_gsusb_usb_init(&s->usb) != SL_OK) {
        (void)snprintf(s->last_error, sizeof s->last_error, "%s", s->usb.err);
        return SL_ERR_PORT;
    }
    // A frame may wait in the USB queue behind a full echo window on a slow adapter: give
    // up on the transfer no earlier than on its echo.
    s->usb.out_timeout_ms = s->drv.cfg.echo_timeout_ms;
    s->opened = true;
    return bring_up(s, t_us);
}

static void flush_queue(slp_gsusb_sink_t *s, uint64_t t_us)
{
    while (s->up && s->q_len > 0U) {
        const sl_can_frame_t *f = &s->q[s->q_head];
        uint64_t qt = s->q_t_us[s->q_head];
        if (s->cfg.max_age_us != 0U && t_us > qt && t_us - qt > s->cfg.max_age_us) {
            s->stats.dropped_stale++;
        } else {
            sl_err_t rc = slp_gsusb_send(&s->drv, f, s->tag, t_us);
            if (rc == SL_ERR_BUSY) {
                return; // window still full: keep it
            }
            if (rc == SL_OK) {
                s->tag++;
                s->stats.submitted++;
            } else if (rc == SL_ERR_ARG) {
                s->stats.dropped_invalid++;
            } else if (s->drv.state == SLP_GSUSB_DOWN) {
                s->stats.dropped_down++;
                s->q_head = (uint16_t)((s->q_head + 1U) % SLP_GSUSB_SINK_QUEUE_MAX);
                s->q_len--;
                go_down(s, t_us, "adapter vanished (USB device gone)");
                return;
            } else {
                s->stats.dropped_error++;
            }
        }
        s->q_head = (uint16_t)((s->q_head + 1U) % SLP_GSUSB_SINK_QUEUE_MAX);
        s->q_len--;
    }
}

// Non-blocking (timeout 0) or waiting driver poll, then the queue.
static void service(slp_gsusb_sink_t *s, uint32_t timeout_ms, uint64_t t_us)
{
    if (!s->up) {
        return;
    }
    sl_ssize_t r = slp_gsusb_poll(&s->drv, timeout_ms, t_us);
    if (r < 0 || s->drv.state != SLP_GSUSB_RUNNING) {
        go_down(s, t_us, "adapter vanished (USB device gone)");
        return;
    }
    flush_queue(s, t_us);
}

sl_err_t slp_gsusb_sink_send(slp_gsusb_sink_t *s, const sl_can_frame_t *f, uint64_t t_us)
{
    if (s == NULL || f == NULL) {
        return SL_ERR_ARG;
    }
    s->stats.offered++;
    if (s->up) {
        service(s, 0U, t_us);
    }
    if (!s->up) {
        s->stats.dropped_down++;
        return SL_ERR_PORT;
    }
    if (s->q_len == 0U) {
        sl_err_t rc = slp_gsusb_send(&s->drv, f, s->tag, t_us);
        if (rc == SL_OK) {
            s->tag++;
            s->stats.submitted++;
            return SL_OK;
        }
        if (rc == SL_ERR_ARG) {
            s->stats.dropped_invalid++;
            return SL_ERR_ARG;
        }
        if (rc != SL_ERR_BUSY) { // BUSY: window full or the adapter slow: queue it
            if (s->drv.state != SLP_GSUSB_RUNNING) {
                s->stats.dropped_down++;
                go_down(s, t_us, "adapter vanished (USB device gone)");
            } else {
                s->stats.dropped_error++;
            }
            return SL_ERR_PORT;
        }
    }
    uint16_t cap = s->cfg.queue_cap;
    if (s->q_len >= cap) {
        s->stats.dropped_full++;
        return SL_ERR_BUSY;
    }
    uint16_t slot = (uint16_t)((s->q_head + s->q_len) % SLP_GSUSB_SINK_QUEUE_MAX);
    s->q[slot] = *f;
    s->q_t_us[slot] = t_us;
    s->q_len++;
    return SL_OK;
}

void slp_gsusb_sink_poll(slp_gsusb_sink_t *s, uint64_t t_us)
{
    if (s == NULL || !s->opened) {
        return;
    }
    if (s->up) {
        service(s, 0U, t_us);
    } else if (t_us >= s->next_reopen_us) {
        s->stats.reopen_attempts++;
        (void)bring_up(s, t_us);
    }
}

void slp_gsusb_sink_wait(slp_gsusb_sink_t *s, uint32_t timeout_ms)
{
    if (s == NULL || !s->opened) {
        return;
    }
    if (s->up) {
        // Wait in the driver's first bulk IN read; expiry uses the time after the wait.
        sl_ssize_t r = slp_gsusb_poll(&s->drv, timeout_ms, slp_now_us());
        uint64_t now = slp_now_us();
        if (r < 0 || s->drv.state != SLP_GSUSB_RUNNING) {
            go_down(s, now, "adapter vanished (USB device gone)");
            return;
        }
        service(s, 0U, now);
        return;
    }
    uint64_t now = slp_now_us();
    if (now < s->next_reopen_us) {
        uint64_t wait_us = s->next_reopen_us - now;
        if (wait_us > (uint64_t)timeout_ms * 1000U) {
            wait_us = (uint64_t)timeout_ms * 1000U;
        }
        struct timespec ts = {(time_t)(wait_us / 1000000U), (long)((wait_us % 1000000U) * 1000U)};
        (void)nanosleep(&ts, NULL);
        now = slp_now_us();
    }
    slp_gsusb_sink_poll(s, now);
}

sl_err_t slp_gsusb_sink_reopen(slp_gsusb_sink_t *s, uint64_t t_us)
{
    if (s == NULL) {
        return SL_ERR_ARG;
    }
    if (!s->opened) {
        return SL_ERR_STATE;
    }
    if (s->up) {
        slp_gsusb_stop(&s->drv);
        drop_queue(s, &s->stats.dropped_down);
        s->up = false;
    }
    s->stats.reopen_attempts++;
    return bring_up(s, t_us);
}

bool slp_gsusb_sink_is_up(const slp_gsusb_sink_t *s)
{
    return s != NULL && s->up;
}

uint32_t slp_gsusb_sink_pending(const slp_gsusb_sink_t *s)
{
    return s == NULL ? 0U : (uint32_t)s->q_len + slp_gsusb_in_flight(&s->drv);
}

const char *slp_gsusb_sink_last_error(const slp_gsusb_sink_t *s)
{
    return s == NULL ? "" : s->last_error;
}

void slp_gsusb_sink_close(slp_gsusb_sink_t *s)
{
    if (s == NULL || !s->opened) {
        return;
    }
    if (s->up) {
        slp_gsusb_stop(&s->drv); // MODE RESET; in flight -> dropped_in_flight
        drop_queue(s, &s->stats.dropped_down);
        s->up = false;
    }
    slp_gsusb_usb_deinit(&s->usb);
    s->opened = false;
}

static sl_err_t sink_send(void *ctx, const sl_can_frame_t *f, uint64_t t_us)
{
    return slp_gsusb_sink_send(ctx, f, t_us);
}

static void sink_poll(void *ctx, uint64_t t_us)
{
    slp_gsusb_sink_poll(ctx, t_us);
}

static void sink_stats(void *ctx, slp_can_sink_stats_t *out)
{
    const slp_gsusb_sink_t *s = ctx;
    const slp_gsusb_sink_stats_t *st = &s->stats;
    const slp_gsusb_stats_t *d = &s->drv.stats;
    out->sent = st->confirmed;
    out->dropped = st->unconfirmed + st->dropped_in_flight + st->dropped_down + st->dropped_full +
                   st->dropped_stale + st->dropped_error + st->dropped_invalid;
    out->queued = slp_gsusb_sink_pending(s);
    out->errors = d->rx_error_frames + d->stalls_in + d->stalls_out + d->tx_errors +
                  d->rx_io_errors + d->ctrl_errors + d->ctrl_stalls + d->rx_malformed;
}

slp_can_sink_t slp_gsusb_sink_as_sink(slp_gsusb_sink_t *s)
{
    slp_can_sink_t k = {"gs_usb", s, sink_send, sink_poll, sink_stats};
    return k;
}
