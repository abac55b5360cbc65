// SPDX-License-Identifier: MIT
// Unit tests for sl_scan.h: azimuth index, rotation boundaries, missing / duplicate /
// out-of-order azimuths, contoured rows, 16-bit reduction, ROI copy, timestamps, double
// buffering, and the whole chain bytes -> sl_proto -> sl_scan under random chunkings.
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_scan.h"
#include "sl_golden.h"

static sl_scan_frame_t g_frames[2];

// ------------------------------------------------------------------------------ recorder

#define MAX_FRAMES 64
#define MAX_AZ_EVENTS 8192

typedef struct rec {
    size_t frames;
    const sl_scan_frame_t *frame_ptr[MAX_FRAMES];
    uint32_t rotation[MAX_FRAMES];
    uint8_t end[MAX_FRAMES];
    sl_scan_frame_stats_t stats[MAX_FRAMES];
    uint64_t hash[MAX_FRAMES]; // rows + flags + bins + times of the complete frame
    size_t az;
    uint16_t az_idx[MAX_AZ_EVENTS];
    uint64_t az_row_hash[MAX_AZ_EVENTS];
} rec_t;

static uint64_t frame_hash(const sl_scan_frame_t *f)
{
    uint64_t h = SL_GOLDEN_FNV_INIT;
    for (uint16_t i = 0; i < f->azimuths; i++) {
        h = sl_golden_fnv1a(f->power[i], f->roi_bins, h);
        h = sl_golden_fnv1a(&f->flags[i], 1, h);
        const uint8_t b[10] = {(uint8_t)f->bins[i], (uint8_t)(f->bins[i] >> 8),
                               (uint8_t)f->t_us[i], (uint8_t)(f->t_us[i] >> 8),
                               (uint8_t)(f->t_us[i] >> 16), (uint8_t)(f->t_us[i] >> 24),
                               (uint8_t)(f->t_us[i] >> 32), (uint8_t)(f->t_us[i] >> 40),
                               (uint8_t)f->ticks[i], (uint8_t)(f->ticks[i] >> 8)};
        h = sl_golden_fnv1a(b, sizeof b, h);
    }
    return h;
}

static void on_frame(void *ctx, const sl_scan_frame_t *f)
{
    rec_t *r = ctx;
    assert_true(r->frames < MAX_FRAMES);
    r->frame_ptr[r->frames] = f;
    r->rotation[r->frames] = f->rotation;
    r->end[r->frames] = f->end;
    r->stats[r->frames] = f->stats;
    r->hash[r->frames] = frame_hash(f);
    r->frames++;
}

static void on_azimuth(void *ctx, const sl_scan_frame_t *f, uint16_t idx)
{
    rec_t *r = ctx;
    assert_true(r->az < MAX_AZ_EVENTS);
    assert_true(idx < f->azimuths);
    assert_true((f->flags[idx] & SL_SCAN_AZ_VALID) != 0);
    r->az_idx[r->az] = idx;
    r->az_row_hash[r->az] = sl_golden_fnv1a(f->power[idx], f->roi_bins, SL_GOLDEN_FNV_INIT);
    r->az++;
}

static rec_t g_rec;

static void scan_init(sl_scan_t *s, uint16_t roi, bool double_buffer, uint16_t az, uint16_t enc)
{
    memset(&g_rec, 0, sizeof g_rec);
    sl_scan_cfg_t c = {.roi_bins = roi, .pow16_shift = 8, .azimuths = az, .encoder_size = enc,
                       .on_azimuth = on_azimuth, .on_frame = on_frame, .ctx = &g_rec};
    assert_int_equal(sl_scan_init(s, &c, &g_frames[0], double_buffer ? &g_frames[1] : NULL), SL_OK);
}

// An FFT message built directly (not from bytes); bins from a caller buffer.
static sl_proto_fft_t fft8(uint16_t ticks, uint16_t sweep, const uint8_t *bins, uint32_t n)
{
    sl_proto_fft_t f = {.id = 30, .bytes_per_bin = 1, .data_offset = 14, .sweep_counter = sweep,
                        .azimuth_ticks = ticks, .seconds = 1000, .split_ns = 0, .bins = n,
                        .bin_data = bins};
    return f;
}

static uint8_t g_bins[8192];

static void fill_bins(uint8_t seed, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        g_bins[i] = (uint8_t)(seed * 31U + i * 7U + 1U);
    }
}

// Feed one azimuth index of a 400 x 5600 radar (ticks 14 * idx), 64 bins of pattern `seed`.
static void feed_idx(sl_scan_t *s, uint16_t idx, uint16_t sweep, uint8_t seed)
{
    fill_bins(seed, 64);
    sl_proto_fft_t f = fft8((uint16_t)(idx * 14U), sweep, g_bins, 64);
    assert_int_equal(sl_scan_on_fft(s, &f), SL_OK);
}

// ---------------------------------------------------------------------------------- tests

static void test_scan_maps_encoder_values_to_the_azimuth_cell_containing_them(void **state)
{
    (void)state;
    // Oxford pattern: ticks 13 + 14 i (the end of cell i) -> index i.
    for (uint32_t i = 0; i < 400; i++) {
        assert_int_equal(sl_scan_az_index(400, 5600, (uint16_t)(13 + 14 * i)), i);
        assert_int_equal(sl_scan_az_index(400, 5600, (uint16_t)(14 * i)), i);
    }
    // Cell 0 is ticks [0, 14), cell 1 starts at 14.
    assert_int_equal(sl_scan_az_index(400, 5600, 7), 0);
    assert_int_equal(sl_scan_az_index(400, 5600, 13), 0);
    assert_int_equal(sl_scan_az_index(400, 5600, 14), 1);
    assert_int_equal(sl_scan_az_index(400, 5600, 5599), 399);
    assert_int_equal(sl_scan_az_index(400, 5600, 0), 0);
    assert_int_equal(sl_scan_az_index(400, 5600, 5600), -1);
    assert_int_equal(sl_scan_az_index(0, 5600, 1), -1);
    assert_int_equal(sl_scan_az_index(400, 0, 0), -1);
    // Exhaustive against a double reference, including a non-integer tick ratio.
    static const uint16_t geo[][2] = {{400, 5600}, {360, 5600}, {400, 65535}, {4096, 4096}};
    for (size_t g = 0; g < 4; g++) {
        for (uint32_t t = 0; t < geo[g][1]; t++) {
            const double x = (double)t * geo[g][0] / geo[g][1];
            const int32_t want = (int32_t)floor(x + 1e-9);
            assert_int_equal(sl_scan_az_index(geo[g][0], geo[g][1], (uint16_t)t), want);
        }
    }
}

// The per-azimuth index uses a reciprocal set with the geometry (no division): it must
// equal the division for every encoder value, on geometries from the CTS350-X's to the
// extremes (one azimuth per tick, 16-bit encoders, coprime sizes, azimuths > encoder values).
static void test_scan_reciprocal_index_equals_the_division_for_every_encoder_value(void **state)
{
    (void)state;
    static const uint16_t geo[][2] = {{400, 5600}, {400, 65535}, {400, 400},  {7, 13},
                                      {399, 65521}, {8, 65535},  {400, 401},  {400, 399},
                                      {256, 4096},  {360, 5760}, {400, 1},    {13, 7}};
    for (size_t g = 0; g < sizeof geo / sizeof geo[0]; g++) {
        sl_scan_t s;
        scan_init(&s, 64, false, geo[g][0], geo[g][1]);
        for (uint32_t t = 0; t <= 65535U; t++) {
            const int32_t want = sl_scan_az_index(geo[g][0], geo[g][1], (uint16_t)t);
            if (sl_scan_az_index_geo(&s, (uint16_t)t) != want) {
                fail_msg("geometry %u/%u ticks %u: %d != %d", geo[g][0], geo[g][1], t,
                         sl_scan_az_index_geo(&s, (uint16_t)t), want);
            }
        }
    }
}

// sl_proto_fft_time_us() divides split_ns by 1000 with a multiply: exact at the edges of
// every 1000-block over the whole 32-bit range (the proof is in sl_proto.h).
static void test_scan_timestamp_us_multiply_equals_the_division(void **state)
{
    (void)state;
    sl_proto_fft_t f = fft8(0, 0, g_bins, 0);
    f.seconds = 1700000000U;
    for (uint64_t b = 0; b <= UINT32_MAX; b += 999983U) { // a prime stride over 2^32
        for (uint32_t d = 0; d < 2000U && b + d <= UINT32_MAX; d++) {
            f.split_ns = (uint32_t)(b + d);
            const uint64_t want = 1700000000ULL * 1000000ULL + (uint64_t)f.split_ns / 1000U;
            assert_true(sl_proto_fft_time_us(&f) == want);
        }
    }
    const uint32_t edge[] = {0U, 999U, 1000U, 999999999U, 1000000000U, UINT32_MAX - 1U, UINT32_MAX};
    for (size_t i = 0; i < sizeof edge / sizeof edge[0]; i++) {
        f.split_ns = edge[i];
        assert_true(sl_proto_fft_time_us(&f) == 1700000000ULL * 1000000ULL + edge[i] / 1000U);
    }
}

static void test_scan_completes_a_frame_when_the_azimuth_index_wraps(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600);
    uint16_t sweep = 0;
    for (int rot = 0; rot < 2; rot++) {
        for (uint16_t i = 0; i < 400; i++) {
            feed_idx(&s, i, sweep++, (uint8_t)i);
        }
    }
    feed_idx(&s, 0, sweep++, 0); // opens rotation 2: completes rotation 1
    assert_int_equal(g_rec.frames, 2);
    for (int k = 0; k < 2; k++) {
        assert_int_equal(g_rec.rotation[k], k);
        assert_int_equal(g_rec.end[k], SL_SCAN_END_WRAP);
        assert_int_equal(g_rec.stats[k].valid, 400);
        assert_int_equal(g_rec.stats[k].missing, 0);
        assert_int_equal(g_rec.stats[k].duplicates, 0);
    }
    assert_int_equal(s.stats.azimuths, 801);
    assert_int_equal(s.stats.sweep_gaps, 0);
    assert_int_equal(g_rec.az, 801);
    for (size_t k = 0; k < 801; k++) {
        assert_int_equal(g_rec.az_idx[k], k % 400);
    }
}

static void test_scan_oxford_png_rows_fill_exactly_one_frame(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600);
    uint16_t sweep = 0;
    for (int rot = 0; rot < 3; rot++) {
        for (uint16_t i = 0; i < 400; i++) {
            fill_bins((uint8_t)i, 64);
            sl_proto_fft_t f = fft8((uint16_t)(13 + 14 * i), sweep++, g_bins, 64);
            assert_int_equal(sl_scan_on_fft(&s, &f), SL_OK);
        }
    }
    // PNG row i (ticks 13 + 14 i) is index i: each PNG is one complete frame, completed by
    // the next PNG's row 0 (the third stays open until a flush).
    assert_int_equal(g_rec.frames, 2);
    for (int k = 0; k < 2; k++) {
        assert_int_equal(g_rec.stats[k].valid, 400);
        assert_int_equal(g_rec.stats[k].missing, 0);
        assert_int_equal(g_rec.end[k], SL_SCAN_END_WRAP);
    }
    const sl_scan_frame_t *last = sl_scan_last_frame(&s);
    assert_non_null(last);
    assert_int_equal(last->ticks[0], 13);
    assert_int_equal(last->ticks[399], 5599);
    assert_int_equal(last->power[0][0], (uint8_t)(0 * 31 + 1)); // row 0's pattern at index 0
}

static void test_scan_counts_and_zero_fills_missing_azimuths(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, false, 400, 5600); // single buffer: rows are reused in place
    uint16_t sweep = 0;
    for (uint16_t i = 0; i < 400; i++) {
        feed_idx(&s, i, sweep++, 0xEE);
    }
    for (uint16_t i = 0; i < 400; i++) {
        if (i == 5 || i == 6 || i == 200) {
            sweep++;
            continue;
        }
        feed_idx(&s, i, sweep++, 3);
    }
    sl_scan_flush(&s);
    assert_int_equal(g_rec.frames, 2);
    assert_int_equal(g_rec.end[1], SL_SCAN_END_FLUSH);
    assert_int_equal(g_rec.stats[1].valid, 397);
    assert_int_equal(g_rec.stats[1].missing, 3);
    assert_int_equal(s.stats.missing, 3);
    assert_int_equal(s.stats.sweep_gaps, 2); // 4->7 and 199->201
    const sl_scan_frame_t *f = &g_frames[0];
    static const uint8_t zero[64];
    assert_int_equal(f->flags[5], 0);
    assert_int_equal(f->bins[200], 0);
    assert_int_equal(f->t_us[6], 0);
    assert_memory_equal(f->power[5], zero, 64); // previous rotation's data is gone
    assert_memory_equal(f->power[200], zero, 64);
    assert_int_equal(f->flags[4], SL_SCAN_AZ_VALID);
    assert_int_equal(f->power[4][0], 3 * 31 + 1);
}

static void test_scan_drops_duplicates_and_keeps_the_first_row(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600);
    feed_idx(&s, 9, 0, 1);
    feed_idx(&s, 10, 1, 1);
    feed_idx(&s, 10, 2, 2); // duplicate of the head, different data
    feed_idx(&s, 11, 3, 1);
    feed_idx(&s, 9, 4, 3); // duplicate of an older row (inside the reorder window)
    sl_scan_flush(&s);
    assert_int_equal(g_rec.frames, 1);
    assert_int_equal(g_rec.stats[0].duplicates, 2);
    assert_int_equal(g_rec.stats[0].valid, 3);
    assert_int_equal(s.stats.duplicates, 2);
    const sl_scan_frame_t *f = sl_scan_last_frame(&s);
    assert_int_equal(f->flags[10], SL_SCAN_AZ_VALID | SL_SCAN_AZ_DUP);
    assert_int_equal(f->flags[9], SL_SCAN_AZ_VALID | SL_SCAN_AZ_DUP);
    assert_int_equal(f->power[10][0], 1 * 31 + 1); // the first one
    assert_int_equal(f->power[9][0], 1 * 31 + 1);
    assert_int_equal(g_rec.az, 3); // duplicates are not reported as new rows
}

static void test_scan_stores_late_azimuths_inside_the_reorder_window(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600); // window = 400 / 8 = 50
    uint16_t sweep = 100;
    for (uint16_t i = 0; i < 400; i++) {
        if (i == 10) {
            continue;
        }
        feed_idx(&s, i, sweep++, 1);
        if (i == 12) {
            feed_idx(&s, 10, 10, 9); // late by 2
        }
    }
    feed_idx(&s, 0, sweep++, 1);
    feed_idx(&s, 1, sweep++, 1);
    feed_idx(&s, 399, 7, 9); // late, but its rotation is already complete: dropped
    feed_idx(&s, 2, sweep++, 1);
    feed_idx(&s, 300, sweep++, 1); // a forward jump: azimuths 3..299 missing
    feed_idx(&s, 100, sweep++, 1); // 200 back, empty slot, sweep +1: disorder, stored
    assert_int_equal(g_rec.frames, 1);
    assert_int_equal(s.stats.disorder, 1);
    feed_idx(&s, 2, sweep++, 1); // stored already in this rotation, sent later: next rotation
    assert_int_equal(g_rec.frames, 2);
    assert_int_equal(g_rec.stats[1].valid, 5);
    assert_int_equal(g_rec.stats[1].disorder, 1);
    assert_int_equal(g_rec.stats[0].valid, 400);
    assert_int_equal(g_rec.stats[0].out_of_order, 1);
    assert_int_equal(s.stats.late_dropped, 1);
    assert_int_equal(g_rec.end[1], SL_SCAN_END_WRAP);
    assert_int_equal(g_rec.stats[1].missing, 395);
    const sl_scan_frame_t *f0 = g_rec.frame_ptr[0];
    (void)f0; // recycled by now (double buffer): check via the recorded hash instead
    // The late row was reported to the per-azimuth callback after 11 and 12.
    assert_int_equal(g_rec.az_idx[10], 11);
    assert_int_equal(g_rec.az_idx[11], 12);
    assert_int_equal(g_rec.az_idx[12], 10);
}

static void test_scan_marks_late_rows_in_the_frame(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600);
    feed_idx(&s, 20, 0, 1);
    feed_idx(&s, 22, 2, 1);
    feed_idx(&s, 21, 1, 1);
    sl_scan_flush(&s);
    const sl_scan_frame_t *f = sl_scan_last_frame(&s);
    assert_int_equal(f->flags[21], SL_SCAN_AZ_VALID | SL_SCAN_AZ_LATE);
    assert_int_equal(f->flags[22], SL_SCAN_AZ_VALID);
    assert_int_equal(f->stats.out_of_order, 1);
}

static void test_scan_zero_fills_short_contoured_azimuths(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 256, false, 400, 5600);
    memset(g_bins, 0xFF, 256);
    sl_proto_fft_t f = fft8(0, 0, g_bins, 256);
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_OK);
    sl_scan_flush(&s);
    fill_bins(5, 100);
    f = fft8(0, 1, g_bins, 100); // contoured: 100 bins only
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_OK);
    sl_scan_flush(&s);
    const sl_scan_frame_t *fr = &g_frames[0];
    assert_int_equal(fr->bins[0], 100);
    assert_int_equal(fr->flags[0], SL_SCAN_AZ_VALID | SL_SCAN_AZ_SHORT);
    assert_memory_equal(fr->power[0], g_bins, 100);
    for (int i = 100; i < 256; i++) {
        assert_int_equal(fr->power[0][i], 0);
    }
    assert_int_equal(fr->stats.short_azimuths, 1);
    assert_int_equal(s.stats.short_azimuths, 1);
    const uint32_t rows = s.stats.azimuths;
    f = fft8(14, 2, g_bins, 0); // an azimuth with no bins at all: not an azimuth
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_ERR_MALFORMED);
    assert_int_equal(s.stats.empty_rows, 1);
    assert_int_equal(s.stats.azimuths, rows);
}

static void test_scan_copies_only_the_region_of_interest(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 96, false, 400, 5600);
    fill_bins(7, 3768);
    sl_proto_fft_t f = fft8(28, 0, g_bins, 3768);
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_OK);
    const sl_scan_frame_t *fr = &g_frames[0];
    assert_int_equal(fr->bins[2], 96);
    assert_int_equal(fr->flags[2], SL_SCAN_AZ_VALID);
    assert_memory_equal(fr->power[2], g_bins, 96);
    for (int i = 96; i < SL_CFG_ROI_BINS; i++) {
        assert_int_equal(fr->power[2][i], 0); // beyond the ROI: never written
    }
    assert_int_equal(fr->roi_bins, 96);
}

static void test_scan_reduces_16_bit_power_by_the_configured_shift(void **state)
{
    (void)state;
    // Through the wire: encode 16-bit bins, decode, store. 77 bins: exercises the 8-bin and
    // 32-bin block paths and their tails; the first six are hand-picked edge values.
    uint16_t v[77] = {0x0000, 0x00FF, 0x0100, 0x12F0, 0xFFFF, 0x0FF0};
    uint32_t x = 12345;
    for (int i = 6; i < 77; i++) {
        x = x * 1103515245U + 12345U;
        v[i] = (uint16_t)(x >> 16);
    }
    uint8_t b[256];
    sl_proto_fft_t h = {.sweep_counter = 0, .azimuth_ticks = 0, .bins = 77};
    const sl_ssize_t n = sl_proto_encode_fft16(b, sizeof b, &h, v);
    assert_int_equal(n, 22 + 14 + 2 * 77);
    sl_proto_msg_t m = {.id = 31, .payload = {b + 22, (size_t)n - 22}};
    static const unsigned shifts[] = {8, 4, 0, 9, 15};
    for (size_t t = 0; t < sizeof shifts / sizeof shifts[0]; t++) {
        const unsigned shift = shifts[t];
        for (unsigned roi = 32; roi <= 96; roi += 64) { // 77 bins: truncated / short row
            memset(&g_rec, 0, sizeof g_rec);
            sl_scan_t s;
            sl_scan_cfg_t c = {.roi_bins = (uint16_t)roi, .pow16_shift = (uint8_t)shift,
                               .azimuths = 400, .encoder_size = 5600};
            assert_int_equal(sl_scan_init(&s, &c, &g_frames[0], NULL), SL_OK);
            assert_int_equal(sl_scan_on_msg(&s, &m), SL_OK);
            const sl_scan_frame_t *fr = &g_frames[0];
            const uint32_t nb = roi < 77 ? roi : 77;
            assert_int_equal(fr->bins[0], nb);
            assert_int_equal(fr->flags[0], SL_SCAN_AZ_VALID | SL_SCAN_AZ_16BIT |
                                               (nb < roi ? SL_SCAN_AZ_SHORT : 0));
            uint32_t sat = 0;
            for (uint32_t i = 0; i < nb; i++) {
                const uint32_t want = (uint32_t)v[i] >> shift;
                sat += want > 255;
                assert_int_equal(fr->power[0][i], want > 255 ? 255 : want);
            }
            for (uint32_t i = nb; i < roi; i++) {
                assert_int_equal(fr->power[0][i], 0);
            }
            assert_int_equal(s.stats.saturated16, sat);
            if (shift == 8) {
                assert_int_equal(sat, 0);
            }
            if (shift == 4) {
                assert_true(sat >= 2); // 0x12F0 and 0xFFFF at least
            }
            assert_int_equal(s.stats.wide_azimuths, 1);
        }
    }
}

static void test_scan_keeps_a_timestamp_per_azimuth(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 32, true, 400, 5600);
    fill_bins(1, 32);
    sl_proto_fft_t f = fft8(14, 0, g_bins, 32);
    f.seconds = 1547131046U;
    f.split_ns = 999999999U;
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_OK);
    f.azimuth_ticks = 28;
    f.sweep_counter = 1;
    f.seconds = 1547131047U;
    f.split_ns = 625999U;
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_OK);
    sl_scan_flush(&s);
    const sl_scan_frame_t *fr = sl_scan_last_frame(&s);
    assert_int_equal(fr->t_us[1], 1547131046ULL * 1000000 + 999999);
    assert_int_equal(fr->t_us[2], 1547131047ULL * 1000000 + 625);
    assert_int_equal(fr->t_first_us, fr->t_us[1]);
    assert_int_equal(fr->t_last_us, fr->t_us[2]);
    assert_int_equal(fr->sweep[2], 1);
    assert_int_equal(fr->ticks[2], 28);
}

static void test_scan_double_buffer_keeps_the_last_frame_intact_for_a_rotation(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600);
    assert_null(sl_scan_last_frame(&s));
    uint16_t sweep = 0;
    for (uint16_t i = 0; i < 400; i++) {
        feed_idx(&s, i, sweep++, (uint8_t)i);
    }
    for (uint16_t i = 0; i < 300; i++) {
        feed_idx(&s, i, sweep++, (uint8_t)(i + 100));
    }
    assert_int_equal(g_rec.frames, 1);
    const sl_scan_frame_t *a = g_rec.frame_ptr[0];
    assert_ptr_equal(sl_scan_last_frame(&s), a);
    assert_true(frame_hash(a) == g_rec.hash[0]); // untouched while the next one fills
    for (uint16_t i = 300; i < 400; i++) {
        feed_idx(&s, i, sweep++, (uint8_t)(i + 100));
    }
    feed_idx(&s, 0, sweep++, 0);
    assert_int_equal(g_rec.frames, 2);
    assert_true(g_rec.frame_ptr[1] != a);
    assert_ptr_equal(sl_scan_last_frame(&s), g_rec.frame_ptr[1]);
    assert_true(frame_hash(g_rec.frame_ptr[1]) == g_rec.hash[1]);
}

static void test_scan_completes_the_frame_on_a_geometry_change(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 0, 0);
    fill_bins(1, 64);
    sl_proto_fft_t early = fft8(42, 0, g_bins, 64);
    assert_int_equal(sl_scan_on_fft(&s, &early), SL_ERR_STATE); // no geometry yet
    assert_int_equal(s.stats.no_config, 1);
    sl_proto_config_t c = {.azimuths = 400, .encoder_size = 5600};
    assert_int_equal(sl_scan_on_config(&s, &c), SL_OK);
    feed_idx(&s, 3, 1, 1);
    feed_idx(&s, 4, 2, 1);
    assert_int_equal(sl_scan_on_config(&s, &c), SL_OK); // identical: the frame continues
    assert_int_equal(g_rec.frames, 0);
    feed_idx(&s, 5, 3, 1);
    c.azimuths = 200;
    c.encoder_size = 2800;
    assert_int_equal(sl_scan_on_config(&s, &c), SL_OK);
    assert_int_equal(g_rec.frames, 1);
    assert_int_equal(g_rec.end[0], SL_SCAN_END_CONFIG);
    assert_int_equal(g_rec.stats[0].valid, 3);
    assert_int_equal(s.stats.configs, 3);
    assert_int_equal(s.stats.config_changes, 1);
    c.azimuths = SL_CFG_MAX_AZIMUTHS + 1;
    assert_int_equal(sl_scan_on_config(&s, &c), SL_ERR_RANGE);
    c.azimuths = 0;
    assert_int_equal(sl_scan_on_config(&s, &c), SL_ERR_RANGE);
    c.azimuths = 200;
    c.encoder_size = 0;
    assert_int_equal(sl_scan_on_config(&s, &c), SL_ERR_RANGE);
    assert_int_equal(s.stats.config_rejected, 3);
    assert_int_equal(s.azimuths, 200); // unchanged
}

static void test_scan_rejects_unexpected_geometry_and_bad_azimuths(void **state)
{
    (void)state;
    sl_scan_t s;
    sl_scan_cfg_t cfg = {.roi_bins = 32, .pow16_shift = 8, .expect_azimuths = 400,
                         .expect_encoder_size = 5600};
    assert_int_equal(sl_scan_init(&s, &cfg, &g_frames[0], NULL), SL_OK);
    sl_proto_config_t c = {.azimuths = 360, .encoder_size = 5600};
    assert_int_equal(sl_scan_on_config(&s, &c), SL_ERR_RANGE);
    assert_int_equal(sl_scan_set_geometry(&s, 400, 4096), SL_ERR_RANGE);
    assert_int_equal(s.stats.config_rejected, 2);
    fill_bins(1, 32);
    sl_proto_fft_t f = fft8(0, 0, g_bins, 32);
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_ERR_STATE);
    assert_int_equal(sl_scan_set_geometry(&s, 400, 5600), SL_OK);
    f.azimuth_ticks = 5600;
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_ERR_RANGE);
    assert_int_equal(s.stats.bad_azimuth, 1);
    f.azimuth_ticks = 0xFFFF;
    assert_int_equal(sl_scan_on_fft(&s, &f), SL_ERR_RANGE);
    assert_int_equal(s.stats.bad_azimuth, 2);
    // Bad init arguments.
    cfg.roi_bins = 0;
    assert_int_equal(sl_scan_init(&s, &cfg, &g_frames[0], NULL), SL_ERR_ARG);
    cfg.roi_bins = SL_CFG_ROI_BINS + 1;
    assert_int_equal(sl_scan_init(&s, &cfg, &g_frames[0], NULL), SL_ERR_ARG);
    cfg.roi_bins = 32;
    assert_int_equal(sl_scan_init(&s, &cfg, &g_frames[0], &g_frames[0]), SL_ERR_ARG);
    cfg.pow16_shift = 16;
    assert_int_equal(sl_scan_init(&s, &cfg, &g_frames[0], NULL), SL_ERR_ARG);
    // Malformed messages through on_msg are counted.
    cfg.pow16_shift = 8;
    assert_int_equal(sl_scan_init(&s, &cfg, &g_frames[0], NULL), SL_OK);
    uint8_t pl[13] = {0};
    sl_proto_msg_t m = {.id = 30, .payload = {pl, sizeof pl}};
    assert_int_equal(sl_scan_on_msg(&s, &m), SL_ERR_MALFORMED);
    m.id = 10;
    assert_int_equal(sl_scan_on_msg(&s, &m), SL_ERR_MALFORMED);
    m.id = 1;
    assert_int_equal(sl_scan_on_msg(&s, &m), SL_OK);
    assert_int_equal(s.stats.malformed, 2);
}

static void test_scan_completes_the_frame_after_a_rotation_of_lost_packets(void **state)
{
    (void)state;
    for (int ignore = 0; ignore < 2; ignore++) {
        memset(&g_rec, 0, sizeof g_rec);
        sl_scan_t s;
        sl_scan_cfg_t c = {.roi_bins = 32, .pow16_shift = 8, .azimuths = 400, .encoder_size = 5600,
                           .ignore_sweep = ignore != 0, .on_frame = on_frame, .ctx = &g_rec};
        assert_int_equal(sl_scan_init(&s, &c, &g_frames[0], &g_frames[1]), SL_OK);
        feed_idx(&s, 10, 1000, 1);
        feed_idx(&s, 20, 1010, 1);
        feed_idx(&s, 30, (uint16_t)(1020 + 400), 1); // same index range, a rotation later
        if (!ignore) {
            assert_int_equal(g_rec.frames, 1);
            assert_int_equal(g_rec.end[0], SL_SCAN_END_SWEEP_GAP);
            assert_int_equal(g_rec.stats[0].valid, 2);
        } else {
            assert_int_equal(g_rec.frames, 0);
        }
        // A sweep counter that wraps at 65535 is a +1 step, not a gap.
        feed_idx(&s, 40, 65535, 1);
        const uint32_t gaps = s.stats.sweep_gaps;
        feed_idx(&s, 41, 0, 1);
        assert_int_equal(s.stats.sweep_gaps, gaps);
    }
}

// The whole chain: golden bytes -> sl_proto (random chunkings) -> sl_scan. Frames must be
// identical for every chunking and hold exactly the golden power values.
typedef struct chain {
    sl_proto_t p;
    sl_scan_t s;
    uint8_t reasm[8192];
} chain_t;

static void run_chain(chain_t *c, const uint8_t *data, size_t n, uint64_t seed, bool double_buffer)
{
    memset(&g_rec, 0, sizeof g_rec);
    sl_scan_cfg_t sc = {.roi_bins = 200, .pow16_shift = 8, .on_azimuth = on_azimuth,
                        .on_frame = on_frame, .ctx = &g_rec};
    assert_int_equal(sl_scan_init(&c->s, &sc, &g_frames[0], double_buffer ? &g_frames[1] : NULL),
                     SL_OK);
    sl_proto_cfg_t pc = {.reasm_buf = c->reasm, .reasm_size = sizeof c->reasm,
                         .max_payload_bytes = 8000, .on_msg = sl_scan_proto_sink, .ctx = &c->s};
    assert_int_equal(sl_proto_init(&c->p, &pc), SL_OK);
    uint64_t r = seed * 0x9E3779B97F4A7C15ULL + 3;
    size_t i = 0;
    while (i < n) {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        size_t k = seed == 0 ? n : 1 + (r % ((seed % 3 == 0) ? 7 : 3000));
        if (k > n - i) {
            k = n - i;
        }
        assert_int_equal(sl_proto_feed(&c->p, data + i, k, 0), SL_OK);
        i += k;
    }
    assert_int_equal(sl_proto_finish(&c->p), SL_OK);
    sl_scan_flush(&c->s);
}

static void test_scan_frames_from_a_byte_stream_match_for_every_chunking(void **state)
{
    (void)state;
    sl_golden_params_t g = sl_golden_defaults();
    g.azimuths = 40;
    g.encoder_size = 5600;
    g.range_bins = 400;
    g.rotations = 3;
    g.keep_alive_every = 13;
    g.contour_bins = 150;
    for (int width = 1; width <= 2; width++) {
        g.bytes_per_bin = (uint8_t)width;
        const size_t n = sl_golden_size(&g);
        uint8_t *data = malloc(n);
        assert_int_equal(sl_golden_build(data, n, &g), n);
        static chain_t c;
        run_chain(&c, data, n, 0, true);
        // Tick offset 13 with 140 ticks per azimuth: index = azimuth (13 < 70), so golden
        // rotation r is frame r exactly.
        assert_int_equal(g_rec.frames, 3);
        uint64_t want_hash[3];
        for (int f = 0; f < 3; f++) {
            want_hash[f] = g_rec.hash[f];
            assert_int_equal(g_rec.stats[f].valid, 40);
            assert_int_equal(g_rec.stats[f].short_azimuths, 20);
            assert_int_equal(g_rec.end[f], f < 2 ? SL_SCAN_END_WRAP : SL_SCAN_END_FLUSH);
        }
        // Content of the last frame (still intact: double buffering) against the generator.
        const sl_scan_frame_t *fr = sl_scan_last_frame(&c.s);
        for (uint32_t a = 0; a < 40; a++) {
            const uint32_t nb = sl_golden_bins(&g, a) < 200 ? sl_golden_bins(&g, a) : 200;
            assert_int_equal(fr->bins[a], nb);
            for (uint32_t b = 0; b < 200; b++) {
                const uint8_t want = b >= nb ? 0
                                     : width == 1 ? sl_golden_power8(&g, 2, a, b)
                                                  : (uint8_t)(sl_golden_power16(&g, 2, a, b) >> 8);
                assert_int_equal(fr->power[a][b], want);
            }
            uint32_t sec, ns;
            sl_golden_time(&g, 80 + a, &sec, &ns);
            assert_int_equal(fr->t_us[a], (uint64_t)sec * 1000000 + ns / 1000);
        }
        for (uint64_t seed = 1; seed <= 12; seed++) {
            run_chain(&c, data, n, seed, seed % 2 == 0);
            assert_int_equal(g_rec.frames, 3);
            for (int f = 0; f < 3; f++) {
                assert_true(g_rec.hash[f] == want_hash[f]);
            }
            assert_int_equal(c.p.stats.bytes_skipped, 0);
        }
        free(data);
    }
}

static void test_scan_follows_a_radar_restart_with_a_new_configuration_mid_stream(void **state)
{
    (void)state;
    // Stream A (40 azimuths) then, mid-stream, a restarted radar's stream B (its own
    // Configuration: 20 azimuths, new sweep counters), then B' = the same radar restarting
    // again with an unchanged configuration.
    sl_golden_params_t a = sl_golden_defaults();
    a.azimuths = 40;
    a.range_bins = 100;
    a.rotations = 2;
    a.keep_alive_every = 9;
    sl_golden_params_t b = a;
    b.azimuths = 20;
    b.seed = 7;
    sl_golden_params_t b2 = b;
    b2.seed = 11;
    const size_t na = sl_golden_size(&a), nb = sl_golden_size(&b), nb2 = sl_golden_size(&b2);
    uint8_t *data = malloc(na + nb + nb2);
    assert_int_equal(sl_golden_build(data, na, &a), na);
    assert_int_equal(sl_golden_build(data + na, nb, &b), nb);
    assert_int_equal(sl_golden_build(data + na + nb, nb2, &b2), nb2);
    static chain_t c;
    for (uint64_t seed = 0; seed <= 6; seed++) {
        run_chain(&c, data, na + nb + nb2, seed, true);
        assert_int_equal(g_rec.frames, 6);
        static const uint8_t ends[6] = {SL_SCAN_END_WRAP, SL_SCAN_END_CONFIG, SL_SCAN_END_WRAP,
                                        SL_SCAN_END_SWEEP_GAP, SL_SCAN_END_WRAP, SL_SCAN_END_FLUSH};
        static const uint16_t valid[6] = {40, 40, 20, 20, 20, 20};
        for (int f = 0; f < 6; f++) {
            assert_int_equal(g_rec.end[f], ends[f]);
            assert_int_equal(g_rec.stats[f].valid, valid[f]);
            assert_int_equal(g_rec.stats[f].missing, 0);
        }
        assert_int_equal(c.s.stats.configs, 3);
        assert_int_equal(c.s.stats.config_changes, 1);
        assert_int_equal(c.p.stats.configuration, 3);
        assert_int_equal(c.p.stats.bytes_skipped, 0);
    }
    free(data);
}

// ------------------------------------------------------------------ frame-less mode

// Row and rotation events (on_row / on_rot), comparable across modes.
#define MAX_ROWS 4096
typedef struct rowrec {
    size_t rows, rots;
    uint64_t row_hash[MAX_ROWS]; // idx, flags, bins, ticks, sweep, t_us, rotation, power
    uint64_t rot_hash[MAX_FRAMES]; // header, stats, flags
    unsigned in_buf, in_other;   // frame-less views: row buffer vs. elsewhere (the message)
    unsigned bad_view;           // a view that is neither where it should be
    unsigned bad_fft;            // a row whose message (r->fft) is missing or not its source
    const uint8_t *row_buf;
    uint16_t roi;
} rowrec_t;
static rowrec_t g_rows;

static void on_row(void *ctx, const sl_scan_row_t *r)
{
    rowrec_t *w = ctx;
    assert_true(w->rows < MAX_ROWS);
    uint64_t h = SL_GOLDEN_FNV_INIT;
    const uint8_t b[17] = {(uint8_t)r->idx, (uint8_t)(r->idx >> 8), r->flags, (uint8_t)r->bins,
                           (uint8_t)(r->bins >> 8), (uint8_t)r->ticks, (uint8_t)(r->ticks >> 8),
                           (uint8_t)r->sweep, (uint8_t)(r->sweep >> 8), (uint8_t)r->t_us,
                           (uint8_t)(r->t_us >> 8), (uint8_t)(r->t_us >> 16),
                           (uint8_t)(r->t_us >> 24), (uint8_t)(r->t_us >> 32),
                           (uint8_t)r->rotation, (uint8_t)(r->rotation >> 8), 0};
    h = sl_golden_fnv1a(b, sizeof b, h);
    h = sl_golden_fnv1a(r->power, w->roi, h);
    w->row_hash[w->rows++] = h;
    // The row's message carries at least the row's bins, and (8-bit) they are the row's.
    if (r->fft == NULL || r->fft->bins < r->bins ||
        ((r->flags & SL_SCAN_AZ_16BIT) == 0U &&
         memcmp(r->fft->bin_data, r->power, r->bins) != 0)) {
        w->bad_fft++;
    }
    if (w->row_buf != NULL) {
        const bool in_buf = r->power == w->row_buf;
        const bool must_copy = (r->flags & (SL_SCAN_AZ_SHORT | SL_SCAN_AZ_16BIT)) != 0U;
        if (in_buf != must_copy) {
            w->bad_view++;
        }
        if (in_buf) {
            w->in_buf++;
        } else {
            w->in_other++;
        }
    }
}

static void on_rot(void *ctx, const sl_scan_rot_t *r)
{
    rowrec_t *w = ctx;
    assert_true(w->rots < MAX_FRAMES);
    uint64_t h = SL_GOLDEN_FNV_INIT;
    const uint8_t b[13] = {(uint8_t)r->rotation, (uint8_t)r->azimuths, (uint8_t)(r->azimuths >> 8),
                           (uint8_t)r->roi_bins, r->end, (uint8_t)r->stats.valid,
                           (uint8_t)(r->stats.valid >> 8), (uint8_t)r->stats.missing,
                           (uint8_t)r->stats.duplicates, (uint8_t)r->stats.out_of_order,
                           (uint8_t)r->stats.short_azimuths, (uint8_t)r->stats.wide_azimuths,
                           (uint8_t)(r->t_last_us - r->t_first_us)};
    h = sl_golden_fnv1a(b, sizeof b, h);
    h = sl_golden_fnv1a(r->flags, r->azimuths, h);
    w->rot_hash[w->rots++] = h;
}

// Frame mode also reports rows and rotations (on_row / on_rot) and they equal its frames.
static void on_azimuth_and_row_agree(void *ctx, const sl_scan_frame_t *f, uint16_t idx)
{
    on_azimuth(ctx, f, idx);
}

// Chain bytes -> decoder -> scan in frame mode (whole-message decoder) or frame-less mode
// (decoder truncating payloads to the ROI: what the pipeline runs).
typedef struct chain2 {
    sl_proto_t p;
    sl_scan_t s;
    uint8_t reasm[8192];
    uint8_t row[SL_CFG_ROI_BINS];
} chain2_t;

static void run_chain2(chain2_t *c, const uint8_t *data, size_t n, uint64_t seed, bool frameless,
                       uint16_t roi)
{
    memset(&g_rec, 0, sizeof g_rec);
    memset(&g_rows, 0, sizeof g_rows);
    g_rows.roi = roi;
    g_rows.row_buf = frameless ? c->row : NULL;
    sl_scan_cfg_t sc = {.roi_bins = roi, .pow16_shift = 8, .on_row = on_row, .on_rot = on_rot,
                        .row_buf = c->row, .row_buf_size = sizeof c->row, .ctx = &g_rows};
    if (frameless) {
        assert_int_equal(sl_scan_init(&c->s, &sc, NULL, NULL), SL_OK);
        assert_null(sl_scan_last_frame(&c->s));
    } else {
        assert_int_equal(sl_scan_init(&c->s, &sc, &g_frames[0], &g_frames[1]), SL_OK);
    }
    // Frame-less: the decoder keeps only what the scan reads (16-bit ROI + fixed part).
    sl_proto_cfg_t pc = {.reasm_buf = c->reasm,
                         .reasm_size = frameless ? (size_t)(14U + 2U * roi) : sizeof c->reasm,
                         .truncate_long = frameless, .on_msg = sl_scan_proto_sink, .ctx = &c->s};
    assert_int_equal(sl_proto_init(&c->p, &pc), SL_OK);
    uint64_t r = seed * 0x9E3779B97F4A7C15ULL + 5;
    size_t i = 0;
    while (i < n) {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        size_t k = seed == 0 ? n : 1 + (r % ((seed % 3 == 0) ? 7 : 3000));
        if (k > n - i) {
            k = n - i;
        }
        assert_int_equal(sl_proto_feed(&c->p, data + i, k, 0), SL_OK);
        i += k;
    }
    assert_int_equal(sl_proto_finish(&c->p), SL_OK);
    sl_scan_flush(&c->s);
}

static void test_scan_frameless_reports_the_rows_and_rotations_of_frame_mode(void **state)
{
    (void)state;
    sl_golden_params_t g = sl_golden_defaults();
    g.azimuths = 40;
    g.range_bins = 400;
    g.rotations = 3;
    g.keep_alive_every = 11;
    g.health_every = 7;
    g.contour_bins = 150; // odd azimuths short of a 160-bin ROI
    for (int width = 1; width <= 2; width++) {
        g.bytes_per_bin = (uint8_t)width;
        const size_t n = sl_golden_size(&g);
        uint8_t *data = malloc(n);
        assert_int_equal(sl_golden_build(data, n, &g), n);
        static chain2_t c;
        static rowrec_t want;
        run_chain2(&c, data, n, 0, false, 160);
        want = g_rows;
        assert_int_equal(want.rows, 120);
        assert_int_equal(want.rots, 3);
        for (uint64_t seed = 0; seed <= 10; seed++) {
            run_chain2(&c, data, n, seed, true, 160);
            assert_int_equal(g_rows.rows, want.rows);
            assert_int_equal(g_rows.rots, want.rots);
            for (size_t k = 0; k < want.rows; k++) {
                assert_true(g_rows.row_hash[k] == want.row_hash[k]);
            }
            for (size_t k = 0; k < want.rots; k++) {
                assert_true(g_rows.rot_hash[k] == want.rot_hash[k]);
            }
            assert_int_equal(g_rows.bad_view, 0);
            assert_int_equal(g_rows.bad_fft, 0);
            // 8-bit complete rows are views of the message; short and 16-bit ones are copies.
            assert_int_equal(g_rows.in_buf, width == 1 ? 60 : 120);
            assert_int_equal(c.p.stats.bytes_skipped, 0);
            assert_int_equal(c.p.stats.too_big, 0);
            assert_true(c.p.stats.cut >= 60U); // whole FFT payloads are longer than 14 + 320
        }
        free(data);
    }
}

// Gaps, duplicates, late rows and a lost rotation: the frame-less bookkeeping equals frame
// mode's (row events, rotation flags and statistics).
// Disorder is bounded: shuffled azimuths (sweep counters travel with their messages) make
// one rotation per pass, every row kept; a reversed rotation is one rotation, not eight.
static uint32_t shuffle_rng(uint32_t *x)
{
    *x ^= *x << 13;
    *x ^= *x >> 17;
    *x ^= *x << 5;
    return *x;
}

static void test_scan_shuffled_azimuths_close_one_rotation_per_pass(void **state)
{
    (void)state;
    for (int use_sweep = 0; use_sweep < 2; use_sweep++) {
        sl_scan_t s;
        scan_init(&s, 64, true, 400, 5600);
        s.cfg.ignore_sweep = use_sweep == 0;
        uint32_t x = 12345;
        uint16_t sweep = 7;
        for (int rot = 0; rot < 6; rot++) {
            uint16_t order[400];
            for (uint16_t i = 0; i < 400; i++) {
                order[i] = i;
            }
            for (uint16_t i = 399; i > 0; i--) { // Fisher-Yates
                const uint16_t j = (uint16_t)(shuffle_rng(&x) % (i + 1U));
                const uint16_t t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
            for (uint16_t i = 0; i < 400; i++) {
                // the radar's sweep counter follows the azimuth, the transport shuffles
                feed_idx(&s, order[i], (uint16_t)(sweep + order[i]), (uint8_t)rot);
            }
            sweep = (uint16_t)(sweep + 400U);
        }
        sl_scan_flush(&s);
        // 6 passes: at most 7 rotations (a pass can split where the next one's first
        // message hits a stored azimuth), never hundreds; every message is a row.
        assert_true(g_rec.frames >= 6 && g_rec.frames <= 7);
        assert_int_equal(s.stats.azimuths + s.stats.duplicates, 2400);
        assert_true(s.stats.disorder > 100);
        if (use_sweep) {
            assert_int_equal(s.stats.duplicates, 0);
            assert_int_equal(s.stats.azimuths, 2400);
        }
        memset(&g_rec, 0, sizeof g_rec);
    }
}

static void test_scan_reversed_rotation_is_one_rotation(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600);
    uint16_t sweep = 0;
    for (int rot = 0; rot < 3; rot++) {
        for (int i = 399; i >= 0; i--) {
            feed_idx(&s, (uint16_t)i, sweep++, 1);
        }
    }
    sl_scan_flush(&s);
    assert_int_equal(g_rec.frames, 3);
    for (int r = 0; r < 3; r++) {
        assert_int_equal(g_rec.stats[r].valid, 400);
        assert_int_equal(g_rec.stats[r].missing, 0);
    }
}

// A rotation whose encoder values are all out of range is counted as missing azimuths.
static void test_scan_blind_rotation_adds_its_azimuths_to_missing(void **state)
{
    (void)state;
    sl_scan_t s;
    scan_init(&s, 64, true, 400, 5600);
    fill_bins(1, 64);
    for (uint16_t i = 0; i < 400; i++) {
        const sl_proto_fft_t f = fft8(5600 + i, i, g_bins, 64); // ticks >= encoder_size
        assert_int_equal(sl_scan_on_fft(&s, &f), SL_ERR_RANGE);
    }
    assert_int_equal(s.stats.bad_azimuth, 400);
    assert_int_equal(s.stats.blind_rotations, 1);
    assert_int_equal(s.stats.missing, 400);
    assert_int_equal(g_rec.frames, 0);
    // Empty rows count the same way (and a good row resets the run).
    const sl_proto_fft_t good = fft8(14, 500, g_bins, 64);
    assert_int_equal(sl_scan_on_fft(&s, &good), SL_OK);
    for (uint16_t i = 0; i < 399; i++) {
        const sl_proto_fft_t f = fft8((uint16_t)(14 * i), (uint16_t)(501 + i), g_bins, 0);
        assert_int_equal(sl_scan_on_fft(&s, &f), SL_ERR_MALFORMED);
    }
    assert_int_equal(s.stats.empty_rows, 399);
    assert_int_equal(s.stats.blind_rotations, 1);
}

static void feed_script(sl_scan_t *s)
{
    static const int16_t script[] = {0, 1, 2, 4, 3, 3, 5, 9, 8, 10, 399, 0, 1, 1, 390, 2, 3, -1};
    uint16_t sweep = 0;
    for (size_t k = 0; script[k] >= 0; k++) {
        if (script[k] == 390) {
            sweep = (uint16_t)(sweep + 500); // a rotation of lost packets
        }
        feed_idx(s, (uint16_t)script[k], sweep++, (uint8_t)k);
    }
    sl_scan_flush(s);
}

static void test_scan_frameless_bookkeeping_equals_frame_mode_with_gaps(void **state)
{
    (void)state;
    static uint8_t row[64];
    static rowrec_t want;
    for (int frameless = 0; frameless < 2; frameless++) {
        memset(&g_rows, 0, sizeof g_rows);
        memset(&g_rec, 0, sizeof g_rec);
        g_rows.roi = 64;
        sl_scan_t s;
        sl_scan_cfg_t c = {.roi_bins = 64, .pow16_shift = 8, .azimuths = 400,
                           .encoder_size = 5600, .on_row = on_row, .on_rot = on_rot,
                           .row_buf = row, .row_buf_size = sizeof row, .ctx = &g_rows};
        if (frameless) {
            assert_int_equal(sl_scan_init(&s, &c, NULL, NULL), SL_OK);
        } else {
            assert_int_equal(sl_scan_init(&s, &c, &g_frames[0], NULL), SL_OK);
        }
        feed_script(&s);
        static sl_scan_stats_t want_stats;
        if (!frameless) {
            want = g_rows;
            want_stats = s.stats;
            assert_true(want.rots >= 3);
            assert_true(s.stats.duplicates >= 2);
            assert_true(s.stats.out_of_order >= 2);
            assert_true(s.stats.missing >= 300);
            continue;
        }
        assert_memory_equal(&s.stats, &want_stats, sizeof want_stats);
        assert_int_equal(g_rows.bad_fft, 0);
        assert_int_equal(g_rows.rows, want.rows);
        assert_int_equal(g_rows.rots, want.rots);
        for (size_t k = 0; k < want.rows; k++) {
            assert_true(g_rows.row_hash[k] == want.row_hash[k]);
        }
        for (size_t k = 0; k < want.rots; k++) {
            assert_true(g_rows.rot_hash[k] == want.rot_hash[k]);
        }

    }
    // Frame-less init needs a row buffer of roi_bins bytes and no spare frame.
    sl_scan_t s;
    sl_scan_cfg_t c = {.roi_bins = 64, .pow16_shift = 8, .row_buf = row, .row_buf_size = 63};
    assert_int_equal(sl_scan_init(&s, &c, NULL, NULL), SL_ERR_ARG);
    c.row_buf_size = 64;
    assert_int_equal(sl_scan_init(&s, &c, NULL, &g_frames[1]), SL_ERR_ARG);
    c.row_buf = NULL;
    assert_int_equal(sl_scan_init(&s, &c, NULL, NULL), SL_ERR_ARG);
    (void)on_azimuth_and_row_agree;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scan_maps_encoder_values_to_the_azimuth_cell_containing_them),
        cmocka_unit_test(test_scan_reciprocal_index_equals_the_division_for_every_encoder_value),
        cmocka_unit_test(test_scan_timestamp_us_multiply_equals_the_division),
        cmocka_unit_test(test_scan_completes_a_frame_when_the_azimuth_index_wraps),
        cmocka_unit_test(test_scan_oxford_png_rows_fill_exactly_one_frame),
        cmocka_unit_test(test_scan_counts_and_zero_fills_missing_azimuths),
        cmocka_unit_test(test_scan_drops_duplicates_and_keeps_the_first_row),
        cmocka_unit_test(test_scan_stores_late_azimuths_inside_the_reorder_window),
        cmocka_unit_test(test_scan_marks_late_rows_in_the_frame),
        cmocka_unit_test(test_scan_zero_fills_short_contoured_azimuths),
        cmocka_unit_test(test_scan_copies_only_the_region_of_interest),
        cmocka_unit_test(test_scan_reduces_16_bit_power_by_the_configured_shift),
        cmocka_unit_test(test_scan_keeps_a_timestamp_per_azimuth),
        cmocka_unit_test(test_scan_double_buffer_keeps_the_last_frame_intact_for_a_rotation),
        cmocka_unit_test(test_scan_completes_the_frame_on_a_geometry_change),
        cmocka_unit_test(test_scan_rejects_unexpected_geometry_and_bad_azimuths),
        cmocka_unit_test(test_scan_completes_the_frame_after_a_rotation_of_lost_packets),
        cmocka_unit_test(test_scan_frames_from_a_byte_stream_match_for_every_chunking),
        cmocka_unit_test(test_scan_follows_a_radar_restart_with_a_new_configuration_mid_stream),
        cmocka_unit_test(test_scan_frameless_reports_the_rows_and_rotations_of_frame_mode),
        cmocka_unit_test(test_scan_frameless_bookkeeping_equals_frame_mode_with_gaps),
        cmocka_unit_test(test_scan_shuffled_azimuths_close_one_rotation_per_pass),
        cmocka_unit_test(test_scan_reversed_rotation_is_one_rotation),
        cmocka_unit_test(test_scan_blind_rotation_adds_its_azimuths_to_missing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
