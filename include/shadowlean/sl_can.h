// SPDX-License-Identifier: MIT
/// @file sl_can.h
/// @brief CAN messages of shadowlean: frame type, message layouts, E2E protection,
///        encoders and decoders (integer only, endian-clean, no allocation).
///
/// The wire contract is this header plus the board file's `[can]` section (ids, bit rate).
/// The DBC file (`sl::make_dbc()`, host_tools/board/sl_dbc.h) is GENERATED from the layout
/// table below (`sl_can_layout()`), so the encoder, the decoder and the DBC cannot disagree.
///
/// Classic CAN, DLC 8, every signal little-endian (Intel, DBC `@1`): a signal with start
/// bit `s` and length `n` occupies frame bits s..s+n-1, where frame bit k is bit (k % 8) of
/// data byte k / 8 (so raw value bit 0 is at bit s). `u` = unsigned, `s` = two's complement.
/// physical = raw x factor (every offset is 0).
///
/// ## E2E protection (AUTOSAR E2E Profile 11) - every message
///
/// | byte/bits | signal  | meaning |
/// |-----------|---------|---------|
/// | 0 (0..7)  | Crc     | CRC-8 (below) of [Data ID low byte, Data ID high byte or 0x00, data[1], ..., data[7]] |
/// | 8..11     | Counter | per message type: 0, 1, ..., 14, 0, ... (modulo 15; 15 is never sent) |
/// | 12..15    | DataIdNibble | mode 11C only: bits 8..11 of the Data ID (the message's own signals otherwise) |
///
/// This is AUTOSAR E2E Profile 11 with its default offsets (CRC at bit 0, counter at bit
/// 8, Data ID nibble at bit 12), so a receiver that configures an AUTOSAR E2E library for
/// Profile 11 with the message's Data ID and mode accepts the frames as they are.
/// CRC: polynomial 0x1D (SAE J1850's, x^8+x^4+x^3+x^2+1), start value 0x00, no
/// reflection, no final XOR (the Profile 11 chaining of Crc_CalculateCRC8 comes to
/// exactly this), over 9 bytes: the 16-bit Data ID's low byte, then its high byte (mode
/// 11A "both") or 0x00 (mode 11C "nibble", where the Data ID's bits 8..11 travel in bits
/// 12..15 of the frame and its bits 12..15 must be 0), then data bytes 1..7 (byte 0, the
/// CRC itself, is skipped). The Data ID is per message and per board (board keys
/// `can.data_id_*` and `can.data_id_mode_*`, DBC attributes SlE2EDataId and SlE2EMode);
/// the defaults are SL_CAN_DATA_ID_* in mode 11A. Mode 11C needs bits 12..15 free: only
/// Health has them (sl_can_tx_init() refuses 11C for another message). A frame of the
/// wrong message type, or a frame copied to another message id, fails the CRC even when
/// its bytes are otherwise plausible.
///
/// Vectors of independent Profile 11 implementations (unit tests of the C core, the
/// Python package and the dissector): 8 zero bytes, Data ID 0x123, counter 0 -> CRC 0xCC
/// (11A) and, with byte 1 = 0x10, 0x2A (11C); counter 1: 0x91 (11A), 0x77 (11C).
/// Worked example (test_canmsg_crc_worked_example): a Status frame (Data ID 0x0053, 11A)
/// whose bytes 1..7 are `30 02 00 00 00 00 00` (Counter 0, LinkState 3 = STREAMING,
/// Rotations 2). CRC input = `53 00 30 02 00 00 00 00 00`, CRC = 0x93, so the frame is
/// `93 30 02 00 00 00 00 00`.
///
/// The counter starts at 0 after `sl_can_tx_init()` and advances by one per frame of that
/// message type (all PoleLean frames of a rotation share one counter). A receiver
/// (`sl_can_e2e_check()`) classifies every frame with the Profile 11 check statuses:
/// ERROR (dlc, flags, CRC, Data ID nibble or counter 15), REPEATED (counter step 0), OK
/// (step 1), OK_SOME_LOST (step 2..max_delta_counter), WRONG_SEQUENCE (a larger step),
/// NO_NEW_DATA (a check without a frame); the first frame after init or a reset is
/// INITIAL (nothing to compare its counter with).
///
/// ## PoleLean (board `can.id_pole_lean`, SHADOWLEAN -> VEHICLE, one frame per target)
///
/// | start | len | signal     | type | factor | range (physical)  | unit | note |
/// |------:|----:|------------|------|--------|-------------------|------|------|
/// |  0 | 8  | Crc        | u | 1    | 0..255         |     | E2E, Data ID 0x0051 |
/// |  8 | 4  | Counter    | u | 1    | 0..14          |     | E2E |
/// | 12 | 3  | Quality    | u | 1    | 0..4           |     | sl_can_quality_t |
/// | 15 | 1  | Clamped    | u | 1    | 0..1           |     | 1 = a value below hit its range limit |
/// | 16 | 4  | TargetId   | u | 1    | 0..15          |     | tracker id of the target |
/// | 20 | 11 | Azimuth    | u | 0.2  | 0..359.8       | deg | clockwise from vehicle forward |
/// | 31 | 10 | Lean       | s | 0.1  | -51.2..51.1    | deg | > 0: top leans towards the vehicle |
/// | 41 | 5  | LeanSigma  | u | 0.2  | 0..6.2         | deg | 1-sigma of Lean |
/// | 46 | 9  | RangeInner | u | 0.02 | 0..10.22       | m   | inner bound r1 of the return |
/// | 55 | 9  | RangeOuter | u | 0.02 | 0..10.22       | m   | outer bound r2 of the return |
///
/// Why these resolutions: the full wish list (0.1 deg 12-bit azimuth, 0.01 m ranges, an
/// 11-bit lean, a wide sigma) needs 73 bits. The radar's azimuth step is 0.9 deg and its
/// range bin 4.38 cm (per-bound sigma 1.26 cm), so 0.2 deg and 0.02 m steps stay well below
/// the sensor's own resolution; 10.22 m covers the ground shadow of every board (<= 6 m
/// slant range); a lean beyond +-51 deg (a fallen pole) is sent clamped with Clamped = 1,
/// and the LeanWarning frame carries the most severe lean at 0.05 deg over +-102 deg.
/// Lean and LeanSigma are meaningful only when Quality is VALID or FILTERED.
///
/// **Quality, one meaning for consumers** (PoleLean and LeanWarning alike): VALID (0) or
/// FILTERED (4) = Lean and LeanSigma are a usable estimate; AMBIGUOUS (1), OUT_OF_MODEL (2),
/// INVALID (3) = no lean number (Lean and LeanSigma are sent as 0). This module sends only
/// confirmed tracks, whose lean is always the tracker's filtered estimate: it sends
/// FILTERED, never VALID (VALID is reserved for a single-rotation estimate, e.g. from
/// another producer). A LeanWarning without a target (HasTarget = 0) carries INVALID, so a
/// consumer that gates on "VALID or FILTERED" never reads a lean that is not there.
///
/// ## LeanWarning (board `can.id_lean_warning`, the most severe target of the rotation)
///
/// | start | len | signal    | type | factor | range (physical) | unit | note |
/// |------:|----:|-----------|------|--------|------------------|------|------|
/// |  0 | 8  | Crc       | u | 1    | 0..255          |     | E2E, Data ID 0x0052 |
/// |  8 | 4  | Counter   | u | 1    | 0..14           |     | E2E |
/// | 12 | 2  | Level     | u | 1    | 0..2            |     | sl_can_level_t |
/// | 14 | 1  | Clamped   | u | 1    | 0..1            |     | |
/// | 15 | 1  | HasTarget | u | 1    | 0..1            |     | 0: no target; the fields below are 0 |
/// | 16 | 4  | TargetId  | u | 1    | 0..15           |     | |
/// | 20 | 12 | Azimuth   | u | 0.1  | 0..359.9        | deg | |
/// | 32 | 12 | Lean      | s | 0.05 | -102.4..102.35  | deg | |
/// | 44 | 11 | Range     | u | 0.01 | 0..20.47        | m   | inner bound r1 |
/// | 55 | 6  | LeanSigma | u | 0.1  | 0..6.3          | deg | |
/// | 61 | 3  | Quality   | u | 1    | 0..4            |     | sl_can_quality_t |
///
/// ## Status (board `can.id_status`, SHADOWLEAN -> VEHICLE, once per rotation while data arrives, every SL_CAN_IDLE_CYCLE_MS_STATUS without)
///
/// | start | len | signal          | type | range        | note |
/// |------:|----:|-----------------|------|--------------|------|
/// |  0 | 8  | Crc             | u | 0..255       | E2E, Data ID 0x0053 |
/// |  8 | 4  | Counter         | u | 0..14        | E2E |
/// | 12 | 3  | LinkState       | u | 0..4         | sl_can_link_state_t |
/// | 15 | 1  | Saturated       | u | 0..1         | 1 = a counter below is stuck at its maximum |
/// | 16 | 18 | Rotations       | u | 0..262143    | rotations processed (saturating) |
/// | 34 | 14 | AzimuthsMissing | u | 0..16383     | azimuths lost in gaps (saturating) |
/// | 48 | 8  | DecoderResyncs  | u | 0..255       | stream decoder resyncs (saturating) |
/// | 56 | 8  | CanDropped      | u | 0..255       | CAN frames dropped by the sinks (saturating) |
///
/// ## Health (board `can.id_health`, SHADOWLEAN -> VEHICLE, sent right after every Status)
///
/// | start | len | signal            | type | range    | note |
/// |------:|----:|-------------------|------|----------|------|
/// |  0 | 8  | Crc               | u | 0..255   | E2E, Data ID 0x0055 |
/// |  8 | 4  | Counter           | u | 0..14    | E2E |
/// | 12 | 4  | (reserved)        |   | 0        | the Data ID nibble in mode 11C |
/// | 16 | 16 | Fault             | u | bitfield | SL_CAN_FAULT_* below, one bit per condition |
/// | 32 | 8  | Reconnects        | u | 0..255   | radar link re-opened since start (saturating) |
/// | 40 | 12 | CandidatesDropped | u | 0..4095  | detection candidates dropped for lack of target slots (saturating) |
/// | 52 | 8  | ThetaDrift        | s | -12.8..12.7 deg, 0.1 deg | live theta minus the loaded calibration's (sl_drift.h); 0 while there is no estimate; saturating |
/// | 60 | 2  | ResponseSource    | u | 0..2     | the range response in use (sl_response.h): PRIOR (the board's), LEARNED (from this stream), CALIBRATED (the vehicle's calibration) |
/// | 62 | 2  | (reserved)        |   | 0        | |
///
/// Fault bits (the DBC carries a value table naming each bit's value): a bit is set in a
/// Health frame when its condition held at any time since the previous Health frame, or
/// still holds (configuration faults hold until a matching Configuration arrives). A
/// consumer should treat any set bit as "the pole-lean output is degraded or blind":
/// - bit0 CONFIG_MISMATCH: the radar's Configuration has another azimuth count or encoder
///   size than the board; every row is refused until a matching one arrives.
/// - bit1 NO_USABLE_ROWS: the link is up but no usable FFT row arrived since the previous
///   Health (malformed, empty, out-of-range or refused rows only; or none at all).
/// - bit2 MALFORMED_DATA: malformed messages, decoder resyncs, empty rows or encoder values
///   out of range were seen.
/// - bit3 LINK_FLAPPING: SL_CAN_FLAP_RECONNECTS reconnects within SL_CAN_FLAP_WINDOW_MS.
/// - bit4 CAN_OUTPUT_ERRORS: CAN frames were dropped by the sinks.
/// - bit5 RANGE_RESOLUTION_MISMATCH: the Configuration's bin size differs from the board's
///   by more than 1 % (ranges follow the radar's value; the board is not this installation).
/// - bit6 AZIMUTH_DISORDER: azimuths stepped back beyond the reorder window.
/// - bit7 CAN_RATE_LIMITED: frames were withheld by the hard output ceiling: token buckets
///   on the port's clock refilled with SL_CAN_MAX_DATA_FRAMES_PER_100MS data frames
///   (PoleLean, LeanWarning, PoleTilt, GroundPlane, GroundHazard) and
///   SL_CAN_MAX_STATUS_FRAMES_PER_100MS Status + Health frames per 100 ms,
///   holding at most SL_CAN_BURST_WINDOWS x that (the backlog of a ~3 s stall of a 4 Hz
///   radar). Sustained: 48 frames x ~130 bits per 100 ms, under 13 % of a 500 kbit/s bus;
///   in any 100 ms at most (SL_CAN_BURST_WINDOWS + 1) x 48 frames, whatever the input.
/// - bit8 TARGET_SLOTS_OVERFLOW: detection had more candidates than target slots.
/// - bit9 THETA_DRIFT: the live ground-return start says theta differs from the loaded
///   calibration's by more than 1 deg, for SL_DRIFT_PERSIST rotations (sl_drift.h): the
///   mount moved or the vehicle is loaded; every lean is skewed by about the ThetaDrift value.
/// - bit10 MOTION_E2E: VehicleMotion frames were rejected by the E2E check (ERROR,
///   REPEATED or WRONG_SEQUENCE; sl_can_motion_rx_feed()): the motion input is unreliable.
///
/// ## PoleTilt (board `can.id_pole_tilt`, SHADOWLEAN -> VEHICLE, one frame per tracked pole while driving)
///
/// The 3D tilt of a confirmed track fitted over the drive-by (sl_tilt.h, sl_tiltobs.h): sent
/// once per rotation for every confirmed track matched on the rotation that has an
/// observation history, i.e. only while a motion input is present (never when parked
/// without VehicleMotion / --motion).
///
/// | start | len | signal         | type | factor | range (physical) | unit | note |
/// |------:|----:|----------------|------|--------|------------------|------|------|
/// |  0 | 8  | Crc            | u | 1    | 0..255          |     | E2E, Data ID 0x0056 |
/// |  8 | 4  | Counter        | u | 1    | 0..14           |     | E2E |
/// | 12 | 3  | Quality        | u | 1    | 0..5            |     | sl_can_tilt_quality_t |
/// | 15 | 1  | Clamped        | u | 1    | 0..1            |     | 1 = a value below hit its range limit |
/// | 16 | 4  | TargetId       | u | 1    | 0..15           |     | tracker id (as PoleLean) |
/// | 20 | 8  | Tilt           | u | 0.1  | 0..25.5         | deg | psi, tilt from vertical |
/// | 28 | 9  | TiltDirection  | u | 1    | 0..359          | deg | direction the top leans towards, CCW from vehicle forward |
/// | 37 | 5  | TiltSigma      | u | 0.2  | 0..6.2          | deg | 1-sigma of Tilt |
/// | 42 | 6  | DirectionSigma | u | 1    | 0..63           | deg | 1-sigma of TiltDirection |
/// | 48 | 8  | BaseX          | s | 0.05 | -6.4..6.35      | m   | pole base, vehicle frame at the frame's time, x forward |
/// | 56 | 8  | BaseY          | s | 0.05 | -6.4..6.35      | m   | ... y left |
///
/// Quality: FITTED (0), AMBIGUOUS (1) and MIRROR (5) carry numbers; INSUFFICIENT_MOTION
/// (2), TOO_FEW (3) and INCONSISTENT (4) send every value as 0. An AMBIGUOUS fit (the
/// observations cannot tell the pole from its mirror image: sl_tilt.h) is an answer with
/// two readings: its frame carries the better-fitting one and is followed, in the same
/// rotation, by a second PoleTilt frame of the same TargetId with Quality MIRROR carrying
/// the other (tilt, direction, their sigmas, base); the pole is one of the two. MIRROR
/// never goes out alone. The fit runs per rotation on at most SL_CFG_TILT_FITS_PER_ROTATION
/// tracks; a frame carries the track's latest fit.
///
/// ## GroundPlane (board `can.id_ground_plane`, SHADOWLEAN -> VEHICLE, once per rotation while the ground is on)
///
/// The vehicle's attitude over the ground from the shadow's edge (sl_ground.h): the plane
/// fitted through the ground-return starts around the vehicle, filtered over rotations.
/// Sent once per rotation while the pipeline's ground is on (cfg.ground, SL_CFG_GROUND:
/// the host configuration), after LeanWarning and before Status.
///
/// | start | len | signal      | type | factor | range (physical) | unit | note |
/// |------:|----:|-------------|------|--------|------------------|------|------|
/// |  0 | 8  | Crc         | u | 1     | 0..255          |     | E2E, Data ID 0x0057 |
/// |  8 | 4  | Counter     | u | 1     | 0..14           |     | E2E |
/// | 12 | 2  | Quality     | u | 1     | 0..2            |     | sl_can_ground_quality_t |
/// | 14 | 1  | Clamped     | u | 1     | 0..1            |     | 1 = a value below hit its range limit |
/// | 15 | 12 | Height      | u | 0.002 | 0..8.19         | m   | radar above the plane, perpendicular to it |
/// | 27 | 11 | Pitch       | s | 0.02  | -20.48..20.46   | deg | nose down > 0 (ISO 8855) |
/// | 38 | 11 | Roll        | s | 0.02  | -20.48..20.46   | deg | right side down > 0 (ISO 8855) |
/// | 49 | 5  | HeightSigma | u | 0.005 | 0..0.155        | m   | 1-sigma of Height |
/// | 54 | 5  | PitchSigma  | u | 0.05  | 0..1.55         | deg | 1-sigma of Pitch |
/// | 59 | 5  | RollSigma   | u | 0.05  | 0..1.55         | deg | 1-sigma of Roll |
///
/// Quality: NONE (0) = no plane this rotation (too few sectors with ground; every value is
/// sent as 0); COARSE (1) = a plane whose sigmas exceed the module's good limits (20 mm,
/// 0.3 deg by default); GOOD (2) = within them. Pitch and roll are relative to the ground
/// under the ring (3-6 m around the vehicle), not to gravity. A sigma beyond its range is
/// sent as its maximum with Clamped = 1 (a bound: at least that).
///
/// ## GroundHazard (board `can.id_ground_hazard`, SHADOWLEAN -> VEHICLE, one frame per confirmed hazard)
///
/// One frame per sector of the ring whose ground departs from the plane (sl_ground.h:
/// DROP lower, STEP higher than the board's thresholds and 4 sigma, confirmed over
/// rotations with hysteresis), every rotation while it stays confirmed, right after the
/// GroundPlane frame of the rotation, in sector order.
///
/// | start | len | signal     | type | factor | range (physical) | unit | note |
/// |------:|----:|------------|------|--------|------------------|------|------|
/// |  0 | 8  | Crc        | u | 1     | 0..255          |     | E2E, Data ID 0x0058 |
/// |  8 | 4  | Counter    | u | 1     | 0..14           |     | E2E |
/// | 12 | 2  | Kind       | u | 1     | 0..2            |     | sl_can_ground_kind_t (DROP, STEP; FLAT never sent) |
/// | 14 | 1  | Clamped    | u | 1     | 0..1            |     | 1 = a value below hit its range limit |
/// | 16 | 6  | Sector     | u | 1     | 0..63           |     | sector of the ring (stable over rotations) |
/// | 22 | 12 | Azimuth    | u | 0.1   | 0..359.9        | deg | the sector's centre, clockwise from vehicle forward |
/// | 34 | 11 | HeightDiff | s | 0.005 | -5.12..5.115    | m   | the ground relative to the plane: < 0 lower (DROP), > 0 higher (STEP) |
/// | 45 | 11 | Distance   | u | 0.01  | 0..20.47        | m   | horizontal, radar to where the ground at the plane's level ends along the sector |
/// | 56 | 8  | Sigma      | u | 0.005 | 0..1.275        | m   | 1-sigma of HeightDiff (the sector's and the plane's) |
///
/// Bit 15 is reserved (0). HeightDiff and Sigma are the rotation's last plane fit's: a
/// hazard holds through its hysteresis (sl_ground.h) while HeightDiff lies inside the
/// threshold, and once the vehicle's whole ring is over the new level the plane follows it
/// (HeightDiff small or of the other sign) until the sector clears. Distance is measured
/// when the hazard is first voted for and moved back by the forward odometry while it holds
/// (sl_ground.h, "distance"); parked, the ring's point. The distance to the vehicle's front
/// is Distance less the radar's distance to the front along the sector.
///
/// ## VehicleMotion (board `can.id_vehicle_motion`, VEHICLE -> SHADOWLEAN, input)
///
/// | start | len | signal       | type | factor | range            | unit  | note |
/// |------:|----:|--------------|------|--------|------------------|-------|------|
/// |  0 | 8  | Crc          | u | 1    | 0..255           |       | E2E, Data ID 0x0054 |
/// |  8 | 4  | Counter      | u | 1    | 0..14            |       | E2E |
/// | 12 | 1  | SpeedValid   | u | 1    | 0..1             |       | |
/// | 13 | 1  | YawRateValid | u | 1    | 0..1             |       | |
/// | 16 | 16 | Speed        | s | 0.01 | -327.68..327.67  | m/s   | > 0 forward |
/// | 32 | 16 | YawRate      | s | 0.01 | -327.68..327.67  | deg/s | > 0 counter-clockwise from above (ISO 8855) |
///
/// Unlisted bits are reserved: sent as 0, ignored by the decoders.
///
/// ## Encoding rules (house style: rounding place 3)
/// raw = physical / factor, rounded half up (towards +infinity at exact halves), exactly
/// once from the finest integer unit available (ranges from um: r1 = 2.6499 m -> raw 132
/// = 2.64 m; never pre-rounded to mm first), then
/// range-checked: a value outside the signal's range is CLAMPED to the nearest limit and
/// the frame's Clamped (Status: Saturated) bit is set and `tx->stats.clamped_frames`
/// counted. Nothing is ever wrapped silently. Azimuths are angles: they are reduced modulo
/// 360 deg first (370 deg is 10 deg), which is not clamping.
///
/// Cost: every encode/decode is O(64) bit operations plus one 64-bit division per scaled
/// signal (libgcc __aeabi_ldivmod on 32-bit cores) and one 9-byte bitwise CRC; no
/// allocation. Stack (Cortex-M0, -Os, from -fstack-usage): encoder 64 bytes + 48 + 40 in
/// its helpers + the libgcc division, under 256 bytes; decoders under 96 bytes.
/// Flash (Cortex-M0, -Os): canmsg.c 7.2 KB (layout table and strings included), crc8.c 88 B.
/// Reentrant; one `sl_can_tx_t` per sender, one `sl_can_e2e_rx_t` per received message id.
/// Not ISR-safe on a shared `sl_can_tx_t` without a lock.
#ifndef SHADOWLEAN_SL_CAN_H
#define SHADOWLEAN_SL_CAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

struct sl_board;

// ---------------------------------------------------------------------------------------
// Frame

#define SL_CAN_FLAG_EFF 0x01U ///< 29-bit identifier
#define SL_CAN_FLAG_RTR 0x02U ///< remote transmission request (no data)
#define SL_CAN_FLAG_ERR 0x04U ///< error frame (SocketCAN; payload per linux/can/error.h)

#define SL_CAN_SFF_MASK 0x000007FFUL ///< 11-bit id mask
#define SL_CAN_EFF_MASK 0x1FFFFFFFUL ///< 29-bit id mask
/// Board/DBC id convention: a 29-bit id is stored with bit 31 set (DBC `BO_` style).
#define SL_CAN_DBC_EFF_BIT 0x80000000UL

/// One classic CAN frame. `id` is the bare 11- or 29-bit identifier (no flag bits in it);
/// the kind is in `flags` (SL_CAN_FLAG_*). `dlc` is 0..8; bytes past `dlc` are 0 in frames
/// the core produces. Plain value type, 16 bytes.
typedef struct sl_can_frame {
    uint32_t id;
    uint8_t dlc;
    uint8_t flags;
    uint8_t data[8];
} sl_can_frame_t;

// ---------------------------------------------------------------------------------------
// Messages, Data IDs, nominal cycle times

/// The message types of this module.
typedef enum sl_can_msg {
    SL_CAN_MSG_POLE_LEAN = 0,
    SL_CAN_MSG_LEAN_WARNING = 1,
    SL_CAN_MSG_STATUS = 2,
    SL_CAN_MSG_VEHICLE_MOTION = 3,
    SL_CAN_MSG_HEALTH = 4,
    SL_CAN_MSG_POLE_TILT = 5,
    SL_CAN_MSG_GROUND_PLANE = 6,
    SL_CAN_MSG_GROUND_HAZARD = 7,
    SL_CAN_MSG_COUNT = 8,
} sl_can_msg_t;

/// Default E2E Data IDs (16-bit, mode 11A), used when the board file does not set one.
#define SL_CAN_DATA_ID_POLE_LEAN 0x0051U
#define SL_CAN_DATA_ID_LEAN_WARNING 0x0052U
#define SL_CAN_DATA_ID_STATUS 0x0053U
#define SL_CAN_DATA_ID_VEHICLE_MOTION 0x0054U
#define SL_CAN_DATA_ID_HEALTH 0x0055U
#define SL_CAN_DATA_ID_POLE_TILT 0x0056U
#define SL_CAN_DATA_ID_GROUND_PLANE 0x0057U
#define SL_CAN_DATA_ID_GROUND_HAZARD 0x0058U ///< every message has its own Data ID

/// Default CAN ids (11-bit). They avoid the ids of a Continental ARS408 radar on the same
/// bus (its inputs and outputs 0x200-0x27F, 0x300-0x37F, 0x400-0x47F, 0x600-0x67F,
/// 0x700-0x77F: the bases 0x200-0x204, 0x300-0x301, 0x400-0x408, 0x600-0x60F, 0x700-0x702
/// plus 0x10 x its sensor id 0..7). docs/CAN.md says how to change them (board file).
#define SL_CAN_ID_DEFAULT_POLE_LEAN 0x5C0U
#define SL_CAN_ID_DEFAULT_LEAN_WARNING 0x5C1U
#define SL_CAN_ID_DEFAULT_STATUS 0x5C2U
#define SL_CAN_ID_DEFAULT_VEHICLE_MOTION 0x5B0U
#define SL_CAN_ID_DEFAULT_HEALTH 0x5C3U
#define SL_CAN_ID_DEFAULT_POLE_TILT 0x5C4U
#define SL_CAN_ID_DEFAULT_GROUND_PLANE 0x5C5U
#define SL_CAN_ID_DEFAULT_GROUND_HAZARD 0x5C6U

/// Default largest accepted counter step of the VehicleMotion receiver (one lost frame).
#define SL_CAN_MAX_DELTA_COUNTER_DEFAULT 2U

#define SL_CAN_COUNTER_MODULO 15U ///< counters run 0..14; 15 is invalid on the wire

/// Nominal cycle times (DBC GenMsgCycleTime): every sent message goes out once per radar
/// rotation while data arrives (CTS350-X: 4 Hz, 250 ms); VehicleMotion as expected from the
/// vehicle. Without data, Status + Health go out every SL_CAN_IDLE_CYCLE_MS_STATUS (DBC
/// attribute SlIdleCycleTime; the daemon's default status_period_ms).
#define SL_CAN_CYCLE_MS_POLE_LEAN 250U
#define SL_CAN_CYCLE_MS_LEAN_WARNING 250U
#define SL_CAN_CYCLE_MS_STATUS 250U
#define SL_CAN_CYCLE_MS_VEHICLE_MOTION 20U
#define SL_CAN_CYCLE_MS_HEALTH 250U
#define SL_CAN_CYCLE_MS_POLE_TILT 250U
#define SL_CAN_CYCLE_MS_GROUND_PLANE 250U
#define SL_CAN_CYCLE_MS_GROUND_HAZARD 250U
#define SL_CAN_IDLE_CYCLE_MS_STATUS 1000U

/// How a message is sent: the DBC attribute GenMsgSendType, whose value table is Vector's
/// (0 Cyclic ... 9 NoMsgSendType), so the numbers are the DBC's.
typedef enum sl_can_send_type {
    SL_CAN_SEND_CYCLIC = 0,           ///< every cycle (LeanWarning, Status, Health,
                                      ///< GroundPlane, VehicleMotion)
    SL_CAN_SEND_CYCLIC_IF_ACTIVE = 2, ///< every cycle while its object exists (PoleLean: one
                                      ///< per confirmed track and rotation; PoleTilt;
                                      ///< GroundHazard: one per confirmed hazard)
} sl_can_send_type_t;

// ---------------------------------------------------------------------------------------
// Value tables

/// PoleLean.Quality / LeanWarning.Quality.
typedef enum sl_can_quality {
    SL_CAN_QUALITY_VALID = 0,        ///< Lean is this rotation's estimate, inside the model
    SL_CAN_QUALITY_AMBIGUOUS = 1,    ///< rho below the ambiguity bound: no lean number
    SL_CAN_QUALITY_OUT_OF_MODEL = 2, ///< geometry outside the model (pole too short, base
                                     ///< outside the shadow, rho or theta out of domain)
    SL_CAN_QUALITY_INVALID = 3,      ///< the return is not a usable run of bins
    SL_CAN_QUALITY_FILTERED = 4,     ///< Lean/LeanSigma are the tracker's filtered estimate
                                     ///< over rotations (valid)
} sl_can_quality_t;
#define SL_CAN_QUALITY_MAX 4U

/// PoleTilt.Quality (the values of sl_tilt_quality_t, sl_tilt.h).
typedef enum sl_can_tilt_quality {
    SL_CAN_TILT_FITTED = 0,
    SL_CAN_TILT_AMBIGUOUS = 1,
    SL_CAN_TILT_INSUFFICIENT_MOTION = 2,
    SL_CAN_TILT_TOO_FEW = 3,
    SL_CAN_TILT_INCONSISTENT = 4,
    SL_CAN_TILT_MIRROR = 5, ///< the other reading of the AMBIGUOUS fit sent just before it
                            ///< with the same TargetId (not a sl_tilt_quality_t value)
} sl_can_tilt_quality_t;
#define SL_CAN_TILT_QUALITY_MAX 5U

/// GroundPlane.Quality (the values of sl_ground_quality_t, sl_ground.h).
typedef enum sl_can_ground_quality {
    SL_CAN_GROUND_NONE = 0,   ///< no plane: every value is sent as 0
    SL_CAN_GROUND_COARSE = 1, ///< a plane, sigmas beyond the module's good limits
    SL_CAN_GROUND_GOOD = 2,   ///< a plane within them
} sl_can_ground_quality_t;
#define SL_CAN_GROUND_QUALITY_MAX 2U

/// GroundHazard.Kind (the values of sl_ground_kind_t, sl_ground.h).
typedef enum sl_can_ground_kind {
    SL_CAN_GROUND_FLAT = 0, ///< no hazard (never sent by the module; every value is sent as 0)
    SL_CAN_GROUND_DROP = 1, ///< ground lower than the plane
    SL_CAN_GROUND_STEP = 2, ///< ground higher than the plane
} sl_can_ground_kind_t;
#define SL_CAN_GROUND_KIND_MAX 2U

/// LeanWarning.Level.
typedef enum sl_can_level {
    SL_CAN_LEVEL_NONE = 0,
    SL_CAN_LEVEL_CAUTION = 1,
    SL_CAN_LEVEL_DANGER = 2,
} sl_can_level_t;
#define SL_CAN_LEVEL_MAX 2U

/// Status.LinkState: state of the radar TCP link.
typedef enum sl_can_link_state {
    SL_CAN_LINK_DISCONNECTED = 0, ///< no TCP connection
    SL_CAN_LINK_CONNECTING = 1,   ///< TCP connect in progress
    SL_CAN_LINK_WAIT_CONFIG = 2,  ///< connected, waiting for the radar's configuration
    SL_CAN_LINK_STREAMING = 3,    ///< usable azimuth rows arriving (within the last second:
                                  ///< malformed, empty or refused rows do not count)
    SL_CAN_LINK_SILENT = 4,       ///< connected but no usable data for longer than the timeout
} sl_can_link_state_t;
#define SL_CAN_LINK_STATE_MAX 4U

/// Health.Fault bits (see "Health" above).
#define SL_CAN_FAULT_CONFIG_MISMATCH 0x0001U
#define SL_CAN_FAULT_NO_USABLE_ROWS 0x0002U
#define SL_CAN_FAULT_MALFORMED_DATA 0x0004U
#define SL_CAN_FAULT_LINK_FLAPPING 0x0008U
#define SL_CAN_FAULT_CAN_OUTPUT_ERRORS 0x0010U
#define SL_CAN_FAULT_RANGE_RESOLUTION_MISMATCH 0x0020U
#define SL_CAN_FAULT_AZIMUTH_DISORDER 0x0040U
#define SL_CAN_FAULT_CAN_RATE_LIMITED 0x0080U
#define SL_CAN_FAULT_TARGET_SLOTS_OVERFLOW 0x0100U
#define SL_CAN_FAULT_THETA_DRIFT 0x0200U
#define SL_CAN_FAULT_MOTION_E2E 0x0400U
#define SL_CAN_FAULT_DEFINED 0x07FFU ///< bits 11..15 are reserved (sent as 0)

/// LINK_FLAPPING: this many reconnects within this window.
#define SL_CAN_FLAP_RECONNECTS 3U
#define SL_CAN_FLAP_WINDOW_MS 30000U
/// Hard output ceiling per 100 ms (a rotation with 32 targets sends 33 data frames, with
/// the ground on one GroundPlane more and a GroundHazard per confirmed sector).
#define SL_CAN_MAX_DATA_FRAMES_PER_100MS 40U
#define SL_CAN_MAX_STATUS_FRAMES_PER_100MS 8U
#define SL_CAN_BURST_WINDOWS 3U

// ---------------------------------------------------------------------------------------
// Signal limits (raw values). The layout table and the encoders use these; tests too.

#define SL_CAN_TARGET_ID_MAX 15U
#define SL_CAN_POLE_AZIMUTH_CDEG_PER_LSB 20  ///< 0.2 deg
#define SL_CAN_POLE_AZIMUTH_RAW_MAX 1799     ///< 359.8 deg
#define SL_CAN_POLE_LEAN_CDEG_PER_LSB 10     ///< 0.1 deg
#define SL_CAN_POLE_LEAN_RAW_MIN (-512)
#define SL_CAN_POLE_LEAN_RAW_MAX 511
#define SL_CAN_POLE_SIGMA_CDEG_PER_LSB 20    ///< 0.2 deg
#define SL_CAN_POLE_SIGMA_RAW_MAX 31
#define SL_CAN_POLE_RANGE_MM_PER_LSB 20      ///< 0.02 m (layout/DBC factor 20/1000)
#define SL_CAN_POLE_RANGE_UM_PER_LSB 20000L  ///< 0.02 m: the encoder's step for um inputs
#define SL_CAN_POLE_RANGE_RAW_MAX 511

#define SL_CAN_WARN_AZIMUTH_CDEG_PER_LSB 10  ///< 0.1 deg
#define SL_CAN_WARN_AZIMUTH_RAW_MAX 3599
#define SL_CAN_WARN_LEAN_CDEG_PER_LSB 5      ///< 0.05 deg
#define SL_CAN_WARN_LEAN_RAW_MIN (-2048)
#define SL_CAN_WARN_LEAN_RAW_MAX 2047
#define SL_CAN_WARN_RANGE_MM_PER_LSB 10      ///< 0.01 m (layout/DBC factor 10/1000)
#define SL_CAN_WARN_RANGE_UM_PER_LSB 10000L  ///< 0.01 m: the encoder's step for um inputs
#define SL_CAN_WARN_RANGE_RAW_MAX 2047
#define SL_CAN_WARN_SIGMA_CDEG_PER_LSB 10    ///< 0.1 deg
#define SL_CAN_WARN_SIGMA_RAW_MAX 63

#define SL_CAN_TILT_CDEG_PER_LSB 10          ///< 0.1 deg
#define SL_CAN_TILT_RAW_MAX 255
#define SL_CAN_TILT_DIR_CDEG_PER_LSB 100     ///< 1 deg
#define SL_CAN_TILT_DIR_RAW_MAX 359
#define SL_CAN_TILT_SIGMA_CDEG_PER_LSB 20    ///< 0.2 deg
#define SL_CAN_TILT_SIGMA_RAW_MAX 31
#define SL_CAN_TILT_DIR_SIGMA_CDEG_PER_LSB 100 ///< 1 deg
#define SL_CAN_TILT_DIR_SIGMA_RAW_MAX 63
#define SL_CAN_TILT_BASE_MM_PER_LSB 50       ///< 0.05 m (layout/DBC factor 50/1000)
#define SL_CAN_TILT_BASE_UM_PER_LSB 50000L   ///< 0.05 m: the encoder's step for um inputs
#define SL_CAN_TILT_BASE_RAW_MIN (-128)
#define SL_CAN_TILT_BASE_RAW_MAX 127

#define SL_CAN_GROUND_HEIGHT_MM_PER_LSB 2      ///< 0.002 m (layout/DBC factor 2/1000)
#define SL_CAN_GROUND_HEIGHT_RAW_MAX 4095
#define SL_CAN_GROUND_ANGLE_CDEG_PER_LSB 2     ///< 0.02 deg (pitch, roll)
#define SL_CAN_GROUND_ANGLE_RAW_MIN (-1024)
#define SL_CAN_GROUND_ANGLE_RAW_MAX 1023
#define SL_CAN_GROUND_HSIGMA_MM_PER_LSB 5      ///< 0.005 m
#define SL_CAN_GROUND_ASIGMA_CDEG_PER_LSB 5    ///< 0.05 deg
#define SL_CAN_GROUND_SIGMA_RAW_MAX 31         ///< the plane's three sigmas (5 bits)
#define SL_CAN_HAZARD_SECTOR_MAX 63U
#define SL_CAN_HAZARD_AZIMUTH_CDEG_PER_LSB 10  ///< 0.1 deg
#define SL_CAN_HAZARD_AZIMUTH_RAW_MAX 3599
#define SL_CAN_HAZARD_DIFF_MM_PER_LSB 5        ///< 0.005 m
#define SL_CAN_HAZARD_DIFF_RAW_MIN (-1024)
#define SL_CAN_HAZARD_DIFF_RAW_MAX 1023
#define SL_CAN_HAZARD_DIST_MM_PER_LSB 10       ///< 0.01 m (layout/DBC factor 10/1000)
#define SL_CAN_HAZARD_DIST_UM_PER_LSB 10000L   ///< 0.01 m: the encoder's step for um inputs
#define SL_CAN_HAZARD_DIST_RAW_MAX 2047
#define SL_CAN_HAZARD_SIGMA_MM_PER_LSB 5       ///< 0.005 m
#define SL_CAN_HAZARD_SIGMA_RAW_MAX 255

#define SL_CAN_STATUS_ROTATIONS_MAX 262143UL ///< 18 bits
#define SL_CAN_STATUS_AZ_MISSING_MAX 16383UL ///< 14 bits
#define SL_CAN_STATUS_RESYNCS_MAX 255UL
#define SL_CAN_STATUS_DROPPED_MAX 255UL
#define SL_CAN_HEALTH_RECONNECTS_MAX 255UL
#define SL_CAN_HEALTH_CANDIDATES_DROPPED_MAX 4095UL
#define SL_CAN_HEALTH_DRIFT_CDEG_PER_LSB 10   ///< 0.1 deg
#define SL_CAN_HEALTH_DRIFT_RAW_MIN (-128)
#define SL_CAN_HEALTH_DRIFT_RAW_MAX 127
#define SL_CAN_RESPONSE_SOURCE_MAX 2U ///< Health.ResponseSource: sl_response_source_t

#define SL_CAN_MOTION_SPEED_MM_S_PER_LSB 10  ///< 0.01 m/s
#define SL_CAN_MOTION_YAW_CDEG_S_PER_LSB 1   ///< 0.01 deg/s
#define SL_CAN_MOTION_RAW_MIN (-32768)
#define SL_CAN_MOTION_RAW_MAX 32767

// ---------------------------------------------------------------------------------------
// Message contents in physical integer units (filled by the pipeline, returned by decoders).
// Ranges are in micrometres, the finest unit the pipeline has, so that each range is
// rounded exactly once on its way to the wire: um -> the signal's step, in the encoder
// (house style rounding place 3). Decoders return raw x step in um (e.g. RangeInner raw
// 132 -> 2,640,000 um).

/// One target (PoleLean). Encode reads the fields marked "in"; decode sets all fields.
typedef struct sl_can_pole_lean {
    uint8_t target_id;        ///< in: 0..15
    uint8_t quality;          ///< in: sl_can_quality_t (0..4)
    int32_t azimuth_cdeg;     ///< in: clockwise from vehicle forward; any value, reduced mod 36000
    uint32_t range_inner_um;  ///< in: inner bound r1, micrometres (rounded once, to 0.02 m)
    uint32_t range_outer_um;  ///< in: outer bound r2, micrometres (rounded once, to 0.02 m)
    int32_t lean_cdeg;        ///< in: > 0 = top towards the vehicle
    uint32_t lean_sigma_cdeg; ///< in: 1-sigma of lean
    bool clamped;             ///< decode: Clamped bit (ignored by encode: it is computed)
    uint8_t counter;          ///< decode: E2E counter (ignored by encode: from sl_can_tx_t)
} sl_can_pole_lean_t;

/// The most severe target (LeanWarning).
typedef struct sl_can_lean_warning {
    uint8_t level;            ///< in: sl_can_level_t
    bool has_target;          ///< in: false: no target; the target fields are sent as 0
    uint8_t target_id;        ///< in: 0..15
    uint8_t quality;          ///< in: sl_can_quality_t of that target
    int32_t azimuth_cdeg;     ///< in: reduced mod 36000
    uint32_t range_um;        ///< in: inner bound r1, micrometres (rounded once, to 0.01 m)
    int32_t lean_cdeg;        ///< in
    uint32_t lean_sigma_cdeg; ///< in
    bool clamped;             ///< decode only
    uint8_t counter;          ///< decode only
} sl_can_lean_warning_t;

/// The 3D tilt of one tracked pole (PoleTilt).
typedef struct sl_can_pole_tilt {
    uint8_t target_id;          ///< in: 0..15
    uint8_t quality;            ///< in: sl_can_tilt_quality_t (0..4)
    int32_t tilt_cdeg;          ///< in: psi, >= 0
    int32_t direction_cdeg;     ///< in: CCW from vehicle forward; reduced mod 36000
    uint32_t tilt_sigma_cdeg;   ///< in
    uint32_t direction_sigma_cdeg; ///< in
    int32_t base_x_um;          ///< in: vehicle frame, x forward (rounded once, to 0.05 m)
    int32_t base_y_um;          ///< in: y left
    bool clamped;               ///< decode only
    uint8_t counter;            ///< decode only
} sl_can_pole_tilt_t;

/// The ground plane of a rotation (GroundPlane). Heights in mm, the ground module's unit
/// (rounded once more, to the signal's step, by the encoder).
typedef struct sl_can_ground_plane {
    uint8_t quality;            ///< in: sl_can_ground_quality_t (0..2); NONE sends every value as 0
    int32_t height_mm;          ///< in: radar above the plane, perpendicular to it
    int32_t pitch_cdeg;         ///< in: nose down > 0
    int32_t roll_cdeg;          ///< in: right side down > 0
    uint32_t height_sigma_mm;   ///< in
    uint32_t pitch_sigma_cdeg;  ///< in
    uint32_t roll_sigma_cdeg;   ///< in
    bool clamped;               ///< decode only
    uint8_t counter;            ///< decode only
} sl_can_ground_plane_t;

/// One confirmed hazard of the ring (GroundHazard).
typedef struct sl_can_ground_hazard {
    uint8_t kind;               ///< in: sl_can_ground_kind_t (1 DROP, 2 STEP); FLAT sends
                                ///< every value as 0
    uint8_t sector;             ///< in: 0..63
    int32_t azimuth_cdeg;       ///< in: the sector's centre, clockwise from vehicle forward;
                                ///< reduced mod 36000
    int32_t height_diff_mm;     ///< in: ground above the plane (< 0 lower: DROP)
    uint32_t distance_um;       ///< in: horizontal distance from the radar (rounded once, to 0.01 m)
    uint32_t sigma_mm;          ///< in: 1-sigma of height_diff_mm
    bool clamped;               ///< decode only
    uint8_t counter;            ///< decode only
} sl_can_ground_hazard_t;

/// Module health (Status). Counters are totals since start; the encoder saturates them.
typedef struct sl_can_status {
    uint8_t link_state;        ///< in: sl_can_link_state_t
    uint32_t rotations;        ///< in: rotations processed
    uint32_t azimuths_missing; ///< in: azimuths lost in gaps
    uint32_t decoder_resyncs;  ///< in: Colossus decoder resynchronisations
    uint32_t can_dropped;      ///< in: CAN frames the sinks dropped
    bool saturated;            ///< decode only: a counter is at its maximum
    uint8_t counter;           ///< decode only
} sl_can_status_t;

/// Module health (Health), sent with every Status.
typedef struct sl_can_health {
    uint16_t fault;              ///< in: SL_CAN_FAULT_* bits (reserved bits are sent as 0)
    uint32_t reconnects;         ///< in: radar link reconnects since start (saturates at 255)
    uint32_t candidates_dropped; ///< in: candidates dropped for lack of target slots (4095)
    int16_t theta_drift_cdeg;    ///< in: ThetaDrift, 0.01 deg (sent in 0.1 deg, saturating)
    uint8_t response_source;     ///< in: ResponseSource, sl_response_source_t (0..2; more
                                 ///< is sent as 2, counted in stats.clamped_frames)
    uint8_t counter;             ///< decode only
} sl_can_health_t;

/// Vehicle motion (input from the vehicle; encoded here for tests and simulators).
typedef struct sl_can_vehicle_motion {
    int32_t speed_mm_s;        ///< > 0 forward
    int32_t yaw_rate_cdeg_s;   ///< 0.01 deg/s, > 0 counter-clockwise seen from above
    bool speed_valid;
    bool yaw_rate_valid;
    uint8_t counter;           ///< decode only
} sl_can_vehicle_motion_t;

// ---------------------------------------------------------------------------------------
// CRC and E2E (AUTOSAR E2E Profile 11)

/// Profile 11 Data ID mode.
typedef enum sl_can_e2e_mode {
    SL_CAN_E2E_MODE_BOTH = 0,   ///< 11A: both Data ID bytes go into the CRC; nothing is sent
    SL_CAN_E2E_MODE_NIBBLE = 1, ///< 11C: low byte and 0x00 go into the CRC; bits 8..11 of the
                                ///< Data ID are sent in frame bits 12..15 (Data ID <= 0x0FFF)
} sl_can_e2e_mode_t;

/// The E2E configuration of one message: its Data ID and mode.
typedef struct sl_can_e2e_cfg {
    uint16_t data_id; ///< 16-bit Data ID (not transmitted; <= 0x0FFF in mode 11C)
    uint8_t mode;     ///< sl_can_e2e_mode_t
} sl_can_e2e_cfg_t;

/// The default configuration of every message (SL_CAN_DATA_ID_*, mode 11A), indexed by
/// sl_can_msg_t.
extern const sl_can_e2e_cfg_t sl_can_e2e_defaults[SL_CAN_MSG_COUNT];

/// CRC-8 with polynomial 0x1D, no reflection: the register `crc` after `len` more bytes,
/// with no start value or final XOR applied (the caller chooses them: SAE J1850 is
/// `sl_can_crc8_0x1d(0xFF, d, n) ^ 0xFF`, check value 0x4B; Profile 11 starts at 0x00 and
/// applies no XOR). `data` may be NULL when `len` is 0. Cost: 8 shift/xor steps per byte.
uint8_t sl_can_crc8_0x1d(uint8_t crc, const uint8_t *data, size_t len);

/// The Profile 11 CRC a frame payload must carry in data[0] (data[0] is not read; in mode
/// 11C data[1]'s high nibble is read as it is: the encoder puts the Data ID nibble there
/// first). Returns 0 for a NULL `cfg`. Cost: one CRC over 9 bytes.
uint8_t sl_can_e2e_crc(const sl_can_e2e_cfg_t *cfg, const uint8_t data[8]);

/// Profile 11 check status of one received frame (or of a receive cycle without one).
typedef enum sl_can_e2e_status {
    SL_CAN_E2E_OK = 0,             ///< counter step 1: new data in sequence
    SL_CAN_E2E_OK_SOME_LOST = 1,   ///< counter step 2..max_delta_counter: new data, frames lost
    SL_CAN_E2E_INITIAL = 2,        ///< first valid frame after init or a reset: sequence synchronised
    SL_CAN_E2E_REPEATED = 3,       ///< counter step 0: the same data again
    SL_CAN_E2E_WRONG_SEQUENCE = 4, ///< counter step above max_delta_counter (the sequence
                                   ///< continues from this frame's counter)
    SL_CAN_E2E_ERROR = 5,          ///< dlc, RTR/error frame, CRC, Data ID nibble or counter 15
    SL_CAN_E2E_NO_NEW_DATA = 6,    ///< no frame in this receive cycle
} sl_can_e2e_status_t;
#define SL_CAN_E2E_STATUS_COUNT 7U

/// E2E receiver state for one message id. Initialise with sl_can_e2e_rx_init().
/// Fields read-only to the application.
typedef struct sl_can_e2e_rx {
    uint8_t last_counter;      ///< counter of the last frame with a valid CRC
    uint8_t max_delta_counter; ///< largest counter step that is still OK_SOME_LOST (1..14)
    bool synced;               ///< false until the first valid frame (or after a reset)
    uint8_t last_status;       ///< sl_can_e2e_status_t of the last check
    struct {
        uint32_t status[SL_CAN_E2E_STATUS_COUNT]; ///< checks per sl_can_e2e_status_t
        uint32_t crc_errors;    ///< ERROR: CRC mismatch
        uint32_t bad_dlc;       ///< ERROR: dlc != 8 or an RTR / error frame
        uint32_t bad_counter;   ///< ERROR: counter 15
        uint32_t bad_nibble;    ///< ERROR: Data ID nibble differs (mode 11C)
        uint32_t lost_frames;   ///< sum of (step - 1) over OK_SOME_LOST and WRONG_SEQUENCE
    } stats;
} sl_can_e2e_rx_t;

/// Reset the receiver: the next valid frame is INITIAL whatever its counter (use after a
/// reception timeout). Keeps the stats. O(1).
void sl_can_e2e_rx_reset(sl_can_e2e_rx_t *rx);

/// Zero everything and set the largest accepted counter step (clamped to 1..14). O(1).
void sl_can_e2e_rx_init(sl_can_e2e_rx_t *rx, uint8_t max_delta_counter);

/// Frames of this status carry new data a receiver may use (OK, OK_SOME_LOST).
bool sl_can_e2e_status_ok(sl_can_e2e_status_t st);

/// A constant name for a status ("OK", "OK_SOME_LOST", ..., "NO_NEW_DATA"; "?" otherwise).
const char *sl_can_e2e_status_name(sl_can_e2e_status_t st);

/// The Profile 11 check of one receive cycle (the caller has matched the id): `f` is the
/// frame received in this cycle, or NULL when none arrived (NO_NEW_DATA). Counts the
/// status in `rx->stats` and keeps it in `rx->last_status`. The counter state follows
/// every frame with a valid CRC (REPEATED and WRONG_SEQUENCE included), as in Profile 11.
/// A NULL `rx` or `cfg` is a caller bug (SL_ASSERT); it returns SL_CAN_E2E_ERROR when
/// assertions are off. Cost: one CRC over 9 bytes.
sl_can_e2e_status_t sl_can_e2e_check(sl_can_e2e_rx_t *rx, const sl_can_e2e_cfg_t *cfg,
                                     const sl_can_frame_t *f);

// ---------------------------------------------------------------------------------------
// Transmitter

/// Message identities in board/DBC style: 11-bit ids as is, 29-bit ids with bit 31 set;
/// with each message's E2E configuration.
typedef struct sl_can_ids {
    uint32_t id[SL_CAN_MSG_COUNT];          ///< indexed by sl_can_msg_t
    sl_can_e2e_cfg_t e2e[SL_CAN_MSG_COUNT]; ///< indexed by sl_can_msg_t
} sl_can_ids_t;

/// The defaults: SL_CAN_ID_DEFAULT_* and sl_can_e2e_defaults. O(1).
void sl_can_ids_default(sl_can_ids_t *ids);

/// The ids, Data IDs and modes of a board (`can_id_*`, `can_data_id*` fields). O(1).
void sl_can_ids_from_board(sl_can_ids_t *ids, const struct sl_board *board);

/// Sender state: ids and one E2E counter per message type. Fields read-only.
typedef struct sl_can_tx {
    sl_can_ids_t ids;
    uint8_t counter[SL_CAN_MSG_COUNT]; ///< counter of the NEXT frame of each type
    struct {
        uint32_t frames;         ///< frames encoded
        uint32_t clamped_frames; ///< frames with a clamped (or saturated) value
    } stats;
} sl_can_tx_t;

/// Initialise a sender. @return SL_ERR_ARG when an id is not a valid 11-bit id or 29-bit
/// id with bit 31 set, two ids are equal, two Data IDs are equal, a mode is not 11A or
/// 11C, or a message in mode 11C has a Data ID above 0x0FFF or signals in bits 12..15
/// (only Health has them free); SL_OK otherwise. O(1).
sl_err_t sl_can_tx_init(sl_can_tx_t *tx, const sl_can_ids_t *ids);

/// Encode one PoleLean frame into `out` (id, dlc 8, data, E2E) and advance the counter.
/// Out-of-range values are clamped and flagged (Clamped bit, stats.clamped_frames);
/// quality > 4 is sent as INVALID (3) with Clamped set; target_id > 15 is sent as 15 with
/// Clamped set. @return SL_OK, or SL_ERR_ARG for NULL pointers. O(1).
sl_err_t sl_can_encode_pole_lean(sl_can_tx_t *tx, const sl_can_pole_lean_t *in,
                                 sl_can_frame_t *out);

/// Encode one LeanWarning frame (same rules; level > 2 is sent as DANGER with Clamped set;
/// has_target false sends every target field as 0 and Quality INVALID).
sl_err_t sl_can_encode_lean_warning(sl_can_tx_t *tx, const sl_can_lean_warning_t *in,
                                    sl_can_frame_t *out);

/// Encode one PoleTilt frame (same rules as PoleLean: clamped values set Clamped; quality
/// > 5 is sent as INCONSISTENT with Clamped set; a quality other than FITTED, AMBIGUOUS or
/// MIRROR sends every value field as 0). The direction is an angle: reduced mod 360 deg, then rounded
/// (359.6 deg is sent as 0).
sl_err_t sl_can_encode_pole_tilt(sl_can_tx_t *tx, const sl_can_pole_tilt_t *in,
                                 sl_can_frame_t *out);

/// Encode one GroundPlane frame (same rules as PoleLean: clamped values set Clamped;
/// quality > 2 is sent as NONE with Clamped set; NONE sends every value as 0; a negative
/// height or sigma is clamped to 0). Defined with SL_CFG_GROUND only (sl_config.h: the
/// host configuration; the firmware configuration has no ground).
sl_err_t sl_can_encode_ground_plane(sl_can_tx_t *tx, const sl_can_ground_plane_t *in,
                                    sl_can_frame_t *out);

/// Encode one GroundHazard frame (same rules: kind > 2 is sent as FLAT with Clamped set;
/// FLAT sends every value as 0; sector > 63 is sent as 63 with Clamped set; the azimuth
/// is reduced mod 360 deg). Defined with SL_CFG_GROUND only.
sl_err_t sl_can_encode_ground_hazard(sl_can_tx_t *tx, const sl_can_ground_hazard_t *in,
                                     sl_can_frame_t *out);

/// Encode one Status frame. Counters saturate at their field maximum (Saturated bit);
/// link_state > 4 is sent as DISCONNECTED with Saturated set.
sl_err_t sl_can_encode_status(sl_can_tx_t *tx, const sl_can_status_t *in, sl_can_frame_t *out);

/// Encode one Health frame. Counters saturate at their field maximum (counted in
/// stats.clamped_frames); fault bits above SL_CAN_FAULT_DEFINED are not sent.
sl_err_t sl_can_encode_health(sl_can_tx_t *tx, const sl_can_health_t *in, sl_can_frame_t *out);

/// Encode one VehicleMotion frame (for tests, simulators and replay tools). Out-of-range
/// speed or yaw rate is clamped and counted in stats.clamped_frames (the message has no
/// Clamped bit: the vehicle owns it).
sl_err_t sl_can_encode_vehicle_motion(sl_can_tx_t *tx, const sl_can_vehicle_motion_t *in,
                                      sl_can_frame_t *out);

// ---------------------------------------------------------------------------------------
// Decoders: check dlc/flags, CRC, Data ID nibble and counter 15 with the message's E2E
// configuration `e2e` (not the sequence: use sl_can_e2e_check or sl_can_motion_rx_feed
// for that) and convert to physical integer units (raw x factor; e.g. Lean raw 123 ->
// 1230 cdeg, RangeInner raw 132 -> 2640000 um). They do not check the id.
// @return SL_OK or SL_ERR_MALFORMED (nothing useful written) / SL_ERR_ARG (NULL).

sl_err_t sl_can_decode_pole_lean(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                 sl_can_pole_lean_t *out);
sl_err_t sl_can_decode_lean_warning(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                    sl_can_lean_warning_t *out);
sl_err_t sl_can_decode_status(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                              sl_can_status_t *out);
sl_err_t sl_can_decode_vehicle_motion(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                      sl_can_vehicle_motion_t *out);
sl_err_t sl_can_decode_health(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                              sl_can_health_t *out);
sl_err_t sl_can_decode_pole_tilt(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                 sl_can_pole_tilt_t *out);
/// GroundPlane and GroundHazard: defined with SL_CFG_GROUND only (as their encoders).
sl_err_t sl_can_decode_ground_plane(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                    sl_can_ground_plane_t *out);
sl_err_t sl_can_decode_ground_hazard(const sl_can_frame_t *f, const sl_can_e2e_cfg_t *e2e,
                                     sl_can_ground_hazard_t *out);

/// VehicleMotion receiver for the motion-aware masks: id match, the Profile 11 check
/// (sl_can_e2e_check(), statuses counted in `e2e.stats`), latest used value with its time.
/// Values of OK and OK_SOME_LOST frames are used; REPEATED, WRONG_SEQUENCE and ERROR
/// frames are not. The first frame after init or after a reception gap (no used or
/// INITIAL frame for `timeout_us`) is INITIAL: it has no counter to be checked against, so a
/// stale or repeated frame would pass as fresh; it only synchronises the sequence and its
/// value is not used (values are used from the next frame that continues it, one frame
/// period later, 20 ms at the DBC's cycle time). A gap is one NO_NEW_DATA check (counted
/// when the next frame arrives) and also drops the last value.
/// Fields read-only to the application.
typedef struct sl_can_motion_rx {
    uint32_t id_dbc;             ///< expected id, board/DBC style
    sl_can_e2e_cfg_t cfg;        ///< Data ID and mode
    sl_can_e2e_rx_t e2e;         ///< statuses counted in e2e.stats (reception gaps: NO_NEW_DATA;
                                 ///< values used: OK + OK_SOME_LOST)
    sl_can_vehicle_motion_t last;///< last used value (valid when have_value)
    bool have_value;
    uint64_t last_t_us;          ///< time of the last used (or INITIAL) frame
    uint64_t timeout_us;         ///< no valid frame for this long: NO_NEW_DATA, sequence resets
    struct {
        uint32_t other_ids;      ///< frames with another id (ignored, counted)
    } stats;
} sl_can_motion_rx_t;

/// Initialise. `timeout_us` is both the staleness limit of sl_can_motion_rx_get() and
/// the gap after which the counter sequence restarts; `max_delta_counter` (1..14) is the
/// largest counter step that is OK_SOME_LOST rather than WRONG_SEQUENCE. O(1).
void sl_can_motion_rx_init(sl_can_motion_rx_t *rx, uint32_t id_dbc, const sl_can_e2e_cfg_t *cfg,
                           uint8_t max_delta_counter, uint64_t timeout_us);

/// Feed one received frame at time `t_us`. @return SL_OK (OK / OK_SOME_LOST: value used;
/// INITIAL: sequence synchronised), SL_ERR_ARG (another id: ignored, counted in
/// stats.other_ids), SL_ERR_MALFORMED (ERROR) or SL_ERR_STATE (REPEATED, WRONG_SEQUENCE);
/// the status is in `e2e.last_status`. O(1).
sl_err_t sl_can_motion_rx_feed(sl_can_motion_rx_t *rx, const sl_can_frame_t *f, uint64_t t_us);

/// The latest accepted motion if it is younger than the timeout at `now_us`. O(1).
/// @return true and `*out` set, or false (none yet, or stale).
bool sl_can_motion_rx_get(const sl_can_motion_rx_t *rx, uint64_t now_us,
                          sl_can_vehicle_motion_t *out);

// ---------------------------------------------------------------------------------------
// Layout table: the single description the DBC generator (host) reads. Static const data.

/// One entry of a value table.
typedef struct sl_can_value_name {
    uint32_t value;
    const char *name;
} sl_can_value_name_t;

/// One signal. physical = raw x factor_num / factor_den (offset 0). raw_min/raw_max are the
/// encoder's clamping limits (the DBC [min|max] is raw_min x factor .. raw_max x factor).
typedef struct sl_can_signal_desc {
    const char *name;
    uint8_t start;            ///< Intel start bit (LSB position)
    uint8_t length;           ///< bits
    bool is_signed;           ///< two's complement
    int16_t factor_num;       ///< 16 bits: every factor is a small fraction
    int16_t factor_den;
    int32_t raw_min;
    int32_t raw_max;
    const char *unit;         ///< "" when none
    const sl_can_value_name_t *values; ///< value table or NULL
    uint8_t n_values;
} sl_can_signal_desc_t;

/// One message.
typedef struct sl_can_message_desc {
    const char *name;         ///< DBC message name, e.g. "PoleLean"
    uint16_t data_id;         ///< default E2E Data ID (the board's may differ)
    uint16_t cycle_ms;        ///< nominal cycle time (GenMsgCycleTime)
    uint16_t idle_cycle_ms;   ///< cycle without radar data (SlIdleCycleTime); 0 = not sent then
    uint8_t send_type;        ///< sl_can_send_type_t (GenMsgSendType)
    bool to_shadowlean;       ///< true: received (VehicleMotion); false: sent
    const sl_can_signal_desc_t *signals;
    uint8_t n_signals;
} sl_can_message_desc_t;

/// Layout of message `m` (NULL when out of range). O(1). Without SL_CFG_GROUND (the
/// firmware configuration) GroundPlane and GroundHazard have their name, Data ID and
/// cycle but no signals (n_signals 0): the DBC is generated in the host configuration.
const sl_can_message_desc_t *sl_can_layout(sl_can_msg_t m);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_CAN_H
