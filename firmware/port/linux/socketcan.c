// SPDX-License-Identifier: MIT
// SocketCAN raw sink (socketcan.h). Non-blocking socket + MSG_DONTWAIT everywhere.
#include "socketcan.h"

#include <errno.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

slp_socketcan_cfg_t slp_socketcan_default_cfg(void)
{
    slp_socketcan_cfg_t c;
    memset(&c, 0, sizeof c);
    c.queue_cap = 16U;
    c.sndbuf_bytes = 0;
    c.max_age_us = 200000U;
    c.bus_off_hold_us = 1000000U;
    c.reopen_interval_us = 1000000U;
    return c;
}

/// Create, configure and bind the socket. Sets s->fd or s->last_errno.
static sl_err_t sock_open(slp_socketcan_t *s)
{
    const int fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        s->last_errno = errno;
        return SL_ERR_PORT;
    }
    // No data frames in (we only send); every error class in.
    const can_err_mask_t err_mask = CAN_ERR_MASK;
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, NULL, 0) != 0 ||
        setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) != 0 ||
        (s->cfg.sndbuf_bytes > 0 && setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &s->cfg.sndbuf_bytes,
                                               sizeof s->cfg.sndbuf_bytes) != 0)) {
        s->last_errno = errno;
        close(fd);
        return SL_ERR_PORT;
    }
    const unsigned idx = if_nametoindex(s->ifname);
    if (idx == 0U) {
        s->last_errno = errno;
        close(fd);
        return SL_ERR_PORT;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)idx;
    if (bind(fd, (const struct sockaddr *)&addr, sizeof addr) != 0) {
        s->last_errno = errno;
        close(fd);
        return SL_ERR_PORT;
    }
    s->fd = fd;
    return SL_OK;
}

sl_err_t slp_socketcan_open(slp_socketcan_t *s, const char *ifname,
                               const slp_socketcan_cfg_t *cfg)
{
    if (s == NULL || ifname == NULL) {
        return SL_ERR_ARG;
    }
    memset(s, 0, sizeof *s);
    s->fd = -1;
    s->cfg = (cfg != NULL) ? *cfg : slp_socketcan_default_cfg();
    const size_t n = strlen(ifname);
    if (n == 0U || n >= sizeof s->ifname || s->cfg.queue_cap > SLP_SOCKETCAN_QUEUE_MAX) {
        return SL_ERR_ARG;
    }
    memcpy(s->ifname, ifname, n + 1U);
    const sl_err_t e = sock_open(s);
    if (e != SL_OK) {
        s->gone = true; // send() retries the open later
    }
    return e;
}

static void queue_clear(slp_socketcan_t *s)
{
    s->q_head = 0;
    s->q_len = 0;
}

void slp_socketcan_close(slp_socketcan_t *s)
{
    if (s == NULL) {
        return;
    }
    if (s->fd >= 0) {
        close(s->fd);
    }
    s->fd = -1;
    queue_clear(s);
}

/// Everything queued is lost (link down / gone): count it.
static void queue_drop_all(slp_socketcan_t *s, uint32_t *counter)
{
    *counter += s->q_len;
    queue_clear(s);
}

static bool queue_push(slp_socketcan_t *s, const sl_can_frame_t *f, uint64_t t_us)
{
    if (s->q_len >= s->cfg.queue_cap) {
        s->stats.dropped_full++;
        return false;
    }
    const unsigned tail = (s->q_head + s->q_len) % SLP_SOCKETCAN_QUEUE_MAX;
    s->q[tail] = *f;
    s->q_t_us[tail] = t_us;
    s->q_len++;
    return true;
}

static void queue_pop(slp_socketcan_t *s)
{
    s->q_head = (uint16_t)((s->q_head + 1U) % SLP_SOCKETCAN_QUEUE_MAX);
    s->q_len--;
}

/// The interface vanished: drop the socket; reopen later.
static void become_gone(slp_socketcan_t *s, uint64_t t_us)
{
    if (s->fd >= 0) {
        close(s->fd);
    }
    s->fd = -1;
    s->gone = true;
    s->next_reopen_t_us = t_us + s->cfg.reopen_interval_us;
    queue_drop_all(s, &s->stats.dropped_down);
}

/// Result of one write attempt.
typedef enum { WR_OK, WR_RETRY, WR_DOWN, WR_GONE, WR_ERROR } wres_t;

static wres_t write_frame(slp_socketcan_t *s, const sl_can_frame_t *f, uint64_t t_us)
{
    struct can_frame cf;
    memset(&cf, 0, sizeof cf);
    canid_t id = (f->flags & SL_CAN_FLAG_EFF) != 0U ? ((canid_t)f->id & CAN_EFF_MASK) | CAN_EFF_FLAG
                                                    : (canid_t)f->id & CAN_SFF_MASK;
    if ((f->flags & SL_CAN_FLAG_RTR) != 0U) {
        id |= CAN_RTR_FLAG;
    }
    if ((f->flags & SL_CAN_FLAG_ERR) != 0U) {
        id = ((canid_t)f->id & CAN_ERR_MASK) | CAN_ERR_FLAG;
    }
    cf.can_id = id;
    cf.len = (f->dlc <= CAN_MAX_DLEN) ? f->dlc : CAN_MAX_DLEN;
    memcpy(cf.data, f->data, cf.len);
    const ssize_t n = send(s->fd, &cf, sizeof cf, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n == (ssize_t)sizeof cf) {
        s->stats.sent++;
        if (s->link_down) {
            s->link_down = false;
            s->stats.link_up++;
        }
        if (s->cfg.on_sent != NULL) {
            s->cfg.on_sent(s->cfg.on_sent_user, f, t_us);
        }
        return WR_OK;
    }
    const int err = (n < 0) ? errno : EIO;
    s->last_errno = err;
    switch (err) {
    case EAGAIN:
#if EWOULDBLOCK != EAGAIN
    case EWOULDBLOCK:
#endif
        s->stats.retries++;
        s->stats.eagain++;
        return WR_RETRY;
    case ENOBUFS:
        s->stats.retries++;
        s->stats.enobufs++;
        return WR_RETRY;
    case ENETDOWN:
        if (!s->link_down) {
            s->link_down = true;
            s->stats.link_down++;
        }
        return WR_DOWN;
    case ENODEV:
    case ENXIO:
        return WR_GONE;
    default:
        return WR_ERROR;
    }
}

/// Read the error frames waiting on the socket (bounded).
static void read_errors(slp_socketcan_t *s, uint64_t t_us)
{
    for (unsigned i = 0; i < SLP_SOCKETCAN_RX_BURST && s->fd >= 0; i++) {
        struct can_frame cf;
        const ssize_t n = recv(s->fd, &cf, sizeof cf, MSG_DONTWAIT);
        if (n < 0) {
            // The kernel reports interface events as a pending socket error: NETDEV_DOWN
            // -> ENETDOWN, NETDEV_UNREGISTER -> ENODEV (and the socket is unbound).
            if (errno == ENODEV || errno == ENXIO) {
                become_gone(s, t_us);
            } else if (errno == ENETDOWN && !s->link_down) {
                s->link_down = true;
                s->stats.link_down++;
            }
            return; // EAGAIN: nothing more
        }
        if (n != (ssize_t)sizeof cf || (cf.can_id & CAN_ERR_FLAG) == 0U) {
            continue; // not an error frame (the filter should make this impossible)
        }
        s->stats.error_frames++;
        const canid_t cls = cf.can_id & CAN_ERR_MASK;
        if ((cls & CAN_ERR_TX_TIMEOUT) != 0U) {
            s->stats.tx_timeouts++;
        }
        if ((cls & (CAN_ERR_LOSTARB | CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_ACK |
                    CAN_ERR_BUSERROR)) != 0U) {
            s->stats.bus_errors++;
        }
        if ((cls & CAN_ERR_CRTL) != 0U) {
            const uint8_t c = cf.data[1];
            if ((c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0U) {
                s->stats.error_passive++;
            }
            if ((c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0U) {
                s->stats.error_warning++;
            }
            if ((c & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0U) {
                s->stats.ctrl_overflow++;
            }
#ifdef CAN_ERR_CRTL_ACTIVE
            if ((c & CAN_ERR_CRTL_ACTIVE) != 0U && s->bus_off) {
                s->bus_off = false;
                s->stats.restarts++;
            }
#endif
        }
        if ((cls & CAN_ERR_BUSOFF) != 0U) {
            s->bus_off = true;
            s->bus_off_t_us = t_us;
            s->stats.bus_off++;
            queue_drop_all(s, &s->stats.dropped_bus_off);
        }
        if ((cls & CAN_ERR_RESTARTED) != 0U) {
            if (s->bus_off) {
                s->bus_off = false;
            }
            s->stats.restarts++;
        }
    }
}

/// Retry the queue head-first until it is empty or the socket pushes back.
static void flush_queue(slp_socketcan_t *s, uint64_t t_us)
{
    while (s->q_len > 0U && s->fd >= 0) {
        const sl_can_frame_t *f = &s->q[s->q_head];
        if (s->cfg.max_age_us != 0U && t_us > s->q_t_us[s->q_head] &&
            t_us - s->q_t_us[s->q_head] > s->cfg.max_age_us) {
            s->stats.dropped_stale++;
            queue_pop(s);
            continue;
        }
        switch (write_frame(s, f, t_us)) {
        case WR_OK:
            queue_pop(s);
            break;
        case WR_RETRY:
            return;
        case WR_DOWN:
            queue_drop_all(s, &s->stats.dropped_down);
            return;
        case WR_GONE:
            become_gone(s, t_us);
            return;
        case WR_ERROR:
            s->stats.dropped_error++;
            queue_pop(s);
            break;
        }
    }
}

void slp_socketcan_poll(slp_socketcan_t *s, uint64_t t_us)
{
    if (s == NULL) {
        return;
    }
    if (s->gone && t_us >= s->next_reopen_t_us) {
        if (sock_open(s) == SL_OK) {
            s->gone = false;
            s->stats.reopens++;
            s->link_down = true; // the next successful write counts as link_up
        } else {
            s->next_reopen_t_us = t_us + s->cfg.reopen_interval_us;
        }
    }
    if (s->fd < 0) {
        return;
    }
    read_errors(s, t_us);
    if (s->bus_off && t_us >= s->bus_off_t_us + s->cfg.bus_off_hold_us) {
        s->bus_off = false;
        s->stats.bus_off_timeouts++;
    }
    if (!s->bus_off) {
        flush_queue(s, t_us);
    }
}

sl_err_t slp_socketcan_send(slp_socketcan_t *s, const sl_can_frame_t *f, uint64_t t_us)
{
    if (s == NULL || f == NULL) {
        return SL_ERR_ARG;
    }
    slp_socketcan_poll(s, t_us);
    if (s->fd < 0) {
        s->stats.dropped_down++;
        return SL_ERR_PORT;
    }
    if (s->bus_off) {
        s->stats.dropped_bus_off++;
        return SL_ERR_BUSY;
    }
    if (s->q_len > 0U) {
        return queue_push(s, f, t_us) ? SL_OK : SL_ERR_BUSY;
    }
    switch (write_frame(s, f, t_us)) {
    case WR_OK:
        return SL_OK;
    case WR_RETRY:
        return queue_push(s, f, t_us) ? SL_OK : SL_ERR_BUSY;
    case WR_DOWN:
        s->stats.dropped_down++;
        return SL_ERR_PORT;
    case WR_GONE:
        s->stats.dropped_down++;
        become_gone(s, t_us);
        return SL_ERR_PORT;
    case WR_ERROR:
        s->stats.dropped_error++;
        return SL_ERR_PORT;
    }
    return SL_ERR_PORT;
}

uint32_t slp_socketcan_dropped(const slp_socketcan_t *s)
{
    const slp_socketcan_stats_t *st = &s->stats;
    return st->dropped_full + st->dropped_stale + st->dropped_down + st->dropped_bus_off +
           st->dropped_error;
}

static sl_err_t sink_send(void *ctx, const sl_can_frame_t *f, uint64_t t_us)
{
    return slp_socketcan_send((slp_socketcan_t *)ctx, f, t_us);
}

static void sink_poll(void *ctx, uint64_t t_us)
{
    slp_socketcan_poll((slp_socketcan_t *)ctx, t_us);
}

static void sink_stats(void *ctx, slp_can_sink_stats_t *out)
{
    const slp_socketcan_t *s = (const slp_socketcan_t *)ctx;
    out->sent = s->stats.sent;
    out->dropped = slp_socketcan_dropped(s);
    out->queued = s->q_len;
    out->errors = s->stats.error_frames;
}

slp_can_sink_t slp_socketcan_sink(slp_socketcan_t *s)
{
    slp_can_sink_t k = {"socketcan", s, sink_send, sink_poll, sink_stats};
    return k;
}
