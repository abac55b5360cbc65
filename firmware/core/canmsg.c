// SPDX-License-Identifier: MIT
// CAN message layouts, encoders and decoders (sl_can.h). The layout tables below are the
// single description of every signal: the encoders and decoders read positions and raw
// limits from them, and the host DBC generator prints them.
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_config.h"

#include <string.h>

// ---------------------------------------------------------------------------------------
// Layout tables

static const sl_can_value_name_t quality_names[] = {
    {0U, "VALID"}, {1U, "AMBIGUOUS"}, {2U, "OUT_OF_MODEL"}, {3U, "INVALID"}, {4U, "FILTERED"},
};
static const sl_can_value_name_t tilt_quality_names[] = {
    {0U, "FITTED"}, {1U, "AMBIGUOUS"}, {2U, "INSUFFICIENT_MOTION"}, {3U, "TOO_FEW"},
    {4U, "INCONSISTENT"}, {5U, "MIRROR"},
};
static const sl_can_value_name_t level_names[] = {
    {0U, "NONE"}, {1U, "CAUTION"}, {2U, "DANGER"},
};
static const sl_can_value_name_t link_names[] = {
    {0U, "DISCONNECTED"}, {1U, "CONNECTING"}, {2U, "WAIT_CONFIG"}, {3U, "STREAMING"},
    {4U, "SILENT"},
};

static const sl_can_value_name_t response_names[] = {
    {0U, "PRIOR"}, {1U, "LEARNED"}, {2U, "CALIBRATED"},
};

static const sl_can_value_name_t fault_names[] = {
    {SL_CAN_FAULT_CONFIG_MISMATCH, "CONFIG_MISMATCH"},
    {SL_CAN_FAULT_NO_USABLE_ROWS, "NO_USABLE_ROWS"},
    {SL_CAN_FAULT_MALFORMED_DATA, "MALFORMED_DATA"},
    {SL_CAN_FAULT_LINK_FLAPPING, "LINK_FLAPPING"},
    {SL_CAN_FAULT_CAN_OUTPUT_ERRORS, "CAN_OUTPUT_ERRORS"},
    {SL_CAN_FAULT_RANGE_RESOLUTION_MISMATCH, "RANGE_RESOLUTION_MISMATCH"},
    {SL_CAN_FAULT_AZIMUTH_DISORDER, "AZIMUTH_DISORDER"},
    {SL_CAN_FAULT_CAN_RATE_LIMITED, "CAN_RATE_LIMITED"},
    {SL_CAN_FAULT_TARGET_SLOTS_OVERFLOW, "TARGET_SLOTS_OVERFLOW"},
    {SL_CAN_FAULT_THETA_DRIFT, "THETA_DRIFT"},
    {SL_CAN_FAULT_MOTION_E2E, "MOTION_E2E"},
};

#define NV(a) ((uint8_t)(sizeof(a) / sizeof((a)[0])))
// name, start, length, signed, factor num/den, raw min/max, unit, values
#define E2E_SIGNALS                                                                          \
    {"Crc", 0U, 8U, false, 1, 1, 0, 255, "", NULL, 0U},                                      \
    {                                                                                        \
        "Counter", 8U, 4U, false, 1, 1, 0, (int32_t)SL_CAN_COUNTER_MODULO - 1, "", NULL, 0U  \
    }

enum { S_CRC = 0, S_COUNTER = 1 }; // the first two entries of every table

enum { P_QUALITY = 2, P_CLAMPED, P_TARGET, P_AZ, P_LEAN, P_SIGMA, P_R1, P_R2, P_N };
static const sl_can_signal_desc_t pole_sigs[P_N] = {
    E2E_SIGNALS,
    {"Quality", 12U, 3U, false, 1, 1, 0, (int32_t)SL_CAN_QUALITY_MAX, "", quality_names,
     NV(quality_names)},
    {"Clamped", 15U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"TargetId", 16U, 4U, false, 1, 1, 0, (int32_t)SL_CAN_TARGET_ID_MAX, "", NULL, 0U},
    {"Azimuth", 20U, 11U, false, SL_CAN_POLE_AZIMUTH_CDEG_PER_LSB, 100, 0,
     SL_CAN_POLE_AZIMUTH_RAW_MAX, "deg", NULL, 0U},
    {"Lean", 31U, 10U, true, SL_CAN_POLE_LEAN_CDEG_PER_LSB, 100, SL_CAN_POLE_LEAN_RAW_MIN,
     SL_CAN_POLE_LEAN_RAW_MAX, "deg", NULL, 0U},
    {"LeanSigma", 41U, 5U, false, SL_CAN_POLE_SIGMA_CDEG_PER_LSB, 100, 0,
     SL_CAN_POLE_SIGMA_RAW_MAX, "deg", NULL, 0U},
    {"RangeInner", 46U, 9U, false, SL_CAN_POLE_RANGE_MM_PER_LSB, 1000, 0,
     SL_CAN_POLE_RANGE_RAW_MAX, "m", NULL, 0U},
    {"RangeOuter", 55U, 9U, false, SL_CAN_POLE_RANGE_MM_PER_LSB, 1000, 0,
     SL_CAN_POLE_RANGE_RAW_MAX, "m", NULL, 0U},
};

enum { W_LEVEL = 2, W_CLAMPED, W_HAS, W_TARGET, W_AZ, W_LEAN, W_RANGE, W_SIGMA, W_QUALITY, W_N };
static const sl_can_signal_desc_t warn_sigs[W_N] = {
    E2E_SIGNALS,
    {"Level", 12U, 2U, false, 1, 1, 0, (int32_t)SL_CAN_LEVEL_MAX, "", level_names,
     NV(level_names)},
    {"Clamped", 14U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"HasTarget", 15U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"TargetId", 16U, 4U, false, 1, 1, 0, (int32_t)SL_CAN_TARGET_ID_MAX, "", NULL, 0U},
    {"Azimuth", 20U, 12U, false, SL_CAN_WARN_AZIMUTH_CDEG_PER_LSB, 100, 0,
     SL_CAN_WARN_AZIMUTH_RAW_MAX, "deg", NULL, 0U},
    {"Lean", 32U, 12U, true, SL_CAN_WARN_LEAN_CDEG_PER_LSB, 100, SL_CAN_WARN_LEAN_RAW_MIN,
     SL_CAN_WARN_LEAN_RAW_MAX, "deg", NULL, 0U},
    {"Range", 44U, 11U, false, SL_CAN_WARN_RANGE_MM_PER_LSB, 1000, 0,
     SL_CAN_WARN_RANGE_RAW_MAX, "m", NULL, 0U},
    {"LeanSigma", 55U, 6U, false, SL_CAN_WARN_SIGMA_CDEG_PER_LSB, 100, 0,
     SL_CAN_WARN_SIGMA_RAW_MAX, "deg", NULL, 0U},
    {"Quality", 61U, 3U, false, 1, 1, 0, (int32_t)SL_CAN_QUALITY_MAX, "", quality_names,
     NV(quality_names)},
};

enum { T_LINK = 2, T_SAT, T_ROT, T_AZMISS, T_RESYNC, T_DROP, T_N };
static const sl_can_signal_desc_t status_sigs[T_N] = {
    E2E_SIGNALS,
    {"LinkState", 12U, 3U, false, 1, 1, 0, (int32_t)SL_CAN_LINK_STATE_MAX, "", link_names,
     NV(link_names)},
    {"Saturated", 15U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"Rotations", 16U, 18U, false, 1, 1, 0, (int32_t)SL_CAN_STATUS_ROTATIONS_MAX, "", NULL, 0U},
    {"AzimuthsMissing", 34U, 14U, false, 1, 1, 0, (int32_t)SL_CAN_STATUS_AZ_MISSING_MAX, "",
     NULL, 0U},
    {"DecoderResyncs", 48U, 8U, false, 1, 1, 0, (int32_t)SL_CAN_STATUS_RESYNCS_MAX, "", NULL,
     0U},
    {"CanDropped", 56U, 8U, false, 1, 1, 0, (int32_t)SL_CAN_STATUS_DROPPED_MAX, "", NULL, 0U},
};

enum { M_SPEED_VALID = 2, M_YAW_VALID, M_SPEED, M_YAW, M_N };
static const sl_can_signal_desc_t motion_sigs[M_N] = {
    E2E_SIGNALS,
    {"SpeedValid", 12U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"YawRateValid", 13U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"Speed", 16U, 16U, true, SL_CAN_MOTION_SPEED_MM_S_PER_LSB, 1000, SL_CAN_MOTION_RAW_MIN,
     SL_CAN_MOTION_RAW_MAX, "m/s", NULL, 0U},
    {"YawRate", 32U, 16U, true, SL_CAN_MOTION_YAW_CDEG_S_PER_LSB, 100, SL_CAN_MOTION_RAW_MIN,
     SL_CAN_MOTION_RAW_MAX, "deg/s", NULL, 0U},
};

enum { H_FAULT = 2, H_RECONNECTS, H_CAND_DROPPED, H_DRIFT, H_RESPONSE, H_N };
static const sl_can_signal_desc_t health_sigs[H_N] = {
    E2E_SIGNALS,
    {"Fault", 16U, 16U, false, 1, 1, 0, 65535, "", fault_names, NV(fault_names)},
    {"Reconnects", 32U, 8U, false, 1, 1, 0, (int32_t)SL_CAN_HEALTH_RECONNECTS_MAX, "", NULL, 0U},
    {"CandidatesDropped", 40U, 12U, false, 1, 1, 0,
     (int32_t)SL_CAN_HEALTH_CANDIDATES_DROPPED_MAX, "", NULL, 0U},
    {"ThetaDrift", 52U, 8U, true, SL_CAN_HEALTH_DRIFT_CDEG_PER_LSB, 100, SL_CAN_HEALTH_DRIFT_RAW_MIN,
     SL_CAN_HEALTH_DRIFT_RAW_MAX, "deg", NULL, 0U},
    {"ResponseSource", 60U, 2U, false, 1, 1, 0, (int32_t)SL_CAN_RESPONSE_SOURCE_MAX, "",
     response_names, NV(response_names)},
};

enum { L_QUALITY = 2, L_CLAMPED, L_TARGET, L_TILT, L_DIR, L_SIGMA, L_DIR_SIGMA, L_BX, L_BY, L_N };
static const sl_can_signal_desc_t tilt_sigs[L_N] = {
    E2E_SIGNALS,
    {"Quality", 12U, 3U, false, 1, 1, 0, (int32_t)SL_CAN_TILT_QUALITY_MAX, "", tilt_quality_names,
     NV(tilt_quality_names)},
    {"Clamped", 15U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"TargetId", 16U, 4U, false, 1, 1, 0, (int32_t)SL_CAN_TARGET_ID_MAX, "", NULL, 0U},
    {"Tilt", 20U, 8U, false, SL_CAN_TILT_CDEG_PER_LSB, 100, 0, SL_CAN_TILT_RAW_MAX, "deg", NULL,
     0U},
    {"TiltDirection", 28U, 9U, false, SL_CAN_TILT_DIR_CDEG_PER_LSB, 100, 0,
     SL_CAN_TILT_DIR_RAW_MAX, "deg", NULL, 0U},
    {"TiltSigma", 37U, 5U, false, SL_CAN_TILT_SIGMA_CDEG_PER_LSB, 100, 0,
     SL_CAN_TILT_SIGMA_RAW_MAX, "deg", NULL, 0U},
    {"DirectionSigma", 42U, 6U, false, SL_CAN_TILT_DIR_SIGMA_CDEG_PER_LSB, 100, 0,
     SL_CAN_TILT_DIR_SIGMA_RAW_MAX, "deg", NULL, 0U},
    {"BaseX", 48U, 8U, true, SL_CAN_TILT_BASE_MM_PER_LSB, 1000, SL_CAN_TILT_BASE_RAW_MIN,
     SL_CAN_TILT_BASE_RAW_MAX, "m", NULL, 0U},
    {"BaseY", 56U, 8U, true, SL_CAN_TILT_BASE_MM_PER_LSB, 1000, SL_CAN_TILT_BASE_RAW_MIN,
     SL_CAN_TILT_BASE_RAW_MAX, "m", NULL, 0U},
};

#if SL_CFG_GROUND
static const sl_can_value_name_t ground_quality_names[] = {
    {0U, "NONE"}, {1U, "COARSE"}, {2U, "GOOD"},
};
static const sl_can_value_name_t ground_kind_names[] = {
    {0U, "FLAT"}, {1U, "DROP"}, {2U, "STEP"},
};

enum { G_QUALITY = 2, G_CLAMPED, G_HEIGHT, G_PITCH, G_ROLL, G_HSIGMA, G_PSIGMA, G_RSIGMA, G_N };
static const sl_can_signal_desc_t plane_sigs[G_N] = {
    E2E_SIGNALS,
    {"Quality", 12U, 2U, false, 1, 1, 0, (int32_t)SL_CAN_GROUND_QUALITY_MAX, "",
     ground_quality_names, NV(ground_quality_names)},
    {"Clamped", 14U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"Height", 15U, 12U, false, SL_CAN_GROUND_HEIGHT_MM_PER_LSB, 1000, 0,
     SL_CAN_GROUND_HEIGHT_RAW_MAX, "m", NULL, 0U},
    {"Pitch", 27U, 11U, true, SL_CAN_GROUND_ANGLE_CDEG_PER_LSB, 100, SL_CAN_GROUND_ANGLE_RAW_MIN,
     SL_CAN_GROUND_ANGLE_RAW_MAX, "deg", NULL, 0U},
    {"Roll", 38U, 11U, true, SL_CAN_GROUND_ANGLE_CDEG_PER_LSB, 100, SL_CAN_GROUND_ANGLE_RAW_MIN,
     SL_CAN_GROUND_ANGLE_RAW_MAX, "deg", NULL, 0U},
    {"HeightSigma", 49U, 5U, false, SL_CAN_GROUND_HSIGMA_MM_PER_LSB, 1000, 0,
     SL_CAN_GROUND_SIGMA_RAW_MAX, "m", NULL, 0U},
    {"PitchSigma", 54U, 5U, false, SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB, 100, 0,
     SL_CAN_GROUND_SIGMA_RAW_MAX, "deg", NULL, 0U},
    {"RollSigma", 59U, 5U, false, SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB, 100, 0,
     SL_CAN_GROUND_SIGMA_RAW_MAX, "deg", NULL, 0U},
};

enum { Z_KIND = 2, Z_CLAMPED, Z_SECTOR, Z_AZ, Z_DIFF, Z_DIST, Z_SIGMA, Z_N };
static const sl_can_signal_desc_t hazard_sigs[Z_N] = {
    E2E_SIGNALS,
    {"Kind", 12U, 2U, false, 1, 1, 0, (int32_t)SL_CAN_GROUND_KIND_MAX, "", ground_kind_names,
     NV(ground_kind_names)},
    {"Clamped", 14U, 1U, false, 1, 1, 0, 1, "", NULL, 0U},
    {"Sector", 16U, 6U, false, 1, 1, 0, (int32_t)SL_CAN_HAZARD_SECTOR_MAX, "", NULL, 0U},
    {"Azimuth", 22U, 12U, false, SL_CAN_HAZARD_AZIMUTH_CDEG_PER_LSB, 100, 0,
     SL_CAN_HAZARD_AZIMUTH_RAW_MAX, "deg", NULL, 0U},
    {"HeightDiff", 34U, 11U, true, SL_CAN_HAZARD_DIFF_MM_PER_LSB, 1000, SL_CAN_HAZARD_DIFF_RAW_MIN,
     SL_CAN_HAZARD_DIFF_RAW_MAX, "m", NULL, 0U},
    {"Distance", 45U, 11U, false, SL_CAN_HAZARD_DIST_MM_PER_LSB, 1000, 0,
     SL_CAN_HAZARD_DIST_RAW_MAX, "m", NULL, 0U},
    {"Sigma", 56U, 8U, false, SL_CAN_HAZARD_SIGMA_MM_PER_LSB, 1000, 0, SL_CAN_HAZARD_SIGMA_RAW_MAX,
     "m", NULL, 0U},
};
#define GROUND_LAYOUT(sigs, n) sigs, n
#else
// The firmware configuration has no ground: its messages keep their identity (ids, Data
// IDs, the DBC's names) without a signal table, encoder or decoder.
#define GROUND_LAYOUT(sigs, n) NULL, 0U
#endif

static const sl_can_message_desc_t messages[SL_CAN_MSG_COUNT] = {
    {"PoleLean", SL_CAN_DATA_ID_POLE_LEAN, SL_CAN_CYCLE_MS_POLE_LEAN, 0U,
     (uint8_t)SL_CAN_SEND_CYCLIC_IF_ACTIVE, false, pole_sigs, P_N},
    {"LeanWarning", SL_CAN_DATA_ID_LEAN_WARNING, SL_CAN_CYCLE_MS_LEAN_WARNING, 0U,
     (uint8_t)SL_CAN_SEND_CYCLIC, false, warn_sigs, W_N},
    {"Status", SL_CAN_DATA_ID_STATUS, SL_CAN_CYCLE_MS_STATUS, SL_CAN_IDLE_CYCLE_MS_STATUS,
     (uint8_t)SL_CAN_SEND_CYCLIC, false, status_sigs, T_N},
    {"VehicleMotion", SL_CAN_DATA_ID_VEHICLE_MOTION, SL_CAN_CYCLE_MS_VEHICLE_MOTION, 0U,
     (uint8_t)SL_CAN_SEND_CYCLIC, true, motion_sigs, M_N},
    {"Health", SL_CAN_DATA_ID_HEALTH, SL_CAN_CYCLE_MS_HEALTH, SL_CAN_IDLE_CYCLE_MS_STATUS,
     (uint8_t)SL_CAN_SEND_CYCLIC, false, health_sigs, H_N},
    {"PoleTilt", SL_CAN_DATA_ID_POLE_TILT, SL_CAN_CYCLE_MS_POLE_TILT, 0U,
     (uint8_t)SL_CAN_SEND_CYCLIC_IF_ACTIVE, false, tilt_sigs, L_N},
    {"GroundPlane", SL_CAN_DATA_ID_GROUND_PLANE, SL_CAN_CYCLE_MS_GROUND_PLANE, 0U,
     (uint8_t)SL_CAN_SEND_CYCLIC, false, GROUND_LAYOUT(plane_sigs, G_N)},
    {"GroundHazard", SL_CAN_DATA_ID_GROUND_HAZARD, SL_CAN_CYCLE_MS_GROUND_HAZARD, 0U,
     (uint8_t)SL_CAN_SEND_CYCLIC_IF_ACTIVE, false, GROUND_LAYOUT(hazard_sigs, Z_N)},
};

const sl_can_message_desc_t *sl_can_layout(sl_can_msg_t m)
{
    return ((unsigned)m < (unsigned)SL_CAN_MSG_COUNT) ? &messages[m] : NULL;
}

// ---------------------------------------------------------------------------------------
// Bit packing (Intel order, byte by byte: endian-clean)

static void put_bits(uint8_t d[8], unsigned start, unsigned len, uint32_t v)
{
    unsigned i = 0;
    while (i < len) {
        const unsigned pos = start + i;
        const unsigned bit = pos % 8U;
        unsigned n = 8U - bit;
        if (n > len - i) {
            n = len - i;
        }
        const uint32_t mask = ((uint32_t)1U << n) - 1U;
        const uint32_t chunk = (v >> i) & mask;
        d[pos / 8U] = (uint8_t)((d[pos / 8U] & ~(mask << bit)) | (chunk << bit));
        i += n;
    }
}

static uint32_t get_bits(const uint8_t d[8], unsigned start, unsigned len)
{
    uint32_t v = 0;
    unsigned i = 0;
    while (i < len) {
        const unsigned pos = start + i;
        const unsigned bit = pos % 8U;
        unsigned n = 8U - bit;
        if (n > len - i) {
            n = len - i;
        }
        const uint32_t mask = ((uint32_t)1U << n) - 1U;
        v |= (((uint32_t)d[pos / 8U] >> bit) & mask) << i;
        i += n;
    }
    return v;
}

/// Write a raw value (already inside [raw_min, raw_max]) into its field.
static void put_sig(uint8_t d[8], const sl_can_signal_desc_t *s, int64_t raw)
{
    // Two's complement of a negative raw value in `length` bits, computed in int64.
    const int64_t field = (raw < 0) ? raw + ((int64_t)1 << s->length) : raw;
    put_bits(d, s->start, s->length, (uint32_t)field);
}

/// Read a field as its raw value (sign-extended for signed signals).
static int64_t get_sig(const uint8_t d[8], const sl_can_signal_desc_t *s)
{
    SL_ASSERT(s->length >= 1U && s->length <= 32U); // layout table invariant
    const uint32_t v = get_bits(d, s->start, s->length);
    if (s->is_signed && ((v >> (s->length - 1U)) & 1U) != 0U) {
        return (int64_t)v - ((int64_t)1 << s->length);
    }
    return (int64_t)v;
}

// ---------------------------------------------------------------------------------------
// Scaling (rounding place 3 of the house style)

/// round(x / d) with halves rounded up (towards +infinity); d > 0. Exact for the int64
/// range used here (|x| < 2^33).
static int64_t div_round_half_up(int64_t x, int64_t d)
{
    const int64_t n = 2 * x + d; // floor((2x + d) / 2d) = floor(x/d + 1/2)
    const int64_t dd = 2 * d;
    int64_t q = n / dd;
    if ((n % dd != 0) && (n < 0)) {
        q -= 1; // C division truncates towards zero: make it floor
    }
    return q;
}

/// Clamp a raw value to the signal's limits; set *clamped when it had to.
static int64_t clamp_raw(const sl_can_signal_desc_t *s, int64_t raw, bool *clamped)
{
    if (raw < (int64_t)s->raw_min) {
        *clamped = true;
        return s->raw_min;
    }
    if (raw > (int64_t)s->raw_max) {
        *clamped = true;
        return s->raw_max;
    }
    return raw;
}

/// Physical integer value -> clamped raw value -> field.
static void put_phys(uint8_t d[8], const sl_can_signal_desc_t *s, int64_t phys, int64_t per_lsb,
                     bool *clamped)
{
    put_sig(d, s, clamp_raw(s, div_round_half_up(phys, per_lsb), clamped));
}

/// An angle in 0.01 deg, any value -> raw steps of `per_lsb` in [0, 36000 / per_lsb).
static void put_azimuth(uint8_t d[8], const sl_can_signal_desc_t *s, int32_t az_cdeg,
                        int64_t per_lsb)
{
    int64_t a = (int64_t)az_cdeg % 36000;
    if (a < 0) {
        a += 36000;
    }
    // 359.95 deg rounds to 360.0 = 0: reduce the raw value modulo a full turn as well.
    const int64_t raw = div_round_half_up(a, per_lsb) % (36000 / per_lsb);
    put_sig(d, s, raw);
}

// ---------------------------------------------------------------------------------------
// Ids, transmitter

static bool id_valid(uint32_t id)
{
    if ((id & SL_CAN_DBC_EFF_BIT) != 0U) {
        return (id & ~SL_CAN_DBC_EFF_BIT) <= SL_CAN_EFF_MASK;
    }
    return id <= SL_CAN_SFF_MASK;
}

static void set_id(sl_can_frame_t *f, uint32_t id_dbc)
{
    if ((id_dbc & SL_CAN_DBC_EFF_BIT) != 0U) {
        f->id = id_dbc & SL_CAN_EFF_MASK;
        f->flags = SL_CAN_FLAG_EFF;
    } else {
        f->id = id_dbc;
        f->flags = 0U;
    }
}

const sl_can_e2e_cfg_t sl_can_e2e_defaults[SL_CAN_MSG_COUNT] = {
    {SL_CAN_DATA_ID_POLE_LEAN, (uint8_t)SL_CAN_E2E_MODE_BOTH},
    {SL_CAN_DATA_ID_LEAN_WARNING, (uint8_t)SL_CAN_E2E_MODE_BOTH},
    {SL_CAN_DATA_ID_STATUS, (uint8_t)SL_CAN_E2E_MODE_BOTH},
    {SL_CAN_DATA_ID_VEHICLE_MOTION, (uint8_t)SL_CAN_E2E_MODE_BOTH},
    {SL_CAN_DATA_ID_HEALTH, (uint8_t)SL_CAN_E2E_MODE_BOTH},
    {SL_CAN_DATA_ID_POLE_TILT, (uint8_t)SL_CAN_E2E_MODE_BOTH},
    {SL_CAN_DATA_ID_GROUND_PLANE, (uint8_t)SL_CAN_E2E_MODE_BOTH},
    {SL_CAN_DATA_ID_GROUND_HAZARD, (uint8_t)SL_CAN_E2E_MODE_BOTH},
};

_Static_assert(SL_BOARD_CAN_MSGS == SL_CAN_MSG_COUNT, "board CAN tables cover every message");

void sl_can_ids_default(sl_can_ids_t *ids)
{
    SL_ASSERT(ids != NULL);
    ids->id[SL_CAN_MSG_POLE_LEAN] = SL_CAN_ID_DEFAULT_POLE_LEAN;
    ids->id[SL_CAN_MSG_LEAN_WARNING] = SL_CAN_ID_DEFAULT_LEAN_WARNING;
    ids->id[SL_CAN_MSG_STATUS] = SL_CAN_ID_DEFAULT_STATUS;
    ids->id[SL_CAN_MSG_VEHICLE_MOTION] = SL_CAN_ID_DEFAULT_VEHICLE_MOTION;
    ids->id[SL_CAN_MSG_HEALTH] = SL_CAN_ID_DEFAULT_HEALTH;
    ids->id[SL_CAN_MSG_POLE_TILT] = SL_CAN_ID_DEFAULT_POLE_TILT;
    ids->id[SL_CAN_MSG_GROUND_PLANE] = SL_CAN_ID_DEFAULT_GROUND_PLANE;
    ids->id[SL_CAN_MSG_GROUND_HAZARD] = SL_CAN_ID_DEFAULT_GROUND_HAZARD;
    memcpy(ids->e2e, sl_can_e2e_defaults, sizeof ids->e2e);
}

void sl_can_ids_from_board(sl_can_ids_t *ids, const struct sl_board *board)
{
    SL_ASSERT(ids != NULL && board != NULL);
    ids->id[SL_CAN_MSG_POLE_LEAN] = board->can_id_pole_lean;
    ids->id[SL_CAN_MSG_LEAN_WARNING] = board->can_id_lean_warning;
    ids->id[SL_CAN_MSG_STATUS] = board->can_id_status;
    ids->id[SL_CAN_MSG_VEHICLE_MOTION] = board->can_id_vehicle_motion;
    ids->id[SL_CAN_MSG_HEALTH] = board->can_id_health;
    ids->id[SL_CAN_MSG_POLE_TILT] = board->can_id_pole_tilt;
    ids->id[SL_CAN_MSG_GROUND_PLANE] = board->can_id_ground_plane;
    ids->id[SL_CAN_MSG_GROUND_HAZARD] = board->can_id_ground_hazard;
    for (unsigned m = 0; m < (unsigned)SL_CAN_MSG_COUNT; m++) {
        ids->e2e[m].data_id = board->can_data_id[m];
        ids->e2e[m].mode = board->can_data_id_mode[m];
    }
}

/// Mode 11C sends the Data ID nibble in frame bits 12..15: only where no signal is (a
/// layout without its signal table in this configuration has them there).
static bool nibble_free(sl_can_msg_t m)
{
    const sl_can_message_desc_t *md = &messages[m];
    if (md->n_signals == 0U) {
        return false;
    }
    for (unsigned i = 0; i < md->n_signals; i++) {
        const unsigned lo = md->signals[i].start;
        const unsigned hi = lo + md->signals[i].length; // exclusive
        if (lo < 16U && hi > 12U) {
            return false;
        }
    }
    return true;
}

static bool e2e_cfg_valid(const sl_can_e2e_cfg_t *c, sl_can_msg_t m)
{
    if (c->mode == (uint8_t)SL_CAN_E2E_MODE_BOTH) {
        return true;
    }
    return c->mode == (uint8_t)SL_CAN_E2E_MODE_NIBBLE && c->data_id <= 0x0FFFU && nibble_free(m);
}

sl_err_t sl_can_tx_init(sl_can_tx_t *tx, const sl_can_ids_t *ids)
{
    if (tx == NULL || ids == NULL) {
        return SL_ERR_ARG;
    }
    for (unsigned i = 0; i < (unsigned)SL_CAN_MSG_COUNT; i++) {
        if (!id_valid(ids->id[i]) || !e2e_cfg_valid(&ids->e2e[i], (sl_can_msg_t)i)) {
            return SL_ERR_ARG;
        }
        for (unsigned j = 0; j < i; j++) {
            if (ids->id[i] == ids->id[j] || ids->e2e[i].data_id == ids->e2e[j].data_id) {
                return SL_ERR_ARG;
            }
        }
    }
    memset(tx, 0, sizeof *tx);
    tx->ids = *ids;
    return SL_OK;
}

/// Counter, CRC, id, dlc; advance the counter; count.
static void finish(sl_can_tx_t *tx, sl_can_msg_t m, uint8_t d[8], bool clamped,
                   sl_can_frame_t *out)
{
    const sl_can_message_desc_t *md = &messages[m];
    const sl_can_e2e_cfg_t *e2e = &tx->ids.e2e[m];
    const uint8_t ctr = tx->counter[m];
    put_sig(d, &md->signals[S_COUNTER], ctr);
    if (e2e->mode == (uint8_t)SL_CAN_E2E_MODE_NIBBLE) {
        put_bits(d, 12U, 4U, (uint32_t)(e2e->data_id >> 8) & 0x0FU); // 11C: bits 8..11
    }
    d[0] = sl_can_e2e_crc(e2e, d);
    tx->counter[m] = (uint8_t)((ctr + 1U) % SL_CAN_COUNTER_MODULO);
    tx->stats.frames++;
    if (clamped) {
        tx->stats.clamped_frames++;
    }
    set_id(out, tx->ids.id[m]);
    out->dlc = 8U;
    memcpy(out->data, d, 8U);
}

sl_err_t sl_can_encode_pole_lean(sl_can_tx_t *tx, const sl_can_pole_lean_t *in,
                                 sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = pole_sigs;
    uint8_t d[8] = {0};
    bool cl = false;
    uint32_t q = in->quality;
    if (q > SL_CAN_QUALITY_MAX) {
        q = SL_CAN_QUALITY_INVALID;
        cl = true;
    }
    put_sig(d, &s[P_QUALITY], q);
    put_sig(d, &s[P_TARGET], clamp_raw(&s[P_TARGET], in->target_id, &cl));
    put_azimuth(d, &s[P_AZ], in->azimuth_cdeg, SL_CAN_POLE_AZIMUTH_CDEG_PER_LSB);
    put_phys(d, &s[P_LEAN], in->lean_cdeg, SL_CAN_POLE_LEAN_CDEG_PER_LSB, &cl);
    put_phys(d, &s[P_SIGMA], in->lean_sigma_cdeg, SL_CAN_POLE_SIGMA_CDEG_PER_LSB, &cl);
    put_phys(d, &s[P_R1], in->range_inner_um, SL_CAN_POLE_RANGE_UM_PER_LSB, &cl); // um: one rounding
    put_phys(d, &s[P_R2], in->range_outer_um, SL_CAN_POLE_RANGE_UM_PER_LSB, &cl);
    put_sig(d, &s[P_CLAMPED], cl ? 1 : 0);
    finish(tx, SL_CAN_MSG_POLE_LEAN, d, cl, out);
    return SL_OK;
}

sl_err_t sl_can_encode_lean_warning(sl_can_tx_t *tx, const sl_can_lean_warning_t *in,
                                    sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = warn_sigs;
    uint8_t d[8] = {0};
    bool cl = false;
    uint32_t level = in->level;
    if (level > SL_CAN_LEVEL_MAX) {
        level = SL_CAN_LEVEL_DANGER; // never under-report a warning
        cl = true;
    }
    put_sig(d, &s[W_LEVEL], level);
    if (in->has_target) {
        uint32_t q = in->quality;
        if (q > SL_CAN_QUALITY_MAX) {
            q = SL_CAN_QUALITY_INVALID;
            cl = true;
        }
        put_sig(d, &s[W_HAS], 1);
        put_sig(d, &s[W_QUALITY], q);
        put_sig(d, &s[W_TARGET], clamp_raw(&s[W_TARGET], in->target_id, &cl));
        put_azimuth(d, &s[W_AZ], in->azimuth_cdeg, SL_CAN_WARN_AZIMUTH_CDEG_PER_LSB);
        put_phys(d, &s[W_LEAN], in->lean_cdeg, SL_CAN_WARN_LEAN_CDEG_PER_LSB, &cl);
        put_phys(d, &s[W_RANGE], in->range_um, SL_CAN_WARN_RANGE_UM_PER_LSB, &cl); // um: one rounding
        put_phys(d, &s[W_SIGMA], in->lean_sigma_cdeg, SL_CAN_WARN_SIGMA_CDEG_PER_LSB, &cl);
    } else {
        // No target, no lean: never VALID (0) by default (a consumer gating on VALID or
        // FILTERED must not see a usable lean here).
        put_sig(d, &s[W_QUALITY], SL_CAN_QUALITY_INVALID);
    }
    put_sig(d, &s[W_CLAMPED], cl ? 1 : 0);
    finish(tx, SL_CAN_MSG_LEAN_WARNING, d, cl, out);
    return SL_OK;
}

sl_err_t sl_can_encode_pole_tilt(sl_can_tx_t *tx, const sl_can_pole_tilt_t *in,
                                 sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = tilt_sigs;
    uint8_t d[8] = {0};
    bool cl = false;
    uint32_t q = in->quality;
    if (q > SL_CAN_TILT_QUALITY_MAX) {
        q = SL_CAN_TILT_INCONSISTENT;
        cl = true;
    }
    put_sig(d, &s[L_QUALITY], q);
    put_sig(d, &s[L_TARGET], clamp_raw(&s[L_TARGET], in->target_id, &cl));
    if (q == SL_CAN_TILT_FITTED || q == SL_CAN_TILT_AMBIGUOUS || q == SL_CAN_TILT_MIRROR) {
        put_phys(d, &s[L_TILT], in->tilt_cdeg, SL_CAN_TILT_CDEG_PER_LSB, &cl);
        put_azimuth(d, &s[L_DIR], in->direction_cdeg, SL_CAN_TILT_DIR_CDEG_PER_LSB);
        put_phys(d, &s[L_SIGMA], in->tilt_sigma_cdeg, SL_CAN_TILT_SIGMA_CDEG_PER_LSB, &cl);
        put_phys(d, &s[L_DIR_SIGMA], in->direction_sigma_cdeg, SL_CAN_TILT_DIR_SIGMA_CDEG_PER_LSB,
                 &cl);
        put_phys(d, &s[L_BX], in->base_x_um, SL_CAN_TILT_BASE_UM_PER_LSB, &cl); // um: one rounding
        put_phys(d, &s[L_BY], in->base_y_um, SL_CAN_TILT_BASE_UM_PER_LSB, &cl);
    }
    put_sig(d, &s[L_CLAMPED], cl ? 1 : 0);
    finish(tx, SL_CAN_MSG_POLE_TILT, d, cl, out);
    return SL_OK;
}

sl_err_t sl_can_encode_status(sl_can_tx_t *tx, const sl_can_status_t *in, sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = status_sigs;
    uint8_t d[8] = {0};
    bool sat = false;
    uint32_t link = in->link_state;
    if (link > SL_CAN_LINK_STATE_MAX) {
        link = SL_CAN_LINK_DISCONNECTED;
        sat = true;
    }
    put_sig(d, &s[T_LINK], link);
    put_sig(d, &s[T_ROT], clamp_raw(&s[T_ROT], in->rotations, &sat));
    put_sig(d, &s[T_AZMISS], clamp_raw(&s[T_AZMISS], in->azimuths_missing, &sat));
    put_sig(d, &s[T_RESYNC], clamp_raw(&s[T_RESYNC], in->decoder_resyncs, &sat));
    put_sig(d, &s[T_DROP], clamp_raw(&s[T_DROP], in->can_dropped, &sat));
    put_sig(d, &s[T_SAT], sat ? 1 : 0);
    finish(tx, SL_CAN_MSG_STATUS, d, sat, out);
    return SL_OK;
}

sl_err_t sl_can_encode_health(sl_can_tx_t *tx, const sl_can_health_t *in, sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = health_sigs;
    uint8_t d[8] = {0};
    bool sat = false;
    put_sig(d, &s[H_FAULT], (int64_t)(in->fault & SL_CAN_FAULT_DEFINED));
    put_sig(d, &s[H_RECONNECTS], clamp_raw(&s[H_RECONNECTS], in->reconnects, &sat));
    put_sig(d, &s[H_CAND_DROPPED], clamp_raw(&s[H_CAND_DROPPED], in->candidates_dropped, &sat));
    put_phys(d, &s[H_DRIFT], in->theta_drift_cdeg, SL_CAN_HEALTH_DRIFT_CDEG_PER_LSB, &sat);
    put_sig(d, &s[H_RESPONSE], clamp_raw(&s[H_RESPONSE], in->response_source, &sat));
    finish(tx, SL_CAN_MSG_HEALTH, d, sat, out);
    return SL_OK;
}

sl_err_t sl_can_encode_vehicle_motion(sl_can_tx_t *tx, const sl_can_vehicle_motion_t *in,
                                      sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = motion_sigs;
    uint8_t d[8] = {0};
    bool cl = false;
    put_sig(d, &s[M_SPEED_VALID], in->speed_valid ? 1 : 0);
    put_sig(d, &s[M_YAW_VALID], in->yaw_rate_valid ? 1 : 0);
    put_phys(d, &s[M_SPEED], in->speed_mm_s, SL_CAN_MOTION_SPEED_MM_S_PER_LSB, &cl);
    put_phys(d, &s[M_YAW], in->yaw_rate_cdeg_s, SL_CAN_MOTION_YAW_CDEG_S_PER_LSB, &cl);
    finish(tx, SL_CAN_MSG_VEHICLE_MOTION, d, cl, out);
    return SL_OK;
}

#if SL_CFG_GROUND
sl_err_t sl_can_encode_ground_plane(sl_can_tx_t *tx, const sl_can_ground_plane_t *in,
                                    sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = plane_sigs;
    uint8_t d[8] = {0};
    bool cl = false;
    uint32_t q = in->quality;
    if (q > SL_CAN_GROUND_QUALITY_MAX) {
        q = SL_CAN_GROUND_NONE;
        cl = true;
    }
    put_sig(d, &s[G_QUALITY], q);
    if (q != SL_CAN_GROUND_NONE) {
        put_phys(d, &s[G_HEIGHT], in->height_mm, SL_CAN_GROUND_HEIGHT_MM_PER_LSB, &cl);
        put_phys(d, &s[G_PITCH], in->pitch_cdeg, SL_CAN_GROUND_ANGLE_CDEG_PER_LSB, &cl);
        put_phys(d, &s[G_ROLL], in->roll_cdeg, SL_CAN_GROUND_ANGLE_CDEG_PER_LSB, &cl);
        put_phys(d, &s[G_HSIGMA], in->height_sigma_mm, SL_CAN_GROUND_HSIGMA_MM_PER_LSB, &cl);
        put_phys(d, &s[G_PSIGMA], in->pitch_sigma_cdeg, SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB, &cl);
        put_phys(d, &s[G_RSIGMA], in->roll_sigma_cdeg, SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB, &cl);
    }
    put_sig(d, &s[G_CLAMPED], cl ? 1 : 0);
    finish(tx, SL_CAN_MSG_GROUND_PLANE, d, cl, out);
    return SL_OK;
}

sl_err_t sl_can_encode_ground_hazard(sl_can_tx_t *tx, const sl_can_ground_hazard_t *in,
                                     sl_can_frame_t *out)
{
    if (tx == NULL || in == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    const sl_can_signal_desc_t *s = hazard_sigs;
    uint8_t d[8] = {0};
    bool cl = false;
    uint32_t kind = in->kind;
    if (kind > SL_CAN_GROUND_KIND_MAX) {
        kind = SL_CAN_GROUND_FLAT; // no kind the consumer knows: no hazard numbers either
        cl = true;
    }
    put_sig(d, &s[Z_KIND], kind);
    if (kind != SL_CAN_GROUND_FLAT) {
        put_sig(d, &s[Z_SECTOR], clamp_raw(&s[Z_SECTOR], in->sector, &cl));
        put_azimuth(d, &s[Z_AZ], in->azimuth_cdeg, SL_CAN_HAZARD_AZIMUTH_CDEG_PER_LSB);
        put_phys(d, &s[Z_DIFF], in->height_diff_mm, SL_CAN_HAZARD_DIFF_MM_PER_LSB, &cl);
        put_phys(d, &s[Z_DIST], in->distance_um, SL_CAN_HAZARD_DIST_UM_PER_LSB, &cl); // um: one rounding
        put_phys(d, &s[Z_SIGMA], in->sigma_mm, SL_CAN_HAZARD_SIGMA_MM_PER_LSB, &cl);
    }
    put_sig(d, &s[Z_CLAMPED], cl ? 1 : 0);
    finish(tx, SL_CAN_MSG_GROUND_HAZARD, d, cl, out);
    return SL_OK;
}
#endif // SL_CFG_GROUND

// ---------------------------------------------------------------------------------------
// E2E receiver and decoders

void sl_can_e2e_rx_init(sl_can_e2e_rx_t *rx, uint8_t max_delta_counter)
{
    SL_ASSERT(rx != NULL);
    memset(rx, 0, sizeof *rx);
    uint8_t m = max_delta_counter;
    if (m < 1U) {
        m = 1U;
    } else if (m > SL_CAN_COUNTER_MODULO - 1U) {
        m = (uint8_t)(SL_CAN_COUNTER_MODULO - 1U);
    }
    rx->max_delta_counter = m;
    rx->last_status = (uint8_t)SL_CAN_E2E_NO_NEW_DATA;
}

void sl_can_e2e_rx_reset(sl_can_e2e_rx_t *rx)
{
    SL_ASSERT(rx != NULL);
    rx->synced = false;
    rx->last_counter = 0U;
}

bool sl_can_e2e_status_ok(sl_can_e2e_status_t st)
{
    return st == SL_CAN_E2E_OK || st == SL_CAN_E2E_OK_SOME_LOST;
}

const char *sl_can_e2e_status_name(sl_can_e2e_status_t st)
{
    switch (st) {
    case SL_CAN_E2E_OK:
        return "OK";
    case SL_CAN_E2E_OK_SOME_LOST:
        return "OK_SOME_LOST";
    case SL_CAN_E2E_INITIAL:
        return "INITIAL";
    case SL_CAN_E2E_REPEATED:
        return "REPEATED";
    case SL_CAN_E2E_WRONG_SEQUENCE:
        return "WRONG_SEQUENCE";
    case SL_CAN_E2E_ERROR:
        return "ERROR";
    case SL_CAN_E2E_NO_NEW_DATA:
        return "NO_NEW_DATA";
    }
    return "?";
}

/// dlc, flags, CRC, Data ID nibble, counter 15. Returns SL_OK or SL_ERR_MALFORMED;
/// counts the reason when `rx`.
static sl_err_t frame_check(sl_can_e2e_rx_t *rx, const sl_can_e2e_cfg_t *cfg,
                            const sl_can_frame_t *f)
{
    if (f->dlc != 8U || (f->flags & (SL_CAN_FLAG_RTR | SL_CAN_FLAG_ERR)) != 0U) {
        if (rx != NULL) {
            rx->stats.bad_dlc++;
        }
        return SL_ERR_MALFORMED;
    }
    if (sl_can_e2e_crc(cfg, f->data) != f->data[0]) {
        if (rx != NULL) {
            rx->stats.crc_errors++;
        }
        return SL_ERR_MALFORMED;
    }
    if (cfg->mode == (uint8_t)SL_CAN_E2E_MODE_NIBBLE &&
        (unsigned)(f->data[1] >> 4) != ((unsigned)(cfg->data_id >> 8) & 0x0FU)) {
        if (rx != NULL) {
            rx->stats.bad_nibble++;
        }
        return SL_ERR_MALFORMED;
    }
    if ((f->data[1] & 0x0FU) >= SL_CAN_COUNTER_MODULO) {
        if (rx != NULL) {
            rx->stats.bad_counter++;
        }
        return SL_ERR_MALFORMED;
    }
    return SL_OK;
}

static sl_can_e2e_status_t e2e_status(sl_can_e2e_rx_t *rx, const sl_can_e2e_cfg_t *cfg,
                                      const sl_can_frame_t *f)
{
    if (f == NULL) {
        return SL_CAN_E2E_NO_NEW_DATA;
    }
    if (frame_check(rx, cfg, f) != SL_OK) {
        return SL_CAN_E2E_ERROR;
    }
    const uint8_t c = (uint8_t)(f->data[1] & 0x0FU);
    const bool synced = rx->synced;
    const unsigned delta = (c + SL_CAN_COUNTER_MODULO - rx->last_counter) % SL_CAN_COUNTER_MODULO;
    rx->synced = true;
    rx->last_counter = c; // Profile 11: the state follows every frame with a valid CRC
    if (!synced) {
        return SL_CAN_E2E_INITIAL;
    }
    if (delta == 0U) {
        return SL_CAN_E2E_REPEATED;
    }
    if (delta > 1U) {
        rx->stats.lost_frames += delta - 1U;
    }
    if (delta == 1U) {
        return SL_CAN_E2E_OK;
    }
    return (delta <= rx->max_delta_counter) ? SL_CAN_E2E_OK_SOME_LOST : SL_CAN_E2E_WRONG_SEQUENCE;
}

sl_can_e2e_status_t sl_can_e2e_check(sl_can_e2e_rx_t *rx, const sl_can_e2e_cfg_t *cfg,
                                     const sl_can_frame_t *f)
{
    SL_ASSERT(rx != NULL && cfg != NULL);
    if (rx == NULL || cfg == NULL) {
        return SL_CAN_E2E_ERROR;
    }
    const sl_can_e2e_status_t st = e2e_status(rx, cfg, f);
    rx->stats.status[st]++;
    rx->last_status = (uint8_t)st;
    return st;
}

static sl_err_t decode_check(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e, const void *out)
{
    if (f == NULL || e2e == NULL || out == NULL) {
        return SL_ERR_ARG;
    }
    return frame_check(NULL, e2e, f);
}

sl_err_t sl_can_decode_pole_lean(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                 sl_can_pole_lean_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = pole_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->quality = (uint8_t)get_sig(d, &s[P_QUALITY]);
    out->clamped = get_sig(d, &s[P_CLAMPED]) != 0;
    out->target_id = (uint8_t)get_sig(d, &s[P_TARGET]);
    out->azimuth_cdeg = (int32_t)(get_sig(d, &s[P_AZ]) * SL_CAN_POLE_AZIMUTH_CDEG_PER_LSB);
    out->lean_cdeg = (int32_t)(get_sig(d, &s[P_LEAN]) * SL_CAN_POLE_LEAN_CDEG_PER_LSB);
    out->lean_sigma_cdeg = (uint32_t)(get_sig(d, &s[P_SIGMA]) * SL_CAN_POLE_SIGMA_CDEG_PER_LSB);
    out->range_inner_um = (uint32_t)(get_sig(d, &s[P_R1]) * SL_CAN_POLE_RANGE_UM_PER_LSB);
    out->range_outer_um = (uint32_t)(get_sig(d, &s[P_R2]) * SL_CAN_POLE_RANGE_UM_PER_LSB);
    return SL_OK;
}

sl_err_t sl_can_decode_lean_warning(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                    sl_can_lean_warning_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = warn_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->level = (uint8_t)get_sig(d, &s[W_LEVEL]);
    out->clamped = get_sig(d, &s[W_CLAMPED]) != 0;
    out->has_target = get_sig(d, &s[W_HAS]) != 0;
    out->target_id = (uint8_t)get_sig(d, &s[W_TARGET]);
    out->quality = (uint8_t)get_sig(d, &s[W_QUALITY]);
    out->azimuth_cdeg = (int32_t)(get_sig(d, &s[W_AZ]) * SL_CAN_WARN_AZIMUTH_CDEG_PER_LSB);
    out->lean_cdeg = (int32_t)(get_sig(d, &s[W_LEAN]) * SL_CAN_WARN_LEAN_CDEG_PER_LSB);
    out->range_um = (uint32_t)(get_sig(d, &s[W_RANGE]) * SL_CAN_WARN_RANGE_UM_PER_LSB);
    out->lean_sigma_cdeg = (uint32_t)(get_sig(d, &s[W_SIGMA]) * SL_CAN_WARN_SIGMA_CDEG_PER_LSB);
    return SL_OK;
}

sl_err_t sl_can_decode_status(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                              sl_can_status_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = status_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->link_state = (uint8_t)get_sig(d, &s[T_LINK]);
    out->saturated = get_sig(d, &s[T_SAT]) != 0;
    out->rotations = (uint32_t)get_sig(d, &s[T_ROT]);
    out->azimuths_missing = (uint32_t)get_sig(d, &s[T_AZMISS]);
    out->decoder_resyncs = (uint32_t)get_sig(d, &s[T_RESYNC]);
    out->can_dropped = (uint32_t)get_sig(d, &s[T_DROP]);
    return SL_OK;
}

sl_err_t sl_can_decode_vehicle_motion(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                      sl_can_vehicle_motion_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = motion_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->speed_valid = get_sig(d, &s[M_SPEED_VALID]) != 0;
    out->yaw_rate_valid = get_sig(d, &s[M_YAW_VALID]) != 0;
    out->speed_mm_s = (int32_t)(get_sig(d, &s[M_SPEED]) * SL_CAN_MOTION_SPEED_MM_S_PER_LSB);
    out->yaw_rate_cdeg_s = (int32_t)(get_sig(d, &s[M_YAW]) * SL_CAN_MOTION_YAW_CDEG_S_PER_LSB);
    return SL_OK;
}

sl_err_t sl_can_decode_pole_tilt(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                 sl_can_pole_tilt_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = tilt_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->quality = (uint8_t)get_sig(d, &s[L_QUALITY]);
    out->clamped = get_sig(d, &s[L_CLAMPED]) != 0;
    out->target_id = (uint8_t)get_sig(d, &s[L_TARGET]);
    out->tilt_cdeg = (int32_t)(get_sig(d, &s[L_TILT]) * SL_CAN_TILT_CDEG_PER_LSB);
    out->direction_cdeg = (int32_t)(get_sig(d, &s[L_DIR]) * SL_CAN_TILT_DIR_CDEG_PER_LSB);
    out->tilt_sigma_cdeg = (uint32_t)(get_sig(d, &s[L_SIGMA]) * SL_CAN_TILT_SIGMA_CDEG_PER_LSB);
    out->direction_sigma_cdeg =
        (uint32_t)(get_sig(d, &s[L_DIR_SIGMA]) * SL_CAN_TILT_DIR_SIGMA_CDEG_PER_LSB);
    out->base_x_um = (int32_t)(get_sig(d, &s[L_BX]) * SL_CAN_TILT_BASE_UM_PER_LSB);
    out->base_y_um = (int32_t)(get_sig(d, &s[L_BY]) * SL_CAN_TILT_BASE_UM_PER_LSB);
    return SL_OK;
}

sl_err_t sl_can_decode_health(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                              sl_can_health_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = health_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->fault = (uint16_t)get_sig(d, &s[H_FAULT]);
    out->reconnects = (uint32_t)get_sig(d, &s[H_RECONNECTS]);
    out->candidates_dropped = (uint32_t)get_sig(d, &s[H_CAND_DROPPED]);
    out->theta_drift_cdeg = (int16_t)(get_sig(d, &s[H_DRIFT]) * SL_CAN_HEALTH_DRIFT_CDEG_PER_LSB);
    out->response_source = (uint8_t)get_sig(d, &s[H_RESPONSE]);
    return SL_OK;
}

#if SL_CFG_GROUND
sl_err_t sl_can_decode_ground_plane(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                    sl_can_ground_plane_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = plane_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->quality = (uint8_t)get_sig(d, &s[G_QUALITY]);
    out->clamped = get_sig(d, &s[G_CLAMPED]) != 0;
    out->height_mm = (int32_t)(get_sig(d, &s[G_HEIGHT]) * SL_CAN_GROUND_HEIGHT_MM_PER_LSB);
    out->pitch_cdeg = (int32_t)(get_sig(d, &s[G_PITCH]) * SL_CAN_GROUND_ANGLE_CDEG_PER_LSB);
    out->roll_cdeg = (int32_t)(get_sig(d, &s[G_ROLL]) * SL_CAN_GROUND_ANGLE_CDEG_PER_LSB);
    out->height_sigma_mm = (uint32_t)(get_sig(d, &s[G_HSIGMA]) * SL_CAN_GROUND_HSIGMA_MM_PER_LSB);
    out->pitch_sigma_cdeg =
        (uint32_t)(get_sig(d, &s[G_PSIGMA]) * SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB);
    out->roll_sigma_cdeg = (uint32_t)(get_sig(d, &s[G_RSIGMA]) * SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB);
    return SL_OK;
}

sl_err_t sl_can_decode_ground_hazard(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                     sl_can_ground_hazard_t *out)
{
    const sl_err_t e = decode_check(f, e2e, out);
    if (e != SL_OK) {
        return e;
    }
    const sl_can_signal_desc_t *s = hazard_sigs;
    const uint8_t *d = f->data;
    out->counter = (uint8_t)get_sig(d, &s[S_COUNTER]);
    out->kind = (uint8_t)get_sig(d, &s[Z_KIND]);
    out->clamped = get_sig(d, &s[Z_CLAMPED]) != 0;
    out->sector = (uint8_t)get_sig(d, &s[Z_SECTOR]);
    out->azimuth_cdeg = (int32_t)(get_sig(d, &s[Z_AZ]) * SL_CAN_HAZARD_AZIMUTH_CDEG_PER_LSB);
    out->height_diff_mm = (int32_t)(get_sig(d, &s[Z_DIFF]) * SL_CAN_HAZARD_DIFF_MM_PER_LSB);
    out->distance_um = (uint32_t)(get_sig(d, &s[Z_DIST]) * SL_CAN_HAZARD_DIST_UM_PER_LSB);
    out->sigma_mm = (uint32_t)(get_sig(d, &s[Z_SIGMA]) * SL_CAN_HAZARD_SIGMA_MM_PER_LSB);
    return SL_OK;
}
#endif // SL_CFG_GROUND

// ---------------------------------------------------------------------------------------
// VehicleMotion receiver

void sl_can_motion_rx_init(sl_can_motion_rx_t *rx, uint32_t id_dbc, const sl_can_e2e_cfg_t *cfg,
                           uint8_t max_delta_counter, uint64_t timeout_us)
{
    SL_ASSERT(rx != NULL && cfg != NULL);
    memset(rx, 0, sizeof *rx);
    rx->id_dbc = id_dbc;
    rx->cfg = *cfg;
    sl_can_e2e_rx_init(&rx->e2e, max_delta_counter);
    rx->timeout_us = timeout_us;
}

static bool id_matches(const sl_can_frame_t *f, uint32_t id_dbc)
{
    const bool eff = (id_dbc & SL_CAN_DBC_EFF_BIT) != 0U;
    if (eff != ((f->flags & SL_CAN_FLAG_EFF) != 0U)) {
        return false;
    }
    return f->id == (eff ? (id_dbc & SL_CAN_EFF_MASK) : id_dbc);
}

sl_err_t sl_can_motion_rx_feed(sl_can_motion_rx_t *rx, const sl_can_frame_t *f, uint64_t t_us)
{
    if (rx == NULL || f == NULL) {
        return SL_ERR_ARG;
    }
    if (!id_matches(f, rx->id_dbc)) {
        rx->stats.other_ids++;
        return SL_ERR_ARG;
    }
    // After a reception gap the counter sequence means nothing: the gap is a receive
    // cycle without new data, and the sequence restarts.
    if (rx->e2e.synced && t_us > rx->last_t_us && t_us - rx->last_t_us > rx->timeout_us) {
        (void)sl_can_e2e_check(&rx->e2e, &rx->cfg, NULL);
        sl_can_e2e_rx_reset(&rx->e2e);
        rx->have_value = false; // stale anyway (sl_can_motion_rx_get), and not renewed by a sync
    }
    const sl_can_e2e_status_t st = sl_can_e2e_check(&rx->e2e, &rx->cfg, f);
    switch (st) {
    case SL_CAN_E2E_OK:
    case SL_CAN_E2E_OK_SOME_LOST:
        (void)sl_can_decode_vehicle_motion(f, &rx->cfg, &rx->last); // cannot fail: checked
        rx->last_t_us = t_us;
        rx->have_value = true;
        return SL_OK;
    case SL_CAN_E2E_INITIAL:
        // First frame since init or a reception gap: nothing to check its counter against,
        // so a stale or repeated frame would pass as fresh. It only synchronises the
        // sequence; values are used from the next frame that continues it.
        rx->last_t_us = t_us;
        return SL_OK;
    case SL_CAN_E2E_REPEATED:
    case SL_CAN_E2E_WRONG_SEQUENCE:
        return SL_ERR_STATE; // no new data: neither the value nor its time is renewed
    case SL_CAN_E2E_ERROR:
    case SL_CAN_E2E_NO_NEW_DATA:
        break;
    }
    return SL_ERR_MALFORMED;
}

bool sl_can_motion_rx_get(const sl_can_motion_rx_t *rx, uint64_t now_us,
                          sl_can_vehicle_motion_t *out)
{
    if (rx == NULL || out == NULL || !rx->have_value) {
        return false;
    }
    if (now_us > rx->last_t_us && now_us - rx->last_t_us > rx->timeout_us) {
        return false;
    }
    *out = rx->last;
    return true;
}
