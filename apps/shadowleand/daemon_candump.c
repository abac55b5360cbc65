// daemon_candump.c: candump -L log sink of shadowleand (see daemon_candump.h).
#include "daemon_candump.h"

#include <errno.h>
#include <inttypes.h>
#include <string.h>

sl_err_t sld_candump_open(sld_candump_t *c, const char *path, const char *iface)
{
    memset(c, 0, sizeof *c);
    const size_t n = iface != NULL ? strlen(iface) : 0;
    if (path == NULL || n == 0 || n >= sizeof c->iface || strpbrk(iface, " \t\n") != NULL) {
        return SL_ERR_ARG;
    }
    memcpy(c->iface, iface, n + 1);
    if (strcmp(path, "-") == 0) {
        c->fp = stdout;
        c->own = false;
        return SL_OK;
    }
    c->fp = fopen(path, "w");
    if (c->fp == NULL) {
        c->last_errno = errno;
        return SL_ERR_PORT;
    }
    c->own = true;
    return SL_OK;
}

sl_err_t sld_candump_format_frame(const sl_can_frame_t *f, char *buf, size_t cap)
{
    static const char hex[] = "0123456789ABCDEF";
    if (f == NULL || buf == NULL || cap < 32 || f->dlc > 8) {
        return SL_ERR_ARG;
    }
    int k;
    if ((f->flags & SL_CAN_FLAG_ERR) != 0) {
        if (f->id > SL_CAN_EFF_MASK) {
            return SL_ERR_ARG;
        }
        k = snprintf(buf, cap, "%08" PRIX32 "#", (uint32_t)(f->id | 0x20000000UL));
    } else if ((f->flags & SL_CAN_FLAG_EFF) != 0) {
        if (f->id > SL_CAN_EFF_MASK) {
            return SL_ERR_ARG;
        }
        k = snprintf(buf, cap, "%08" PRIX32 "#", f->id);
    } else {
        if (f->id > SL_CAN_SFF_MASK) {
            return SL_ERR_ARG;
        }
        k = snprintf(buf, cap, "%03" PRIX32 "#", f->id);
    }
    size_t pos = (size_t)k;
    if ((f->flags & SL_CAN_FLAG_RTR) != 0) {
        buf[pos++] = 'R';
        if (f->dlc > 0) {
            buf[pos++] = (char)('0' + f->dlc);
        }
    } else {
        for (unsigned i = 0; i < f->dlc; i++) {
            buf[pos++] = hex[f->data[i] >> 4];
            buf[pos++] = hex[f->data[i] & 0x0F];
        }
    }
    buf[pos] = '\0';
    return SL_OK;
}

static void count_io_error(sld_candump_t *c)
{
    c->last_errno = errno;
    c->stats.errors++;
    if (errno == EPIPE) {
        c->broken_pipe = true;
    }
}

sl_err_t sld_candump_send(sld_candump_t *c, const sl_can_frame_t *f)
{
    char text[40];
    if (sld_candump_format_frame(f, text, sizeof text) != SL_OK) {
        c->stats.dropped++;
        return SL_ERR_ARG;
    }
    if (c->fp == NULL || c->broken_pipe) {
        c->stats.dropped++;
        return SL_ERR_PORT;
    }
    const uint64_t sec = c->stamp_us / 1000000U;
    const uint64_t usec = c->stamp_us % 1000000U;
    if (fprintf(c->fp, "(%010" PRIu64 ".%06" PRIu64 ") %s %s\n", sec, usec, c->iface, text) < 0) {
        count_io_error(c);
        c->stats.dropped++;
        return SL_ERR_PORT;
    }
    c->stats.sent++;
    c->unflushed++;
    return SL_OK;
}

void sld_candump_flush(sld_candump_t *c)
{
    if (c->fp == NULL || c->broken_pipe) {
        return;
    }
    if (fflush(c->fp) != 0) {
        count_io_error(c);
        c->stats.dropped += c->unflushed; // buffered lines that never reached the file
    }
    c->unflushed = 0;
}

void sld_candump_close(sld_candump_t *c)
{
    if (c->fp == NULL) {
        return;
    }
    sld_candump_flush(c);
    if (c->own && fclose(c->fp) != 0) {
        count_io_error(c);
    }
    c->fp = NULL;
}

static sl_err_t sink_send(void *ctx, const sl_can_frame_t *f, uint64_t t_us)
{
    (void)t_us;
    return sld_candump_send(ctx, f);
}

static void sink_poll(void *ctx, uint64_t t_us)
{
    (void)t_us;
    sld_candump_flush(ctx);
}

static void sink_stats(void *ctx, sl_can_sink_stats_t *out)
{
    const sld_candump_t *c = ctx;
    *out = c->stats;
}

sl_can_sink_t sld_candump_sink(sld_candump_t *c)
{
    sl_can_sink_t s = {"candump", c, sink_send, sink_poll, sink_stats};
    return s;
}
