// SPDX-License-Identifier: MIT
// Unit tests of the calibration blob (sl_calblob.h): round trip of every linked board,
// in place and through the workspace, and every corruption rejected with its own error
// and never used (the output view stays untouched).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "shadowlean/sl_calblob.h"
#include "shadowlean/sl_pipeline.h"

// 8-byte aligned storage with one spare byte in front for the misaligned case.
static union {
    uint64_t align;
    uint8_t b[SL_CALBLOB_MAX_BYTES + 16];
} g_buf;
static sl_calblob_ws_t g_ws;
static sl_pipeline_t g_pipe;

static const sl_board_t *paper_sim(void)
{
    const sl_board_t *b = sl_board_find("paper-sim");
    assert_non_null(b);
    return b;
}

static size_t write_blob(const sl_board_t *b, uint8_t *buf)
{
    const sl_ssize_t n = sl_calblob_write(b, buf, SL_CALBLOB_MAX_BYTES);
    assert_true(n > 0);
    assert_int_equal((size_t)n, SL_CALBLOB_BYTES(b->azimuths));
    return (size_t)n;
}

static void assert_same_board(const sl_board_t *a, const sl_board_t *b)
{
    assert_string_equal(a->name, b->name);
    assert_int_equal(a->azimuths, b->azimuths);
    assert_int_equal(a->radar_height_um, b->radar_height_um);
    assert_int_equal(a->near_exclusion_bins, b->near_exclusion_bins);
    assert_int_equal(a->pole_radius_um, b->pole_radius_um);
    assert_int_equal(a->range_sigma_um, b->range_sigma_um);
    assert_int_equal(a->theta_sigma_cdeg, b->theta_sigma_cdeg);
    assert_int_equal(a->elong_points, b->elong_points);
    assert_memory_equal(a->elong_range_um, b->elong_range_um, sizeof a->elong_range_um);
    assert_memory_equal(a->elong_d_um, b->elong_d_um, sizeof a->elong_d_um);
    assert_int_equal(a->can_id_health, b->can_id_health);
    assert_int_equal(a->threshold, b->threshold);
    const size_t n = a->azimuths;
    assert_memory_equal(a->geom, b->geom, n * sizeof a->geom[0]);
    assert_memory_equal(a->theta_cdeg, b->theta_cdeg, n * sizeof a->theta_cdeg[0]);
    assert_memory_equal(a->shadow_um, b->shadow_um, n * sizeof a->shadow_um[0]);
    assert_memory_equal(a->shadow_bins, b->shadow_bins, n * sizeof a->shadow_bins[0]);
}

static bool host_little_endian(void)
{
    const uint16_t one = 1U;
    uint8_t b[2];
    memcpy(b, &one, sizeof b);
    return b[0] == 1U;
}

static void test_calblob_round_trip_every_board(void **state)
{
    (void)state;
    for (size_t k = 0; k < sl_board_count(); k++) {
        const sl_board_t *nom = sl_board_at(k);
        const size_t n = write_blob(nom, g_buf.b);
        sl_board_t v;
        sl_calblob_info_t info;
        memset(&g_ws, 0xA5, sizeof g_ws);
        const sl_err_t e = sl_calblob_open(g_buf.b, n, nom, &g_ws, &v, &info);
        if (e != SL_OK) {
            print_error("%s: %s at %u\n", nom->name, info.what, (unsigned)info.index);
        }
        assert_int_equal(e, SL_OK);
        assert_null(info.what);
        assert_int_equal(info.version, SL_CALBLOB_VERSION);
        assert_int_equal(info.azimuths, nom->azimuths);
        assert_int_equal(info.board_id, sl_calblob_board_id(nom));
        assert_same_board(&v, nom);
        if (host_little_endian()) {
            // zero copy: the tables are the blob's bytes
            assert_true(info.zero_copy);
            assert_ptr_equal((const void *)v.geom, (const void *)(g_buf.b + SL_CALBLOB_HEADER_BYTES));
            assert_ptr_equal(v.name, nom->name);
        } else {
            // big-endian: decoded into the workspace
            assert_false(info.zero_copy);
            assert_ptr_equal(v.geom, g_ws.geom);
        }
        // the same bytes are written again from the view (the blob is a pure function)
        static uint8_t again[SL_CALBLOB_MAX_BYTES];
        assert_int_equal(sl_calblob_write(&v, again, sizeof again), (sl_ssize_t)n);
        assert_memory_equal(again, g_buf.b, n);
    }
}

static void test_calblob_misaligned_uses_workspace_or_refuses(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    uint8_t *odd = g_buf.b + 1;
    const size_t n = write_blob(nom, odd);
    sl_board_t v, untouched;
    memset(&v, 0x5A, sizeof v);
    untouched = v;
    sl_calblob_info_t info;
    assert_int_equal(sl_calblob_open(odd, n, nom, NULL, &v, &info), SL_ERR_CAL_WORKSPACE);
    assert_memory_equal(&v, &untouched, sizeof v);
    assert_int_equal(sl_calblob_open(odd, n, nom, &g_ws, &v, &info), SL_OK);
    assert_false(info.zero_copy);
    assert_ptr_equal(v.theta_cdeg, g_ws.theta_cdeg);
    assert_same_board(&v, nom);
}

static void test_calblob_view_initialises_a_pipeline(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    const size_t n = write_blob(nom, g_buf.b);
    sl_board_t v;
    assert_int_equal(sl_calblob_open(g_buf.b, n, nom, &g_ws, &v, NULL), SL_OK);
    assert_int_equal(sl_pipeline_init(&g_pipe, &v, NULL), SL_OK);
    assert_ptr_equal(g_pipe.board, &v);
}

// Opens and requires `want`, the failed check `what`, and the view untouched.
static void expect_reject(const uint8_t *blob, size_t len, const sl_board_t *nom, sl_err_t want,
                          const char *what)
{
    sl_board_t v, untouched;
    memset(&v, 0x3C, sizeof v);
    untouched = v;
    sl_calblob_info_t info;
    const sl_err_t e = sl_calblob_open(blob, len, nom, &g_ws, &v, &info);
    assert_int_equal(e, want);
    if (what != NULL) {
        assert_non_null(info.what);
        assert_string_equal(info.what, what);
    }
    assert_memory_equal(&v, &untouched, sizeof v);
}

static void put16le(uint8_t *b, uint16_t v)
{
    b[0] = (uint8_t)v;
    b[1] = (uint8_t)(v >> 8);
}

static void put32le(uint8_t *b, uint32_t v)
{
    for (unsigned i = 0; i < 4U; i++) {
        b[i] = (uint8_t)(v >> (8U * i));
    }
}

static void recrc(uint8_t *b, size_t n)
{
    uint32_t c = sl_calblob_crc32(0U, b, 12U);
    c = sl_calblob_crc32(c, b + 16, n - 16U);
    put32le(b + 12, c);
}

// A calibration's range response travels in the blob's response section (flags bit 0): it
// opens as the view's prior with response_calibrated set, read in place or decoded into the
// workspace (odd address), and a pipeline started on the view uses it as CALIBRATED. A blob
// without the section keeps the nominal board's prior.
static void test_calblob_response_section_round_trips(void **state)
{
    (void)state;
    const sl_board_t *nom = sl_board_find("robotcar-leaf");
    assert_non_null(nom);
    uint16_t cal[SL_RESP_TAPS];
    sl_response_prior_cts350x(cal);
    cal[SL_CFG_RESP_HALF - 1] = (uint16_t)(cal[SL_CFG_RESP_HALF - 1] + 3U); // not the prior
    cal[SL_CFG_RESP_HALF + 1] = (uint16_t)(cal[SL_CFG_RESP_HALF + 1] + 3U);
    sl_board_t b = *nom;
    b.response_prior_q8 = cal;
    b.response_calibrated = 1U;
    for (size_t off = 0; off < 2U; off++) {
        uint8_t *buf = g_buf.b + off;
        const sl_ssize_t n = sl_calblob_write(&b, buf, SL_CALBLOB_MAX_BYTES);
        assert_int_equal(n, (sl_ssize_t)(SL_CALBLOB_BYTES(nom->azimuths) + SL_CALBLOB_RESPONSE_BYTES));
        assert_int_equal(buf[54], SL_CALBLOB_FLAG_RESPONSE);
        sl_board_t v;
        sl_calblob_info_t info;
        assert_int_equal(sl_calblob_open(buf, (size_t)n, nom, &g_ws, &v, &info), SL_OK);
        assert_int_equal(v.response_calibrated, 1U);
        assert_memory_equal(v.response_prior_q8, cal, sizeof cal);
        if (off == 1U) {
            assert_ptr_equal(v.response_prior_q8, g_ws.response_q8);
        }
        assert_int_equal(sl_pipeline_init(&g_pipe, &v, NULL), SL_OK);
        assert_int_equal(g_pipe.resp.source, SL_RESPONSE_CALIBRATED);
        assert_memory_equal(g_pipe.resp.drop_q8, cal, sizeof cal);
    }
    const size_t n0 = write_blob(nom, g_buf.b);
    sl_board_t v0;
    assert_int_equal(sl_calblob_open(g_buf.b, n0, nom, &g_ws, &v0, NULL), SL_OK);
    assert_int_equal(v0.response_calibrated, 0U);
    assert_ptr_equal(v0.response_prior_q8, nom->response_prior_q8);
    assert_int_equal(sl_pipeline_init(&g_pipe, &v0, NULL), SL_OK);
    assert_int_equal(g_pipe.resp.source, SL_RESPONSE_PRIOR);
}

// The response section is checked like a learned shape: its tap count must be this build's,
// the shape plausible (falling on both sides); unknown flag bits are refused; each with
// the view untouched.
static void test_calblob_bad_response_section_is_refused(void **state)
{
    (void)state;
    const sl_board_t *nom = sl_board_find("robotcar-leaf");
    assert_non_null(nom);
    uint16_t cal[SL_RESP_TAPS];
    sl_response_prior_cts350x(cal);
    sl_board_t b = *nom;
    b.response_prior_q8 = cal;
    b.response_calibrated = 1U;
    const size_t n = (size_t)sl_calblob_write(&b, g_buf.b, SL_CALBLOB_MAX_BYTES);
    uint8_t *const resp = g_buf.b + SL_CALBLOB_BYTES(nom->azimuths);
    put16le(resp, (uint16_t)(SL_RESP_TAPS - 2));
    recrc(g_buf.b, n);
    expect_reject(g_buf.b, n, nom, SL_ERR_CAL_VALUE, "response_taps");
    put16le(resp, (uint16_t)SL_RESP_TAPS);
    put16le(resp + 2U + 2U * (SL_CFG_RESP_HALF + 2), 0U); // a second peak beside the centre
    recrc(g_buf.b, n);
    expect_reject(g_buf.b, n, nom, SL_ERR_CAL_VALUE, "response");
    put16le(resp + 2U + 2U * (SL_CFG_RESP_HALF + 2), cal[SL_CFG_RESP_HALF + 2]);
    put16le(g_buf.b + 54, 0x0003U);
    recrc(g_buf.b, n);
    expect_reject(g_buf.b, n, nom, SL_ERR_CAL_VALUE, "flags");
    put16le(g_buf.b + 54, 0U); // the section without its flag: the size no longer matches
    recrc(g_buf.b, n);
    expect_reject(g_buf.b, n, nom, SL_ERR_CAL_SIZE, "size");
    put16le(g_buf.b + 54, SL_CALBLOB_FLAG_RESPONSE);
    recrc(g_buf.b, n);
    sl_board_t v;
    assert_int_equal(sl_calblob_open(g_buf.b, n, nom, &g_ws, &v, NULL), SL_OK);
}

static void test_calblob_every_bit_flip_is_rejected(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    const size_t n = write_blob(nom, g_buf.b);
    size_t flips = 0;
    // Every bit of the first 16 header bytes (magic, version, sizes, CRC), then one bit in
    // every 8th header byte and every 127th payload byte (a varying bit): ~300 flips, each a
    // full CRC-32 over 19 KB (bitwise: kept cheap for the qemu runs).
    for (size_t bit = 0; bit < n * 8U;
         bit = (bit < 128U) ? bit + 1U
                            : ((bit / 8U < SL_CALBLOB_HEADER_BYTES) ? bit + 64U + 1U : bit + 127U * 8U + 3U)) {
        g_buf.b[bit / 8U] ^= (uint8_t)(1U << (bit % 8U));
        const size_t byte = bit / 8U;
        sl_err_t want = SL_ERR_CAL_CRC;
        if (byte < 4U) {
            want = SL_ERR_CAL_MAGIC;
        } else if (byte < 6U) {
            want = SL_ERR_CAL_VERSION;
        } else if (byte < 12U || byte == 52U || byte == 53U) {
            want = SL_ERR_CAL_SIZE; // size fields, azimuth count (sizes the payload)
        }
        expect_reject(g_buf.b, n, nom, want, NULL);
        g_buf.b[bit / 8U] ^= (uint8_t)(1U << (bit % 8U));
        flips++;
    }
    assert_true(flips > 250U);
    sl_board_t v;
    assert_int_equal(sl_calblob_open(g_buf.b, n, nom, &g_ws, &v, NULL), SL_OK);
}

static void test_calblob_wrong_version_magic_and_truncation(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    const size_t n = write_blob(nom, g_buf.b);
    expect_reject(g_buf.b, n - 1U, nom, SL_ERR_CAL_SIZE, "size");
    expect_reject(g_buf.b, n - SL_CALBLOB_AZ_BYTES, nom, SL_ERR_CAL_SIZE, "size");
    expect_reject(g_buf.b, SL_CALBLOB_HEADER_BYTES - 1U, nom, SL_ERR_CAL_SIZE, "length");
    expect_reject(g_buf.b, 0U, nom, SL_ERR_CAL_SIZE, "length");
    expect_reject(g_buf.b, n + 1U, nom, SL_ERR_CAL_SIZE, "size");
    put16le(g_buf.b + 4, 2U); // a future version, CRC made valid
    recrc(g_buf.b, n);
    expect_reject(g_buf.b, n, nom, SL_ERR_CAL_VERSION, "version");
    write_blob(nom, g_buf.b);
    g_buf.b[0] = 'X';
    recrc(g_buf.b, n);
    expect_reject(g_buf.b, n, nom, SL_ERR_CAL_MAGIC, "magic");
    expect_reject(NULL, n, nom, SL_ERR_ARG, NULL);
    expect_reject(g_buf.b, n, NULL, SL_ERR_ARG, NULL);
}

static void test_calblob_wrong_board_is_refused(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    const size_t n = write_blob(nom, g_buf.b);
    const sl_board_t *leaf = sl_board_find("robotcar-leaf");
    assert_non_null(leaf);
    expect_reject(g_buf.b, n, leaf, SL_ERR_CAL_BOARD, "name");
    // same name, another installation: a different bin size or radar yaw changes the identity
    sl_board_t other = *nom;
    other.bin_size_um = 43200U;
    expect_reject(g_buf.b, n, &other, SL_ERR_CAL_BOARD, "board_id");
    other = *nom;
    other.radar_yaw_cdeg = 9000;
    expect_reject(g_buf.b, n, &other, SL_ERR_CAL_BOARD, "board_id");
    other = *nom;
    other.azimuths = 200U;
    expect_reject(g_buf.b, n, &other, SL_ERR_CAL_AZIMUTHS, "azimuths");
    // calibratable fields are not identity: a nominal board with another height accepts it
    other = *nom;
    other.radar_height_um = 2490000U;
    sl_board_t v;
    assert_int_equal(sl_calblob_open(g_buf.b, n, &other, &g_ws, &v, NULL), SL_OK);
    assert_int_equal(v.radar_height_um, nom->radar_height_um);
}

// A copy of paper-sim's tables the test can corrupt, written with a valid CRC.
static sl_incline_geom_t c_geom[SL_CFG_MAX_AZIMUTHS];
static int16_t c_theta[SL_CFG_MAX_AZIMUTHS];
static uint32_t c_shadow[SL_CFG_MAX_AZIMUTHS];
static uint16_t c_bins[SL_CFG_MAX_AZIMUTHS];

static sl_board_t copy_board(const sl_board_t *nom)
{
    sl_board_t b = *nom;
    memcpy(c_geom, nom->geom, nom->azimuths * sizeof c_geom[0]);
    memcpy(c_theta, nom->theta_cdeg, nom->azimuths * sizeof c_theta[0]);
    memcpy(c_shadow, nom->shadow_um, nom->azimuths * sizeof c_shadow[0]);
    memcpy(c_bins, nom->shadow_bins, nom->azimuths * sizeof c_bins[0]);
    b.geom = c_geom;
    b.theta_cdeg = c_theta;
    b.shadow_um = c_shadow;
    b.shadow_bins = c_bins;
    return b;
}

static void expect_bad_value(const sl_board_t *bad, const sl_board_t *nom, const char *what,
                         uint32_t index)
{
    const size_t n = write_blob(bad, g_buf.b);
    expect_reject(g_buf.b, n, nom, SL_ERR_CAL_VALUE, what);
    sl_calblob_info_t info;
    sl_board_t v;
    assert_int_equal(sl_calblob_open(g_buf.b, n, nom, &g_ws, &v, &info), SL_ERR_CAL_VALUE);
    assert_int_equal(info.index, index);
}

static void test_calblob_out_of_range_values_are_refused(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    sl_board_t b = copy_board(nom);
    c_theta[5] = 50; // 0.5 deg: below the estimator's domain
    expect_bad_value(&b, nom, "theta_cdeg", 5U);
    b = copy_board(nom);
    c_theta[6] = 2700; // theta table and geometry disagree by 1 deg
    expect_bad_value(&b, nom, "geom.theta", 6U);
    b = copy_board(nom);
    c_geom[7].beta_bam32 = 0x02000000U; // beta differs from the board's
    expect_bad_value(&b, nom, "geom.beta", 7U);
    b = copy_board(nom);
    c_shadow[8] = c_shadow[8] + c_shadow[8] / 50U; // 2 % off H / tan(theta)
    expect_bad_value(&b, nom, "shadow_um", 8U);
    b = copy_board(nom);
    c_bins[9] = (uint16_t)(c_bins[9] + 3U);
    expect_bad_value(&b, nom, "shadow_bins", 9U);
    b = copy_board(nom);
    b.radar_height_um = 100000U; // 10 cm
    expect_bad_value(&b, nom, "radar_height_um", 0U);
    b = copy_board(nom);
    b.near_exclusion_bins = nom->roi_bins;
    expect_bad_value(&b, nom, "near_exclusion_bins", 0U);
    b = copy_board(nom);
    b.theta_sigma_cdeg = 2000U;
    expect_bad_value(&b, nom, "theta_sigma_cdeg", 0U);
    b = copy_board(nom);
    b.elong_points = 3U;
    b.elong_range_um[0] = 2000000U;
    b.elong_range_um[1] = 3000000U;
    b.elong_range_um[2] = 2500000U; // not ascending
    b.elong_d_um[0] = b.elong_d_um[1] = b.elong_d_um[2] = 20000;
    expect_bad_value(&b, nom, "elong_range_um", 2U);
    b.elong_range_um[2] = 4000000U;
    b.elong_d_um[1] = 5100000; // 5.1 m
    expect_bad_value(&b, nom, "elong_d_um", 1U);
    b.elong_d_um[1] = 20000; // now valid, and used
    const size_t n = write_blob(&b, g_buf.b);
    sl_board_t v;
    assert_int_equal(sl_calblob_open(g_buf.b, n, nom, &g_ws, &v, NULL), SL_OK);
    assert_int_equal(v.elong_points, 3);
    assert_int_equal(v.elong_range_um[2], 4000000U);
}

// Mutations past the CRC (the CRC made valid again after each one, so the value checks are
// what stands between the bytes and the pipeline): an accepted blob always satisfies the
// documented ranges; a rejected one leaves the view untouched. Deterministic (xorshift).
static void test_calblob_mutations_with_valid_crc_never_yield_out_of_range_tables(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    uint32_t x = 0x2545F491U;
    unsigned accepted = 0, rejected = 0;
    for (int k = 0; k < 400; k++) {
        const size_t n = write_blob(nom, g_buf.b);
        const int edits = 1 + (int)(k % 4);
        for (int e = 0; e < edits; e++) {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            // header scalars (from the name on) or the tables
            const size_t at = (k % 2 == 0) ? 16U + x % (SL_CALBLOB_HEADER_BYTES - 16U)
                                           : SL_CALBLOB_HEADER_BYTES + x % (n - SL_CALBLOB_HEADER_BYTES);
            g_buf.b[at] ^= (uint8_t)(1U << ((x >> 24) % 8U));
        }
        recrc(g_buf.b, n);
        sl_board_t v, untouched;
        memset(&v, 0x77, sizeof v);
        untouched = v;
        sl_calblob_info_t info;
        const sl_err_t err = sl_calblob_open(g_buf.b, n, nom, &g_ws, &v, &info);
        if (err != SL_OK) {
            assert_memory_equal(&v, &untouched, sizeof v);
            assert_non_null(info.what);
            rejected++;
            continue;
        }
        accepted++;
        assert_true(v.radar_height_um >= 200000U && v.radar_height_um <= 20000000U);
        assert_true(v.near_exclusion_bins < v.roi_bins);
        assert_true(v.elong_points <= SL_CFG_MAX_ELONG_POINTS);
        for (unsigned i = 0; i < v.azimuths; i++) {
            assert_true(v.theta_cdeg[i] >= SL_INCLINE_THETA_MIN_CDEG);
            assert_true(v.theta_cdeg[i] <= v.lower_bound_cdeg);
            assert_true(sl_incline_geom_ok(&v.geom[i]));
            assert_true(v.shadow_bins[i] < v.roi_bins);
            // the estimator runs on every accepted entry without surprise
            const sl_incline_result_t r = sl_incline_estimate(3000000U, 3600000U, &v.geom[i], 12640U, 10U);
            assert_true(r.flag <= SL_INCLINE_OUT_OF_DOMAIN);
        }
    }
    // both outcomes occur (a flipped low bit of a table value can stay in range)
    assert_true(accepted > 0U);
    assert_true(rejected > 100U);
}

static void test_calblob_writer_arguments(void **state)
{
    (void)state;
    const sl_board_t *nom = paper_sim();
    assert_int_equal(sl_calblob_write(NULL, g_buf.b, sizeof g_buf.b), SL_ERR_ARG);
    assert_int_equal(sl_calblob_write(nom, NULL, sizeof g_buf.b), SL_ERR_ARG);
    assert_int_equal(sl_calblob_write(nom, g_buf.b, SL_CALBLOB_BYTES(nom->azimuths) - 1U),
                     SL_ERR_FULL);
    sl_board_t b = *nom;
    b.name = "a-board-name-that-is-too-long-for-the-blob";
    assert_int_equal(sl_calblob_write(&b, g_buf.b, sizeof g_buf.b), SL_ERR_ARG);
    // CRC-32 (IEEE) check value
    assert_int_equal(sl_calblob_crc32(0U, (const uint8_t *)"123456789", 9U), 0xCBF43926U);
    assert_string_equal(sl_err_str(SL_ERR_CAL_CRC), "SL_ERR_CAL_CRC");
    assert_string_equal(sl_err_str(SL_ERR_CAL_WORKSPACE), "SL_ERR_CAL_WORKSPACE");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_calblob_round_trip_every_board),
        cmocka_unit_test(test_calblob_misaligned_uses_workspace_or_refuses),
        cmocka_unit_test(test_calblob_view_initialises_a_pipeline),
        cmocka_unit_test(test_calblob_every_bit_flip_is_rejected),
        cmocka_unit_test(test_calblob_wrong_version_magic_and_truncation),
        cmocka_unit_test(test_calblob_wrong_board_is_refused),
        cmocka_unit_test(test_calblob_out_of_range_values_are_refused),
        cmocka_unit_test(test_calblob_mutations_with_valid_crc_never_yield_out_of_range_tables),
        cmocka_unit_test(test_calblob_writer_arguments),
        cmocka_unit_test(test_calblob_response_section_round_trips),
        cmocka_unit_test(test_calblob_bad_response_section_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
