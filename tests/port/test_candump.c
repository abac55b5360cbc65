// SPDX-License-Identifier: MIT
// Unit tests for firmware/port/linux/candump.h: can-utils frame text and candump -L lines,
// both ways (the sl-gsusb-send log input and its --tx-log/--rx-log output), and the log
// file sink of the daemon's --can-log (lines read back with the parser).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "candump.h"

static void test_candump_parses_sff_eff_rtr_and_error_frames(void **state)
{
    (void)state;
    sl_can_frame_t f;
    const char *why = NULL;
    assert_int_equal(slp_candump_parse_frame("123#DEADBEEF", &f, &why), SL_OK);
    assert_int_equal(f.id, 0x123);
    assert_int_equal(f.flags, 0);
    assert_int_equal(f.dlc, 4);
    assert_int_equal(f.data[0], 0xde);
    assert_int_equal(f.data[3], 0xef);
    assert_int_equal(slp_candump_parse_frame("1abcde0f#01.02", &f, &why), SL_OK);
    assert_int_equal(f.id, 0x1ABCDE0F);
    assert_int_equal(f.flags, SL_CAN_FLAG_EFF);
    assert_int_equal(f.dlc, 2);
    assert_int_equal(slp_candump_parse_frame("7FF#", &f, &why), SL_OK);
    assert_int_equal(f.dlc, 0);
    assert_int_equal(slp_candump_parse_frame("10F#R", &f, &why), SL_OK);
    assert_int_equal(f.flags, SL_CAN_FLAG_RTR);
    assert_int_equal(f.dlc, 0);
    assert_int_equal(slp_candump_parse_frame("00000001#R3", &f, &why), SL_OK);
    assert_int_equal(f.flags, SL_CAN_FLAG_RTR | SL_CAN_FLAG_EFF);
    assert_int_equal(f.dlc, 3);
    assert_int_equal(slp_candump_parse_frame("20000040#0000000000000000", &f, &why), SL_OK);
    assert_int_equal(f.flags, SL_CAN_FLAG_ERR);
    assert_int_equal(f.id, 0x40);
    assert_int_equal(f.dlc, 8);
}

static void test_candump_rejects_malformed_frames_with_a_reason(void **state)
{
    (void)state;
    sl_can_frame_t f;
    const char *bad[] = {"12#00",      "1234#00",   "800#00",   "123",         "123#0",
                         "123#GG",     "123##1AA",  "123#R9",   "123#RX",      "5FFFFFFF#00",
                         "123#00112233445566778899", "#00", "2000000A#R"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        const char *why = NULL;
        if (slp_candump_parse_frame(bad[i], &f, &why) != SL_ERR_MALFORMED || why == NULL) {
            fail_msg("accepted '%s'", bad[i]);
        }
    }
}

static void test_candump_lines_with_timestamp_interface_and_markers(void **state)
{
    (void)state;
    sl_can_frame_t f;
    const char *why = NULL;
    assert_int_equal(slp_candump_parse_line("(1700000000.000001) can0 621#2A0095FB5A040000\n", &f, &why), SL_OK);
    assert_int_equal(f.id, 0x621);
    assert_int_equal(f.dlc, 8);
    assert_int_equal(slp_candump_parse_line("  123#11  ", &f, &why), SL_OK);
    assert_int_equal(f.data[0], 0x11);
    assert_int_equal(slp_candump_parse_line("(1.000000) vcan0 123#11 R", &f, &why), SL_OK); // python-can
    assert_int_equal(slp_candump_parse_line("   \n", &f, &why), SL_ERR_NEED_MORE);
    assert_int_equal(slp_candump_parse_line("can0 123#11", &f, &why), SL_ERR_MALFORMED);
}

static void test_candump_formats_like_candump_and_round_trips(void **state)
{
    (void)state;
    const char *texts[] = {"123#DEADBEEF", "1ABCDE0F#0102", "7FF#", "10F#R", "00000001#R3",
                           "000#1122334455667788", "20000004#0008000000000000"};
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        sl_can_frame_t f;
        char buf[48];
        assert_int_equal(slp_candump_parse_frame(texts[i], &f, NULL), SL_OK);
        assert_string_equal(slp_candump_format_frame(&f, buf, sizeof buf), texts[i]);
    }
    sl_can_frame_t f;
    assert_int_equal(slp_candump_parse_frame("123#AB", &f, NULL), SL_OK);
    char line[96];
    assert_string_equal(slp_candump_format_line(&f, 1700000000123456ULL, "gsusb0", line, sizeof line),
                        "(1700000000.123456) gsusb0 123#AB");
    assert_string_equal(slp_candump_format_line(&f, 5, "can0", line, sizeof line),
                        "(0000000000.000005) can0 123#AB");
}

static void test_candump_sink_writes_lines_the_parser_reads_back(void **state)
{
    (void)state;
    char path[] = "/tmp/sl_candump_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    slp_candump_t c;
    assert_int_equal(slp_candump_open(&c, path, "can0"), SL_OK);
    slp_can_sink_t sink = slp_candump_sink(&c);
    const sl_can_frame_t good[3] = {
        {.id = 0x620, .dlc = 8, .data = {1, 2, 3, 4, 5, 6, 7, 8}},
        {.id = 0x1ABCDE0F, .dlc = 2, .flags = SL_CAN_FLAG_EFF, .data = {0xAA, 0x55}},
        {.id = 0x10F, .dlc = 3, .flags = SL_CAN_FLAG_RTR},
    };
    for (unsigned i = 0; i < 3; i++) {
        c.stamp_us = 1700000000000000ULL + i;
        assert_int_equal(sink.send(sink.ctx, &good[i], 0), SL_OK);
    }
    const sl_can_frame_t bad = {.id = 0x800, .dlc = 1}; // 12 bits in an 11-bit id
    assert_int_equal(sink.send(sink.ctx, &bad, 0), SL_ERR_ARG);
    sink.poll(sink.ctx, 0);
    slp_can_sink_stats_t st;
    sink.get_stats(sink.ctx, &st);
    assert_int_equal(st.sent, 3);
    assert_int_equal(st.dropped, 1);
    slp_candump_close(&c);
    slp_candump_close(&c); // idempotent

    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[128];
    unsigned n = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        assert_true(n < 3);
        char want[32];
        snprintf(want, sizeof want, "(1700000000.%06u) can0 ", n);
        assert_memory_equal(line, want, strlen(want));
        sl_can_frame_t back;
        const char *why = NULL;
        assert_int_equal(slp_candump_parse_line(line, &back, &why), SL_OK);
        assert_int_equal(back.id, good[n].id);
        assert_int_equal(back.dlc, good[n].dlc);
        assert_int_equal(back.flags, good[n].flags);
        if ((good[n].flags & SL_CAN_FLAG_RTR) == 0U) {
            assert_memory_equal(back.data, good[n].data, good[n].dlc);
        }
        n++;
    }
    fclose(f);
    assert_int_equal(n, 3);
    unlink(path);
    assert_int_equal(slp_candump_open(&c, path, "bad iface"), SL_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_candump_parses_sff_eff_rtr_and_error_frames),
        cmocka_unit_test(test_candump_rejects_malformed_frames_with_a_reason),
        cmocka_unit_test(test_candump_lines_with_timestamp_interface_and_markers),
        cmocka_unit_test(test_candump_formats_like_candump_and_round_trips),
        cmocka_unit_test(test_candump_sink_writes_lines_the_parser_reads_back),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
