// SPDX-License-Identifier: MIT
// candump.c: the candump text format (frames, -L lines, both ways) and the log file sink (see candump.h).
#include "candump.h"

#include <ctype.h>
#include <errno.h>
#include <inttypes.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#define CAN_ERR_FLAG_BIT 0x20000000UL

static int hexval(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

sl_err_t slp_candump_parse_frame(const char *s, sl_can_frame_t *out, const char **why)
{
    const char *dummy = NULL;
    if (why == NULL) {
        why = &dummy;
    }
    memset(out, 0, sizeof *out);
    size_t idlen = 0;
    uint32_t id = 0;
    while (s[idlen] != '\0' && s[idlen] != '#') {
        int v = hexval(s[idlen]);
        if (v < 0 || idlen >= 8) {
            *why = "identifier: 3 or 8 hex digits expected before '#'";
            return SL_ERR_MALFORMED;
        }
        id = (id << 4) | (uint32_t)v;
        idlen++;
    }
    if (s[idlen] != '#' || (idlen != 3 && idlen != 8)) {
        *why = "identifier: 3 or 8 hex digits expected before '#'";
        return SL_ERR_MALFORMED;
    }
    if (idlen == 3) {
        if (id > SL_CAN_SFF_MASK) {
            *why = "11-bit identifier above 7FF";
            return SL_ERR_MALFORMED;
        }
    } else if ((id & CAN_ERR_FLAG_BIT) != 0U) {
        out->flags = SL_CAN_FLAG_ERR;
        id &= (uint32_t)SL_CAN_EFF_MASK;
    } else {
        if (id > SL_CAN_EFF_MASK) {
            *why = "29-bit identifier above 1FFFFFFF";
            return SL_ERR_MALFORMED;
        }
        out->flags = SL_CAN_FLAG_EFF;
    }
    out->id = id;
    const char *p = s + idlen + 1;
    if (*p == '#') {
        *why = "CAN FD frames are not supported";
        return SL_ERR_MALFORMED;
    }
    if (*p == 'R' || *p == 'r') {
        if ((out->flags & SL_CAN_FLAG_ERR) != 0U) {
            *why = "an error frame cannot be a remote request";
            return SL_ERR_MALFORMED;
        }
        out->flags |= SL_CAN_FLAG_RTR;
        p++;
        if (*p >= '0' && *p <= '8') {
            out->dlc = (uint8_t)(*p - '0');
            p++;
        }
        if (*p != '\0') {
            *why = "junk after R";
            return SL_ERR_MALFORMED;
        }
        return SL_OK;
    }
    uint8_t n = 0;
    while (*p != '\0') {
        if (*p == '.') {
            p++;
            continue;
        }
        int hi = hexval(p[0]);
        int lo = hi < 0 ? -1 : hexval(p[1]);
        if (hi < 0 || lo < 0) {
            *why = "data: hex byte pairs expected";
            return SL_ERR_MALFORMED;
        }
        if (n >= 8U) {
            *why = "more than 8 data bytes";
            return SL_ERR_MALFORMED;
        }
        out->data[n++] = (uint8_t)((hi << 4) | lo);
        p += 2;
    }
    out->dlc = n;
    return SL_OK;
}

sl_err_t slp_candump_parse_line(const char *line, sl_can_frame_t *out, const char **why)
{
    char buf[256];
    const char *dummy = NULL;
    if (why == NULL) {
        why = &dummy;
    }
    size_t n = strlen(line);
    if (n >= sizeof buf) {
        *why = "line too long";
        return SL_ERR_MALFORMED;
    }
    memcpy(buf, line, n + 1U);
    while (n > 0U && isspace((unsigned char)buf[n - 1U])) {
        buf[--n] = '\0';
    }
    char *p = buf;
    while (isspace((unsigned char)*p)) {
        p++;
    }
    if (*p == '\0') {
        return SL_ERR_NEED_MORE;
    }
    // The frame is the last blank-separated field ("(ts) iface frame" or a bare frame),
    // unless python-can appended " R"/" T" (rx/tx marker): then the one before it.
    char *last = strrchr(p, ' ');
    char *frame = last != NULL ? last + 1 : p;
    if (last != NULL && (strcmp(frame, "R") == 0 || strcmp(frame, "T") == 0)) {
        *last = '\0';
        last = strrchr(p, ' ');
        frame = last != NULL ? last + 1 : p;
    }
    if (frame != p && *p != '(') {
        *why = "expected '(timestamp) interface frame'";
        return SL_ERR_MALFORMED;
    }
    return slp_candump_parse_frame(frame, out, why);
}

char *slp_candump_format_frame(const sl_can_frame_t *f, char *buf, size_t cap)
{
    int k;
    if ((f->flags & SL_CAN_FLAG_ERR) != 0U) {
        k = snprintf(buf, cap, "%08lX#",
                     (unsigned long)((f->id & SL_CAN_EFF_MASK) | CAN_ERR_FLAG_BIT));
    } else if ((f->flags & SL_CAN_FLAG_EFF) != 0U) {
        k = snprintf(buf, cap, "%08lX#", (unsigned long)(f->id & SL_CAN_EFF_MASK));
    } else {
        k = snprintf(buf, cap, "%03lX#", (unsigned long)(f->id & SL_CAN_SFF_MASK));
    }
    if (k < 0 || (size_t)k >= cap) {
        return buf;
    }
    if ((f->flags & SL_CAN_FLAG_RTR) != 0U) {
        if (f->dlc > 0U && f->dlc <= 8U) {
            (void)snprintf(buf + k, cap - (size_t)k, "R%u", (unsigned)f->dlc);
        } else {
            (void)snprintf(buf + k, cap - (size_t)k, "R");
        }
        return buf;
    }
    for (uint8_t i = 0; i < f->dlc && i < 8U && (size_t)k + 3U <= cap; i++) {
        k += snprintf(buf + k, cap - (size_t)k, "%02X", (unsigned)f->data[i]);
    }
    return buf;
}

char *slp_candump_format_line(const sl_can_frame_t *f, uint64_t t_us, const char *iface, char *buf,
                             size_t cap)
{
    char fr[40];
    (void)snprintf(buf, cap, "(%010lu.%06lu) %s %s", (unsigned long)(t_us / 1000000U),
                   (unsigned long)(t_us % 1000000U), iface, slp_candump_format_frame(f, fr, sizeof fr));
    return buf;
}

sl_err_t slp_candump_parse_record(const char *line, slp_candump_record_t *out, const char **why)
{
    const char *dummy = NULL;
    if (why == NULL) {
        why = &dummy;
    }
    memset(out, 0, sizeof *out);
    const char *p = line;
    if (*p != '(') {
        *why = "line does not start with '('";
        return SL_ERR_MALFORMED;
    }
    p++;
    uint64_t sec = 0, frac = 0;
    size_t nsec = 0, nfrac = 0;
    for (; *p >= '0' && *p <= '9'; p++, nsec++) {
        if (sec > 18000000000000ULL) {
            *why = "bad seconds in the time stamp";
            return SL_ERR_MALFORMED;
        }
        sec = sec * 10U + (uint64_t)(*p - '0');
    }
    if (nsec == 0 || *p != '.') {
        *why = strchr(line, ')') == NULL ? "no ')' after the time stamp"
                                         : "time stamp is not <seconds>.<1..9 digits>";
        return SL_ERR_MALFORMED;
    }
    for (p++; *p >= '0' && *p <= '9'; p++, nfrac++) {
        if (nfrac < 6) {
            frac = frac * 10U + (uint64_t)(*p - '0');
        }
    }
    if (*p != ')') {
        *why = strchr(p, ')') == NULL ? "no ')' after the time stamp" : "bad fraction in the time stamp";
        return SL_ERR_MALFORMED;
    }
    if (nfrac == 0 || nfrac > 9) {
        *why = "time stamp is not <seconds>.<1..9 digits>";
        return SL_ERR_MALFORMED;
    }
    for (size_t k = nfrac; k < 6; k++) {
        frac *= 10U;
    }
    out->t_us = sec * 1000000U + frac;
    p++;
    // Tokens: iface, frame, optional direction marker.
    const char *tok[4];
    size_t len[4], n = 0;
    while (*p != '\0' && *p != '\n' && *p != '\r') {
        while (*p == ' ' || *p == '\t') {
            p++;
        }
        const char *e = p;
        while (*e != '\0' && *e != ' ' && *e != '\t' && *e != '\n' && *e != '\r') {
            e++;
        }
        if (e > p) {
            if (n == 4) {
                *why = "unexpected text after the frame";
                return SL_ERR_MALFORMED;
            }
            tok[n] = p;
            len[n++] = (size_t)(e - p);
        }
        p = e;
    }
    if (*p == '\r' || *p == '\n') {
        while (*p == '\r' || *p == '\n') {
            p++;
        }
        if (*p != '\0') {
            *why = "unexpected text after the frame";
            return SL_ERR_MALFORMED;
        }
    }
    if (n < 2) {
        *why = "expected '<iface> <frame>' after the time stamp";
        return SL_ERR_MALFORMED;
    }
    if (n > 3 || (n == 3 && !(len[2] == 1 && (tok[2][0] == 'R' || tok[2][0] == 'T')))) {
        *why = "unexpected text after the frame";
        return SL_ERR_MALFORMED;
    }
    if (len[0] >= sizeof out->iface) {
        *why = "interface name longer than 15 characters";
        return SL_ERR_MALFORMED;
    }
    memcpy(out->iface, tok[0], len[0]);
    char frame[64];
    if (len[1] >= sizeof frame) {
        *why = "frame text too long";
        return SL_ERR_MALFORMED;
    }
    memcpy(frame, tok[1], len[1]);
    frame[len[1]] = '\0';
    return slp_candump_parse_frame(frame, &out->frame, why);
}

bool slp_candump_frame_ok(const sl_can_frame_t *f)
{
    const uint32_t lim = (f->flags & (SL_CAN_FLAG_EFF | SL_CAN_FLAG_ERR)) != 0U ? SL_CAN_EFF_MASK : SL_CAN_SFF_MASK;
    return f->dlc <= 8U && f->id <= lim;
}

// ---------------------------------------------------------------------------------------
// Log file sink

sl_err_t slp_candump_open(slp_candump_t *c, const char *path, const char *iface)
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

static void count_io_error(slp_candump_t *c)
{
    c->last_errno = errno;
    c->stats.errors++;
    if (errno == EPIPE) {
        c->broken_pipe = true;
    }
}

sl_err_t slp_candump_send(slp_candump_t *c, const sl_can_frame_t *f)
{
    char text[40];
    if (f == NULL || !slp_candump_frame_ok(f)) {
        c->stats.dropped++;
        return SL_ERR_ARG;
    }
    if (c->fp == NULL || c->broken_pipe) {
        c->stats.dropped++;
        return SL_ERR_PORT;
    }
    (void)slp_candump_format_frame(f, text, sizeof text);
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

void slp_candump_flush(slp_candump_t *c)
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

void slp_candump_close(slp_candump_t *c)
{
    if (c->fp == NULL) {
        return;
    }
    slp_candump_flush(c);
    if (c->own && fclose(c->fp) != 0) {
        count_io_error(c);
    }
    c->fp = NULL;
}

static sl_err_t sink_send(void *ctx, const sl_can_frame_t *f, uint64_t t_us)
{
    (void)t_us;
    return slp_candump_send(ctx, f);
}

static void sink_poll(void *ctx, uint64_t t_us)
{
    (void)t_us;
    slp_candump_flush(ctx);
}

static void sink_stats(void *ctx, slp_can_sink_stats_t *out)
{
    const slp_candump_t *c = ctx;
    *out = c->stats;
}

slp_can_sink_t slp_candump_sink(slp_candump_t *c)
{
    slp_can_sink_t s = {"candump", c, sink_send, sink_poll, sink_stats};
    return s;
}
