// SPDX-License-Identifier: MIT
// Unit tests of the pipeline's honest health (issue 14): every fault a radar, a network or a
// CAN bus can cause is visible in the Status and Health frames, decoded with the core's own
// decoders (the layout table the DBC is generated from). Streams are built here with the
// core's encoders; nothing is tuned to a simulator.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_can.h"

/// The default E2E configuration of message SL_CAN_MSG_<m>.
#define E2E(m) (&sl_can_e2e_defaults[SL_CAN_MSG_##m])

/// The receiver took the frame as part of its sequence (the first one, or any later step).
static bool e2e_accepted(sl_can_e2e_status_t st)
{
    return st == SL_CAN_E2E_OK || st == SL_CAN_E2E_OK_SOME_LOST || st == SL_CAN_E2E_INITIAL;
}
#include "shadowlean/sl_pipeline.h"
#include "shadowlean/sl_proto.h"

static sl_pipeline_t pl;
static const sl_board_t *B;

// ------------------------------------------------------------------------- recording port

#define MAXCAN 20000
typedef struct rec {
    sl_can_frame_t can[MAXCAN];
    uint64_t t_us[MAXCAN];
    int n;
    int rotations;
} rec_t;
static rec_t rec;
static uint64_t g_now;

static sl_err_t port_can_tx(void *ctx, const sl_can_frame_t *f)
{
    rec_t *r = ctx;
    if (r->n < MAXCAN) {
        r->t_us[r->n] = g_now;
        r->can[r->n++] = *f;
    }
    return SL_OK;
}

static void port_on_rotation(void *ctx, const sl_pipeline_rotation_t *x)
{
    (void)x;
    ((rec_t *)ctx)->rotations++;
}

static void init(void)
{
    memset(&rec, 0, sizeof rec);
    sl_pipeline_cfg_t c;
    sl_pipeline_cfg_default(&c, B);
    c.port.can_tx = port_can_tx;
    c.port.on_rotation = port_on_rotation;
    c.port.ctx = &rec;
    assert_int_equal(sl_pipeline_init(&pl, B, &c), SL_OK);
}

// The last Status and Health frames, decoded (E2E checked by the decoders).
static void last_status(sl_can_status_t *st, sl_can_health_t *h)
{
    int si = -1, hi = -1;
    for (int i = 0; i < rec.n; i++) {
        if (rec.can[i].id == B->can_id_status) {
            si = i;
        } else if (rec.can[i].id == B->can_id_health) {
            hi = i;
        }
    }
    assert_true(si >= 0 && hi == si + 1); // Health right after its Status
    assert_int_equal(sl_can_decode_status(&rec.can[si], E2E(STATUS), st), SL_OK);
    assert_int_equal(sl_can_decode_health(&rec.can[hi], E2E(HEALTH), h), SL_OK);
}

// ------------------------------------------------------------------------- stream builder

static uint8_t g_buf[4 << 20];
static size_t g_n;
static uint16_t g_sweep;
static uint32_t g_msg;

static void put_config(uint16_t azimuths, uint16_t encoder, uint16_t bin_100um)
{
    const sl_proto_config_t c = {.azimuths = azimuths, .bin_size_100um = bin_100um,
                                 .range_bins = 3768, .encoder_size = encoder,
                                 .rotation_mhz = 4000, .packet_rate = 1600,
                                 .has_data_width = true, .data_width = 1};
    const sl_ssize_t k = sl_proto_encode_config(g_buf + g_n, sizeof g_buf - g_n, &c,
                                                (sl_bytes_t){NULL, 0});
    assert_true(k > 0);
    g_n += (size_t)k;
}

// One FFT message of `bins` quiet bins at encoder value `ticks`; `sweep` as given.
static void put_fft(uint16_t ticks, uint16_t sweep, uint32_t bins)
{
    static uint8_t row[512];
    const uint64_t t = 1700000000ULL * 1000000ULL + (uint64_t)g_msg++ * 625U;
    const sl_proto_fft_t f = {.sweep_counter = sweep, .azimuth_ticks = ticks,
                              .seconds = (uint32_t)(t / 1000000U),
                              .split_ns = (uint32_t)(t % 1000000U) * 1000U, .bins = bins};
    memset(row, 20, sizeof row);
    const sl_ssize_t k = sl_proto_encode_fft8(g_buf + g_n, sizeof g_buf - g_n, &f, row);
    assert_true(k > 0);
    g_n += (size_t)k;
}

static void put_rotations(int rotations, uint32_t bins)
{
    for (int r = 0; r < rotations; r++) {
        for (uint16_t a = 0; a < 400; a++) {
            put_fft((uint16_t)(a * 14U), g_sweep++, bins);
        }
    }
}

static void reset_stream(void)
{
    g_n = 0;
    g_sweep = 0;
    g_msg = 0;
}

// Feed the stream message by message at 1600 messages/s of port time from `t0`.
static void feed_paced(uint64_t t0)
{
    size_t i = 0;
    uint64_t t = t0;
    while (i < g_n) {
        // one whole message per call: header length field
        const uint32_t plen = ((uint32_t)g_buf[i + 18] << 24) | ((uint32_t)g_buf[i + 19] << 16) |
                              ((uint32_t)g_buf[i + 20] << 8) | g_buf[i + 21];
        const size_t k = 22U + plen;
        g_now = t;
        assert_int_equal(sl_pipeline_feed(&pl, g_buf + i, k, t), SL_OK);
        i += k;
        t += 625U;
    }
    g_now = t;
}

// ---------------------------------------------------------------------------------- tests

// Issue 14.1: a Configuration with 7 azimuths (or an encoder size the board does not have):
// every row is refused, and CAN says so: LinkState not STREAMING, CONFIG_MISMATCH and
// NO_USABLE_ROWS, no rotation counted. A matching Configuration recovers.
static void test_health_config_mismatch_is_a_fault_on_can(void **state)
{
    (void)state;
    const uint16_t bad[][2] = {{7, 5600}, {400, 5601}, {800, 5600}};
    for (size_t b = 0; b < sizeof bad / sizeof bad[0]; b++) {
        init();
        reset_stream();
        sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
        put_config(bad[b][0], bad[b][1], 438);
        put_rotations(3, 200);
        feed_paced(1000000U);
        assert_int_equal(sl_pipeline_send_status(&pl, g_now), SL_OK);
        sl_can_status_t st;
        sl_can_health_t h;
        last_status(&st, &h);
        assert_int_equal(st.link_state, SL_CAN_LINK_SILENT);
        assert_int_equal(st.rotations, 0);
        assert_true((h.fault & SL_CAN_FAULT_CONFIG_MISMATCH) != 0U);
        assert_true((h.fault & SL_CAN_FAULT_NO_USABLE_ROWS) != 0U);
        assert_int_equal(rec.rotations, 0);
        assert_true(pl.stats.rows_dropped >= 1200 || pl.scan.stats.bad_azimuth > 0);
        // The radar comes back with the board's geometry: rows flow, the fault clears.
        reset_stream();
        put_config(400, 5600, 438);
        put_rotations(3, 200);
        feed_paced(g_now + 1000U);
        assert_true(rec.rotations >= 2);
        assert_int_equal(sl_pipeline_send_status(&pl, g_now), SL_OK);
        last_status(&st, &h);
        assert_int_equal(st.link_state, SL_CAN_LINK_STREAMING);
        assert_int_equal(h.fault & (SL_CAN_FAULT_CONFIG_MISMATCH | SL_CAN_FAULT_NO_USABLE_ROWS), 0);
    }
}

// Issue 14.3 and 8: FFT messages that are all malformed (or have 0 bins, or encoder values
// out of range) keep the link from looking healthy, and their rotations count as missing.
static void test_health_unusable_fft_is_silent_malformed_and_missing(void **state)
{
    (void)state;
    for (int kind = 0; kind < 3; kind++) {
        init();
        reset_stream();
        sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
        put_config(400, 5600, 438);
        for (uint16_t a = 0; a < 800; a++) {
            const size_t at = g_n;
            put_fft(kind == 2 ? (uint16_t)(5600U + a) : (uint16_t)((a % 400U) * 14U), g_sweep++,
                    kind == 1 ? 0U : 64U);
            if (kind == 0) {
                g_buf[at + 22] = 0x00; // data_offset 5 (< 14): malformed
                g_buf[at + 23] = 0x05;
            }
        }
        feed_paced(1000000U);
        assert_int_equal(sl_pipeline_send_status(&pl, g_now), SL_OK);
        sl_can_status_t st;
        sl_can_health_t h;
        last_status(&st, &h);
        assert_int_equal(st.link_state, SL_CAN_LINK_SILENT);
        assert_int_equal(st.rotations, 0);
        assert_int_equal(st.azimuths_missing, 800); // two rotations' worth, seen by nobody
        assert_true((h.fault & SL_CAN_FAULT_NO_USABLE_ROWS) != 0U);
        assert_true((h.fault & SL_CAN_FAULT_MALFORMED_DATA) != 0U);
        assert_int_equal(pl.stats.azimuths, 0);
    }
}

// Issue 14.2: the Configuration's bin size differs from the board's by more than 1 %.
static void test_health_range_resolution_mismatch_is_flagged(void **state)
{
    (void)state;
    const struct {
        uint16_t bin_100um;
        bool flagged;
    } cases[] = {{596, true}, {438, false}, {442, false}, {443, true}, {434, false}, {433, true}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        init();
        reset_stream();
        sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
        put_config(400, 5600, cases[i].bin_100um);
        put_rotations(2, 200);
        feed_paced(1000000U);
        assert_int_equal(sl_pipeline_send_status(&pl, g_now), SL_OK);
        sl_can_status_t st;
        sl_can_health_t h;
        last_status(&st, &h);
        assert_int_equal((h.fault & SL_CAN_FAULT_RANGE_RESOLUTION_MISMATCH) != 0U, cases[i].flagged);
        assert_int_equal(pl.radar_bin_um, (uint32_t)cases[i].bin_100um * 100U);
    }
}

// Issue 14.2: ranges come from the radar's bin size. The same returns (a post occupying
// bins 50..56 on two azimuths) from a radar that says 0.0596 m bins and from one that says
// 0.0438 m: RangeInner on CAN is the bin index times the radar's bin size, not the board's.
static uint32_t pole_range_um(uint16_t bin_100um)
{
    init();
    reset_stream();
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
    put_config(400, 5600, bin_100um);
    static uint8_t row[256];
    for (int r = 0; r < 24; r++) {
        for (uint16_t a = 0; a < 400; a++) {
            memset(row, 10, sizeof row);
            if (a == 100 || a == 101) {
                memset(row + 50, 200, 7);
            }
            const uint64_t t = 1700000000ULL * 1000000ULL + (uint64_t)g_msg++ * 625U;
            const sl_proto_fft_t f = {.sweep_counter = g_sweep++, .azimuth_ticks = (uint16_t)(a * 14U),
                                      .seconds = (uint32_t)(t / 1000000U),
                                      .split_ns = (uint32_t)(t % 1000000U) * 1000U, .bins = 256};
            const sl_ssize_t k = sl_proto_encode_fft8(g_buf + g_n, sizeof g_buf - g_n, &f, row);
            assert_true(k > 0);
            g_n += (size_t)k;
        }
    }
    feed_paced(1000000U);
    uint32_t r1 = 0;
    for (int i = 0; i < rec.n; i++) {
        sl_can_pole_lean_t pole;
        if (rec.can[i].id == B->can_id_pole_lean && sl_can_decode_pole_lean(&rec.can[i], E2E(POLE_LEAN), &pole) == SL_OK) {
            r1 = pole.range_inner_um;
        }
    }
    return r1;
}

static void test_health_ranges_use_the_radars_bin_size(void **state)
{
    (void)state;
    const uint32_t r_board = pole_range_um(438);
    const uint32_t r_cir = pole_range_um(596);
    print_message("RangeInner: %u um with 0.0438 m bins, %u um with 0.0596 m bins\n", r_board, r_cir);
    assert_true(r_board > 0U && r_cir > 0U); // a target was sent in both cases
    // r1 = 50 bins (+ the half-bin and other corrections, < 2 bins) x the radar's bin size.
    assert_true(r_board >= 50U * 43800U && r_board <= 52U * 43800U);
    assert_true(r_cir >= 50U * 59600U && r_cir <= 52U * 59600U);
    assert_int_equal(pl.stats.bin_size_changes, 1);
    sl_can_status_t st;
    sl_can_health_t h;
    assert_int_equal(sl_pipeline_send_status(&pl, g_now), SL_OK);
    last_status(&st, &h);
    assert_true((h.fault & SL_CAN_FAULT_RANGE_RESOLUTION_MISMATCH) != 0U); // still flagged
}

// Issue 14.5: reconnects are counted on CAN (saturating) and flapping is a fault.
static void test_health_reconnects_counted_and_flapping_flagged(void **state)
{
    (void)state;
    init();
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_CONNECTING);
    sl_can_status_t st;
    sl_can_health_t h;
    uint64_t t = 1000000U;
    for (int i = 0; i < 7; i++) { // 7 reconnects in 14 s
        sl_pipeline_add_reconnect(&pl, t);
        t += 2000000U;
    }
    assert_int_equal(sl_pipeline_send_status(&pl, t), SL_OK);
    last_status(&st, &h);
    assert_int_equal(h.reconnects, 7);
    assert_true((h.fault & SL_CAN_FAULT_LINK_FLAPPING) != 0U);
    // Stable for longer than the window: no longer flapping; the total stays.
    t += (uint64_t)SL_CAN_FLAP_WINDOW_MS * 1000U + 1000U;
    assert_int_equal(sl_pipeline_send_status(&pl, t), SL_OK);
    last_status(&st, &h);
    assert_int_equal(h.reconnects, 7);
    assert_int_equal(h.fault & SL_CAN_FAULT_LINK_FLAPPING, 0);
    // Two reconnects far apart never flap; the counter saturates at 255 on the wire.
    for (int i = 0; i < 300; i++) {
        t += 60000000U;
        sl_pipeline_add_reconnect(&pl, t);
    }
    assert_int_equal(sl_pipeline_send_status(&pl, t), SL_OK);
    last_status(&st, &h);
    assert_int_equal(h.reconnects, 255);
    assert_int_equal(h.fault & SL_CAN_FAULT_LINK_FLAPPING, 0);
    assert_int_equal(pl.stats.reconnects, 307);
}

// Frames in any 100 ms window of the port clock.
static void assert_ceiling(void)
{
    int lo = 0;
    int data = 0, status = 0;
    for (int i = 0; i < rec.n; i++) {
        // slide: frames within [t_i - 99999, t_i]
        while (rec.t_us[lo] + 100000U <= rec.t_us[i]) {
            const bool st = rec.can[lo].id == B->can_id_status || rec.can[lo].id == B->can_id_health;
            status -= st ? 1 : 0;
            data -= st ? 0 : 1;
            lo++;
        }
        const bool st = rec.can[i].id == B->can_id_status || rec.can[i].id == B->can_id_health;
        status += st ? 1 : 0;
        data += st ? 0 : 1;
        // Token buckets: a full bucket plus one window's refill in any 100 ms span.
        assert_true(data <= (int)((SL_CAN_BURST_WINDOWS + 1U) * SL_CAN_MAX_DATA_FRAMES_PER_100MS));
        assert_true(status <= (int)((SL_CAN_BURST_WINDOWS + 1U) * SL_CAN_MAX_STATUS_FRAMES_PER_100MS));
    }
}

// Issue 14.7: shuffled azimuths at 1600 messages/s make about one rotation per pass (not
// one per step back), keep every row, raise AZIMUTH_DISORDER; the CAN rate stays bounded.
static void test_health_shuffled_azimuths_are_bounded_disorder(void **state)
{
    (void)state;
    init();
    reset_stream();
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
    put_config(400, 5600, 438);
    uint32_t x = 2463534242U;
    for (int r = 0; r < 20; r++) {
        uint16_t order[400];
        for (uint16_t i = 0; i < 400; i++) {
            order[i] = i;
        }
        for (uint16_t i = 399; i > 0; i--) {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            const uint16_t j = (uint16_t)(x % (i + 1U));
            const uint16_t t = order[i];
            order[i] = order[j];
            order[j] = t;
        }
        for (uint16_t i = 0; i < 400; i++) {
            put_fft((uint16_t)(order[i] * 14U), (uint16_t)(g_sweep + order[i]), 200);
        }
        g_sweep = (uint16_t)(g_sweep + 400U);
    }
    feed_paced(1000000U);
    sl_pipeline_finish(&pl, g_now);
    assert_true(rec.rotations >= 20 && rec.rotations <= 21);
    assert_int_equal(pl.stats.azimuths, 8000); // nothing valid lost
    assert_int_equal(pl.stats.azimuths_missing, 0);
    assert_true(pl.scan.stats.disorder > 1000);
    // 20 passes in 5 s: CAN frames per second stay at the rotation rate (4 Hz x 3 frames
    // without targets), nowhere near a third of the bus.
    assert_true(rec.n <= 21 * 4);
    int disorder = 0;
    for (int i = 0; i < rec.n; i++) {
        sl_can_health_t h;
        if (rec.can[i].id == B->can_id_health) {
            assert_int_equal(sl_can_decode_health(&rec.can[i], E2E(HEALTH), &h), SL_OK);
            disorder += (h.fault & SL_CAN_FAULT_AZIMUTH_DISORDER) != 0U ? 1 : 0;
        }
    }
    assert_true(disorder >= 19); // every rotation's Health after the first pass
    assert_ceiling();
}

// The hard ceiling holds whatever closes rotations: here every message jumps the sweep
// counter by a rotation (each one completes a rotation: 1600 rotations/s).
static void test_health_can_output_ceiling_holds_for_any_input(void **state)
{
    (void)state;
    init();
    reset_stream();
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
    put_config(400, 5600, 438);
    for (uint16_t i = 0; i < 3200; i++) {
        put_fft((uint16_t)((i % 400U) * 14U), (uint16_t)(i * 400U), 200);
    }
    feed_paced(1000000U);
    assert_true(rec.rotations >= 3000);
    assert_true(pl.stats.can_rate_limited > 0);
    assert_ceiling();
    // 2 s of input: at most the full buckets plus 20 windows' refill.
    assert_true(rec.n <= (int)((20U + SL_CAN_BURST_WINDOWS) *
                               (SL_CAN_MAX_DATA_FRAMES_PER_100MS + SL_CAN_MAX_STATUS_FRAMES_PER_100MS)));
    bool limited = false;
    for (int i = 0; i < rec.n; i++) {
        sl_can_health_t h;
        if (rec.can[i].id == B->can_id_health && sl_can_decode_health(&rec.can[i], E2E(HEALTH), &h) == SL_OK &&
            (h.fault & SL_CAN_FAULT_CAN_RATE_LIMITED) != 0U) {
            limited = true;
        }
    }
    assert_true(limited);
}

// A clean stream: STREAMING, no fault, Health after every Status with its own E2E sequence.
static void test_health_clean_stream_has_no_fault(void **state)
{
    (void)state;
    init();
    reset_stream();
    sl_pipeline_set_link_state(&pl, SL_CAN_LINK_STREAMING);
    put_config(400, 5600, 438);
    put_rotations(6, 200);
    feed_paced(1000000U);
    sl_can_e2e_rx_t rx;
    sl_can_e2e_rx_init(&rx, SL_CAN_COUNTER_MODULO - 1U);
    int healths = 0;
    for (int i = 0; i < rec.n; i++) {
        if (rec.can[i].id != B->can_id_health) {
            continue;
        }
        assert_int_equal(rec.can[i - 1].id, B->can_id_status);
        assert_true(e2e_accepted(sl_can_e2e_check(&rx, E2E(HEALTH), &rec.can[i])));
        sl_can_health_t h;
        assert_int_equal(sl_can_decode_health(&rec.can[i], E2E(HEALTH), &h), SL_OK);
        assert_int_equal(h.fault, 0);
        healths++;
    }
    assert_int_equal(healths, rec.rotations);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_OK_SOME_LOST], 0);
    // Silence after data: within the row timeout still STREAMING, after it SILENT + fault.
    assert_int_equal(sl_pipeline_send_status(&pl, g_now + 500000U), SL_OK);
    sl_can_status_t st;
    sl_can_health_t h;
    last_status(&st, &h);
    assert_int_equal(st.link_state, SL_CAN_LINK_STREAMING);
    assert_int_equal(h.fault, 0);
    assert_int_equal(sl_pipeline_send_status(&pl, g_now + 2000000U), SL_OK);
    last_status(&st, &h);
    assert_int_equal(st.link_state, SL_CAN_LINK_SILENT);
    assert_int_equal(h.fault, SL_CAN_FAULT_NO_USABLE_ROWS);
}

// Health encoder/decoder round trip and saturation (layout from the table the DBC prints).
static void test_health_frame_round_trip(void **state)
{
    (void)state;
    sl_can_ids_t ids;
    sl_can_ids_default(&ids);
    ids.id[SL_CAN_MSG_HEALTH] = 0x623U;
    sl_can_tx_t tx;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_OK);
    const sl_can_health_t in = {.fault = 0xFFFFU, .reconnects = 1000U, .candidates_dropped = 5000U};
    sl_can_frame_t f;
    assert_int_equal(sl_can_encode_health(&tx, &in, &f), SL_OK);
    assert_int_equal(f.id, 0x623U);
    assert_int_equal(f.dlc, 8);
    sl_can_health_t out;
    assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_OK);
    assert_int_equal(out.fault, SL_CAN_FAULT_DEFINED); // reserved bits are not sent
    assert_int_equal(out.reconnects, 255);
    assert_int_equal(out.candidates_dropped, 4095);
    assert_int_equal(f.data[1] & 0xF0U, 0); // reserved 12..15
    assert_int_equal(f.data[6] & 0xF0U, 0); // reserved 52..63
    assert_int_equal(f.data[7], 0);
    assert_int_equal(tx.stats.clamped_frames, 1);
    const sl_can_health_t one = {.fault = SL_CAN_FAULT_AZIMUTH_DISORDER, .reconnects = 3,
                                 .candidates_dropped = 17};
    assert_int_equal(sl_can_encode_health(&tx, &one, &f), SL_OK);
    // Fault 16|16, Reconnects 32|8, CandidatesDropped 40|12 (Intel).
    assert_int_equal(f.data[2], 0x40);
    assert_int_equal(f.data[3], 0x00);
    assert_int_equal(f.data[4], 3);
    assert_int_equal(f.data[5], 17);
    assert_int_equal(f.data[6] & 0x0FU, 0);
    assert_int_equal(out.counter, 0);
    assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_OK);
    assert_int_equal(out.counter, 1);
    f.data[3] ^= 1U; // corrupted: CRC
    assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_ERR_MALFORMED);
    const sl_can_message_desc_t *m = sl_can_layout(SL_CAN_MSG_HEALTH);
    assert_non_null(m);
    assert_string_equal(m->name, "Health");
    assert_int_equal(m->data_id, 0x55);
}

static int setup(void **state)
{
    (void)state;
    B = sl_board_find("paper-sim");
    return B == NULL ? -1 : 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_health_frame_round_trip),
        cmocka_unit_test(test_health_clean_stream_has_no_fault),
        cmocka_unit_test(test_health_config_mismatch_is_a_fault_on_can),
        cmocka_unit_test(test_health_unusable_fft_is_silent_malformed_and_missing),
        cmocka_unit_test(test_health_range_resolution_mismatch_is_flagged),
        cmocka_unit_test(test_health_ranges_use_the_radars_bin_size),
        cmocka_unit_test(test_health_reconnects_counted_and_flapping_flagged),
        cmocka_unit_test(test_health_shuffled_azimuths_are_bounded_disorder),
        cmocka_unit_test(test_health_can_output_ceiling_holds_for_any_input),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
