// SPDX-License-Identifier: MIT
/// @file sl_board.h
/// @brief One installation (vehicle + radar): constants and generated per-azimuth tables.
///
/// A board is described by `boards/<name>/board.ini` (the single source of truth). The
/// host generator `sl-tables` turns it into `boards/<name>/sl_board_<name>.{c,h}`, which
/// are committed and linked into `sl_core`. The core only reads `sl_board_t`; it never
/// parses the INI. All fields are integers with their unit in the name.
///
/// Azimuth index i (0..azimuths-1) is the i-th azimuth of a rotation, at encoder tick
/// i * encoder_size / azimuths, clockwise seen from above, 0 = the radar's encoder zero.
/// The board's `radar_yaw_cdeg` gives the direction of encoder zero relative to the
/// vehicle's forward axis (clockwise positive, seen from above).
#ifndef SHADOWLEAN_SL_BOARD_H
#define SHADOWLEAN_SL_BOARD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_config.h"
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_response.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Messages with a CAN id, Data ID and mode on a board (SL_CAN_MSG_COUNT in sl_can.h).
#define SL_BOARD_CAN_MSGS 8

/// A board: read-only constants, usually `static const` in flash.
typedef struct sl_board {
    const char *name;              ///< e.g. "paper-sim"
    // --- radar installation
    uint32_t radar_height_um;      ///< radar phase centre above flat ground
    int32_t radar_x_um;            ///< radar position on the vehicle: forward of origin
    int32_t radar_y_um;            ///< radar position on the vehicle: left of origin
    int32_t radar_yaw_cdeg;        ///< encoder zero relative to vehicle forward, clockwise
    int32_t beta_up_cdeg;          ///< upper emission bound, elevation (CTS350-X: +300)
    int32_t lower_bound_cdeg;      ///< lower emission bound, depression (CTS350-X: 3500)
    uint16_t azimuths;             ///< azimuths per rotation (400)
    uint16_t encoder_size;         ///< encoder ticks per rotation (5600)
    uint32_t bin_size_um;          ///< range bin size (0.0438 m = 43800)
    uint16_t range_bins;           ///< bins per azimuth in the radar's configuration
    uint16_t roi_bins;             ///< bins kept (region of interest), <= SL_CFG_ROI_BINS
    uint32_t max_message_bytes;    ///< largest acceptable Colossus payload for this radar
    // --- detection parameters (used by the detection pipeline)
    uint16_t near_exclusion_bins;  ///< near-field leakage band: bins [0, this) never targets
    uint16_t threshold;            ///< power threshold (8-bit scale) for "occupied"
    uint8_t mask_frames;           ///< consistency window n, 1..SL_CFG_MASK_FRAMES_MAX
    uint8_t max_targets;           ///< targets per rotation, <= SL_CFG_MAX_TARGETS
    uint32_t pole_radius_um;       ///< radius correction (0 = estimate from width / none)
    uint16_t range_sigma_um;       ///< per-bound range uncertainty for sigma(alpha)
    uint16_t theta_sigma_cdeg;     ///< calibration uncertainty of theta for sigma(alpha)
    int32_t caution_lean_cdeg;     ///< warning level CAUTION at |lean| >= this
    int32_t danger_lean_cdeg;      ///< warning level DANGER at lean towards >= this
    uint32_t track_timeout_us;     ///< drop a track not seen for this long
    uint8_t elong_points;          ///< entries in the elongation table (0 = no correction)
    /// Elongation table d(r), keyed by the OBSERVED outer bound r2 (slant range after the
    /// half-bin correction, before removing d): detection looks d up with what it measures.
    /// Piecewise linear between points, constant beyond the ends.
    uint32_t elong_range_um[SL_CFG_MAX_ELONG_POINTS]; ///< ascending observed r2
    int32_t elong_d_um[SL_CFG_MAX_ELONG_POINTS];      ///< outward bias d at each r2
    // --- CAN
    uint32_t can_bitrate;          ///< bit/s
    uint32_t can_id_pole_lean;     ///< 11-bit ids, or 29-bit ids with bit 31 set (DBC style;
                                   ///< board file: `0x18FF5A00 ext`)
    uint32_t can_id_lean_warning;
    uint32_t can_id_status;
    uint32_t can_id_vehicle_motion;
    uint32_t can_id_health;        ///< Health message (required board key can.id_health)
    uint32_t can_id_pole_tilt;     ///< PoleTilt message (required board key can.id_pole_tilt)
    uint32_t can_id_ground_plane;  ///< GroundPlane message (required board key can.id_ground_plane)
    uint32_t can_id_ground_hazard; ///< GroundHazard message (required board key
                                   ///< can.id_ground_hazard)
    /// E2E Profile 11 Data ID of each message (board keys can.data_id_*), indexed by
    /// sl_can_msg_t (PoleLean, LeanWarning, Status, VehicleMotion, Health, PoleTilt,
    /// GroundPlane, GroundHazard).
    uint16_t can_data_id[SL_BOARD_CAN_MSGS];
    /// E2E Profile 11 Data ID mode of each message (sl_can_e2e_mode_t: 0 = 11A both,
    /// 1 = 11C nibble; board keys can.data_id_mode_*), indexed as can_data_id.
    uint8_t can_data_id_mode[SL_BOARD_CAN_MSGS];
    /// VehicleMotion receiver: largest accepted counter step (1..14; board key
    /// can.max_delta_counter_vehicle_motion). Steps 2..this are OK_SOME_LOST, larger ones
    /// WRONG_SEQUENCE (sl_can.h).
    uint8_t can_max_delta_counter_motion;
    // --- generated per-azimuth tables, `azimuths` entries each
    sl_vscale_t value_scale;       ///< what the 8-bit values are (board `response.value_scale`)
    /// The range response a point return makes before one is learned from the stream:
    /// SL_RESP_TAPS drops below the centre, log2 power Q8 (sl_response.h); board
    /// `response.prior` = cts350x (the lobe measured on the CTS350-X) or ideal (one bin).
    /// NULL: the built-in CTS350-X lobe.
    const uint16_t *response_prior_q8;
    uint8_t response_calibrated;   ///< 1: response_prior_q8 is the vehicle's calibration's
                                   ///< (sl_calblob.h), used as SL_RESPONSE_CALIBRATED
    const sl_incline_geom_t *geom; ///< trig + branch bounds per azimuth
    const int16_t *theta_cdeg;     ///< opening angle theta per azimuth, 0.01 deg
    const uint32_t *shadow_um;     ///< ground shadow radius R = H / tan(theta) per azimuth
    const uint16_t *shadow_bins;   ///< last range bin wholly inside the ground shadow
} sl_board_t;

/// Number of boards linked into this build. O(1).
size_t sl_board_count(void);

/// Board number `i` (0..count-1), or NULL. O(1).
const sl_board_t *sl_board_at(size_t i);

/// Board by name ("paper-sim"), or NULL when not linked in. O(boards x name length).
const sl_board_t *sl_board_find(const char *name);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_BOARD_H
