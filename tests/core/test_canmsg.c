// SPDX-License-Identifier: MIT
// Unit tests for sl_can.h: CRC, E2E, layout table, encoders/decoders, VehicleMotion rx.
// Byte-level expectations only (the suite also runs on big-endian s390x under qemu).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <string.h>

#include "shadowlean/sl_can.h"
#include "shadowlean/sl_config.h"
#include "shadowlean/sl_response.h"

/// The default E2E configuration of message SL_CAN_MSG_<m>.
#define E2E(m) (&sl_can_e2e_defaults[SL_CAN_MSG_##m])

#define ID_POLE SL_CAN_ID_DEFAULT_POLE_LEAN
#define ID_WARN SL_CAN_ID_DEFAULT_LEAN_WARNING
#define ID_STATUS SL_CAN_ID_DEFAULT_STATUS
#define ID_MOTION SL_CAN_ID_DEFAULT_VEHICLE_MOTION
#define ID_HEALTH SL_CAN_ID_DEFAULT_HEALTH
#define ID_TILT SL_CAN_ID_DEFAULT_POLE_TILT
#define ID_GPLANE SL_CAN_ID_DEFAULT_GROUND_PLANE
#define ID_GHAZARD SL_CAN_ID_DEFAULT_GROUND_HAZARD

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint32_t rnd32(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 16);
}
/// Uniform in [lo, hi] (hi - lo < 2^32).
static int64_t rnd_range(int64_t lo, int64_t hi)
{
    const uint64_t span = (uint64_t)(hi - lo) + 1U;
    return lo + (int64_t)((((uint64_t)rnd32() << 16) ^ rnd32()) % span);
}

static void tx_setup(sl_can_tx_t *tx)
{
    sl_can_ids_t ids;
    sl_can_ids_default(&ids);
    const uint32_t id[SL_CAN_MSG_COUNT] = {ID_POLE,   ID_WARN, ID_STATUS, ID_MOTION,
                                           ID_HEALTH, ID_TILT, ID_GPLANE, ID_GHAZARD};
    memcpy(ids.id, id, sizeof id);
    assert_int_equal(sl_can_tx_init(tx, &ids), SL_OK);
}

/// round(x / d), halves up, by a different route than the core (double-free integer math).
static int64_t ref_round(int64_t x, int64_t d)
{
    int64_t q = x / d, r = x % d;
    if (r < 0) {
        q -= 1;
        r += d;
    }
    return (2 * r >= d) ? q + 1 : q;
}

static int64_t clamp64(int64_t v, int64_t lo, int64_t hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static void test_canmsg_crc8_0x1d_gives_the_sae_j1850_and_gsm_a_check_values(void **state)
{
    (void)state;
    const uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    // SAE J1850 (start 0xFF, final XOR 0xFF) and the Profile 11 form (start 0x00, no XOR,
    // the catalogue's CRC-8/GSM-A): the same register, two conventions.
    assert_int_equal(sl_can_crc8_0x1d(0xFFU, check, sizeof check) ^ 0xFFU, 0x4B);
    assert_int_equal(sl_can_crc8_0x1d(0x00U, check, sizeof check), 0x37);
    assert_int_equal(sl_can_crc8_0x1d(0x5AU, NULL, 0), 0x5A);
    // AUTOSAR CRC library test vectors for CRC8 SAE J1850.
    const uint8_t v1[] = {0x00, 0x00, 0x00, 0x00};
    const uint8_t v2[] = {0xF2, 0x01, 0x83};
    const uint8_t v3[] = {0x0F, 0xAA, 0x00, 0x55};
    const uint8_t v4[] = {0xFF, 0xFF, 0xFF, 0xFF};
    assert_int_equal(sl_can_crc8_0x1d(0xFFU, v1, sizeof v1) ^ 0xFFU, 0x59);
    assert_int_equal(sl_can_crc8_0x1d(0xFFU, v2, sizeof v2) ^ 0xFFU, 0x37);
    assert_int_equal(sl_can_crc8_0x1d(0xFFU, v3, sizeof v3) ^ 0xFFU, 0x79);
    assert_int_equal(sl_can_crc8_0x1d(0xFFU, v4, sizeof v4) ^ 0xFFU, 0x74);
}

// AUTOSAR E2E Profile 11 vectors of two implementations that are not this one: the
// `autosar-e2e` Rust crate (src/profiles/profile11.rs, tests basic_both_example and
// basic_nibble_example) and the `autosar-e2e` Python package (zariiii9003/autosar-e2e,
// test/test_p01.py, modes BOTH and NIBBLE): 8 zero bytes, Data ID 0x123.
static void test_canmsg_e2e_crc_matches_independent_profile_11_vectors(void **state)
{
    (void)state;
    const sl_can_e2e_cfg_t both = {0x123U, SL_CAN_E2E_MODE_BOTH};
    const sl_can_e2e_cfg_t nibble = {0x123U, SL_CAN_E2E_MODE_NIBBLE};
    uint8_t d[8] = {0};
    assert_int_equal(sl_can_e2e_crc(&both, d), 0xCC); // counter 0
    d[1] = 0x01;
    assert_int_equal(sl_can_e2e_crc(&both, d), 0x91); // counter 1
    d[1] = 0x10; // Data ID bits 8..11 in the high nibble, counter 0
    assert_int_equal(sl_can_e2e_crc(&nibble, d), 0x2A);
    d[1] = 0x11;
    assert_int_equal(sl_can_e2e_crc(&nibble, d), 0x77);
    // The receiver accepts exactly those frames; the Python package's negative vectors
    // (a nibble of 2 instead of 1, a counter bit flipped under an 11A CRC) are errors.
    const uint8_t ok_both[2][8] = {{0xCC, 0x00}, {0x91, 0x01}};
    const uint8_t ok_nibble[2][8] = {{0x2A, 0x10}, {0x77, 0x11}};
    sl_can_e2e_rx_t rb, rn;
    sl_can_e2e_rx_init(&rb, 1U);
    sl_can_e2e_rx_init(&rn, 1U);
    sl_can_frame_t f = {.id = 0x123U, .dlc = 8U};
    for (unsigned k = 0; k < 2U; k++) {
        const sl_can_e2e_status_t want = (k == 0U) ? SL_CAN_E2E_INITIAL : SL_CAN_E2E_OK;
        memcpy(f.data, ok_both[k], 8U);
        assert_int_equal(sl_can_e2e_check(&rb, &both, &f), want);
        memcpy(f.data, ok_nibble[k], 8U);
        assert_int_equal(sl_can_e2e_check(&rn, &nibble, &f), want);
    }
    const uint8_t bad_both[8] = {0xCC, 0x10};
    const uint8_t bad_nibble[8] = {0x77, 0x21};
    memcpy(f.data, bad_both, 8U);
    assert_int_equal(sl_can_e2e_check(&rb, &both, &f), SL_CAN_E2E_ERROR);
    memcpy(f.data, bad_nibble, 8U);
    assert_int_equal(sl_can_e2e_check(&rn, &nibble, &f), SL_CAN_E2E_ERROR);
    assert_int_equal(rn.stats.crc_errors, 1); // the nibble is inside the CRC too
    // The encoder's 11C frame on Health (the only message with bits 12..15 free).
    sl_can_ids_t ids;
    sl_can_ids_default(&ids);
    ids.e2e[SL_CAN_MSG_HEALTH] = nibble;
    sl_can_tx_t tx;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_OK);
    const sl_can_health_t h = {0};
    assert_int_equal(sl_can_encode_health(&tx, &h, &f), SL_OK);
    const uint8_t want[8] = {0x2A, 0x10, 0, 0, 0, 0, 0, 0};
    assert_memory_equal(f.data, want, 8);
    sl_can_health_t back;
    assert_int_equal(sl_can_decode_health(&f, &nibble, &back), SL_OK);
    assert_int_equal(sl_can_decode_health(&f, &both, &back), SL_ERR_MALFORMED);
}

// Per-message vectors: 8 zero bytes but the counter (0, then 1), each message's default
// Data ID in 11A, and Health with paper-sim-29bit's Data ID 0x0355 in 11C. The CRC bytes
// come from tests/system/daemon/p11_frames.py (the AUTOSAR library chaining, pinned there
// to the published vectors); the Python suite and the dissector test assert the same table.
static void test_canmsg_e2e_crc_of_every_message_matches_its_vectors(void **state)
{
    (void)state;
    static const struct {
        sl_can_msg_t msg;
        uint8_t crc[2]; // counter 0, counter 1
    } v[] = {
        {SL_CAN_MSG_POLE_LEAN, {0x03, 0x5E}},      {SL_CAN_MSG_LEAN_WARNING, {0xAC, 0xF1}},
        {SL_CAN_MSG_STATUS, {0xC9, 0x94}},         {SL_CAN_MSG_VEHICLE_MOTION, {0xEF, 0xB2}},
        {SL_CAN_MSG_HEALTH, {0x8A, 0xD7}},         {SL_CAN_MSG_POLE_TILT, {0x25, 0x78}},
        {SL_CAN_MSG_GROUND_PLANE, {0x40, 0x1D}},   {SL_CAN_MSG_GROUND_HAZARD, {0x69, 0x34}},
    };
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        for (uint8_t c = 0; c < 2U; c++) {
            const uint8_t d[8] = {0, c, 0, 0, 0, 0, 0, 0};
            assert_int_equal(sl_can_e2e_crc(&sl_can_e2e_defaults[v[k].msg], d), v[k].crc[c]);
        }
    }
    const sl_can_e2e_cfg_t h11c = {0x0355U, SL_CAN_E2E_MODE_NIBBLE};
    const uint8_t d0[8] = {0, 0x30}, d1[8] = {0, 0x31};
    assert_int_equal(sl_can_e2e_crc(&h11c, d0), 0x5C);
    assert_int_equal(sl_can_e2e_crc(&h11c, d1), 0x01);
}

static void test_canmsg_tx_init_refuses_nibble_mode_over_signals_and_shared_data_ids(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    sl_can_ids_t ids;
    sl_can_ids_default(&ids);
    // PoleLean carries Quality and Clamped in bits 12..15: 11C would overwrite them.
    ids.e2e[SL_CAN_MSG_POLE_LEAN].mode = SL_CAN_E2E_MODE_NIBBLE;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
    sl_can_ids_default(&ids);
    ids.e2e[SL_CAN_MSG_HEALTH].mode = SL_CAN_E2E_MODE_NIBBLE;
    ids.e2e[SL_CAN_MSG_HEALTH].data_id = 0x1055U; // bits 12..15 cannot be sent
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
    ids.e2e[SL_CAN_MSG_HEALTH].data_id = 0x0F55U;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_OK);
    ids.e2e[SL_CAN_MSG_HEALTH].mode = 2U;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
    sl_can_ids_default(&ids);
    ids.e2e[SL_CAN_MSG_STATUS].data_id = ids.e2e[SL_CAN_MSG_HEALTH].data_id;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
}

static void test_canmsg_e2e_crc_mixes_both_data_id_bytes_first(void **state)
{
    (void)state;
    uint8_t d[8] = {0xEE, 0x31, 0x42, 0x53, 0x64, 0x75, 0x86, 0x97};
    const sl_can_e2e_cfg_t cfg = {0x1A51U, SL_CAN_E2E_MODE_BOTH};
    const uint8_t seq[9] = {0x51, 0x1A, 0x31, 0x42, 0x53, 0x64, 0x75, 0x86, 0x97};
    assert_int_equal(sl_can_e2e_crc(&cfg, d), sl_can_crc8_0x1d(0x00U, seq, 9));
    // Byte 0 (the CRC slot) is not part of the CRC.
    const uint8_t c = sl_can_e2e_crc(&cfg, d);
    d[0] = 0x00;
    assert_int_equal(sl_can_e2e_crc(&cfg, d), c);
    // Every other low byte, and every other high byte in 11A, gives another CRC for the
    // same bytes (the CRC register is a bijection of one input byte when the rest is fixed).
    for (unsigned b = 0; b < 256U; b++) {
        sl_can_e2e_cfg_t o = {(uint16_t)((cfg.data_id & 0xFF00U) | b), SL_CAN_E2E_MODE_BOTH};
        if (o.data_id != cfg.data_id) {
            assert_int_not_equal(sl_can_e2e_crc(&o, d), c);
        }
        o.data_id = (uint16_t)((b << 8) | (cfg.data_id & 0xFFU));
        if (o.data_id != cfg.data_id) {
            assert_int_not_equal(sl_can_e2e_crc(&o, d), c);
        }
    }
}

static void test_canmsg_crc_worked_example(void **state)
{
    (void)state;
    // The example of the sl_can.h header comment and the DBC: Status, Data ID 0x0053, 11A.
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_status_t st = {.link_state = SL_CAN_LINK_STREAMING, .rotations = 2};
    sl_can_frame_t f;
    assert_int_equal(sl_can_encode_status(&tx, &st, &f), SL_OK);
    const uint8_t want[8] = {0x93, 0x30, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00};
    assert_memory_equal(f.data, want, 8);
    assert_int_equal(f.id, ID_STATUS);
    assert_int_equal(f.dlc, 8);
    assert_int_equal(f.flags, 0);
}

static void test_canmsg_pole_lean_golden_bytes(void **state)
{
    (void)state;
    // Bytes computed independently (by hand from the layout table of sl_can.h):
    // Quality 4 @12, Clamped 0, TargetId 9 @16, Azimuth 123.4 deg = raw 617 @20,
    // Lean -12.3 deg = raw -123 (10-bit 0x385) @31, LeanSigma 1.4 deg = raw 7 @41,
    // RangeInner 2.46 m = raw 123 @46, RangeOuter 3.00 m = raw 150 @55, Counter 0.
    sl_can_tx_t tx;
    tx_setup(&tx);
    const sl_can_pole_lean_t in = {.target_id = 9, .quality = SL_CAN_QUALITY_FILTERED,
                                   .azimuth_cdeg = 12340, .range_inner_um = 2460000,
                                   .range_outer_um = 3000000, .lean_cdeg = -1230,
                                   .lean_sigma_cdeg = 140};
    sl_can_frame_t f;
    assert_int_equal(sl_can_encode_pole_lean(&tx, &in, &f), SL_OK);
    // value = 4<<12 | 9<<16 | 617<<20 | 0x385<<31 | 7<<41 | 123<<46 | 150<<55
    const uint64_t v = (4ull << 12) | (9ull << 16) | (617ull << 20) | (0x385ull << 31) |
                       (7ull << 41) | (123ull << 46) | (150ull << 55);
    uint8_t want[8];
    for (unsigned i = 0; i < 8; i++) {
        want[i] = (uint8_t)(v >> (8 * i));
    }
    want[0] = sl_can_e2e_crc(E2E(POLE_LEAN), want);
    assert_memory_equal(f.data, want, 8);
}

// PoleTilt: the layout fixed for the whole project (sl_can.h), a worked frame, round trips
// of random values against an independent rounding, clamping, and the non-fitted qualities.
static void test_canmsg_pole_tilt_layout_encode_decode(void **state)
{
    (void)state;
    const sl_can_message_desc_t *md = sl_can_layout(SL_CAN_MSG_POLE_TILT);
    assert_non_null(md);
    assert_string_equal(md->name, "PoleTilt");
    assert_int_equal(md->data_id, 0x56);
    static const struct {
        const char *name;
        unsigned start, len;
        bool sgn;
    } want[] = {{"Crc", 0, 8, false},         {"Counter", 8, 4, false},
                {"Quality", 12, 3, false},    {"Clamped", 15, 1, false},
                {"TargetId", 16, 4, false},   {"Tilt", 20, 8, false},
                {"TiltDirection", 28, 9, false}, {"TiltSigma", 37, 5, false},
                {"DirectionSigma", 42, 6, false}, {"BaseX", 48, 8, true},
                {"BaseY", 56, 8, true}};
    assert_int_equal(md->n_signals, sizeof want / sizeof want[0]);
    for (unsigned i = 0; i < md->n_signals; i++) {
        assert_string_equal(md->signals[i].name, want[i].name);
        assert_int_equal(md->signals[i].start, want[i].start);
        assert_int_equal(md->signals[i].length, want[i].len);
        assert_int_equal(md->signals[i].is_signed, want[i].sgn);
    }
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    // Worked frame: target 5, tilt 12.34 deg, direction 271.6 deg, sigmas 0.5 / 7 deg,
    // base (1.23, -2.51) m.
    sl_can_pole_tilt_t in = {.target_id = 5, .quality = SL_CAN_TILT_FITTED, .tilt_cdeg = 1234,
                             .direction_cdeg = 27160, .tilt_sigma_cdeg = 50,
                             .direction_sigma_cdeg = 700, .base_x_um = 1230000,
                             .base_y_um = -2510000};
    assert_int_equal(sl_can_encode_pole_tilt(&tx, &in, &f), SL_OK);
    assert_int_equal(f.id, ID_TILT);
    assert_int_equal(f.dlc, 8);
    sl_can_pole_tilt_t out;
    assert_int_equal(sl_can_decode_pole_tilt(&f, E2E(POLE_TILT), &out), SL_OK);
    assert_int_equal(out.quality, SL_CAN_TILT_FITTED);
    assert_int_equal(out.target_id, 5);
    assert_int_equal(out.tilt_cdeg, 1230);      // 123 x 0.1
    assert_int_equal(out.direction_cdeg, 27200); // 272 deg
    assert_int_equal(out.tilt_sigma_cdeg, 60);  // 50 / 20 = 2.5 -> 3 x 0.2 (halves up)
    assert_int_equal(out.direction_sigma_cdeg, 700);
    assert_int_equal(out.base_x_um, 1250000);   // 24.6 -> 25 x 0.05
    assert_int_equal(out.base_y_um, -2500000);  // -50.2 -> -50
    assert_false(out.clamped);
    assert_int_equal(f.data[0], sl_can_e2e_crc(E2E(POLE_TILT), f.data));
    // Random round trips against the reference rounding.
    for (int k = 0; k < 20000; k++) {
        in.target_id = (uint8_t)rnd_range(0, 15);
        const uint8_t with_values[3] = {SL_CAN_TILT_FITTED, SL_CAN_TILT_AMBIGUOUS,
                                        SL_CAN_TILT_MIRROR};
        in.quality = with_values[rnd_range(0, 2)];
        in.tilt_cdeg = (int32_t)rnd_range(0, 3000);
        in.direction_cdeg = (int32_t)rnd_range(-72000, 72000);
        in.tilt_sigma_cdeg = (uint32_t)rnd_range(0, 800);
        in.direction_sigma_cdeg = (uint32_t)rnd_range(0, 8000);
        in.base_x_um = (int32_t)rnd_range(-8000000, 8000000);
        in.base_y_um = (int32_t)rnd_range(-8000000, 8000000);
        assert_int_equal(sl_can_encode_pole_tilt(&tx, &in, &f), SL_OK);
        assert_int_equal(sl_can_decode_pole_tilt(&f, E2E(POLE_TILT), &out), SL_OK);
        bool cl = false;
        const int64_t tilt = ref_round(in.tilt_cdeg, 10);
        const int64_t sig = ref_round(in.tilt_sigma_cdeg, 20);
        const int64_t dsig = ref_round(in.direction_sigma_cdeg, 100);
        const int64_t bx = ref_round(in.base_x_um, 50000);
        const int64_t by = ref_round(in.base_y_um, 50000);
        cl = tilt > 255 || sig > 31 || dsig > 63 || bx > 127 || bx < -128 || by > 127 || by < -128;
        int64_t dir = ((int64_t)in.direction_cdeg % 36000 + 36000) % 36000;
        dir = ref_round(dir, 100) % 360;
        assert_int_equal(out.tilt_cdeg, clamp64(tilt, 0, 255) * 10);
        assert_int_equal(out.tilt_sigma_cdeg, clamp64(sig, 0, 31) * 20);
        assert_int_equal(out.direction_sigma_cdeg, clamp64(dsig, 0, 63) * 100);
        assert_int_equal(out.base_x_um, clamp64(bx, -128, 127) * 50000);
        assert_int_equal(out.base_y_um, clamp64(by, -128, 127) * 50000);
        assert_int_equal(out.direction_cdeg, dir * 100);
        assert_int_equal(out.clamped, cl);
        assert_int_equal(out.target_id, in.target_id);
        assert_int_equal(out.quality, in.quality);
    }
    // Qualities without numbers send zeros; an unknown quality is INCONSISTENT + Clamped.
    const uint8_t no_values[4] = {2, 3, 4, 6};
    for (size_t i = 0; i < 4U; i++) {
        const uint8_t q = no_values[i];
        in.quality = q;
        in.tilt_cdeg = 1000;
        in.base_x_um = 9000000; // would clamp if it were sent
        assert_int_equal(sl_can_encode_pole_tilt(&tx, &in, &f), SL_OK);
        assert_int_equal(sl_can_decode_pole_tilt(&f, E2E(POLE_TILT), &out), SL_OK);
        assert_int_equal(out.quality, q > SL_CAN_TILT_QUALITY_MAX ? SL_CAN_TILT_INCONSISTENT : q);
        assert_int_equal(out.tilt_cdeg, 0);
        assert_int_equal(out.base_x_um, 0);
        assert_int_equal(out.direction_cdeg, 0);
        assert_int_equal(out.clamped, q > SL_CAN_TILT_QUALITY_MAX);
    }
    // Another message's frame fails the CRC (Data ID 0x56 is PoleTilt's own).
    in.quality = 0;
    assert_int_equal(sl_can_encode_pole_tilt(&tx, &in, &f), SL_OK);
    sl_can_pole_lean_t pl;
    assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &pl), SL_ERR_MALFORMED);
    assert_int_equal(sl_can_encode_pole_tilt(NULL, &in, &f), SL_ERR_ARG);
    assert_int_equal(sl_can_decode_pole_tilt(NULL, E2E(POLE_TILT), &out), SL_ERR_ARG);
}

#if SL_CFG_GROUND
// GroundPlane bytes computed independently (tests/system/daemon/p11_frames.py packing the
// fields by hand): GOOD, 2.58 m, pitch 1.5 deg, roll -1.0 deg, sigmas 10 mm, 0.2 and
// 0.25 deg; counter 0 (Data ID 0x0057).
static void test_canmsg_ground_plane_golden_bytes_and_round_trip(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    const sl_can_ground_plane_t in = {
        .quality = SL_CAN_GROUND_GOOD, .height_mm = 2580, .pitch_cdeg = 150, .roll_cdeg = -100,
        .height_sigma_mm = 10U, .pitch_sigma_cdeg = 20U, .roll_sigma_cdeg = 25U,
    };
    sl_can_frame_t f;
    assert_int_equal(sl_can_encode_ground_plane(&tx, &in, &f), SL_OK);
    const uint8_t want[8] = {0x1B, 0x20, 0x85, 0x5A, 0x82, 0xF3, 0x05, 0x29};
    assert_int_equal(f.id, ID_GPLANE);
    assert_int_equal(f.dlc, 8);
    assert_int_equal(f.flags, 0);
    assert_memory_equal(f.data, want, 8);
    sl_can_ground_plane_t out;
    assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &out), SL_OK);
    assert_int_equal(out.quality, SL_CAN_GROUND_GOOD);
    assert_int_equal(out.height_mm, 2580);
    assert_int_equal(out.pitch_cdeg, 150);
    assert_int_equal(out.roll_cdeg, -100);
    assert_int_equal(out.height_sigma_mm, 10);
    assert_int_equal(out.pitch_sigma_cdeg, 20);
    assert_int_equal(out.roll_sigma_cdeg, 25);
    assert_false(out.clamped);
    assert_int_equal(out.counter, 0);
    // Every raw value of every field survives encode -> decode (the fields side by side).
    for (int32_t r = -1024; r <= 4095; r++) {
        const sl_can_ground_plane_t v = {
            .quality = (uint8_t)(1U + (uint32_t)(r & 1)),
            .height_mm = (r < 0 ? -r : r) * SL_CAN_GROUND_HEIGHT_MM_PER_LSB,
            .pitch_cdeg = (r % 1024) * SL_CAN_GROUND_ANGLE_CDEG_PER_LSB,
            .roll_cdeg = -(r % 1024) * SL_CAN_GROUND_ANGLE_CDEG_PER_LSB,
            .height_sigma_mm = (uint32_t)((r & 31) * SL_CAN_GROUND_HSIGMA_MM_PER_LSB),
            .pitch_sigma_cdeg = (uint32_t)(((r >> 5) & 31) * SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB),
            .roll_sigma_cdeg = (uint32_t)((31 - (r & 31)) * SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB),
        };
        assert_int_equal(sl_can_encode_ground_plane(&tx, &v, &f), SL_OK);
        assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &out), SL_OK);
        assert_int_equal(out.quality, v.quality);
        assert_int_equal(out.height_mm, v.height_mm);
        assert_int_equal(out.pitch_cdeg, v.pitch_cdeg);
        assert_int_equal(out.roll_cdeg, v.roll_cdeg);
        assert_int_equal(out.height_sigma_mm, v.height_sigma_mm);
        assert_int_equal(out.pitch_sigma_cdeg, v.pitch_sigma_cdeg);
        assert_int_equal(out.roll_sigma_cdeg, v.roll_sigma_cdeg);
        assert_false(out.clamped);
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
}

// Random physical values come back within half a step, rounded half up once; values out
// of range are clamped to the limit and flagged, never wrapped.
static void test_canmsg_ground_plane_rounds_once_and_saturates(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_ground_plane_t out;
    for (unsigned i = 0; i < 20000U; i++) {
        const sl_can_ground_plane_t v = {
            .quality = SL_CAN_GROUND_COARSE,
            .height_mm = (int32_t)rnd_range(-100, 9000),
            .pitch_cdeg = (int32_t)rnd_range(-2500, 2500),
            .roll_cdeg = (int32_t)rnd_range(-2500, 2500),
            .height_sigma_mm = (uint32_t)rnd_range(0, 200),
            .pitch_sigma_cdeg = (uint32_t)rnd_range(0, 200),
            .roll_sigma_cdeg = (uint32_t)rnd_range(0, 200),
        };
        assert_int_equal(sl_can_encode_ground_plane(&tx, &v, &f), SL_OK);
        assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &out), SL_OK);
        const int64_t h = clamp64(ref_round(v.height_mm, 2), 0, 4095);
        const int64_t p = clamp64(ref_round(v.pitch_cdeg, 2), -1024, 1023);
        const int64_t r = clamp64(ref_round(v.roll_cdeg, 2), -1024, 1023);
        const int64_t hs = clamp64(ref_round(v.height_sigma_mm, 5), 0, 31);
        const int64_t ps = clamp64(ref_round(v.pitch_sigma_cdeg, 5), 0, 31);
        const int64_t rs = clamp64(ref_round(v.roll_sigma_cdeg, 5), 0, 31);
        assert_int_equal(out.height_mm, h * 2);
        assert_int_equal(out.pitch_cdeg, p * 2);
        assert_int_equal(out.roll_cdeg, r * 2);
        assert_int_equal(out.height_sigma_mm, hs * 5);
        assert_int_equal(out.pitch_sigma_cdeg, ps * 5);
        assert_int_equal(out.roll_sigma_cdeg, rs * 5);
        const bool cl = h != ref_round(v.height_mm, 2) || p != ref_round(v.pitch_cdeg, 2) ||
                        r != ref_round(v.roll_cdeg, 2) || hs != ref_round(v.height_sigma_mm, 5) ||
                        ps != ref_round(v.pitch_sigma_cdeg, 5) ||
                        rs != ref_round(v.roll_sigma_cdeg, 5);
        assert_int_equal(out.clamped, cl);
    }
    // Halves round up (towards +infinity): 2.581 m -> 2.582 m, -0.01 deg -> 0, -0.03 -> -0.02.
    sl_can_ground_plane_t v = {.quality = SL_CAN_GROUND_GOOD, .height_mm = 2581,
                               .pitch_cdeg = -1, .roll_cdeg = -3};
    assert_int_equal(sl_can_encode_ground_plane(&tx, &v, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &out), SL_OK);
    assert_int_equal(out.height_mm, 2582);
    assert_int_equal(out.pitch_cdeg, 0);
    assert_int_equal(out.roll_cdeg, -2);
    // Saturation at every limit.
    const uint32_t before = tx.stats.clamped_frames;
    v = (sl_can_ground_plane_t){.quality = SL_CAN_GROUND_COARSE, .height_mm = INT32_MAX,
                                .pitch_cdeg = INT32_MIN, .roll_cdeg = INT32_MAX,
                                .height_sigma_mm = UINT32_MAX, .pitch_sigma_cdeg = 156U,
                                .roll_sigma_cdeg = 1000U};
    assert_int_equal(sl_can_encode_ground_plane(&tx, &v, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &out), SL_OK);
    assert_true(out.clamped);
    assert_int_equal(out.height_mm, 8190);
    assert_int_equal(out.pitch_cdeg, -2048);
    assert_int_equal(out.roll_cdeg, 2046);
    assert_int_equal(out.height_sigma_mm, 155);
    assert_int_equal(out.pitch_sigma_cdeg, 155);
    assert_int_equal(out.roll_sigma_cdeg, 155);
    assert_int_equal(tx.stats.clamped_frames, before + 1U);
    v.height_mm = -2; // below the radar: clamped to 0, flagged (-1 mm rounds to 0)
    v.pitch_cdeg = 0;
    v.roll_cdeg = 0;
    v.height_sigma_mm = v.pitch_sigma_cdeg = v.roll_sigma_cdeg = 0U;
    assert_int_equal(sl_can_encode_ground_plane(&tx, &v, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &out), SL_OK);
    assert_true(out.clamped);
    assert_int_equal(out.height_mm, 0);
    // NONE carries no numbers; an unknown quality is sent as NONE with Clamped set.
    const uint8_t qs[] = {SL_CAN_GROUND_NONE, 3U, 200U};
    for (size_t i = 0; i < sizeof qs; i++) {
        v = (sl_can_ground_plane_t){.quality = qs[i], .height_mm = 2580, .pitch_cdeg = 9999,
                                    .roll_sigma_cdeg = 30U};
        assert_int_equal(sl_can_encode_ground_plane(&tx, &v, &f), SL_OK);
        assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &out), SL_OK);
        assert_int_equal(out.quality, SL_CAN_GROUND_NONE);
        assert_int_equal(out.clamped, qs[i] != SL_CAN_GROUND_NONE);
        assert_int_equal(out.height_mm, 0);
        assert_int_equal(out.pitch_cdeg, 0);
        assert_int_equal(out.roll_sigma_cdeg, 0);
        assert_int_equal(f.data[2] | f.data[3] | f.data[4] | f.data[5] | f.data[6] | f.data[7], 0);
    }
    assert_int_equal(sl_can_encode_ground_plane(NULL, &v, &f), SL_ERR_ARG);
    assert_int_equal(sl_can_encode_ground_plane(&tx, NULL, &f), SL_ERR_ARG);
    assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), NULL), SL_ERR_ARG);
}

// GroundHazard bytes computed independently (p11_frames.py): DROP in sector 3 at 33.75 deg
// (rounded half up to 33.8), 0.2 m lower, 3.4567 m away, sigma 30 mm; counter 0.
static void test_canmsg_ground_hazard_golden_bytes_and_round_trip(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    const sl_can_ground_hazard_t in = {
        .kind = SL_CAN_GROUND_DROP, .sector = 3U, .azimuth_cdeg = 3375, .height_diff_mm = -200,
        .distance_um = 3456700U, .sigma_mm = 30U,
    };
    sl_can_frame_t f;
    assert_int_equal(sl_can_encode_ground_hazard(&tx, &in, &f), SL_OK);
    const uint8_t want[8] = {0xEB, 0x10, 0x83, 0x54, 0x60, 0x5F, 0x2B, 0x06};
    assert_int_equal(f.id, ID_GHAZARD);
    assert_memory_equal(f.data, want, 8);
    sl_can_ground_hazard_t out;
    assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
    assert_int_equal(out.kind, SL_CAN_GROUND_DROP);
    assert_int_equal(out.sector, 3);
    assert_int_equal(out.azimuth_cdeg, 3380);
    assert_int_equal(out.height_diff_mm, -200);
    assert_int_equal(out.distance_um, 3460000U);
    assert_int_equal(out.sigma_mm, 30);
    assert_false(out.clamped);
    // Every raw value of every field survives encode -> decode.
    for (int32_t r = -1024; r <= 3599; r++) {
        const uint32_t u = (uint32_t)(r + 1024);
        const sl_can_ground_hazard_t v = {
            .kind = (uint8_t)(1U + (u & 1U)),
            .sector = (uint8_t)(u & 63U),
            .azimuth_cdeg = (r < 0 ? -r : r) * SL_CAN_HAZARD_AZIMUTH_CDEG_PER_LSB,
            .height_diff_mm = (r % 1024) * SL_CAN_HAZARD_DIFF_MM_PER_LSB,
            .distance_um = (u % 2048U) * (uint32_t)SL_CAN_HAZARD_DIST_UM_PER_LSB,
            .sigma_mm = (u % 256U) * SL_CAN_HAZARD_SIGMA_MM_PER_LSB,
        };
        assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
        assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
        assert_int_equal(out.kind, v.kind);
        assert_int_equal(out.sector, v.sector);
        assert_int_equal(out.azimuth_cdeg, v.azimuth_cdeg);
        assert_int_equal(out.height_diff_mm, v.height_diff_mm);
        assert_int_equal(out.distance_um, v.distance_um);
        assert_int_equal(out.sigma_mm, v.sigma_mm);
        assert_false(out.clamped);
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
    // A GroundPlane frame is not a GroundHazard (Data ID in the CRC), nor a short frame.
    const sl_can_ground_plane_t pl = {.quality = SL_CAN_GROUND_GOOD, .height_mm = 2000};
    assert_int_equal(sl_can_encode_ground_plane(&tx, &pl, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_ERR_MALFORMED);
    sl_can_ground_plane_t pout;
    assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &pout), SL_OK);
    f.dlc = 7U;
    assert_int_equal(sl_can_decode_ground_plane(&f, E2E(GROUND_PLANE), &pout), SL_ERR_MALFORMED);
}

static void test_canmsg_ground_hazard_rounds_once_and_saturates(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_ground_hazard_t out;
    // Distances are rounded once, from um: 12.344999 m -> 12.34 m, 12.345 m -> 12.35 m.
    sl_can_ground_hazard_t v = {.kind = SL_CAN_GROUND_STEP, .sector = 9U, .distance_um = 12344999U};
    assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
    assert_int_equal(out.distance_um, 12340000U);
    v.distance_um = 12345000U;
    assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
    assert_int_equal(out.distance_um, 12350000U);
    assert_false(out.clamped);
    // Azimuths are reduced modulo a turn (not clamped): 360.1 deg is 0.1, -0.5 deg is 359.5,
    // 359.96 deg rounds to 0.
    const int32_t az[][2] = {{36010, 10}, {-50, 35950}, {35996, 0}, {72000 + 1234, 1230}};
    for (size_t i = 0; i < sizeof az / sizeof az[0]; i++) {
        v.azimuth_cdeg = az[i][0];
        assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
        assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
        assert_int_equal(out.azimuth_cdeg, az[i][1]);
        assert_false(out.clamped);
    }
    // Limits: sector 64 -> 63, the height difference beyond +-5.12 m, 20.47 m, 1.275 m.
    const uint32_t before = tx.stats.clamped_frames;
    v = (sl_can_ground_hazard_t){.kind = SL_CAN_GROUND_DROP, .sector = 64U,
                                 .height_diff_mm = -6000, .distance_um = UINT32_MAX,
                                 .sigma_mm = 2000U};
    assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
    assert_true(out.clamped);
    assert_int_equal(out.sector, 63);
    assert_int_equal(out.height_diff_mm, -5120);
    assert_int_equal(out.distance_um, 20470000U);
    assert_int_equal(out.sigma_mm, 1275);
    v = (sl_can_ground_hazard_t){.kind = SL_CAN_GROUND_STEP, .sector = 1U, .height_diff_mm = INT32_MAX};
    assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
    assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
    assert_true(out.clamped);
    assert_int_equal(out.height_diff_mm, 5115);
    assert_int_equal(out.sector, 1);
    assert_int_equal(tx.stats.clamped_frames, before + 2U);
    // FLAT carries no numbers; an unknown kind is sent as FLAT with Clamped set.
    const uint8_t ks[] = {SL_CAN_GROUND_FLAT, 3U, 255U};
    for (size_t i = 0; i < sizeof ks; i++) {
        v = (sl_can_ground_hazard_t){.kind = ks[i], .sector = 5U, .azimuth_cdeg = 9000,
                                     .height_diff_mm = -300, .distance_um = 4000000U,
                                     .sigma_mm = 20U};
        assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
        assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
        assert_int_equal(out.kind, SL_CAN_GROUND_FLAT);
        assert_int_equal(out.clamped, ks[i] != SL_CAN_GROUND_FLAT);
        assert_int_equal(out.sector, 0);
        assert_int_equal(out.azimuth_cdeg, 0);
        assert_int_equal(out.height_diff_mm, 0);
        assert_int_equal(out.distance_um, 0U);
        assert_int_equal(f.data[2] | f.data[3] | f.data[4] | f.data[5] | f.data[6] | f.data[7], 0);
    }
    // Bit 15 is reserved: never set.
    for (unsigned i = 0; i < 2000U; i++) {
        v = (sl_can_ground_hazard_t){.kind = (uint8_t)rnd_range(0, 4), .sector = (uint8_t)rnd32(),
                                     .azimuth_cdeg = (int32_t)rnd32(),
                                     .height_diff_mm = (int32_t)rnd32(),
                                     .distance_um = rnd32(), .sigma_mm = rnd32()};
        assert_int_equal(sl_can_encode_ground_hazard(&tx, &v, &f), SL_OK);
        assert_int_equal(f.data[1] & 0x80U, 0);
        assert_int_equal(sl_can_decode_ground_hazard(&f, E2E(GROUND_HAZARD), &out), SL_OK);
    }
    assert_int_equal(sl_can_encode_ground_hazard(&tx, NULL, &f), SL_ERR_ARG);
    assert_int_equal(sl_can_decode_ground_hazard(NULL, E2E(GROUND_HAZARD), &out), SL_ERR_ARG);
}
#endif // SL_CFG_GROUND

static void test_canmsg_layout_table_is_consistent(void **state)
{
    (void)state;
    for (unsigned m = 0; m < SL_CAN_MSG_COUNT; m++) {
        const sl_can_message_desc_t *md = sl_can_layout((sl_can_msg_t)m);
        assert_non_null(md);
        uint64_t used = 0;
        assert_string_equal(md->signals[0].name, "Crc");
        assert_int_equal(md->signals[0].start, 0);
        assert_int_equal(md->signals[0].length, 8);
        assert_string_equal(md->signals[1].name, "Counter");
        assert_int_equal(md->signals[1].start, 8);
        assert_int_equal(md->signals[1].length, 4);
        for (unsigned i = 0; i < md->n_signals; i++) {
            const sl_can_signal_desc_t *s = &md->signals[i];
            assert_true(s->length >= 1 && s->start + s->length <= 64);
            const uint64_t mask = ((s->length == 64) ? ~0ull : ((1ull << s->length) - 1U))
                                  << s->start;
            assert_int_equal(used & mask, 0); // no overlap
            used |= mask;
            // raw limits fit the field
            if (s->is_signed) {
                assert_true(s->raw_min >= -(1 << (s->length - 1)));
                assert_true(s->raw_max <= (1 << (s->length - 1)) - 1);
            } else {
                assert_true(s->raw_min >= 0);
                assert_true((uint64_t)s->raw_max <= (1ull << s->length) - 1U);
            }
            assert_true(s->factor_num > 0 && s->factor_den > 0);
            for (unsigned k = 0; k < s->n_values; k++) {
                assert_true((int64_t)s->values[k].value <= s->raw_max);
            }
        }
    }
    assert_null(sl_can_layout(SL_CAN_MSG_COUNT));
    // The DBC factors (physical per LSB) are the documented ones.
    struct {
        sl_can_msg_t m;
        const char *sig;
        int32_t num, den; // expected factor num/den, compared as fractions
    } want[] = {
        {SL_CAN_MSG_POLE_LEAN, "Azimuth", 1, 5},      {SL_CAN_MSG_POLE_LEAN, "Lean", 1, 10},
        {SL_CAN_MSG_POLE_LEAN, "LeanSigma", 1, 5},    {SL_CAN_MSG_POLE_LEAN, "RangeInner", 1, 50},
        {SL_CAN_MSG_POLE_LEAN, "RangeOuter", 1, 50},  {SL_CAN_MSG_LEAN_WARNING, "Azimuth", 1, 10},
        {SL_CAN_MSG_LEAN_WARNING, "Lean", 1, 20},     {SL_CAN_MSG_LEAN_WARNING, "Range", 1, 100},
        {SL_CAN_MSG_LEAN_WARNING, "LeanSigma", 1, 10}, {SL_CAN_MSG_VEHICLE_MOTION, "Speed", 1, 100},
        {SL_CAN_MSG_VEHICLE_MOTION, "YawRate", 1, 100},
        {SL_CAN_MSG_GROUND_PLANE, "Height", 1, 500},  {SL_CAN_MSG_GROUND_PLANE, "Pitch", 1, 50},
        {SL_CAN_MSG_GROUND_PLANE, "Roll", 1, 50},     {SL_CAN_MSG_GROUND_PLANE, "HeightSigma", 1, 200},
        {SL_CAN_MSG_GROUND_PLANE, "PitchSigma", 1, 20}, {SL_CAN_MSG_GROUND_PLANE, "RollSigma", 1, 20},
        {SL_CAN_MSG_GROUND_HAZARD, "Azimuth", 1, 10}, {SL_CAN_MSG_GROUND_HAZARD, "HeightDiff", 1, 200},
        {SL_CAN_MSG_GROUND_HAZARD, "Distance", 1, 100}, {SL_CAN_MSG_GROUND_HAZARD, "Sigma", 1, 200},
    };
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++) {
        const sl_can_message_desc_t *md = sl_can_layout(want[k].m);
        bool found = false;
        for (unsigned i = 0; i < md->n_signals; i++) {
            const sl_can_signal_desc_t *s = &md->signals[i];
            if (strcmp(s->name, want[k].sig) == 0) {
                assert_int_equal(s->factor_num * want[k].den, s->factor_den * want[k].num);
                found = true;
            }
        }
        assert_true(found);
    }
}

static void test_canmsg_pole_lean_round_trips_every_raw_value(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_pole_lean_t out;
    // Each signal exhaustively over its raw range (others random in range).
    for (int32_t raw = -600; raw <= 2100; raw++) {
        sl_can_pole_lean_t in = {
            .target_id = (uint8_t)((raw + 600) % 16),
            .quality = (uint8_t)((raw + 600) % 5),
            .azimuth_cdeg = (int32_t)(clamp64(raw, 0, SL_CAN_POLE_AZIMUTH_RAW_MAX) * 20),
            .lean_cdeg = (int32_t)(clamp64(raw, -512, 511) * 10),
            .lean_sigma_cdeg = (uint32_t)(clamp64(raw, 0, 31) * 20),
            .range_inner_um = (uint32_t)(clamp64(raw, 0, 511) * 20000),
            .range_outer_um = (uint32_t)(clamp64(2100 - raw, 0, 511) * 20000),
        };
        assert_int_equal(sl_can_encode_pole_lean(&tx, &in, &f), SL_OK);
        assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &out), SL_OK);
        assert_int_equal(out.target_id, in.target_id);
        assert_int_equal(out.quality, in.quality);
        assert_int_equal(out.azimuth_cdeg, in.azimuth_cdeg);
        assert_int_equal(out.lean_cdeg, in.lean_cdeg);
        assert_int_equal(out.lean_sigma_cdeg, in.lean_sigma_cdeg);
        assert_int_equal(out.range_inner_um, in.range_inner_um);
        assert_int_equal(out.range_outer_um, in.range_outer_um);
        assert_false(out.clamped);
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
}

static void test_canmsg_pole_lean_random_values_within_half_lsb(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_pole_lean_t out;
    for (int i = 0; i < 200000; i++) {
        sl_can_pole_lean_t in = {
            .target_id = (uint8_t)rnd_range(0, 15),
            .quality = (uint8_t)rnd_range(0, 4),
            .azimuth_cdeg = (int32_t)rnd_range(-100000, 100000),
            .lean_cdeg = (int32_t)rnd_range(-5125, 5114),
            .lean_sigma_cdeg = (uint32_t)rnd_range(0, 629),
            .range_inner_um = (uint32_t)rnd_range(0, 10229999),
            .range_outer_um = (uint32_t)rnd_range(0, 10229999),
        };
        assert_int_equal(sl_can_encode_pole_lean(&tx, &in, &f), SL_OK);
        assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &out), SL_OK);
        assert_false(out.clamped);
        assert_int_equal(out.lean_cdeg, ref_round(in.lean_cdeg, 10) * 10);
        assert_true(out.lean_cdeg - in.lean_cdeg <= 5 && in.lean_cdeg - out.lean_cdeg <= 5);
        assert_int_equal(out.lean_sigma_cdeg, ref_round(in.lean_sigma_cdeg, 20) * 20);
        assert_int_equal(out.range_inner_um, ref_round(in.range_inner_um, 20000) * 20000);
        assert_int_equal(out.range_outer_um, ref_round(in.range_outer_um, 20000) * 20000);
        int64_t az = in.azimuth_cdeg % 36000;
        az += (az < 0) ? 36000 : 0;
        assert_int_equal(out.azimuth_cdeg, (ref_round(az, 20) % 1800) * 20);
    }
}

static void test_canmsg_ranges_are_rounded_once_from_um(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    // r1 = 2.6499 m: once to 0.02 m is 132.495 -> 132 = 2.64 m (rounding to mm first gave
    // 2650 mm = 132.5 -> 133 = 2.66 m). r2 = 2.6501 m -> 132.505 -> 133 = 2.66 m.
    const sl_can_pole_lean_t p = {.range_inner_um = 2649900, .range_outer_um = 2650100};
    assert_int_equal(sl_can_encode_pole_lean(&tx, &p, &f), SL_OK);
    sl_can_pole_lean_t po;
    assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &po), SL_OK);
    assert_int_equal(po.range_inner_um, 2640000);
    assert_int_equal(po.range_outer_um, 2660000);
    // Exact half (2.65 m = 132.5 LSB) rounds up, as every signal does.
    const sl_can_pole_lean_t half = {.range_inner_um = 2650000, .range_outer_um = 2669999};
    assert_int_equal(sl_can_encode_pole_lean(&tx, &half, &f), SL_OK);
    assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &po), SL_OK);
    assert_int_equal(po.range_inner_um, 2660000);
    assert_int_equal(po.range_outer_um, 2660000);
    // LeanWarning.Range (0.01 m): 2.6449 m -> 264.49 -> 2.64 m (via mm: 2645 -> 2.65 m).
    const sl_can_lean_warning_t w = {.has_target = true, .range_um = 2644900};
    assert_int_equal(sl_can_encode_lean_warning(&tx, &w, &f), SL_OK);
    sl_can_lean_warning_t wo;
    assert_int_equal(sl_can_decode_lean_warning(&f, E2E(LEAN_WARNING), &wo), SL_OK);
    assert_int_equal(wo.range_um, 2640000);
    assert_false(wo.clamped);
    // Within half an LSB of the um input everywhere (the whole RangeInner range, 1 um steps
    // near each rounding edge).
    for (uint32_t raw = 0; raw < 511U; raw++) {
        for (uint32_t d = 9990; d <= 10010; d++) {
            const sl_can_pole_lean_t q = {.range_inner_um = raw * 20000U + d};
            assert_int_equal(sl_can_encode_pole_lean(&tx, &q, &f), SL_OK);
            assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &po), SL_OK);
            assert_int_equal(po.range_inner_um, (raw + (d >= 10000U ? 1U : 0U)) * 20000U);
        }
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
}

static void test_canmsg_clamps_and_flags_out_of_range_values(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_pole_lean_t out;
    struct {
        int32_t lean;
        uint32_t sigma, r1, r2;
        uint8_t id, quality;
        int32_t want_lean;
        uint32_t want_sigma, want_r1, want_r2;
        uint8_t want_id, want_q;
        bool clamped;
    } cases[] = {
        // lean: 51.14 rounds to 51.1 (in range); 51.15 rounds to 51.2: clamped to 51.1
        {5114, 0, 0, 0, 0, 0, 5110, 0, 0, 0, 0, 0, false},
        {5115, 0, 0, 0, 0, 0, 5110, 0, 0, 0, 0, 0, true},
        {9000, 0, 0, 0, 0, 0, 5110, 0, 0, 0, 0, 0, true},
        {INT32_MAX, 0, 0, 0, 0, 0, 5110, 0, 0, 0, 0, 0, true},
        // -51.25 rounds half up to -51.2 (in range); -51.26 -> -51.3: clamped to -51.2
        {-5125, 0, 0, 0, 0, 0, -5120, 0, 0, 0, 0, 0, false},
        {-5126, 0, 0, 0, 0, 0, -5120, 0, 0, 0, 0, 0, true},
        {INT32_MIN, 0, 0, 0, 0, 0, -5120, 0, 0, 0, 0, 0, true},
        // sigma max 6.2 deg
        {0, 629, 0, 0, 0, 0, 0, 620, 0, 0, 0, 0, false},
        {0, 630, 0, 0, 0, 0, 0, 620, 0, 0, 0, 0, true},
        {0, UINT32_MAX, 0, 0, 0, 0, 0, 620, 0, 0, 0, 0, true},
        // ranges (um) max 10.22 m: 10.229999 m rounds to 10.22 m, 10.23 m to 10.24: clamped
        {0, 0, 10229999, 10229999, 0, 0, 0, 0, 10220000, 10220000, 0, 0, false},
        {0, 0, 10230000, 5, 0, 0, 0, 0, 10220000, 0, 0, 0, true},
        {0, 0, 5, UINT32_MAX, 0, 0, 0, 0, 0, 10220000, 0, 0, true},
        // ids and enums
        {0, 0, 0, 0, 15, 4, 0, 0, 0, 0, 15, 4, false},
        {0, 0, 0, 0, 16, 0, 0, 0, 0, 0, 15, 0, true},
        {0, 0, 0, 0, 255, 5, 0, 0, 0, 0, 15, SL_CAN_QUALITY_INVALID, true},
        {0, 0, 0, 0, 1, 200, 0, 0, 0, 0, 1, SL_CAN_QUALITY_INVALID, true},
    };
    uint32_t want_clamped = 0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        sl_can_pole_lean_t in = {.target_id = cases[i].id, .quality = cases[i].quality,
                                 .lean_cdeg = cases[i].lean, .lean_sigma_cdeg = cases[i].sigma,
                                 .range_inner_um = cases[i].r1, .range_outer_um = cases[i].r2};
        assert_int_equal(sl_can_encode_pole_lean(&tx, &in, &f), SL_OK);
        assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &out), SL_OK);
        assert_int_equal(out.lean_cdeg, cases[i].want_lean);
        assert_int_equal(out.lean_sigma_cdeg, cases[i].want_sigma);
        assert_int_equal(out.range_inner_um, cases[i].want_r1);
        assert_int_equal(out.range_outer_um, cases[i].want_r2);
        assert_int_equal(out.target_id, cases[i].want_id);
        assert_int_equal(out.quality, cases[i].want_q);
        assert_int_equal(out.clamped, cases[i].clamped);
        want_clamped += cases[i].clamped ? 1U : 0U;
    }
    assert_int_equal(tx.stats.clamped_frames, want_clamped);
}

static void test_canmsg_azimuth_wraps_modulo_a_turn_not_clamped(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_pole_lean_t out;
    const int32_t in_az[] = {0, 36000, -20, 35990, 35989, 72010, -36000, INT32_MIN, INT32_MAX};
    for (size_t i = 0; i < sizeof in_az / sizeof in_az[0]; i++) {
        sl_can_pole_lean_t in = {.azimuth_cdeg = in_az[i]};
        assert_int_equal(sl_can_encode_pole_lean(&tx, &in, &f), SL_OK);
        assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &out), SL_OK);
        int64_t a = (int64_t)in_az[i] % 36000;
        a += (a < 0) ? 36000 : 0;
        const int64_t want = (ref_round(a, 20) % 1800) * 20;
        assert_int_equal(out.azimuth_cdeg, want);
        assert_false(out.clamped);
    }
    sl_can_pole_lean_t in = {.azimuth_cdeg = 35990}; // 359.9 deg -> 360.0 -> 0
    sl_can_encode_pole_lean(&tx, &in, &f);
    sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &out);
    assert_int_equal(out.azimuth_cdeg, 0);
}

static void test_canmsg_lean_warning_round_trips_and_clamps(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_lean_warning_t out;
    for (int32_t raw = -2048; raw <= 4095; raw++) {
        sl_can_lean_warning_t in = {
            .level = (uint8_t)((raw + 2048) % 3), .has_target = true,
            .target_id = (uint8_t)((raw + 2048) % 16), .quality = (uint8_t)((raw + 2048) % 5),
            .azimuth_cdeg = (int32_t)(clamp64(raw, 0, 3599) * 10),
            .lean_cdeg = (int32_t)(clamp64(raw, -2048, 2047) * 5),
            .range_um = (uint32_t)(clamp64(raw, 0, 2047) * 10000),
            .lean_sigma_cdeg = (uint32_t)(clamp64(raw, 0, 63) * 10),
        };
        assert_int_equal(sl_can_encode_lean_warning(&tx, &in, &f), SL_OK);
        assert_int_equal(f.id, ID_WARN);
        assert_int_equal(sl_can_decode_lean_warning(&f, E2E(LEAN_WARNING), &out), SL_OK);
        assert_int_equal(out.level, in.level);
        assert_true(out.has_target);
        assert_int_equal(out.target_id, in.target_id);
        assert_int_equal(out.quality, in.quality);
        assert_int_equal(out.azimuth_cdeg, in.azimuth_cdeg);
        assert_int_equal(out.lean_cdeg, in.lean_cdeg);
        assert_int_equal(out.range_um, in.range_um);
        assert_int_equal(out.lean_sigma_cdeg, in.lean_sigma_cdeg);
        assert_false(out.clamped);
    }
    // Out of range: lean 150 deg, level 7 (-> DANGER, never under-reported), range 30 m.
    sl_can_lean_warning_t in = {.level = 7, .has_target = true, .lean_cdeg = 15000,
                                .range_um = 30000000, .lean_sigma_cdeg = 100};
    sl_can_encode_lean_warning(&tx, &in, &f);
    assert_int_equal(sl_can_decode_lean_warning(&f, E2E(LEAN_WARNING), &out), SL_OK);
    assert_int_equal(out.level, SL_CAN_LEVEL_DANGER);
    assert_int_equal(out.lean_cdeg, 2047 * 5);
    assert_int_equal(out.range_um, 20470000);
    assert_true(out.clamped);
    // No target: every target field is zero whatever the input says.
    sl_can_lean_warning_t none = {.level = SL_CAN_LEVEL_NONE, .has_target = false,
                                  .target_id = 3, .lean_cdeg = 999, .range_um = 77000};
    sl_can_encode_lean_warning(&tx, &none, &f);
    assert_int_equal(sl_can_decode_lean_warning(&f, E2E(LEAN_WARNING), &out), SL_OK);
    assert_false(out.has_target);
    assert_int_equal(out.target_id, 0);
    assert_int_equal(out.lean_cdeg, 0);
    assert_int_equal(out.range_um, 0);
    assert_int_equal(f.data[2] | f.data[3] | f.data[4] | f.data[5] | f.data[6], 0);
    // ... and Quality INVALID (bits 61..63), never VALID: no lean to read.
    assert_int_equal(out.quality, SL_CAN_QUALITY_INVALID);
    assert_int_equal(f.data[7], SL_CAN_QUALITY_INVALID << 5);
}

static void test_canmsg_status_counters_saturate_and_flag(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_status_t out;
    for (int i = 0; i < 50000; i++) {
        sl_can_status_t in = {.link_state = (uint8_t)rnd_range(0, 4),
                              .rotations = (uint32_t)rnd_range(0, 262143),
                              .azimuths_missing = (uint32_t)rnd_range(0, 16383),
                              .decoder_resyncs = (uint32_t)rnd_range(0, 255),
                              .can_dropped = (uint32_t)rnd_range(0, 255)};
        sl_can_encode_status(&tx, &in, &f);
        assert_int_equal(sl_can_decode_status(&f, E2E(STATUS), &out), SL_OK);
        assert_int_equal(out.link_state, in.link_state);
        assert_int_equal(out.rotations, in.rotations);
        assert_int_equal(out.azimuths_missing, in.azimuths_missing);
        assert_int_equal(out.decoder_resyncs, in.decoder_resyncs);
        assert_int_equal(out.can_dropped, in.can_dropped);
        assert_false(out.saturated);
    }
    const sl_can_status_t big = {.link_state = SL_CAN_LINK_SILENT, .rotations = 262144,
                                 .azimuths_missing = UINT32_MAX, .decoder_resyncs = 256,
                                 .can_dropped = 1000};
    sl_can_encode_status(&tx, &big, &f);
    assert_int_equal(sl_can_decode_status(&f, E2E(STATUS), &out), SL_OK);
    assert_true(out.saturated);
    assert_int_equal(out.rotations, 262143);
    assert_int_equal(out.azimuths_missing, 16383);
    assert_int_equal(out.decoder_resyncs, 255);
    assert_int_equal(out.can_dropped, 255);
    assert_int_equal(out.link_state, SL_CAN_LINK_SILENT);
    const sl_can_status_t bad_link = {.link_state = 9};
    sl_can_encode_status(&tx, &bad_link, &f);
    sl_can_decode_status(&f, E2E(STATUS), &out);
    assert_int_equal(out.link_state, SL_CAN_LINK_DISCONNECTED);
    assert_true(out.saturated);
    assert_int_equal(tx.stats.clamped_frames, 2);
}

// Health: every fault bit and counter value round-trips; reserved bits are never sent;
// the totals saturate at their field maximum (counted as clamped frames); the golden bytes
// follow the fixed layout (Fault 16|16, Reconnects 32|8, CandidatesDropped 40|12).
static void test_canmsg_health_round_trips_saturates_and_keeps_reserved_bits_zero(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_health_t out;
    for (int i = 0; i < 20000; i++) {
        const sl_can_health_t in = {.fault = (uint16_t)rnd_range(0, 0x1FF),
                                    .reconnects = (uint32_t)rnd_range(0, 255),
                                    .candidates_dropped = (uint32_t)rnd_range(0, 4095)};
        assert_int_equal(sl_can_encode_health(&tx, &in, &f), SL_OK);
        assert_int_equal(f.id, ID_HEALTH);
        assert_int_equal(f.dlc, 8);
        assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_OK);
        assert_int_equal(out.fault, in.fault);
        assert_int_equal(out.reconnects, in.reconnects);
        assert_int_equal(out.candidates_dropped, in.candidates_dropped);
        assert_int_equal(f.data[1] & 0xF0U, 0);   // reserved 12|4
        assert_int_equal(f.data[6] & 0xF0U, 0);   // ThetaDrift 52|8: 0 here
        assert_int_equal(f.data[7], 0);           // ... and reserved 60|4
        assert_int_equal(f.data[0], sl_can_e2e_crc(E2E(HEALTH), f.data));
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
    const sl_can_health_t big = {.fault = 0xFFFFU, .reconnects = 256, .candidates_dropped = 5000};
    sl_can_encode_health(&tx, &big, &f);
    assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_OK);
    assert_int_equal(out.fault, SL_CAN_FAULT_DEFINED);
    assert_int_equal(out.reconnects, 255);
    assert_int_equal(out.candidates_dropped, 4095);
    assert_int_equal(tx.stats.clamped_frames, 1);
    // Golden: TARGET_SLOTS_OVERFLOW, 3 reconnects, 0xABC dropped.
    const sl_can_health_t g = {.fault = SL_CAN_FAULT_TARGET_SLOTS_OVERFLOW, .reconnects = 3,
                               .candidates_dropped = 0xABCU};
    sl_can_encode_health(&tx, &g, &f);
    assert_int_equal(f.data[2], 0x00);
    assert_int_equal(f.data[3], 0x01);
    assert_int_equal(f.data[4], 0x03);
    assert_int_equal(f.data[5], 0xBC);
    assert_int_equal(f.data[6], 0x0A);
    assert_int_equal(sl_can_decode_health(NULL, E2E(HEALTH), NULL), SL_ERR_ARG);
    assert_int_equal(sl_can_encode_health(NULL, &g, &f), SL_ERR_ARG);
    f.data[0] ^= 1U;
    assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_ERR_MALFORMED);
    const sl_can_message_desc_t *md = sl_can_layout(SL_CAN_MSG_HEALTH);
    assert_string_equal(md->name, "Health");
    assert_int_equal(md->data_id, SL_CAN_DATA_ID_HEALTH);
    assert_int_equal(md->signals[2].n_values, 11); // bit 9 THETA_DRIFT, bit 10 MOTION_E2E
    for (unsigned k = 0; k < md->signals[2].n_values; k++) {
        assert_int_equal(md->signals[2].values[k].value, 1U << k);
    }
}

static void test_canmsg_health_theta_drift_round_trips_and_saturates(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_health_t out;
    for (int32_t raw = -128; raw <= 127; raw++) {
        const sl_can_health_t in = {.theta_drift_cdeg = (int16_t)(raw * 10)};
        assert_int_equal(sl_can_encode_health(&tx, &in, &f), SL_OK);
        assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_OK);
        assert_int_equal(out.theta_drift_cdeg, in.theta_drift_cdeg);
        assert_int_equal(f.data[7] & 0xF0U, 0); // ResponseSource 60|2 (PRIOR) and reserved 62|2
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
    // Golden: +2.0 deg = raw 20 = 0x14 at 52|8 (little-endian bit numbering), THETA_DRIFT.
    const sl_can_health_t g = {.fault = SL_CAN_FAULT_THETA_DRIFT, .theta_drift_cdeg = 200};
    sl_can_encode_health(&tx, &g, &f);
    assert_int_equal(f.data[2], 0x00);
    assert_int_equal(f.data[3], 0x02);
    assert_int_equal(f.data[6], 0x40);
    assert_int_equal(f.data[7], 0x01);
    // 0.05 deg rounds half up to 0.1; -0.05 to 0.0; beyond +-12.8 deg saturates (clamped)
    const sl_can_health_t h1 = {.theta_drift_cdeg = 5};
    sl_can_encode_health(&tx, &h1, &f);
    sl_can_decode_health(&f, E2E(HEALTH), &out);
    assert_int_equal(out.theta_drift_cdeg, 10);
    const sl_can_health_t big = {.theta_drift_cdeg = -2000};
    sl_can_encode_health(&tx, &big, &f);
    sl_can_decode_health(&f, E2E(HEALTH), &out);
    assert_int_equal(out.theta_drift_cdeg, -1280);
    assert_int_equal(tx.stats.clamped_frames, 1);
}

// ResponseSource at 60|2: each sl_response_source_t value round-trips at its bits; a value
// beyond CALIBRATED is sent as CALIBRATED and counted clamped; the reserved bits 62|2 stay 0.
static void test_canmsg_health_response_source_round_trips_and_saturates(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_health_t out;
    for (uint8_t v = 0; v <= (uint8_t)SL_CAN_RESPONSE_SOURCE_MAX; v++) {
        const sl_can_health_t in = {.response_source = v};
        assert_int_equal(sl_can_encode_health(&tx, &in, &f), SL_OK);
        assert_int_equal((f.data[7] >> 4) & 3U, v);
        assert_int_equal(f.data[7] & 0xC0U, 0);
        assert_int_equal(sl_can_decode_health(&f, E2E(HEALTH), &out), SL_OK);
        assert_int_equal(out.response_source, v);
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
    const sl_can_health_t big = {.response_source = 3U};
    sl_can_encode_health(&tx, &big, &f);
    sl_can_decode_health(&f, E2E(HEALTH), &out);
    assert_int_equal(out.response_source, SL_CAN_RESPONSE_SOURCE_MAX);
    assert_int_equal(tx.stats.clamped_frames, 1);
    assert_int_equal(SL_CAN_RESPONSE_SOURCE_MAX, SL_RESPONSE_CALIBRATED);
}

static void test_canmsg_vehicle_motion_round_trips_full_range(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    sl_can_vehicle_motion_t out;
    for (int32_t raw = -32768; raw <= 32767; raw++) {
        sl_can_vehicle_motion_t in = {.speed_mm_s = raw * 10, .yaw_rate_cdeg_s = -1 - raw,
                                      .speed_valid = (raw & 1) != 0,
                                      .yaw_rate_valid = (raw & 2) != 0};
        assert_int_equal(sl_can_encode_vehicle_motion(&tx, &in, &f), SL_OK);
        assert_int_equal(f.id, ID_MOTION);
        assert_int_equal(sl_can_decode_vehicle_motion(&f, E2E(VEHICLE_MOTION), &out), SL_OK);
        assert_int_equal(out.speed_mm_s, in.speed_mm_s);
        assert_int_equal(out.yaw_rate_cdeg_s, in.yaw_rate_cdeg_s);
        assert_int_equal(out.speed_valid, in.speed_valid);
        assert_int_equal(out.yaw_rate_valid, in.yaw_rate_valid);
    }
    assert_int_equal(tx.stats.clamped_frames, 0);
    const sl_can_vehicle_motion_t fast = {.speed_mm_s = 400000, .yaw_rate_cdeg_s = -40000};
    sl_can_encode_vehicle_motion(&tx, &fast, &f);
    sl_can_decode_vehicle_motion(&f, E2E(VEHICLE_MOTION), &out);
    assert_int_equal(out.speed_mm_s, 327670);
    assert_int_equal(out.yaw_rate_cdeg_s, -32768);
    assert_int_equal(tx.stats.clamped_frames, 1);
    // 1.235 m/s = 123.5 LSB rounds half up to 124 -> 1240 mm/s; -1.235 -> -123.5 -> -123
    const sl_can_vehicle_motion_t half = {.speed_mm_s = 1235};
    sl_can_encode_vehicle_motion(&tx, &half, &f);
    sl_can_decode_vehicle_motion(&f, E2E(VEHICLE_MOTION), &out);
    assert_int_equal(out.speed_mm_s, 1240);
    const sl_can_vehicle_motion_t nhalf = {.speed_mm_s = -1235};
    sl_can_encode_vehicle_motion(&tx, &nhalf, &f);
    sl_can_decode_vehicle_motion(&f, E2E(VEHICLE_MOTION), &out);
    assert_int_equal(out.speed_mm_s, -1230);
}

static void test_canmsg_counter_wraps_modulo_15_per_message(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    const sl_can_pole_lean_t p = {0};
    const sl_can_status_t s = {0};
    for (unsigned i = 0; i < 100U; i++) {
        sl_can_encode_pole_lean(&tx, &p, &f);
        assert_int_equal(f.data[1] & 0x0F, i % 15U);
        assert_int_not_equal(f.data[1] & 0x0F, 15);
        if (i % 3U == 0U) { // another message type keeps its own counter
            sl_can_encode_status(&tx, &s, &f);
            assert_int_equal(f.data[1] & 0x0F, (i / 3U) % 15U);
        }
    }
    assert_int_equal(tx.stats.frames, 100 + 34);
}

static void test_canmsg_e2e_detects_every_single_bit_error(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_frame_t f;
    const sl_can_pole_lean_t p = {.target_id = 3, .lean_cdeg = 456, .range_inner_um = 3000000,
                                  .range_outer_um = 3300000, .azimuth_cdeg = 9000};
    sl_can_encode_pole_lean(&tx, &p, &f);
    sl_can_e2e_rx_t rx;
    sl_can_e2e_rx_init(&rx, 1U);
    for (unsigned bit = 0; bit < 64U; bit++) {
        sl_can_frame_t g = f;
        g.data[bit / 8U] ^= (uint8_t)(1U << (bit % 8U));
        assert_int_equal(sl_can_e2e_check(&rx, E2E(POLE_LEAN), &g), SL_CAN_E2E_ERROR);
        sl_can_pole_lean_t out;
        assert_int_equal(sl_can_decode_pole_lean(&g, E2E(POLE_LEAN), &out), SL_ERR_MALFORMED);
    }
    assert_int_equal(rx.stats.crc_errors, 64);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_ERROR], 64);
    assert_false(rx.synced); // errors never touch the sequence
    // The right frame under another Data ID (e.g. received on the Status id) is rejected.
    assert_int_equal(sl_can_e2e_check(&rx, E2E(STATUS), &f), SL_CAN_E2E_ERROR);
    sl_can_status_t st;
    assert_int_equal(sl_can_decode_status(&f, E2E(STATUS), &st), SL_ERR_MALFORMED);
    assert_int_equal(sl_can_e2e_check(&rx, E2E(POLE_LEAN), &f), SL_CAN_E2E_INITIAL);
    // Wrong DLC, RTR and error frames.
    sl_can_frame_t g = f;
    g.dlc = 7;
    assert_int_equal(sl_can_e2e_check(&rx, E2E(POLE_LEAN), &g), SL_CAN_E2E_ERROR);
    g = f;
    g.flags = SL_CAN_FLAG_RTR;
    assert_int_equal(sl_can_e2e_check(&rx, E2E(POLE_LEAN), &g), SL_CAN_E2E_ERROR);
    assert_int_equal(rx.stats.bad_dlc, 2);
    // Counter 15 with a correct CRC.
    g = f;
    g.data[1] = (uint8_t)((g.data[1] & 0xF0U) | 0x0FU);
    g.data[0] = sl_can_e2e_crc(E2E(POLE_LEAN), g.data);
    assert_int_equal(sl_can_e2e_check(&rx, E2E(POLE_LEAN), &g), SL_CAN_E2E_ERROR);
    assert_int_equal(rx.stats.bad_counter, 1);
    // A receive cycle without a frame.
    assert_int_equal(sl_can_e2e_check(&rx, E2E(POLE_LEAN), NULL), SL_CAN_E2E_NO_NEW_DATA);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_NO_NEW_DATA], 1);
    assert_int_equal(rx.last_status, SL_CAN_E2E_NO_NEW_DATA);
}

// The Profile 11 statuses of a sequence with max delta counter 3: step 1 OK, 2..3
// OK_SOME_LOST, 0 REPEATED, 4 and more WRONG_SEQUENCE; the counter state follows every
// frame with a valid CRC, so the frame after a WRONG_SEQUENCE one continues from it.
static void test_canmsg_e2e_classifies_steps_with_the_max_delta_counter(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_e2e_rx_t rx;
    sl_can_e2e_rx_init(&rx, 3U);
    sl_can_frame_t fr[40];
    const sl_can_status_t s = {.link_state = SL_CAN_LINK_STREAMING};
    for (unsigned i = 0; i < 40U; i++) {
        sl_can_encode_status(&tx, &s, &fr[i]);
    }
    const sl_can_e2e_cfg_t *c = E2E(STATUS);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[0]), SL_CAN_E2E_INITIAL);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[1]), SL_CAN_E2E_OK);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[1]), SL_CAN_E2E_REPEATED);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[4]), SL_CAN_E2E_OK_SOME_LOST); // step 3
    assert_int_equal(rx.stats.lost_frames, 2);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[9]), SL_CAN_E2E_WRONG_SEQUENCE); // step 5
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[10]), SL_CAN_E2E_OK);
    // In sequence across the 14 -> 0 wrap.
    for (unsigned i = 11; i < 20U; i++) {
        assert_int_equal(sl_can_e2e_check(&rx, c, &fr[i]), SL_CAN_E2E_OK);
    }
    // Frame i carries counter i mod 15: 19 (counter 4) -> 27 (12) is a step of 8; 27 -> 29
    // (14) is 2; 29 -> 31 (counter 1) is 2 over the 14 -> 0 wrap.
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[27]), SL_CAN_E2E_WRONG_SEQUENCE);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[29]), SL_CAN_E2E_OK_SOME_LOST);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[31]), SL_CAN_E2E_OK_SOME_LOST);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_OK], 11);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_OK_SOME_LOST], 3);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_WRONG_SEQUENCE], 2);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_REPEATED], 1);
    assert_int_equal(rx.stats.lost_frames, 2 + 4 + 7 + 1 + 1);
    // After a reset the next frame is INITIAL whatever its counter (even a repeat).
    sl_can_e2e_rx_reset(&rx);
    assert_int_equal(sl_can_e2e_check(&rx, c, &fr[31]), SL_CAN_E2E_INITIAL);
    assert_int_equal(rx.stats.status[SL_CAN_E2E_INITIAL], 2);
    // The max delta counter is clamped to 1..14; 1 makes every gap a WRONG_SEQUENCE.
    sl_can_e2e_rx_init(&rx, 0U);
    assert_int_equal(rx.max_delta_counter, 1);
    sl_can_e2e_rx_init(&rx, 200U);
    assert_int_equal(rx.max_delta_counter, 14);
    assert_true(sl_can_e2e_status_ok(SL_CAN_E2E_OK_SOME_LOST));
    assert_false(sl_can_e2e_status_ok(SL_CAN_E2E_INITIAL));
    assert_string_equal(sl_can_e2e_status_name(SL_CAN_E2E_WRONG_SEQUENCE), "WRONG_SEQUENCE");
    assert_string_equal(sl_can_e2e_status_name((sl_can_e2e_status_t)99), "?");
}

static void test_canmsg_tx_init_validates_ids(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    sl_can_ids_t ids;
    sl_can_ids_default(&ids);
    ids.id[SL_CAN_MSG_POLE_LEAN] = 0x800U;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
    sl_can_ids_default(&ids);
    ids.id[SL_CAN_MSG_STATUS] = ids.id[SL_CAN_MSG_POLE_LEAN];
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
    sl_can_ids_default(&ids);
    ids.id[SL_CAN_MSG_POLE_LEAN] = 0x80000000UL | 0x20000000UL;
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_ERR_ARG);
    const uint32_t eff[SL_CAN_MSG_COUNT] = {0x80000000UL | 0x18FF1234UL, 0x7FFU, 0U, 0x123U,
                                            0x124U, 0x125U, 0x126U, 0x80000000UL | 0x127U};
    memcpy(ids.id, eff, sizeof eff);
    assert_int_equal(sl_can_tx_init(&tx, &ids), SL_OK);
    assert_int_equal(sl_can_tx_init(NULL, &ids), SL_ERR_ARG);
    sl_can_frame_t f;
    const sl_can_pole_lean_t p = {0};
    sl_can_encode_pole_lean(&tx, &p, &f);
    assert_int_equal(f.id, 0x18FF1234UL);
    assert_int_equal(f.flags, SL_CAN_FLAG_EFF);
    sl_can_pole_lean_t back;
    assert_int_equal(sl_can_decode_pole_lean(&f, E2E(POLE_LEAN), &back), SL_OK);
    const sl_can_status_t s = {0};
    sl_can_encode_status(&tx, &s, &f);
    assert_int_equal(f.id, 0);
    assert_int_equal(f.flags, 0);
    assert_int_equal(sl_can_encode_status(NULL, &s, &f), SL_ERR_ARG);
    assert_int_equal(sl_can_decode_status(NULL, E2E(STATUS), NULL), SL_ERR_ARG);
    sl_can_status_t back_status;
    assert_int_equal(sl_can_decode_status(&f, NULL, &back_status), SL_ERR_ARG);
}

static void test_canmsg_motion_rx_checks_id_sequence_and_age(void **state)
{
    (void)state;
    sl_can_tx_t tx;
    tx_setup(&tx);
    sl_can_motion_rx_t rx;
    sl_can_motion_rx_init(&rx, ID_MOTION, E2E(VEHICLE_MOTION), 2U, 100000U);
    sl_can_vehicle_motion_t mv;
    assert_false(sl_can_motion_rx_get(&rx, 0, &mv));
    sl_can_frame_t f[10];
    for (int i = 0; i < 10; i++) {
        const sl_can_vehicle_motion_t in = {.speed_mm_s = 1000 * i, .yaw_rate_cdeg_s = -50 * i,
                                            .speed_valid = true, .yaw_rate_valid = true};
        sl_can_encode_vehicle_motion(&tx, &in, &f[i]);
    }
    const uint32_t *n = rx.e2e.stats.status;
    uint64_t t = 1000000;
    // The first frame only synchronises the sequence (INITIAL): its value is not used.
    assert_int_equal(sl_can_motion_rx_feed(&rx, &f[8], t - 20000), SL_OK);
    assert_int_equal(n[SL_CAN_E2E_INITIAL], 1);
    assert_false(sl_can_motion_rx_get(&rx, t - 20000, &mv));
    // A step of 7 is WRONG_SEQUENCE at max delta 2 (not used; the sequence continues from
    // it), then a step of 2 is OK_SOME_LOST: used.
    assert_int_equal(sl_can_motion_rx_feed(&rx, &f[0], t - 10000), SL_ERR_STATE); // 8 -> 0: step 7
    assert_int_equal(n[SL_CAN_E2E_WRONG_SEQUENCE], 1);
    assert_false(sl_can_motion_rx_get(&rx, t - 10000, &mv)); // WRONG_SEQUENCE: not used
    assert_int_equal(sl_can_motion_rx_feed(&rx, &f[2], t), SL_OK); // 0 -> 2: step 2
    assert_int_equal(n[SL_CAN_E2E_OK_SOME_LOST], 1);
    assert_true(sl_can_motion_rx_get(&rx, t + 100000, &mv));
    assert_int_equal(mv.speed_mm_s, 2000);
    assert_false(sl_can_motion_rx_get(&rx, t + 100001, &mv));
    // Another id is ignored and counted.
    sl_can_frame_t other = f[3];
    other.id = ID_STATUS;
    assert_int_equal(sl_can_motion_rx_feed(&rx, &other, t), SL_ERR_ARG);
    assert_int_equal(rx.stats.other_ids, 1);
    other = f[3];
    other.flags = SL_CAN_FLAG_EFF; // same number as a 29-bit id is another id
    assert_int_equal(sl_can_motion_rx_feed(&rx, &other, t), SL_ERR_ARG);
    // A corrupted frame is an ERROR and the last good value is kept.
    sl_can_frame_t bad = f[3];
    bad.data[3] ^= 0x40U;
    assert_int_equal(sl_can_motion_rx_feed(&rx, &bad, t + 10000), SL_ERR_MALFORMED);
    assert_int_equal(rx.e2e.stats.crc_errors, 1);
    assert_int_equal(rx.e2e.last_status, SL_CAN_E2E_ERROR);
    assert_true(sl_can_motion_rx_get(&rx, t + 10000, &mv));
    assert_int_equal(mv.speed_mm_s, 2000);
    // In sequence: OK.
    assert_int_equal(sl_can_motion_rx_feed(&rx, &f[3], t + 20000), SL_OK);
    assert_int_equal(n[SL_CAN_E2E_OK], 1);
    assert_true(sl_can_motion_rx_get(&rx, t + 20000, &mv));
    assert_int_equal(mv.speed_mm_s, 3000);
    assert_int_equal(mv.yaw_rate_cdeg_s, -150);
    assert_true(mv.speed_valid && mv.yaw_rate_valid);
    // A repetition is REPEATED: rejected, and it does not renew the value's age.
    assert_int_equal(sl_can_motion_rx_feed(&rx, &f[3], t + 30000), SL_ERR_STATE);
    assert_int_equal(n[SL_CAN_E2E_REPEATED], 1);
    assert_false(sl_can_motion_rx_get(&rx, t + 120001, &mv));
    // After a gap longer than the timeout: one NO_NEW_DATA, the sequence restarts, and the
    // first frame after the gap (here a stale repetition of frame 3, 3.0 m/s) is INITIAL:
    // never used, whatever its counter.
    assert_int_equal(sl_can_motion_rx_feed(&rx, &f[3], t + 500000), SL_OK);
    assert_int_equal(n[SL_CAN_E2E_NO_NEW_DATA], 1);
    assert_int_equal(n[SL_CAN_E2E_INITIAL], 2);
    assert_false(sl_can_motion_rx_get(&rx, t + 500000, &mv));
    assert_int_equal(sl_can_motion_rx_feed(&rx, &f[4], t + 520000), SL_OK);
    assert_true(sl_can_motion_rx_get(&rx, t + 520000, &mv));
    assert_int_equal(mv.speed_mm_s, 4000);
    assert_int_equal(n[SL_CAN_E2E_OK] + n[SL_CAN_E2E_OK_SOME_LOST], 3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_canmsg_crc8_0x1d_gives_the_sae_j1850_and_gsm_a_check_values),
        cmocka_unit_test(test_canmsg_e2e_crc_matches_independent_profile_11_vectors),
        cmocka_unit_test(test_canmsg_e2e_crc_of_every_message_matches_its_vectors),
        cmocka_unit_test(test_canmsg_tx_init_refuses_nibble_mode_over_signals_and_shared_data_ids),
        cmocka_unit_test(test_canmsg_e2e_crc_mixes_both_data_id_bytes_first),
        cmocka_unit_test(test_canmsg_crc_worked_example),
        cmocka_unit_test(test_canmsg_pole_lean_golden_bytes),
        cmocka_unit_test(test_canmsg_layout_table_is_consistent),
        cmocka_unit_test(test_canmsg_pole_lean_round_trips_every_raw_value),
        cmocka_unit_test(test_canmsg_pole_lean_random_values_within_half_lsb),
        cmocka_unit_test(test_canmsg_ranges_are_rounded_once_from_um),
        cmocka_unit_test(test_canmsg_clamps_and_flags_out_of_range_values),
        cmocka_unit_test(test_canmsg_azimuth_wraps_modulo_a_turn_not_clamped),
        cmocka_unit_test(test_canmsg_lean_warning_round_trips_and_clamps),
        cmocka_unit_test(test_canmsg_status_counters_saturate_and_flag),
        cmocka_unit_test(test_canmsg_health_theta_drift_round_trips_and_saturates),
        cmocka_unit_test(test_canmsg_health_response_source_round_trips_and_saturates),
        cmocka_unit_test(test_canmsg_vehicle_motion_round_trips_full_range),
        cmocka_unit_test(test_canmsg_health_round_trips_saturates_and_keeps_reserved_bits_zero),
        cmocka_unit_test(test_canmsg_counter_wraps_modulo_15_per_message),
        cmocka_unit_test(test_canmsg_e2e_detects_every_single_bit_error),
        cmocka_unit_test(test_canmsg_e2e_classifies_steps_with_the_max_delta_counter),
        cmocka_unit_test(test_canmsg_tx_init_validates_ids),
        cmocka_unit_test(test_canmsg_pole_tilt_layout_encode_decode),
#if SL_CFG_GROUND
        cmocka_unit_test(test_canmsg_ground_plane_golden_bytes_and_round_trip),
        cmocka_unit_test(test_canmsg_ground_plane_rounds_once_and_saturates),
        cmocka_unit_test(test_canmsg_ground_hazard_golden_bytes_and_round_trip),
        cmocka_unit_test(test_canmsg_ground_hazard_rounds_once_and_saturates),
#endif
        cmocka_unit_test(test_canmsg_motion_rx_checks_id_sequence_and_age),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
