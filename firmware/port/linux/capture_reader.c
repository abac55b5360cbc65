// SPDX-License-Identifier: MIT
// capture_reader.c: streaming raw / pcap / pcapng capture reader (see capture_reader.h).
#include "capture_reader.h"

#include <errno.h>
#include <fcntl.h>
#include <pcap/pcap.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#define SNIFF_BYTES 4u
#define DEFAULT_PORT 6317u

// The 16-byte Colossus signature, used only to auto-detect the radar side of a pcap.
static const uint8_t k_signature[16] = {0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                                        0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE};

typedef struct seg {
    int64_t a;      // session stream offset of data[0]
    uint32_t len;
    uint8_t *data;  // malloc'd copy
} seg_t;

typedef struct flow {
    uint8_t src[16], dst[16];
    uint8_t alen;
    uint16_t sport, dport;
    bool have_seq;
    uint32_t last_seq;
    int64_t last_rel;
    bool syn, fin, rst, had_payload;
    int64_t syn_rel, fin_rel;
    uint64_t first_ts_us, last_ts_us;
    uint64_t packets, payload_bytes;
    bool was_selected;
    int role;       // ROLE_*
} flow_t;

// DONE: a session already reassembled; its late packets (retransmissions) are ignored.
enum { ROLE_NONE = 0, ROLE_SELECTED, ROLE_CANDIDATE, ROLE_IGNORED, ROLE_DONE };

typedef struct sess {
    bool active;
    int flow;
    bool have_base;
    int64_t base;     // flow-relative sequence number of stream offset 0
    int64_t cursor;   // bytes delivered (session stream offset)
    int64_t max_end;
    bool closing;     // being drained before the candidate takes over
    bool fin_gap_done;
    seg_t *pend;      // sorted by a, non-overlapping
    size_t n_pend;
    size_t pend_bytes;
} sess_t;

typedef struct pkt_seg { // the current packet's payload for a session (retryable)
    bool valid;
    bool counted;
    int flow;
    int64_t data_rel;
    const uint8_t *data;
    uint32_t len;
} pkt_seg_t;

struct slp_capture {
    int fd;
    bool own_fd;
    slp_capture_opts_t opt;
    slp_capture_report_t rep;
    char err[512];
    bool finished;
    slp_capture_piece_kind_t final_kind;
    uint64_t out_off;   // bytes delivered in total

    // raw
    bool mapped;        // regular file: read through a sliding read-only mapping (no copy)
    uint64_t file_size, map_off;
    void *map;
    size_t map_len;
    uint8_t *buf;
    size_t prefix_len;  // sniffed bytes at buf[0..prefix_len) not yet handed on
    size_t prefix_pos;

    // pcap
    FILE *fp;
    pcap_t *pc;
    int dlt;
    bool eof;
    bool port_locked;
    uint16_t radar_port;
    flow_t flows[SLP_CAPTURE_MAX_FLOWS];
    size_t n_flows;
    size_t last_flow;
    sess_t sel, cand;
    pkt_seg_t ps;
    uint8_t *held;      // segment storage handed out by the previous DATA piece
    bool brk_pending;
    slp_capture_piece_t brk;
    uint8_t *tail;      // last SLP_CAPTURE_TAIL delivered bytes of the selected session (ring)
    // Payload seen before the radar port is known (auto-detection), replayed into the
    // session of the flow that turns out to be the radar's.
    struct held_seg {
        int flow;
        int64_t data_rel;
        uint32_t len;
        uint8_t *data;
    } *pre;
    size_t n_pre, pre_bytes;
};

#define PRE_SEGS 4096u
#define PRE_BYTES (4u << 20)

// ---------------------------------------------------------------------------------------
// helpers

static uint16_t be16(const uint8_t *p) { return (uint16_t)((unsigned)p[0] << 8 | p[1]); }
static uint32_t be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | (uint32_t)p[3];
}

static int id_side(uint8_t id)
{
    switch (id) {
    case 1: case 10: case 30: case 31: case 40: case 123: case 127: return 1;
    case 20: case 21: case 22: case 23: case 24: case 25: case 28: case 29: case 50:
    case 51: case 76: case 120: case 121: case 122: case 124: case 140: return -1;
    default: return 0;
    }
}

static int64_t score_payload(const uint8_t *p, size_t n)
{
    int64_t s = 0;
    for (size_t i = 0; i + 18 <= n; ++i) {
        if (p[i] == 0x00 && p[i + 1] == 0x01 && memcmp(p + i, k_signature, 16) == 0 && p[i + 16] == 1) {
            s += id_side(p[i + 17]);
            i += 17;
        }
    }
    return s;
}

const char *slp_capture_format_name(slp_capture_format_t f)
{
    switch (f) {
    case SLP_CAPTURE_RAW: return "raw";
    case SLP_CAPTURE_PCAP: return "pcap";
    case SLP_CAPTURE_PCAPNG: return "pcapng";
    }
    return "unknown";
}

// A stdio stream over the fd that first returns the sniffed bytes: libpcap reads the
// capture from its first byte without the file being reopened (pipes, FIFOs, stdin).
static ssize_t cookie_read(void *cookie, char *out, size_t size)
{
    slp_capture_t *c = cookie;
    if (c->prefix_pos < c->prefix_len) {
        size_t n = c->prefix_len - c->prefix_pos;
        if (n > size) {
            n = size;
        }
        memcpy(out, c->buf + c->prefix_pos, n);
        c->prefix_pos += n;
        c->rep.bytes_in += n;
        return (ssize_t)n;
    }
    for (;;) {
        const ssize_t n = read(c->fd, out, size);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n > 0) {
            c->rep.bytes_in += (uint64_t)n;
        }
        return n;
    }
}

static int cookie_close(void *cookie)
{
    (void)cookie; // the fd is closed by slp_capture_close
    return 0;
}

// ---------------------------------------------------------------------------------------
// sessions

static void sess_free(sess_t *s)
{
    for (size_t i = 0; i < s->n_pend; i++) {
        free(s->pend[i].data);
    }
    s->n_pend = 0;
    s->pend_bytes = 0;
}

static void sess_reset(sess_t *s, int flow)
{
    seg_t *p = s->pend;
    sess_free(s);
    memset(s, 0, sizeof *s);
    s->pend = p;
    s->active = flow >= 0;
    s->flow = flow;
}

/// Bytes of [a, b) already seen: below the cursor or held out of order.
static int64_t sess_covered(const sess_t *s, int64_t a, int64_t b)
{
    int64_t n = 0;
    if (a < s->cursor) {
        n += (b < s->cursor ? b : s->cursor) - a;
        a = s->cursor;
    }
    for (size_t i = 0; i < s->n_pend && a < b; i++) {
        const int64_t lo = s->pend[i].a > a ? s->pend[i].a : a;
        const int64_t e = s->pend[i].a + (int64_t)s->pend[i].len;
        const int64_t hi = e < b ? e : b;
        if (hi > lo) {
            n += hi - lo;
        }
        if (s->pend[i].a >= b) {
            break;
        }
    }
    return n;
}

static bool sess_full(const sess_t *s, uint32_t len)
{
    return s->n_pend + 2 > SLP_CAPTURE_PENDING_SEGS ||
           s->pend_bytes + len > SLP_CAPTURE_PENDING_MAX;
}

/// Hold the parts of [a, a+len) not held yet (first copy wins), counting differing re-sends.
static bool sess_insert(slp_capture_t *c, sess_t *s, int64_t a, const uint8_t *d, uint32_t len)
{
    int64_t b = a + (int64_t)len;
    size_t i = 0;
    while (a < b) {
        while (i < s->n_pend && s->pend[i].a + (int64_t)s->pend[i].len <= a) {
            i++;
        }
        int64_t stop = b;
        if (i < s->n_pend && s->pend[i].a <= a) { // overlap with a held segment: compare
            const seg_t *g = &s->pend[i];
            const int64_t e = g->a + (int64_t)g->len < b ? g->a + (int64_t)g->len : b;
            for (int64_t k = a; k < e; k++) {
                c->rep.retransmit_mismatch_bytes += g->data[k - g->a] != d[k - (b - (int64_t)len)] ? 1u : 0u;
            }
            a = e;
            continue;
        }
        if (i < s->n_pend && s->pend[i].a < stop) {
            stop = s->pend[i].a;
        }
        if (s->n_pend >= SLP_CAPTURE_PENDING_SEGS) {
            return false;
        }
        const size_t n = (size_t)(stop - a);
        uint8_t *copy = malloc(n);
        if (copy == NULL) {
            return false;
        }
        memcpy(copy, d + (a - (b - (int64_t)len)), n);
        memmove(&s->pend[i + 1], &s->pend[i], (s->n_pend - i) * sizeof s->pend[0]);
        s->pend[i] = (seg_t){a, (uint32_t)n, copy};
        s->n_pend++;
        s->pend_bytes += n;
        i++;
        a = stop;
    }
    return true;
}

static void tail_put(slp_capture_t *c, int64_t at, const uint8_t *d, size_t n)
{
    if (n > SLP_CAPTURE_TAIL) {
        at += (int64_t)(n - SLP_CAPTURE_TAIL);
        d += n - SLP_CAPTURE_TAIL;
        n = SLP_CAPTURE_TAIL;
    }
    for (size_t k = 0; k < n;) {
        const size_t pos = (size_t)((uint64_t)(at + (int64_t)k) % SLP_CAPTURE_TAIL);
        size_t run = SLP_CAPTURE_TAIL - pos;
        if (run > n - k) {
            run = n - k;
        }
        memcpy(c->tail + pos, d + k, run);
        k += run;
    }
}

static void set_gap(slp_capture_t *c, uint64_t missing)
{
    c->brk_pending = true;
    c->brk = (slp_capture_piece_t){.kind = SLP_CAPTURE_BREAK, .brk = SLP_CAPTURE_GAP,
                                       .output_offset = c->out_off, .missing_bytes = missing,
                                       .stream_offset = (uint64_t)c->sel.cursor,
                                       .session = c->rep.sessions > 0 ? (uint32_t)(c->rep.sessions - 1) : 0u};
    c->rep.gaps++;
    c->rep.gap_bytes += missing;
}

static void data_piece(slp_capture_t *c, slp_capture_piece_t *pc, const uint8_t *d, size_t n)
{
    *pc = (slp_capture_piece_t){.kind = SLP_CAPTURE_DATA, .data = d, .size = n,
                                    .output_offset = c->out_off};
    c->out_off += n;
    c->rep.stream_bytes += n;
}

// ---------------------------------------------------------------------------------------
// packets

static flow_t *flow_find(slp_capture_t *c, const uint8_t *src, const uint8_t *dst, uint8_t alen,
                         uint16_t sport, uint16_t dport, bool syn, uint64_t ts, int *idx)
{
    int found = -1;
    for (size_t k = 0; k < c->n_flows; k++) {
        const size_t i = (c->last_flow + k) % c->n_flows;
        const flow_t *f = &c->flows[i];
        if (f->sport == sport && f->dport == dport && f->alen == alen &&
            memcmp(f->src, src, alen) == 0 && memcmp(f->dst, dst, alen) == 0) {
            found = (int)i;
            break;
        }
    }
    // A SYN on a 4-tuple that already carried data starts a new session (port reuse).
    if (found >= 0 && syn && c->flows[found].had_payload) {
        flow_t *old = &c->flows[found];
        if (old->role == ROLE_SELECTED) {
            old->rst = true; // ended: a successor may take over
        }
        if (old->role != ROLE_SELECTED && old->role != ROLE_CANDIDATE) {
            old->role = ROLE_DONE;
        }
        old->alen = (uint8_t)(old->alen | 0x80u); // never matched again (kept until drained)
        found = -1;
    }
    if (found < 0) {
        if (c->n_flows >= SLP_CAPTURE_MAX_FLOWS) {
            c->rep.flows_untracked++;
            return NULL;
        }
        found = (int)c->n_flows++;
        flow_t *f = &c->flows[found];
        memset(f, 0, sizeof *f);
        memcpy(f->src, src, alen);
        memcpy(f->dst, dst, alen);
        f->alen = alen;
        f->sport = sport;
        f->dport = dport;
        f->first_ts_us = ts;
    }
    c->last_flow = (size_t)found;
    *idx = found;
    return &c->flows[found];
}

/// Count one selected-session segment [a, a+len) against what was seen before.
static void classify(slp_capture_t *c, sess_t *s, int64_t a, const uint8_t *d, uint32_t len)
{
    const int64_t b = a + (int64_t)len;
    c->rep.segments++;
    c->rep.payload_bytes += len;
    const int64_t cov = sess_covered(s, a, b);
    if (cov == (int64_t)len) {
        c->rep.retransmitted_segments++;
    } else {
        if (cov > 0) {
            c->rep.partial_overlap_segments++;
        }
        const int64_t lim = b < s->max_end ? b : s->max_end;
        if (a < lim && sess_covered(s, a, lim) < lim - a) {
            c->rep.out_of_order_segments++;
        }
    }
    c->rep.retransmitted_bytes += (uint64_t)cov;
    if (s->max_end < b) {
        s->max_end = b;
    }
    // Re-sent bytes already delivered: compare with the tail still held.
    const int64_t lo = a > s->cursor - (int64_t)SLP_CAPTURE_TAIL ? a : s->cursor - (int64_t)SLP_CAPTURE_TAIL;
    const int64_t hi = b < s->cursor ? b : s->cursor;
    for (int64_t k = lo; k < hi; k++) {
        c->rep.retransmit_mismatch_bytes +=
            c->tail[(uint64_t)k % SLP_CAPTURE_TAIL] != d[k - a] ? 1u : 0u;
    }
}

/// Segment of the selected session. @return 1 with `pc` set (DATA), 0 consumed, -1 retry
/// after the hole before the held bytes is declared a gap and they are delivered.
static int sel_segment(slp_capture_t *c, slp_capture_piece_t *pc)
{
    sess_t *s = &c->sel;
    pkt_seg_t *ps = &c->ps;
    const flow_t *f = &c->flows[s->flow];
    if (!s->have_base) {
        s->have_base = true;
        if (f->syn) {
            s->base = f->syn_rel + 1;
        } else {
            s->base = ps->data_rel;
            c->rep.started_mid_stream = true;
        }
    }
    int64_t a = ps->data_rel - s->base;
    const uint8_t *d = ps->data;
    uint32_t len = ps->len;
    if (a < 0) { // bytes before the ISN: impossible in a sane capture, drop them
        const int64_t cut = -a < (int64_t)len ? -a : (int64_t)len;
        d += cut;
        len -= (uint32_t)cut;
        a = 0;
        if (len == 0) {
            return 0;
        }
    }
    const int64_t b = a + (int64_t)len;
    if (!ps->counted) {
        ps->counted = true;
        classify(c, s, a, d, len);
    }
    if (b <= s->cursor) {
        return 0;
    }
    if (a <= s->cursor) {
        const size_t off = (size_t)(s->cursor - a);
        // bytes beyond b held out of order stay held; they overlap nothing delivered yet
        tail_put(c, s->cursor, d + off, len - off);
        data_piece(c, pc, d + off, len - off);
        s->cursor = b;
        return 1;
    }
    if (sess_full(s, len) || !sess_insert(c, s, a, d, len)) {
        // The store is full: the hole before the first bytes we have becomes a gap.
        const int64_t to = s->n_pend > 0 && s->pend[0].a < a ? s->pend[0].a : a;
        set_gap(c, (uint64_t)(to - s->cursor));
        s->cursor = to;
        return -1;
    }
    return 0;
}

/// Segment of the candidate session: held until it takes over (or is ignored).
static void cand_segment(slp_capture_t *c)
{
    sess_t *s = &c->cand;
    const flow_t *f = &c->flows[s->flow];
    if (!s->have_base) {
        s->have_base = true;
        s->base = f->syn ? f->syn_rel + 1 : c->ps.data_rel;
    }
    int64_t a = c->ps.data_rel - s->base;
    const uint8_t *d = c->ps.data;
    uint32_t len = c->ps.len;
    if (a < 0) {
        const int64_t cut = -a < (int64_t)len ? -a : (int64_t)len;
        d += cut;
        len -= (uint32_t)cut;
        a = 0;
    }
    if (len > 0 && !sess_full(s, len)) {
        (void)sess_insert(c, s, a, d, len);
    }
    // Held enough without the selected session sending: it has gone, the newcomer takes over.
    if (sess_full(s, 65536u)) {
        c->sel.closing = true;
    }
}

static void pre_free(slp_capture_t *c)
{
    for (size_t i = 0; i < c->n_pre; i++) {
        free(c->pre[i].data);
    }
    c->n_pre = 0;
    c->pre_bytes = 0;
}

/// Before the radar port is known: keep a copy (bounded; beyond, the bytes are lost and
/// show as a gap or a later start if that flow is the radar's).
static void pre_store(slp_capture_t *c, int flow, int64_t data_rel, const uint8_t *d, size_t n)
{
    if (c->pre == NULL || c->n_pre >= PRE_SEGS || c->pre_bytes + n > PRE_BYTES) {
        return;
    }
    uint8_t *copy = malloc(n);
    if (copy == NULL) {
        return;
    }
    memcpy(copy, d, n);
    c->pre[c->n_pre++] = (struct held_seg){flow, data_rel, (uint32_t)n, copy};
    c->pre_bytes += n;
}

/// The radar's flow is known and selected: its payload seen before goes into the session.
static void pre_replay(slp_capture_t *c, int flow, int64_t cur_rel)
{
    sess_t *s = &c->sel;
    const flow_t *f = &c->flows[flow];
    bool any = false;
    int64_t lo = cur_rel;
    for (size_t i = 0; i < c->n_pre; i++) {
        if (c->pre[i].flow == flow) {
            any = true;
            lo = c->pre[i].data_rel < lo ? c->pre[i].data_rel : lo;
        }
    }
    if (any) {
        s->have_base = true;
        if (f->syn) {
            s->base = f->syn_rel + 1;
        } else {
            s->base = lo;
            c->rep.started_mid_stream = true;
        }
        for (size_t i = 0; i < c->n_pre; i++) {
            const struct held_seg *h = &c->pre[i];
            if (h->flow != flow) {
                continue;
            }
            int64_t a = h->data_rel - s->base;
            const uint8_t *d = h->data;
            uint32_t len = h->len;
            if (a < 0) {
                const int64_t cut = -a < (int64_t)len ? -a : (int64_t)len;
                d += cut;
                len -= (uint32_t)cut;
                a = 0;
            }
            if (len == 0) {
                continue;
            }
            classify(c, s, a, d, len);
            (void)sess_insert(c, s, a, d, len);
        }
    }
    pre_free(c);
    free(c->pre);
    c->pre = NULL;
}

/// Parse one packet; set c->ps when it carries payload of a session. @return false when
/// it is not a TCP packet we can use (counted).
static void on_packet(slp_capture_t *c, const struct pcap_pkthdr *h, const uint8_t *p)
{
    slp_capture_report_t *rep = &c->rep;
    rep->packets_total++;
    c->ps.valid = false;
    const size_t cap = h->caplen;
    int ethertype = -1;
    size_t off = 0;
    switch (c->dlt) {
    case DLT_EN10MB:
        if (cap < 14) {
            off = SIZE_MAX;
            break;
        }
        ethertype = be16(p + 12);
        off = 14;
        while ((ethertype == 0x8100 || ethertype == 0x88a8) && cap >= off + 4) {
            ethertype = be16(p + off + 2);
            off += 4;
        }
        break;
    case DLT_LINUX_SLL:
        if (cap < 16) {
            off = SIZE_MAX;
            break;
        }
        ethertype = be16(p + 14);
        off = 16;
        break;
#ifdef DLT_LINUX_SLL2
    case DLT_LINUX_SLL2:
        if (cap < 20) {
            off = SIZE_MAX;
            break;
        }
        ethertype = be16(p);
        off = 20;
        break;
#endif
    case DLT_NULL:
    case DLT_LOOP:
        off = 4;
        break;
    case DLT_RAW:
#ifdef DLT_IPV4
    case DLT_IPV4:
    case DLT_IPV6:
#endif
        off = 0;
        break;
    default:
        off = SIZE_MAX;
        break;
    }
    if (off == SIZE_MAX || off >= cap) {
        rep->packets_undecoded++;
        return;
    }
    const uint8_t *ip = p + off;
    size_t ipcap = cap - off;
    const int ver = ip[0] >> 4;
    if ((ethertype == 0x0800 && ver != 4) || (ethertype == 0x86dd && ver != 6) ||
        (ethertype != -1 && ethertype != 0x0800 && ethertype != 0x86dd)) {
        rep->packets_undecoded++;
        return;
    }
    const uint8_t *src, *dst, *tcp;
    uint8_t alen;
    size_t l4len;
    if (ver == 4) {
        if (ipcap < 20) {
            rep->packets_undecoded++;
            return;
        }
        const size_t ihl = (size_t)(ip[0] & 0x0F) * 4;
        const size_t tot = be16(ip + 2);
        if (ihl < 20 || tot < ihl || ipcap < ihl || ip[9] != 6) {
            rep->packets_undecoded++;
            return;
        }
        if ((be16(ip + 6) & 0x3FFF) != 0) {
            rep->ip_fragments++;
            return;
        }
        src = ip + 12;
        dst = ip + 16;
        alen = 4;
        tcp = ip + ihl;
        l4len = tot - ihl;
        ipcap -= ihl;
    } else if (ver == 6) {
        if (ipcap < 40) {
            rep->packets_undecoded++;
            return;
        }
        src = ip + 8;
        dst = ip + 24;
        alen = 16;
        const size_t plen = be16(ip + 4);
        uint8_t nh = ip[6];
        size_t hoff = 40;
        bool frag = false, ok = true;
        while (nh == 0 || nh == 43 || nh == 60 || nh == 51 || nh == 44) {
            if (ipcap < hoff + 8) {
                ok = false;
                break;
            }
            if (nh == 44) {
                frag = true;
                break;
            }
            const size_t el = nh == 51 ? ((size_t)ip[hoff + 1] + 2) * 4 : ((size_t)ip[hoff + 1] + 1) * 8;
            nh = ip[hoff];
            hoff += el;
            if (plen < hoff - 40) {
                ok = false;
                break;
            }
        }
        if (frag) {
            rep->ip_fragments++;
            return;
        }
        if (!ok || nh != 6 || ipcap < hoff) {
            rep->packets_undecoded++;
            return;
        }
        tcp = ip + hoff;
        l4len = plen - (hoff - 40);
        ipcap -= hoff;
    } else {
        rep->packets_undecoded++;
        return;
    }
    if (ipcap < 20 || l4len < 20) {
        rep->packets_undecoded++;
        return;
    }
    const size_t thl = (size_t)(tcp[12] >> 4) * 4;
    if (thl < 20 || thl > l4len || ipcap < thl) {
        rep->packets_undecoded++;
        return;
    }
    const uint16_t sport = be16(tcp), dport = be16(tcp + 2);
    const uint32_t seq = be32(tcp + 4);
    const uint8_t flags = tcp[13];
    const bool f_syn = (flags & 0x02) != 0, f_fin = (flags & 0x01) != 0, f_rst = (flags & 0x04) != 0;
    const size_t payload_len = l4len - thl;
    const size_t payload_cap = payload_len < ipcap - thl ? payload_len : ipcap - thl;
    const uint8_t *payload = tcp + thl;
    const uint64_t ts = (uint64_t)h->ts.tv_sec * 1000000u + (uint64_t)h->ts.tv_usec;

    int fi = -1;
    flow_t *f = flow_find(c, src, dst, alen, sport, dport, f_syn, ts, &fi);
    if (f == NULL) {
        return;
    }
    f->last_ts_us = ts;
    f->packets++;
    f->payload_bytes += payload_cap;
    if (!f->have_seq) {
        f->have_seq = true;
        f->last_seq = seq;
        f->last_rel = 0;
    }
    const int64_t rel = f->last_rel + (int32_t)(seq - f->last_seq);
    f->last_rel = rel;
    f->last_seq = seq;
    if (f_syn && !f->syn) {
        f->syn = true;
        f->syn_rel = rel;
    }
    const int64_t data_rel = rel + (f_syn ? 1 : 0);
    if (f_fin) {
        f->fin = true;
        f->fin_rel = data_rel + (int64_t)payload_len;
    }
    if (f_rst) {
        f->rst = true;
    }
    // The selected session sent after the candidate started: the candidate overlaps it.
    if (f->role == ROLE_SELECTED && c->cand.active && !c->sel.closing &&
        ts > c->flows[c->cand.flow].first_ts_us) {
        c->flows[c->cand.flow].role = ROLE_IGNORED;
        c->rep.flows_ignored++;
        sess_reset(&c->cand, -1);
    }
    if (payload_len > 0 && payload_cap < payload_len) {
        rep->packets_truncated++; // every direction, as the host tools' reader counts them
    }
    if (payload_cap == 0) {
        return;
    }
    f->had_payload = true;
    if (!c->port_locked) {
        if (sport == c->radar_port) {
            c->port_locked = true;
            c->rep.radar_port = sport;
        } else if (!c->opt.port_explicit && score_payload(payload, payload_cap) > 0) {
            c->radar_port = sport;
            c->port_locked = true;
            c->rep.radar_port = sport;
            c->rep.port_auto_detected = true;
        } else if (!c->opt.port_explicit) {
            pre_store(c, fi, data_rel, payload, payload_cap);
            return;
        }
    }
    if (!c->port_locked || sport != c->radar_port) {
        return;
    }
    if (f->role == ROLE_NONE) {
        if (!c->sel.active) {
            if (c->rep.sessions > 0) {
                c->brk_pending = true;
                c->brk = (slp_capture_piece_t){.kind = SLP_CAPTURE_BREAK,
                                                   .brk = SLP_CAPTURE_NEW_SESSION,
                                                   .output_offset = c->out_off,
                                                   .session = (uint32_t)c->rep.sessions};
            }
            sess_reset(&c->sel, fi);
            f->role = ROLE_SELECTED;
            f->was_selected = true;
            c->rep.sessions++;
            if (c->pre != NULL) {
                pre_replay(c, fi, data_rel);
            }
        } else if (!c->cand.active) {
            sess_reset(&c->cand, fi);
            f->role = ROLE_CANDIDATE;
            const flow_t *sf = &c->flows[c->sel.flow];
            if (sf->fin || sf->rst) {
                c->sel.closing = true;
            }
        } else {
            f->role = ROLE_IGNORED;
            c->rep.flows_ignored++;
        }
    }
    if (f->role == ROLE_SELECTED || f->role == ROLE_CANDIDATE) {
        c->ps = (pkt_seg_t){true, false, fi, data_rel, payload, (uint32_t)payload_cap};
    }
}

// ---------------------------------------------------------------------------------------
// public

slp_capture_t *slp_capture_open(const char *path, const slp_capture_opts_t *opts, char *err,
                                        size_t err_size)
{
    slp_capture_t *c = calloc(1, sizeof *c);
    if (c == NULL) {
        snprintf(err, err_size, "%s: out of memory", path);
        return NULL;
    }
    if (opts != NULL) {
        c->opt = *opts;
    }
    c->radar_port = c->opt.radar_port != 0 ? c->opt.radar_port : (uint16_t)DEFAULT_PORT;
    if (strcmp(path, "-") == 0) {
        c->fd = STDIN_FILENO;
    } else {
        c->fd = open(path, O_RDONLY | O_CLOEXEC);
        if (c->fd < 0) {
            snprintf(err, err_size, "%s: %s", path, strerror(errno));
            free(c);
            return NULL;
        }
        c->own_fd = true;
    }
    c->buf = malloc(SLP_CAPTURE_CHUNK);
    if (c->buf == NULL) {
        snprintf(err, err_size, "%s: out of memory", path);
        slp_capture_close(c);
        return NULL;
    }
    // A regular file is sniffed with pread (nothing consumed) and, when raw, mapped window
    // by window. Anything else (pipe, FIFO, terminal, device) is read sequentially: the
    // sniffed bytes are kept and handed on first.
    struct stat st;
    if (fstat(c->fd, &st) == 0 && S_ISREG(st.st_mode)) {
        uint8_t m[4] = {0, 0, 0, 0};
        const ssize_t n = pread(c->fd, m, sizeof m, 0);
        const bool pcap_magic = n == 4 && (be32(m) == 0xa1b2c3d4u || be32(m) == 0xd4c3b2a1u ||
                                           be32(m) == 0xa1b23c4du || be32(m) == 0x4d3cb2a1u ||
                                           be32(m) == 0x0a0d0d0au);
        if (n >= 0 && !pcap_magic) {
            c->mapped = true;
            c->file_size = (uint64_t)st.st_size;
            c->rep.format = SLP_CAPTURE_RAW;
            return c;
        }
    }
    // Sniff: read until SNIFF_BYTES are there or the input ends; keep them.
    while (c->prefix_len < SNIFF_BYTES) {
        const ssize_t n = read(c->fd, c->buf + c->prefix_len, SLP_CAPTURE_CHUNK - c->prefix_len);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n < 0) {
            snprintf(err, err_size, "%s: %s", path, strerror(errno));
            slp_capture_close(c);
            return NULL;
        }
        if (n == 0) {
            break;
        }
        c->prefix_len += (size_t)n;
    }
    c->rep.format = SLP_CAPTURE_RAW;
    if (c->prefix_len >= 4) {
        const uint8_t *m = c->buf;
        const uint32_t be = be32(m);
        const uint32_t le = (uint32_t)m[3] << 24 | (uint32_t)m[2] << 16 | (uint32_t)m[1] << 8 | m[0];
        if (be == 0xa1b2c3d4u || le == 0xa1b2c3d4u || be == 0xa1b23c4du || le == 0xa1b23c4du) {
            c->rep.format = SLP_CAPTURE_PCAP;
        } else if (be == 0x0a0d0d0au) {
            c->rep.format = SLP_CAPTURE_PCAPNG;
        }
    }
    if (c->rep.format == SLP_CAPTURE_RAW) {
        return c;
    }
    c->sel.pend = malloc(SLP_CAPTURE_PENDING_SEGS * sizeof(seg_t));
    c->cand.pend = malloc(SLP_CAPTURE_PENDING_SEGS * sizeof(seg_t));
    c->tail = malloc(SLP_CAPTURE_TAIL);
    c->pre = c->opt.port_explicit ? NULL : malloc(PRE_SEGS * sizeof *c->pre);
    c->sel.flow = c->cand.flow = -1;
    const cookie_io_functions_t io = {.read = cookie_read, .close = cookie_close};
    c->fp = (c->sel.pend && c->cand.pend && c->tail) ? fopencookie(c, "r", io) : NULL;
    if (c->fp == NULL) {
        snprintf(err, err_size, "%s: out of memory", path);
        slp_capture_close(c);
        return NULL;
    }
    char ebuf[PCAP_ERRBUF_SIZE] = {0};
    c->pc = pcap_fopen_offline(c->fp, ebuf);
    if (c->pc == NULL) {
        c->fp = NULL; // closed by libpcap on failure
        snprintf(err, err_size, "%s: %s", path, ebuf);
        slp_capture_close(c);
        return NULL;
    }
    c->dlt = pcap_datalink(c->pc);
    const char *dn = pcap_datalink_val_to_name(c->dlt);
    if (dn != NULL) {
        snprintf(c->rep.link_type, sizeof c->rep.link_type, "%s", dn);
    } else {
        snprintf(c->rep.link_type, sizeof c->rep.link_type, "%d", c->dlt);
    }
    return c;
}

static void finish(slp_capture_t *c, slp_capture_piece_t *pc, slp_capture_piece_kind_t k)
{
    c->finished = true;
    c->final_kind = k;
    *pc = (slp_capture_piece_t){.kind = k, .output_offset = c->out_off};
}

#define MAP_WINDOW (16u << 20) // bytes mapped at a time (a multiple of the page size)

static void next_mapped(slp_capture_t *c, slp_capture_piece_t *pc)
{
    if (c->map != NULL) {
        munmap(c->map, c->map_len);
        c->map = NULL;
        c->map_off += c->map_len;
    }
    if (c->map_off >= c->file_size) {
        finish(c, pc, SLP_CAPTURE_END);
        return;
    }
    const uint64_t left = c->file_size - c->map_off;
    c->map_len = left < MAP_WINDOW ? (size_t)left : MAP_WINDOW;
    c->map = mmap(NULL, c->map_len, PROT_READ, MAP_PRIVATE | MAP_POPULATE, c->fd, (off_t)c->map_off);
    if (c->map == MAP_FAILED) {
        c->map = NULL;
        snprintf(c->err, sizeof c->err, "mmap: %s", strerror(errno));
        finish(c, pc, SLP_CAPTURE_ERROR);
        return;
    }
    (void)madvise(c->map, c->map_len, MADV_SEQUENTIAL);
    c->rep.bytes_in += c->map_len;
    data_piece(c, pc, c->map, c->map_len);
}

static void next_raw(slp_capture_t *c, slp_capture_piece_t *pc)
{
    if (c->mapped) {
        next_mapped(c, pc);
        return;
    }
    if (c->prefix_pos < c->prefix_len) {
        const size_t n = c->prefix_len - c->prefix_pos;
        c->rep.bytes_in += n;
        data_piece(c, pc, c->buf + c->prefix_pos, n);
        c->prefix_pos = c->prefix_len;
        return;
    }
    for (;;) {
        const ssize_t n = read(c->fd, c->buf, SLP_CAPTURE_CHUNK);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n < 0) {
            snprintf(c->err, sizeof c->err, "read error: %s", strerror(errno));
            finish(c, pc, SLP_CAPTURE_ERROR);
            return;
        }
        if (n == 0) {
            finish(c, pc, SLP_CAPTURE_END);
            return;
        }
        c->rep.bytes_in += (uint64_t)n;
        data_piece(c, pc, c->buf, (size_t)n);
        return;
    }
}

static void next_pcap(slp_capture_t *c, slp_capture_piece_t *pc)
{
    free(c->held);
    c->held = NULL;
    for (;;) {
        if (c->brk_pending) {
            c->brk_pending = false;
            *pc = c->brk;
            return;
        }
        sess_t *s = &c->sel;
        // Held bytes that are now contiguous.
        if (s->active && s->n_pend > 0 && s->pend[0].a <= s->cursor) {
            seg_t g = s->pend[0];
            memmove(&s->pend[0], &s->pend[1], (s->n_pend - 1) * sizeof s->pend[0]);
            s->n_pend--;
            s->pend_bytes -= g.len;
            const int64_t e = g.a + (int64_t)g.len;
            if (e <= s->cursor) {
                free(g.data);
                continue;
            }
            const size_t off = (size_t)(s->cursor - g.a);
            c->held = g.data;
            tail_put(c, s->cursor, g.data + off, g.len - off);
            data_piece(c, pc, g.data + off, g.len - off);
            s->cursor = e;
            return;
        }
        // The current packet, again after a forced gap.
        if (c->ps.valid && s->active && c->ps.flow == s->flow) {
            const int r = sel_segment(c, pc);
            if (r < 0) {
                continue;
            }
            c->ps.valid = false;
            if (r > 0) {
                return;
            }
        }
        // Session change: drain the selected session, then the candidate takes over.
        if (s->active && (s->closing || (c->eof && c->cand.active))) {
            s->closing = true;
            if (s->n_pend > 0) {
                set_gap(c, (uint64_t)(s->pend[0].a - s->cursor));
                s->cursor = s->pend[0].a;
                continue;
            }
            const flow_t *f = &c->flows[s->flow];
            if (!s->fin_gap_done && f->fin && s->have_base && f->fin_rel - s->base > s->cursor) {
                s->fin_gap_done = true;
                set_gap(c, (uint64_t)(f->fin_rel - s->base - s->cursor));
                continue;
            }
            c->flows[s->flow].role = ROLE_DONE;
            if (!c->cand.active) {
                sess_reset(s, -1);
                continue;
            }
            // swap: the candidate's held segments become the selected session's
            seg_t *sp = s->pend;
            *s = c->cand;
            s->closing = false;
            c->cand = (sess_t){.pend = sp, .flow = -1};
            c->flows[s->flow].role = ROLE_SELECTED;
            c->flows[s->flow].was_selected = true;
            if (!c->flows[s->flow].syn) {
                c->rep.started_mid_stream = true;
                if (s->n_pend > 0) { // mid-stream: start at the first byte held
                    s->cursor = s->pend[0].a;
                }
            }
            s->max_end = s->n_pend > 0 ? s->pend[s->n_pend - 1].a + (int64_t)s->pend[s->n_pend - 1].len : 0;
            c->rep.sessions++;
            c->rep.segments += s->n_pend; // held segments, counted when they took over
            for (size_t i = 0; i < s->n_pend; i++) {
                c->rep.payload_bytes += s->pend[i].len;
            }
            c->brk_pending = true;
            c->brk = (slp_capture_piece_t){.kind = SLP_CAPTURE_BREAK,
                                               .brk = SLP_CAPTURE_NEW_SESSION,
                                               .output_offset = c->out_off,
                                               .session = (uint32_t)(c->rep.sessions - 1)};
            continue;
        }
        if (c->eof) {
            if (s->active && s->n_pend > 0) {
                set_gap(c, (uint64_t)(s->pend[0].a - s->cursor));
                s->cursor = s->pend[0].a;
                continue;
            }
            if (s->active) {
                const flow_t *f = &c->flows[s->flow];
                if (!s->fin_gap_done && f->fin && s->have_base && f->fin_rel - s->base > s->cursor) {
                    s->fin_gap_done = true;
                    set_gap(c, (uint64_t)(f->fin_rel - s->base - s->cursor));
                    continue;
                }
            }
            if (c->rep.sessions == 0) {
                snprintf(c->err, sizeof c->err, "no TCP payload from port %u%s%s%s",
                         (unsigned)c->radar_port,
                         c->opt.port_explicit ? "" : " and no flow carrying Colossus radar messages",
                         c->rep.read_error[0] ? "; read error: " : "", c->rep.read_error);
                finish(c, pc, SLP_CAPTURE_ERROR);
                return;
            }
            finish(c, pc, SLP_CAPTURE_END);
            return;
        }
        struct pcap_pkthdr *h = NULL;
        const u_char *pkt = NULL;
        const int rc = pcap_next_ex(c->pc, &h, &pkt);
        if (rc != 1) {
            if (rc == PCAP_ERROR) {
                snprintf(c->rep.read_error, sizeof c->rep.read_error, "%s", pcap_geterr(c->pc));
            }
            c->eof = true;
            continue;
        }
        on_packet(c, h, pkt);
        if (c->ps.valid && c->cand.active && c->ps.flow == c->cand.flow) {
            cand_segment(c);
            c->ps.valid = false;
        }
    }
}

void slp_capture_next(slp_capture_t *c, slp_capture_piece_t *pc)
{
    if (c->finished) {
        *pc = (slp_capture_piece_t){.kind = c->final_kind, .output_offset = c->out_off};
        return;
    }
    if (c->rep.format == SLP_CAPTURE_RAW) {
        next_raw(c, pc);
    } else {
        next_pcap(c, pc);
    }
}

static void addr_str(char *out, size_t size, const uint8_t *a, uint8_t alen, uint16_t port)
{
    if ((alen & 0x7Fu) == 4u) {
        snprintf(out, size, "%u.%u.%u.%u:%u", a[0], a[1], a[2], a[3], (unsigned)port);
        return;
    }
    size_t k = (size_t)snprintf(out, size, "[");
    for (unsigned i = 0; i < 16 && k < size; i += 2) {
        k += (size_t)snprintf(out + k, size - k, "%s%x", i ? ":" : "", (unsigned)be16(a + i));
    }
    if (k < size) {
        snprintf(out + k, size - k, "]:%u", (unsigned)port);
    }
}

size_t slp_capture_flows(const slp_capture_t *c, slp_capture_flow_t *out, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < c->n_flows; i++) {
        const flow_t *f = &c->flows[i];
        if (!c->port_locked || f->sport != c->radar_port || !f->had_payload) {
            continue;
        }
        if (n < max) {
            slp_capture_flow_t *o = &out[n];
            memset(o, 0, sizeof *o);
            addr_str(o->src, sizeof o->src, f->src, f->alen, f->sport);
            addr_str(o->dst, sizeof o->dst, f->dst, f->alen, f->dport);
            o->packets = f->packets;
            o->payload_bytes = f->payload_bytes;
            o->first_ts_us = f->first_ts_us;
            o->last_ts_us = f->last_ts_us;
            o->syn = f->syn;
            o->fin = f->fin;
            o->rst = f->rst;
            o->selected = f->was_selected;
        }
        n++;
    }
    return n;
}

const slp_capture_report_t *slp_capture_report(const slp_capture_t *c) { return &c->rep; }

const char *slp_capture_error(const slp_capture_t *c) { return c->err; }

void slp_capture_report_line(const slp_capture_t *c, char *buf, size_t size)
{
    const slp_capture_report_t *r = &c->rep;
    if (r->format == SLP_CAPTURE_RAW) {
        if (size > 0) {
            buf[0] = '\0';
        }
        return;
    }
    snprintf(buf, size,
             "radar port %u%s, %llu packets, %llu segments, %llu stream bytes, %llu retransmitted, "
             "%llu out of order, %llu gaps (%llu bytes), %llu sessions%s%s%s",
             (unsigned)c->radar_port, r->port_auto_detected ? " (auto-detected)" : "",
             (unsigned long long)r->packets_total, (unsigned long long)r->segments,
             (unsigned long long)r->stream_bytes, (unsigned long long)r->retransmitted_segments,
             (unsigned long long)r->out_of_order_segments, (unsigned long long)r->gaps,
             (unsigned long long)r->gap_bytes, (unsigned long long)r->sessions,
             r->started_mid_stream ? ", starts mid-stream" : "", r->read_error[0] ? ", read error: " : "",
             r->read_error);
}

void slp_capture_close(slp_capture_t *c)
{
    if (c == NULL) {
        return;
    }
    if (c->pc != NULL) {
        pcap_close(c->pc); // closes c->fp
    } else if (c->fp != NULL) {
        fclose(c->fp);
    }
    if (c->map != NULL) {
        munmap(c->map, c->map_len);
    }
    pre_free(c);
    free(c->pre);
    free(c->held);
    if (c->sel.pend != NULL) {
        sess_free(&c->sel);
    }
    if (c->cand.pend != NULL) {
        sess_free(&c->cand);
    }
    free(c->sel.pend);
    free(c->cand.pend);
    free(c->tail);
    free(c->buf);
    if (c->own_fd) {
        close(c->fd);
    }
    free(c);
}
