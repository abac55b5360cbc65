// SPDX-License-Identifier: MIT
// The calibration file reader (firmware/port/linux/calib_file.c): INI -> blob that the core
// opens, measured azimuths changed and the others bit for bit the board's, elongation and
// scalars applied, blobs passed through, and bad files refused naming the line and key.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "calib_file.h"
#include "shadowlean/sl_calblob.h"

static char g_dir[] = "/tmp/sl_calib_file_XXXXXX";
static sl_calblob_ws_t g_ws;

static const char *write_tmp(const char *name, const char *text, size_t len)
{
    static char path[256];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, len, f), len);
    fclose(f);
    return path;
}

static const sl_board_t *paper_sim(void)
{
    const sl_board_t *b = sl_board_find("paper-sim");
    assert_non_null(b);
    return b;
}

static void test_calib_file_ini_changes_measured_azimuths_only(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    const char ini[] = "; --- sl-calib shadow ---\n[calib]\nversion = 1\ntool = sl-calib 0.1.0\n"
                       "date = 2026-11-24T06:00:00Z\nboard = paper-sim\nframes = 12\nazimuths = 400\n"
                       "radar_height_m = 2.5800\nusable_azimuths = 3\n"
                       "theta_table = 0:30.09, 1:30.10,\n    399:29.50\n"
                       "unusable = 2-398 no ground edge\n"
                       "; --- sl-calib elongation ---\n[detect]\nelongation = 2.5:0.02, 3.5:0.03\n";
    uint8_t *blob = NULL;
    size_t len = 0;
    char err[256] = "";
    assert_int_equal(slp_calib_file_load(write_tmp("v.ini", ini, sizeof ini - 1U), nom, &blob, &len, err,
                                     sizeof err), 0);
    assert_int_equal(len, SL_CALBLOB_BYTES(400));
    sl_board_t v;
    sl_calblob_info_t info;
    assert_int_equal(sl_calblob_open(blob, len, nom, &g_ws, &v, &info), SL_OK);
    assert_int_equal(v.theta_cdeg[0], 3009);
    assert_int_equal(v.theta_cdeg[1], 3010);
    assert_int_equal(v.theta_cdeg[399], 2950);
    assert_true(v.shadow_um[0] < nom->shadow_um[0]); // a smaller shadow
    for (unsigned i = 2; i < 399; i++) {             // unusable: the board's, bit for bit
        assert_int_equal(v.theta_cdeg[i], nom->theta_cdeg[i]);
        assert_int_equal(v.shadow_um[i], nom->shadow_um[i]);
        assert_int_equal(v.shadow_bins[i], nom->shadow_bins[i]);
        assert_memory_equal(&v.geom[i], &nom->geom[i], sizeof v.geom[i]);
    }
    assert_int_equal(v.elong_points, 2);
    assert_int_equal(v.elong_range_um[1], 3500000U);
    assert_int_equal(v.elong_d_um[1], 30000);
    free(blob);
}

static void test_calib_file_blob_is_passed_through(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    static uint8_t raw[SL_CALBLOB_MAX_BYTES];
    const sl_ssize_t n = sl_calblob_write(nom, raw, sizeof raw);
    assert_true(n > 0);
    uint8_t *blob = NULL;
    size_t len = 0;
    char err[256] = "";
    assert_int_equal(slp_calib_file_load(write_tmp("v.bin", (const char *)raw, (size_t)n), nom, &blob, &len,
                                     err, sizeof err), 0);
    assert_int_equal(len, (size_t)n);
    assert_memory_equal(blob, raw, len);
    free(blob);
}

static void expect_refused(const char *text, const char *why)
{
    uint8_t *blob = (uint8_t *)1;
    size_t len = 0;
    char err[256] = "";
    assert_int_equal(slp_calib_file_load(write_tmp("bad.ini", text, strlen(text)), paper_sim(), &blob, &len,
                                     err, sizeof err), -1);
    assert_null(blob);
    if (strstr(err, why) == NULL) {
        print_error("error '%s' does not name '%s'\n", err, why);
        fail();
    }
}

static void test_calib_file_refuses_bad_files_naming_the_line(void **state)
{
    (void)state;
    expect_refused("[calib]\nboard = paper-bench\n", ":2: board = 'paper-bench' but the board is 'paper-sim'");
    expect_refused("[calib]\nazimuths = 200\n", "azimuths = '200' but board paper-sim has 400");
    expect_refused("[calib]\ntheta_table = 0:30.1, 400:30.0\n", "azimuth index 400 outside 0..399");
    expect_refused("[calib]\ntheta_table = 0:75\n", "theta 75 deg outside [1, 60]");
    expect_refused("[calib]\ntheta_table = 0:abc\n", "is not two numbers");
    expect_refused("[calib]\nversion = 2\n", "this reader knows version 1");
    expect_refused("[calib]\nthet_table = 0:30\n", "[calib] thet_table: unknown key");
    expect_refused("[calibration]\nboard = paper-sim\n", "[calibration] board: unknown section or key");
    expect_refused("[detect]\nelongation = 3.0:0.1, 2.0:0.1\n", "ranges must ascend");
    expect_refused("[calib]\nradar_height_m = 50\n", "radar_height_m = '50'");
    uint8_t *blob = NULL;
    size_t len = 0;
    char err[256] = "";
    assert_int_equal(slp_calib_file_load("/nonexistent/v.ini", paper_sim(), &blob, &len, err, sizeof err), -1);
    assert_non_null(strstr(err, "/nonexistent/v.ini"));
}

static int setup(void **state)
{
    (void)state;
    return mkdtemp(g_dir) != NULL ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char path[256];
    static const char *const names[] = {"v.ini", "v.bin", "bad.ini"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", g_dir, names[i]);
        (void)unlink(path);
    }
    return rmdir(g_dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_calib_file_ini_changes_measured_azimuths_only),
        cmocka_unit_test(test_calib_file_blob_is_passed_through),
        cmocka_unit_test(test_calib_file_refuses_bad_files_naming_the_line),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
