// Unit tests for host_tools/gsusb/candump_text.h: can-utils frame text and candump -L lines,
// both ways (the sl-gsusb-send log input and its --tx-log/--rx-log output).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "candump_text.h"

static void test_candump_parses_sff_eff_rtr_and_error_frames(void **state)
{
    (void)state;
    sl_can_frame_t f;
    const char *why = NULL;
    assert_int_equal(sl_candump_parse_frame("123#DEADBEEF", &f, &why), SL_OK);
    assert_int_equal(f.id, 0x123);
    assert_int_equal(f.flags, 0);
    assert_int_equal(f.dlc, 4);
    assert_int_equal(f.data[0], 0xde);
    assert_int_equal(f.data[3], 0xef);
    assert_int_equal(sl_candump_parse_frame("1abcde0f#01.02", &f, &why), SL_OK);
    assert_int_equal(f.id, 0x1ABCDE0F);
    assert_int_equal(f.flags, SL_CAN_FLAG_EFF);
    assert_int_equal(f.dlc, 2);
    assert_int_equal(sl_candump_parse_frame("7FF#", &f, &why), SL_OK);
    assert_int_equal(f.dlc, 0);
    assert_int_equal(sl_candump_parse_frame("10F#R", &f, &why), SL_OK);
    assert_int_equal(f.flags, SL_CAN_FLAG_RTR);
    assert_int_equal(f.dlc, 0);
    assert_int_equal(sl_candump_parse_frame("00000001#R3", &f, &why), SL_OK);
    assert_int_equal(f.flags, SL_CAN_FLAG_RTR | SL_CAN_FLAG_EFF);
    assert_int_equal(f.dlc, 3);
    assert_int_equal(sl_candump_parse_frame("20000040#0000000000000000", &f, &why), SL_OK);
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
        if (sl_candump_parse_frame(bad[i], &f, &why) != SL_ERR_MALFORMED || why == NULL) {
            fail_msg("accepted '%s'", bad[i]);
        }
    }
}

static void test_candump_lines_with_timestamp_interface_and_markers(void **state)
{
    (void)state;
    sl_can_frame_t f;
    const char *why = NULL;
    assert_int_equal(sl_candump_parse_line("(1700000000.000001) can0 621#2A0095FB5A040000\n", &f, &why), SL_OK);
    assert_int_equal(f.id, 0x621);
    assert_int_equal(f.dlc, 8);
    assert_int_equal(sl_candump_parse_line("  123#11  ", &f, &why), SL_OK);
    assert_int_equal(f.data[0], 0x11);
    assert_int_equal(sl_candump_parse_line("(1.000000) vcan0 123#11 R", &f, &why), SL_OK); // python-can
    assert_int_equal(sl_candump_parse_line("   \n", &f, &why), SL_ERR_NEED_MORE);
    assert_int_equal(sl_candump_parse_line("can0 123#11", &f, &why), SL_ERR_MALFORMED);
}

static void test_candump_formats_like_candump_and_round_trips(void **state)
{
    (void)state;
    const char *texts[] = {"123#DEADBEEF", "1ABCDE0F#0102", "7FF#", "10F#R", "00000001#R3",
                           "000#1122334455667788", "20000004#0008000000000000"};
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        sl_can_frame_t f;
        char buf[48];
        assert_int_equal(sl_candump_parse_frame(texts[i], &f, NULL), SL_OK);
        assert_string_equal(sl_candump_format_frame(&f, buf, sizeof buf), texts[i]);
    }
    sl_can_frame_t f;
    assert_int_equal(sl_candump_parse_frame("123#AB", &f, NULL), SL_OK);
    char line[96];
    assert_string_equal(sl_candump_format_line(&f, 1700000000123456ULL, "gsusb0", line, sizeof line),
                        "(1700000000.123456) gsusb0 123#AB");
    assert_string_equal(sl_candump_format_line(&f, 5, "can0", line, sizeof line),
                        "(0000000000.000005) can0 123#AB");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_candump_parses_sff_eff_rtr_and_error_frames),
        cmocka_unit_test(test_candump_rejects_malformed_frames_with_a_reason),
        cmocka_unit_test(test_candump_lines_with_timestamp_interface_and_markers),
        cmocka_unit_test(test_candump_formats_like_candump_and_round_trips),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
