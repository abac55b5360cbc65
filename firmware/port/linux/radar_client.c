// SPDX-License-Identifier: MIT
// radar_client.c: non-blocking Colossus TCP client (see radar_client.h).
#include "radar_client.h"

#include <errno.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "port_clock.h"

static uint64_t default_clock(void *ctx)
{
    (void)ctx;
    return slp_now_us();
}

static uint64_t ms_to_us(uint32_t ms) { return (uint64_t)ms * 1000U; }

void slp_radar_client_cfg_defaults(slp_radar_client_cfg_t *cfg)
{
    if (cfg == NULL) {
        return;
    }
    memset(cfg, 0, sizeof *cfg);
    cfg->port = 6317;
    cfg->connect_timeout_ms = 2000;
    cfg->silence_timeout_ms = 3000;
    cfg->data_timeout_ms = 3000;
    cfg->config_request_ms = 1000;
    cfg->config_timeout_ms = 5000;
    cfg->backoff_initial_ms = 100;
    cfg->backoff_max_ms = 5000;
}

const char *slp_radar_state_str(slp_radar_state_t s)
{
    switch (s) {
    case SLP_RADAR_IDLE: return "IDLE";
    case SLP_RADAR_BACKOFF: return "BACKOFF";
    case SLP_RADAR_CONNECTING: return "CONNECTING";
    case SLP_RADAR_WAIT_CONFIG: return "WAIT_CONFIG";
    case SLP_RADAR_STREAMING: return "STREAMING";
    }
    return "?";
}

const char *slp_radar_reason_str(slp_radar_reason_t r)
{
    switch (r) {
    case SLP_RADAR_REASON_NONE: return "NONE";
    case SLP_RADAR_REASON_EOF: return "EOF";
    case SLP_RADAR_REASON_ERROR: return "ERROR";
    case SLP_RADAR_REASON_SILENCE: return "SILENCE";
    case SLP_RADAR_REASON_CONFIG_TIMEOUT: return "CONFIG_TIMEOUT";
    case SLP_RADAR_REASON_CONNECT_TIMEOUT: return "CONNECT_TIMEOUT";
    case SLP_RADAR_REASON_STOP: return "STOP";
    case SLP_RADAR_REASON_NO_DATA: return "NO_DATA";
    }
    return "?";
}

static void emit(slp_radar_client_t *c, slp_radar_event_t ev, slp_radar_reason_t reason)
{
    if (c->cfg.on_event != NULL) {
        c->cfg.on_event(c->cfg.ctx, ev, reason, c->now_us);
    }
}

// Queue a bare command header; it is flushed by try_send().
static void queue_command(slp_radar_client_t *c, uint8_t id)
{
    if (c->tx_len + SL_PROTO_HEADER_BYTES > sizeof c->tx) {
        c->stats.tx_overflow++;
        return;
    }
    const sl_ssize_t n = sl_proto_encode_command(c->tx + c->tx_len, sizeof c->tx - c->tx_len, id);
    if (n > 0) {
        c->tx_len += (size_t)n;
    }
}

static void close_socket(slp_radar_client_t *c)
{
    if (c->fd >= 0) {
        (void)close(c->fd);
        c->fd = -1;
    }
    c->tx_len = 0;
    c->have_config = false;
    c->config_requested = false;
    c->data_restarted = false;
}

// Drop the connection (or failed attempt) and schedule the next attempt after the backoff.
static void drop(slp_radar_client_t *c, slp_radar_event_t ev, slp_radar_reason_t reason)
{
    const bool was_connected = c->state == SLP_RADAR_WAIT_CONFIG || c->state == SLP_RADAR_STREAMING;
    close_socket(c);
    if (was_connected) {
        (void)sl_proto_finish(&c->proto);
    }
    c->state = SLP_RADAR_BACKOFF;
    c->deadline_us = c->now_us + ms_to_us(c->stats.backoff_ms);
    uint64_t next = (uint64_t)c->stats.backoff_ms * 2U;
    if (next > c->cfg.backoff_max_ms) {
        next = c->cfg.backoff_max_ms;
    }
    c->stats.backoff_ms = (uint32_t)next;
    emit(c, ev, reason);
}

static void on_socket_error(slp_radar_client_t *c, int err)
{
    c->stats.last_errno = err;
    c->stats.disconnects_error++;
    drop(c, SLP_RADAR_EV_DISCONNECTED, SLP_RADAR_REASON_ERROR);
}

static void try_send(slp_radar_client_t *c)
{
    while (c->fd >= 0 && c->tx_len > 0) {
        const ssize_t n = send(c->fd, c->tx, c->tx_len, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n > 0) {
            const size_t sent = (size_t)n;
            memmove(c->tx, c->tx + sent, c->tx_len - sent);
            c->tx_len -= sent;
            c->stats.bytes_tx += sent;
        } else if (n < 0 && errno == EINTR) {
            continue;
        } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            c->stats.tx_would_block++;
            return;
        } else {
            on_socket_error(c, n < 0 ? errno : EPIPE);
            return;
        }
    }
}

static void on_connected(slp_radar_client_t *c)
{
    c->state = SLP_RADAR_WAIT_CONFIG;
    c->connected_us = c->now_us;
    c->last_rx_us = c->now_us;
    c->have_config = false;
    c->config_requested = false;
    if (c->stats.connects > 0U) {
        c->stats.reconnects++;
    }
    c->stats.connects++;
    emit(c, SLP_RADAR_EV_CONNECTED, SLP_RADAR_REASON_NONE);
}

// Decoder callback: bookkeeping, handshake, then the application's callback.
static void on_proto_msg(void *ctx, const sl_proto_msg_t *msg)
{
    slp_radar_client_t *c = (slp_radar_client_t *)ctx;
    c->stats.messages++;
    switch (msg->id) {
    case SL_PROTO_ID_KEEP_ALIVE:
        c->stats.keep_alives++;
        break;
    case SL_PROTO_ID_FFT_DATA:
    case SL_PROTO_ID_FFT_DATA_16: {
        c->stats.fft_messages++;
        sl_proto_fft_t f;
        if (sl_proto_parse_fft(msg, &f) == SL_OK && f.bins > 0U) {
            c->stats.usable_fft++;
            c->last_data_us = c->now_us;
            c->data_restarted = false;
            // A healthy session (usable data, not just a Configuration): the next failure
            // starts again from the initial backoff.
            c->stats.backoff_ms = c->cfg.backoff_initial_ms;
        }
        break;
    }
    case SL_PROTO_ID_CONFIGURATION:
        c->stats.configs++;
        if (c->fd >= 0 && !c->have_config) {
            c->have_config = true;
            queue_command(c, c->cfg.non_contour ? (uint8_t)SL_PROTO_ID_START_NONCONTOUR_FFT
                                                : (uint8_t)SL_PROTO_ID_START_FFT);
            c->stats.starts_sent++;
            c->state = SLP_RADAR_STREAMING;
            c->last_data_us = c->now_us; // the watchdog measures from Start FFT
        }
        emit(c, SLP_RADAR_EV_CONFIG, SLP_RADAR_REASON_NONE);
        break;
    default:
        break;
    }
    if (c->cfg.on_msg != NULL) {
        c->cfg.on_msg(c->cfg.ctx, msg, c->now_us);
    }
}

sl_err_t slp_radar_client_init(slp_radar_client_t *c, const slp_radar_client_cfg_t *cfg)
{
    if (c == NULL || cfg == NULL || cfg->host == NULL || cfg->port == 0U ||
        cfg->backoff_initial_ms == 0U || cfg->backoff_max_ms < cfg->backoff_initial_ms ||
        cfg->connect_timeout_ms == 0U || (cfg->reasm_buf == NULL && cfg->reasm_size > 0U)) {
        return SL_ERR_ARG;
    }
    memset(c, 0, sizeof *c);
    c->cfg = *cfg;
    if (c->cfg.clock_us == NULL) {
        c->cfg.clock_us = default_clock;
    }
    c->fd = -1;
    c->state = SLP_RADAR_IDLE;
    c->stats.backoff_ms = cfg->backoff_initial_ms;

    sl_proto_cfg_t pc;
    memset(&pc, 0, sizeof pc);
    pc.reasm_buf = cfg->reasm_buf;
    pc.reasm_size = cfg->reasm_size;
    pc.max_payload_bytes = cfg->max_payload_bytes;
    pc.on_msg = on_proto_msg;
    pc.ctx = c;
    if (sl_proto_init(&c->proto, &pc) != SL_OK) {
        return SL_ERR_ARG;
    }

    char port[8];
    (void)snprintf(port, sizeof port, "%u", (unsigned)cfg->port);
    struct addrinfo hints;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_NUMERICSERV;
    struct addrinfo *res = NULL;
    if (getaddrinfo(cfg->host, port, &hints, &res) != 0 || res == NULL) {
        return SL_ERR_PORT;
    }
    for (const struct addrinfo *ai = res; ai != NULL && c->n_addrs < SLP_RADAR_MAX_ADDRS; ai = ai->ai_next) {
        if (ai->ai_addrlen <= sizeof c->addrs[0]) {
            memcpy(&c->addrs[c->n_addrs], ai->ai_addr, ai->ai_addrlen);
            c->addr_lens[c->n_addrs] = ai->ai_addrlen;
            c->n_addrs++;
        }
    }
    freeaddrinfo(res);
    return c->n_addrs > 0U ? SL_OK : SL_ERR_PORT;
}

sl_err_t slp_radar_client_start(slp_radar_client_t *c)
{
    if (c == NULL) {
        return SL_ERR_ARG;
    }
    if (c->state != SLP_RADAR_IDLE) {
        return SL_ERR_STATE;
    }
    c->state = SLP_RADAR_BACKOFF;
    c->deadline_us = 0; // the first attempt is due at once
    return SL_OK;
}

int slp_radar_client_fd(const slp_radar_client_t *c) { return c != NULL ? c->fd : -1; }

short slp_radar_client_events(const slp_radar_client_t *c)
{
    if (c == NULL || c->fd < 0) {
        return 0;
    }
    if (c->state == SLP_RADAR_CONNECTING) {
        return POLLOUT;
    }
    return (short)(POLLIN | (c->tx_len > 0U ? POLLOUT : 0));
}

// Next deadline of the current state, or UINT64_MAX.
static uint64_t next_deadline(const slp_radar_client_t *c)
{
    uint64_t d = UINT64_MAX;
    switch (c->state) {
    case SLP_RADAR_IDLE:
        break;
    case SLP_RADAR_BACKOFF:
    case SLP_RADAR_CONNECTING:
        d = c->deadline_us;
        break;
    case SLP_RADAR_WAIT_CONFIG:
        if (c->cfg.config_request_ms > 0U && !c->config_requested) {
            const uint64_t t = c->connected_us + ms_to_us(c->cfg.config_request_ms);
            d = t < d ? t : d;
        }
        if (c->cfg.config_timeout_ms > 0U) {
            const uint64_t t = c->connected_us + ms_to_us(c->cfg.config_timeout_ms);
            d = t < d ? t : d;
        }
        // fall through: the silence timeout applies in both connected states
        /* FALLTHROUGH */
    case SLP_RADAR_STREAMING:
        if (c->cfg.silence_timeout_ms > 0U) {
            const uint64_t t = c->last_rx_us + ms_to_us(c->cfg.silence_timeout_ms);
            d = t < d ? t : d;
        }
        if (c->state == SLP_RADAR_STREAMING && c->cfg.data_timeout_ms > 0U) {
            const uint64_t t = c->last_data_us + ms_to_us(c->cfg.data_timeout_ms);
            d = t < d ? t : d;
        }
        break;
    }
    return d;
}

int slp_radar_client_timeout_ms(const slp_radar_client_t *c, uint64_t now_us)
{
    if (c == NULL) {
        return -1;
    }
    const uint64_t d = next_deadline(c);
    if (d == UINT64_MAX) {
        return -1;
    }
    if (d <= now_us) {
        return 0;
    }
    const uint64_t ms = (d - now_us + 999U) / 1000U; // round up: never wake before it is due
    return ms > (uint64_t)INT32_MAX ? INT32_MAX : (int)ms;
}

static void start_connect(slp_radar_client_t *c)
{
    const unsigned i = c->next_addr % c->n_addrs;
    c->next_addr = (i + 1U) % c->n_addrs;
    c->stats.connect_attempts++;
    const struct sockaddr *sa = (const struct sockaddr *)&c->addrs[i];
    const int fd = socket(sa->sa_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, IPPROTO_TCP);
    if (fd < 0) {
        c->stats.last_errno = errno;
        c->stats.connect_failures++;
        c->state = SLP_RADAR_CONNECTING; // so that drop() schedules the backoff
        drop(c, SLP_RADAR_EV_CONNECT_FAILED, SLP_RADAR_REASON_ERROR);
        return;
    }
    const int one = 1;
    (void)setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    c->fd = fd;
    c->state = SLP_RADAR_CONNECTING;
    c->deadline_us = c->now_us + ms_to_us(c->cfg.connect_timeout_ms);
    int rc;
    do {
        rc = connect(fd, sa, c->addr_lens[i]);
    } while (rc < 0 && errno == EINTR);
    if (rc == 0) {
        on_connected(c);
    } else if (errno != EINPROGRESS) {
        c->stats.last_errno = errno;
        c->stats.connect_failures++;
        drop(c, SLP_RADAR_EV_CONNECT_FAILED, SLP_RADAR_REASON_ERROR);
    }
}

static void do_read(slp_radar_client_t *c)
{
    size_t budget = SL_RADAR_RX_BUDGET;
    while (c->fd >= 0 && budget > 0U) {
        const ssize_t n = recv(c->fd, c->rx, sizeof c->rx, MSG_DONTWAIT);
        if (n > 0) {
            const size_t got = (size_t)n;
            budget = got >= budget ? 0U : budget - got;
            c->stats.bytes_rx += got;
            c->last_rx_us = c->now_us;
            if (c->cfg.on_bytes != NULL) {
                c->cfg.on_bytes(c->cfg.ctx, c->rx, got, c->now_us);
            }
            (void)sl_proto_feed(&c->proto, c->rx, got, c->now_us);
            try_send(c); // a Start FFT may have been queued by the decoder callback
            if (got < sizeof c->rx) {
                return; // drained for now
            }
        } else if (n == 0) {
            c->stats.disconnects_eof++;
            drop(c, SLP_RADAR_EV_DISCONNECTED, SLP_RADAR_REASON_EOF);
            return;
        } else if (errno == EINTR) {
            continue;
        } else if (errno == EAGAIN || errno == EWOULDBLOCK) {
            return;
        } else {
            on_socket_error(c, errno);
            return;
        }
    }
}

sl_err_t slp_radar_client_handle(slp_radar_client_t *c, short revents, uint64_t now_us)
{
    if (c == NULL) {
        return SL_ERR_ARG;
    }
    c->now_us = now_us;
    c->stats.handle_calls++;

    if (c->fd >= 0 && revents != 0) {
        if (c->state == SLP_RADAR_CONNECTING) {
            int err = 0;
            socklen_t len = sizeof err;
            if (getsockopt(c->fd, SOL_SOCKET, SO_ERROR, &err, &len) < 0) {
                err = errno;
            }
            if (err == 0 && (revents & POLLOUT) != 0) {
                on_connected(c);
            } else if (err != 0 || (revents & (POLLERR | POLLHUP)) != 0) {
                c->stats.last_errno = err != 0 ? err : ECONNREFUSED;
                c->stats.connect_failures++;
                drop(c, SLP_RADAR_EV_CONNECT_FAILED, SLP_RADAR_REASON_ERROR);
            }
        } else {
            if ((revents & (POLLIN | POLLHUP | POLLERR)) != 0) {
                do_read(c); // reads EOF / error conditions as well
            }
            if (c->fd >= 0 && (revents & POLLOUT) != 0) {
                try_send(c);
            }
        }
    }

    // Timers.
    switch (c->state) {
    case SLP_RADAR_IDLE:
        break;
    case SLP_RADAR_BACKOFF:
        if (now_us >= c->deadline_us) {
            start_connect(c);
        }
        break;
    case SLP_RADAR_CONNECTING:
        if (now_us >= c->deadline_us) {
            c->stats.connect_timeouts++;
            drop(c, SLP_RADAR_EV_CONNECT_FAILED, SLP_RADAR_REASON_CONNECT_TIMEOUT);
        }
        break;
    case SLP_RADAR_WAIT_CONFIG:
        if (c->cfg.config_timeout_ms > 0U &&
            now_us >= c->connected_us + ms_to_us(c->cfg.config_timeout_ms)) {
            c->stats.config_timeouts++;
            drop(c, SLP_RADAR_EV_DISCONNECTED, SLP_RADAR_REASON_CONFIG_TIMEOUT);
            break;
        }
        if (c->cfg.config_request_ms > 0U && !c->config_requested &&
            now_us >= c->connected_us + ms_to_us(c->cfg.config_request_ms)) {
            c->config_requested = true;
            c->stats.config_requests++;
            queue_command(c, (uint8_t)SL_PROTO_ID_CONFIG_REQUEST);
            try_send(c);
        }
        /* FALLTHROUGH */
    case SLP_RADAR_STREAMING:
        if (c->fd >= 0 && c->cfg.silence_timeout_ms > 0U &&
            now_us >= c->last_rx_us + ms_to_us(c->cfg.silence_timeout_ms)) {
            c->stats.silence_timeouts++;
            drop(c, SLP_RADAR_EV_DISCONNECTED, SLP_RADAR_REASON_SILENCE);
            break;
        }
        if (c->fd >= 0 && c->state == SLP_RADAR_STREAMING && c->cfg.data_timeout_ms > 0U &&
            now_us >= c->last_data_us + ms_to_us(c->cfg.data_timeout_ms)) {
            if (!c->data_restarted) {
                // Bytes but no usable rows: ask for the data again, once.
                c->data_restarted = true;
                c->stats.data_restarts++;
                c->last_data_us = now_us;
                queue_command(c, c->cfg.non_contour ? (uint8_t)SL_PROTO_ID_START_NONCONTOUR_FFT
                                                    : (uint8_t)SL_PROTO_ID_START_FFT);
                c->stats.starts_sent++;
                try_send(c);
            } else {
                c->stats.data_timeouts++;
                drop(c, SLP_RADAR_EV_DISCONNECTED, SLP_RADAR_REASON_NO_DATA);
            }
        }
        break;
    }
    return SL_OK;
}

sl_err_t slp_radar_client_poll(slp_radar_client_t *c, int timeout_ms)
{
    if (c == NULL) {
        return SL_ERR_ARG;
    }
    if (c->state == SLP_RADAR_IDLE) {
        return SL_ERR_STATE;
    }
    const uint64_t t0 = c->cfg.clock_us(c->cfg.ctx);
    int t = slp_radar_client_timeout_ms(c, t0);
    if (timeout_ms >= 0 && (t < 0 || timeout_ms < t)) {
        t = timeout_ms;
    }
    struct pollfd pfd;
    pfd.fd = c->fd;
    pfd.events = slp_radar_client_events(c);
    pfd.revents = 0;
    const int rc = poll(&pfd, c->fd >= 0 ? 1U : 0U, t);
    if (rc < 0) {
        if (errno == EINTR) {
            return SL_OK;
        }
        c->stats.last_errno = errno;
        return SL_ERR_PORT;
    }
    return slp_radar_client_handle(c, rc > 0 ? pfd.revents : 0, c->cfg.clock_us(c->cfg.ctx));
}

sl_err_t slp_radar_client_stop(slp_radar_client_t *c, uint32_t linger_ms)
{
    if (c == NULL) {
        return SL_ERR_ARG;
    }
    c->now_us = c->cfg.clock_us(c->cfg.ctx);
    if (c->fd >= 0 && c->state == SLP_RADAR_STREAMING) {
        queue_command(c, (uint8_t)SL_PROTO_ID_STOP_FFT);
        c->stats.stops_sent++;
        const uint64_t end = c->now_us + ms_to_us(linger_ms);
        try_send(c);
        while (c->fd >= 0 && c->tx_len > 0U) {
            const uint64_t now = c->cfg.clock_us(c->cfg.ctx);
            if (now >= end) {
                break;
            }
            struct pollfd pfd = {c->fd, POLLOUT, 0};
            const int rc = poll(&pfd, 1U, (int)((end - now + 999U) / 1000U));
            if (rc < 0 && errno != EINTR) {
                break;
            }
            c->now_us = c->cfg.clock_us(c->cfg.ctx);
            try_send(c);
        }
        if (c->fd >= 0) {
            (void)shutdown(c->fd, SHUT_WR);
        }
    }
    const bool was_connected = c->state == SLP_RADAR_WAIT_CONFIG || c->state == SLP_RADAR_STREAMING;
    close_socket(c);
    if (was_connected) {
        (void)sl_proto_finish(&c->proto);
    }
    const bool was_idle = c->state == SLP_RADAR_IDLE;
    c->state = SLP_RADAR_IDLE;
    if (!was_idle) {
        emit(c, SLP_RADAR_EV_STOPPED, SLP_RADAR_REASON_STOP);
    }
    return SL_OK;
}

void slp_radar_client_deinit(slp_radar_client_t *c)
{
    if (c != NULL) {
        (void)slp_radar_client_stop(c, 0);
    }
}
