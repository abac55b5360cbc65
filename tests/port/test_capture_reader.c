// SPDX-License-Identifier: MIT
// test_capture_reader.c: the port's streaming capture reader (firmware/port/linux/capture_reader.c).
// Raw and pcap captures from regular files and from pipes (/dev/fd/N, the format sniffed
// from bytes already read), TCP reassembly of a damaged session (retransmission, reordering,
// a lost segment, a second session) and every byte accounted for.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "capture_reader.h"
#include "sl_golden.h"

typedef struct collected {
    uint8_t *data;
    size_t size;
    size_t breaks;
    size_t gaps, sessions;
    uint64_t gap_at[8], gap_missing[8], session_at[8];
} collected_t;

static void collect(slp_capture_t *c, collected_t *out)
{
    memset(out, 0, sizeof *out);
    size_t cap = 1u << 20;
    out->data = malloc(cap);
    assert_non_null(out->data);
    for (;;) {
        slp_capture_piece_t p;
        slp_capture_next(c, &p);
        if (p.kind == SLP_CAPTURE_DATA) {
            assert_int_equal(p.output_offset, out->size);
            while (out->size + p.size > cap) {
                cap *= 2;
                out->data = realloc(out->data, cap);
                assert_non_null(out->data);
            }
            memcpy(out->data + out->size, p.data, p.size);
            out->size += p.size;
        } else if (p.kind == SLP_CAPTURE_BREAK) {
            assert_int_equal(p.output_offset, out->size);
            if (p.brk == SLP_CAPTURE_GAP && out->gaps < 8) {
                out->gap_at[out->gaps] = p.output_offset;
                out->gap_missing[out->gaps++] = p.missing_bytes;
            } else if (p.brk == SLP_CAPTURE_NEW_SESSION && out->sessions < 8) {
                out->session_at[out->sessions++] = p.output_offset;
            }
            out->breaks++;
        } else {
            assert_int_equal(p.kind, SLP_CAPTURE_END);
            slp_capture_next(c, &p); // END is sticky
            assert_int_equal(p.kind, SLP_CAPTURE_END);
            return;
        }
    }
}

static uint8_t *golden_stream(size_t *n)
{
    sl_golden_params_t gp = sl_golden_defaults();
    gp.rotations = 2;
    *n = sl_golden_size(&gp);
    uint8_t *b = malloc(*n);
    assert_non_null(b);
    assert_int_equal(sl_golden_build(b, *n, &gp), *n);
    return b;
}

static void write_file(const char *path, const uint8_t *d, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(d, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
}

/// Writes `d` into a pipe from a child process, in small writes; returns "/dev/fd/N".
static pid_t pipe_from_child(const uint8_t *d, size_t n, char *path, size_t path_size)
{
    int fds[2];
    assert_int_equal(pipe(fds), 0);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        close(fds[0]);
        for (size_t off = 0; off < n;) {
            const size_t k = n - off < 3001 ? n - off : 3001; // odd sizes: pieces never align
            const ssize_t w = write(fds[1], d + off, k);
            if (w <= 0) {
                _exit(1);
            }
            off += (size_t)w;
        }
        _exit(0);
    }
    close(fds[1]);
    snprintf(path, path_size, "/dev/fd/%d", fds[0]);
    return pid;
}

static void finish_child(pid_t pid, const char *path)
{
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    close(atoi(path + strlen("/dev/fd/")));
}

// ---------------------------------------------------------------------------------------
// a small pcap writer (Ethernet / IPv4 / TCP)

typedef struct pcapw {
    uint8_t *b;
    size_t n, cap;
    uint32_t t_us;
} pcapw_t;

static void put(pcapw_t *w, const void *d, size_t n)
{
    while (w->n + n > w->cap) {
        w->cap = w->cap ? 2 * w->cap : 1u << 16;
        w->b = realloc(w->b, w->cap);
        assert_non_null(w->b);
    }
    memcpy(w->b + w->n, d, n);
    w->n += n;
}

static void put_le32(pcapw_t *w, uint32_t v)
{
    const uint8_t b[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    put(w, b, 4);
}

static void pcap_header(pcapw_t *w)
{
    put_le32(w, 0xa1b2c3d4u);
    const uint8_t ver[4] = {2, 0, 4, 0};
    put(w, ver, 4);
    put_le32(w, 0);
    put_le32(w, 0);
    put_le32(w, 65535);
    put_le32(w, 1); // DLT_EN10MB
}

/// One TCP packet 10.0.0.2:sport -> 10.0.0.1:dport.
static void tcp_packet(pcapw_t *w, uint16_t sport, uint16_t dport, uint32_t seq, uint8_t flags,
                       const uint8_t *payload, size_t len)
{
    uint8_t h[54] = {0};
    h[12] = 0x08; // IPv4
    uint8_t *ip = h + 14;
    ip[0] = 0x45;
    const size_t tot = 40 + len;
    ip[2] = (uint8_t)(tot >> 8);
    ip[3] = (uint8_t)tot;
    ip[8] = 64;
    ip[9] = 6;
    ip[12] = 10, ip[15] = 2;
    ip[16] = 10, ip[19] = 1;
    uint8_t *tcp = ip + 20;
    tcp[0] = (uint8_t)(sport >> 8), tcp[1] = (uint8_t)sport;
    tcp[2] = (uint8_t)(dport >> 8), tcp[3] = (uint8_t)dport;
    tcp[4] = (uint8_t)(seq >> 24), tcp[5] = (uint8_t)(seq >> 16), tcp[6] = (uint8_t)(seq >> 8), tcp[7] = (uint8_t)seq;
    tcp[12] = 5 << 4;
    tcp[13] = flags;
    w->t_us += 100;
    put_le32(w, 0);
    put_le32(w, w->t_us);
    put_le32(w, (uint32_t)(54 + len));
    put_le32(w, (uint32_t)(54 + len));
    put(w, h, 54);
    if (len > 0) {
        put(w, payload, len);
    }
}

#define SEG 1000u
#define ISN 0xfffff000u // wraps during the session
#define NONE ((size_t)1 << 30) // no such segment

/// Session of `s` (n bytes) from the radar port: SYN, segments of SEG bytes with segment
/// `rtx` sent twice, `swap` and swap+1 exchanged, `drop` missing; FIN. build_pcap adds a
/// second, clean session and a late retransmission of the first one.
static void session(pcapw_t *w, uint16_t cport, const uint8_t *s, size_t n, size_t rtx, size_t swap,
                    size_t drop)
{
    tcp_packet(w, 6317, cport, ISN, 0x12, NULL, 0);
    const size_t nseg = (n + SEG - 1) / SEG;
    for (size_t k = 0; k < nseg; k++) {
        size_t i = k;
        if (k == swap) {
            i = swap + 1;
        } else if (k == swap + 1) {
            i = swap;
        }
        const size_t off = i * SEG, len = n - off < SEG ? n - off : SEG;
        if (i != drop) {
            tcp_packet(w, 6317, cport, ISN + 1u + (uint32_t)off, 0x18, s + off, len);
        }
        tcp_packet(w, cport, 6317, 1, 0x10, NULL, 0); // the client's ACK
        if (i == rtx) {
            tcp_packet(w, 6317, cport, ISN + 1u + (uint32_t)off, 0x18, s + off, len);
        }
    }
    tcp_packet(w, 6317, cport, ISN + 1u + (uint32_t)n, 0x11, NULL, 0);
}

static void build_pcap(pcapw_t *w, const uint8_t *s, size_t n)
{
    memset(w, 0, sizeof *w);
    pcap_header(w);
    session(w, 40001, s, n, 5, 10, 20);
    session(w, 40002, s, n, NONE, NONE, NONE);
    // a late retransmission of the first session: ignored, no third session
    tcp_packet(w, 6317, 40001, ISN + 1u, 0x18, s, SEG);
}

static void check_pcap_result(const collected_t *got, const slp_capture_report_t *r, const uint8_t *s,
                              size_t n)
{
    // TCP session 1 without segment 20, then TCP session 2 complete
    const size_t lost = 20 * SEG;
    assert_int_equal(got->size, 2 * n - SEG);
    assert_memory_equal(got->data, s, lost);
    assert_memory_equal(got->data + lost, s + lost + SEG, n - lost - SEG);
    assert_memory_equal(got->data + n - SEG, s, n);
    assert_int_equal(got->gaps, 1);
    assert_int_equal(got->gap_at[0], lost);
    assert_int_equal(got->gap_missing[0], SEG);
    assert_int_equal(got->sessions, 1);
    assert_int_equal(got->session_at[0], n - SEG);
    assert_int_equal(r->format, SLP_CAPTURE_PCAP);
    assert_int_equal(r->sessions, 2);
    assert_int_equal(r->retransmitted_segments, 1);
    assert_int_equal(r->retransmitted_bytes, SEG);
    assert_int_equal(r->retransmit_mismatch_bytes, 0);
    assert_int_equal(r->out_of_order_segments, 1);
    assert_int_equal(r->gaps, 1);
    assert_int_equal(r->gap_bytes, SEG);
    assert_int_equal(r->stream_bytes, 2 * n - SEG);
    assert_int_equal(r->radar_port, 6317);
    assert_false(r->port_auto_detected);
    assert_false(r->started_mid_stream);
}

// ---------------------------------------------------------------------------------------

static void test_capture_raw_file_delivers_every_byte(void **state)
{
    (void)state;
    size_t n;
    uint8_t *s = golden_stream(&n);
    char path[] = "/tmp/sl_capture_raw_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(path, s, n);
    char err[256];
    slp_capture_t *c = slp_capture_open(path, NULL, err, sizeof err);
    assert_non_null(c);
    collected_t got;
    collect(c, &got);
    assert_int_equal(got.size, n);
    assert_memory_equal(got.data, s, n);
    assert_int_equal(got.breaks, 0);
    assert_int_equal(slp_capture_report(c)->bytes_in, n);
    assert_int_equal(slp_capture_report(c)->format, SLP_CAPTURE_RAW);
    slp_capture_close(c);
    unlink(path);
    free(got.data);
    free(s);
}

static void test_capture_raw_pipe_loses_no_byte_to_sniffing(void **state)
{
    (void)state;
    size_t n;
    uint8_t *s = golden_stream(&n);
    char path[64];
    const pid_t pid = pipe_from_child(s, n, path, sizeof path);
    char err[256];
    slp_capture_t *c = slp_capture_open(path, NULL, err, sizeof err);
    assert_non_null(c);
    collected_t got;
    collect(c, &got);
    assert_int_equal(got.size, n);
    assert_memory_equal(got.data, s, n);
    assert_int_equal(slp_capture_report(c)->bytes_in, n);
    slp_capture_close(c);
    finish_child(pid, path);
    free(got.data);
    free(s);
}

static void test_capture_pcap_file_reassembles_damaged_sessions(void **state)
{
    (void)state;
    size_t n;
    uint8_t *s = golden_stream(&n);
    pcapw_t w;
    build_pcap(&w, s, n);
    char path[] = "/tmp/sl_capture_pcap_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(path, w.b, w.n);
    if (getenv("SL_TEST_KEEP_PCAP") != NULL) {
        write_file(getenv("SL_TEST_KEEP_PCAP"), w.b, w.n);
    }
    char err[256];
    slp_capture_t *c = slp_capture_open(path, NULL, err, sizeof err);
    assert_non_null(c);
    collected_t got;
    collect(c, &got);
    check_pcap_result(&got, slp_capture_report(c), s, n);
    assert_int_equal(slp_capture_report(c)->bytes_in, w.n);
    slp_capture_flow_t fl[4];
    assert_int_equal(slp_capture_flows(c, fl, 4), 2); // the two radar-side sessions
    assert_string_equal(fl[0].src, "10.0.0.2:6317");
    assert_string_equal(fl[0].dst, "10.0.0.1:40001");
    assert_true(fl[0].selected && fl[1].selected && fl[0].syn && fl[0].fin);
    char line[512];
    slp_capture_report_line(c, line, sizeof line);
    assert_non_null(strstr(line, "1 gaps (1000 bytes)"));
    slp_capture_close(c);
    unlink(path);
    free(got.data);
    free(w.b);
    free(s);
}

static void test_capture_pcap_through_a_pipe_equals_the_file(void **state)
{
    (void)state;
    size_t n;
    uint8_t *s = golden_stream(&n);
    pcapw_t w;
    build_pcap(&w, s, n);
    char path[64];
    const pid_t pid = pipe_from_child(w.b, w.n, path, sizeof path);
    char err[256];
    slp_capture_t *c = slp_capture_open(path, NULL, err, sizeof err);
    assert_non_null(c);
    collected_t got;
    collect(c, &got);
    check_pcap_result(&got, slp_capture_report(c), s, n);
    assert_int_equal(slp_capture_report(c)->bytes_in, w.n);
    slp_capture_close(c);
    finish_child(pid, path);
    free(got.data);
    free(w.b);
    free(s);
}

static void test_capture_empty_input_ends_at_once(void **state)
{
    (void)state;
    char err[256];
    slp_capture_t *c = slp_capture_open("/dev/null", NULL, err, sizeof err);
    assert_non_null(c);
    slp_capture_piece_t p;
    slp_capture_next(c, &p);
    assert_int_equal(p.kind, SLP_CAPTURE_END);
    assert_int_equal(slp_capture_report(c)->bytes_in, 0);
    slp_capture_close(c);
}

static void test_capture_missing_file_is_an_error_naming_it(void **state)
{
    (void)state;
    char err[256] = "";
    assert_null(slp_capture_open("/nonexistent/x.colossus", NULL, err, sizeof err));
    assert_non_null(strstr(err, "/nonexistent/x.colossus"));
}

static void test_capture_pcap_without_radar_payload_ends_with_error(void **state)
{
    (void)state;
    pcapw_t w;
    memset(&w, 0, sizeof w);
    pcap_header(&w);
    const uint8_t junk[100] = {1, 2, 3};
    tcp_packet(&w, 80, 40000, 1, 0x18, junk, sizeof junk); // no radar port, no Colossus
    char path[] = "/tmp/sl_capture_norad_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(path, w.b, w.n);
    char err[256];
    slp_capture_t *c = slp_capture_open(path, NULL, err, sizeof err);
    assert_non_null(c);
    slp_capture_piece_t p;
    slp_capture_next(c, &p);
    assert_int_equal(p.kind, SLP_CAPTURE_ERROR);
    assert_non_null(strstr(slp_capture_error(c), "no TCP payload from port 6317"));
    slp_capture_close(c);
    unlink(path);
    free(w.b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_capture_raw_file_delivers_every_byte),
        cmocka_unit_test(test_capture_raw_pipe_loses_no_byte_to_sniffing),
        cmocka_unit_test(test_capture_pcap_file_reassembles_damaged_sessions),
        cmocka_unit_test(test_capture_pcap_through_a_pipe_equals_the_file),
        cmocka_unit_test(test_capture_empty_input_ends_at_once),
        cmocka_unit_test(test_capture_missing_file_is_an_error_naming_it),
        cmocka_unit_test(test_capture_pcap_without_radar_payload_ends_with_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
