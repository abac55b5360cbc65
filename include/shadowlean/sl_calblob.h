// SPDX-License-Identifier: MIT
/// @file sl_calblob.h
/// @brief Per-vehicle calibration as data: a versioned, CRC-protected binary blob holding the
/// tables the core uses, validated against the compiled-in (nominal) board at run time.
///
/// A fleet runs one firmware image; each vehicle keeps its own calibration (measured with
/// `sl-calib`, converted by `sl-tables --calibration F --blob OUT`) in a flash sector or NVM,
/// separate from code. `sl_calblob_open()` validates the blob against the nominal board
/// (`sl_board_find(name)`) and yields an `sl_board_t` view: the nominal board with the
/// calibrated scalars and per-azimuth tables. Hand that view to `sl_pipeline_init()` like any
/// board (nothing of the blob is copied into `sl_pipeline_t`). The compiled-in board stays the
/// default: without a blob nothing changes.
///
/// ## Ownership and zero copy
/// The view's per-azimuth arrays point INTO the blob when the target is little-endian and the
/// blob starts on a 4-byte boundary (an ECU's flash sector): the blob must then stay valid
/// and unchanged while the view (and a pipeline using it) lives. Otherwise (big-endian s390x,
/// a blob read at an odd address) the arrays are decoded into the caller's workspace
/// (`sl_calblob_ws_t`, 19.3 KB for 400 azimuths; may be NULL when zero copy is known to
/// apply), which must then outlive the view. The same holds for the response section. The view's `name` is the nominal board's.
///
/// ## Format (version 1; all integers little-endian; offsets in bytes)
///
/// | offset | size | field |
/// |---|---|---|
/// | 0 | 4 | magic "SLCB" |
/// | 4 | 2 | format version (SL_CALBLOB_VERSION) |
/// | 6 | 2 | header size (SL_CALBLOB_HEADER_BYTES) |
/// | 8 | 4 | total size, header + payload = header + azimuths x 48 (+ the response section) |
/// | 12 | 4 | CRC-32 (IEEE 802.3: reflected poly 0xEDB88320, init and xorout 0xFFFFFFFF) over bytes [0, 12) then [16, total) |
/// | 16 | 32 | board name, NUL padded (must equal the nominal board's) |
/// | 48 | 4 | board identity: sl_calblob_board_id() of the nominal board |
/// | 52 | 2 | azimuths (must equal the nominal board's) |
/// | 54 | 2 | flags: bit 0 SL_CALBLOB_FLAG_RESPONSE (a response section follows); others 0 |
/// | 56 | 4 | radar_height_um |
/// | 60 | 4 | pole_radius_um |
/// | 64 | 2 | near_exclusion_bins |
/// | 66 | 2 | range_sigma_um |
/// | 68 | 2 | theta_sigma_cdeg |
/// | 70 | 1 | elong_points (<= SL_CFG_MAX_ELONG_POINTS and <= 16) |
/// | 71 | 1 | reserved (0) |
/// | 72 | 64 | elong_range_um[16] (u32; unused entries 0) |
/// | 136 | 64 | elong_d_um[16] (i32) |
/// | 200 | 8 | reserved (0) |
/// | 208 | 40 x az | geom: sl_incline_geom_t per azimuth, its ten 32-bit fields in declaration order |
/// | ... | 4 x az | shadow_um (u32) |
/// | ... | 2 x az | theta_cdeg (i16) |
/// | ... | 2 x az | shadow_bins (u16) |
/// | ... | 2 | with SL_CALBLOB_FLAG_RESPONSE: taps (must be SL_RESP_TAPS) |
/// | ... | 2 x taps | the range response measured on this vehicle's radar: drops below the centre, log2 power Q8 (sl_response.h) |
///
/// Identity fields (cannot be calibrated; a blob made for another installation is refused):
/// name, azimuths, encoder_size, bin_size_um, range_bins, roi_bins, radar position and yaw,
/// beta_up_cdeg, lower_bound_cdeg. Everything else is taken from the nominal board (CAN ids,
/// thresholds, warning levels, ...). A response section makes the view's
/// `response_prior_q8` the calibration's (`response_calibrated` 1): the pipeline starts from
/// it as SL_RESPONSE_CALIBRATED; without one the nominal board's prior stays.
///
/// ## Checks, in this order, one error each (`info->what` names the field, `info->index`
/// the azimuth or table entry; the view is left untouched on any error: never used)
/// - SL_ERR_ARG: NULL blob / nominal / out.
/// - SL_ERR_CAL_SIZE: shorter than the header, or total size / header size inconsistent with
///   the length given or with the azimuth count (truncated or padded).
/// - SL_ERR_CAL_MAGIC: not "SLCB".
/// - SL_ERR_CAL_VERSION: a format version this core does not read.
/// - SL_ERR_CAL_CRC: CRC-32 mismatch (any flipped bit).
/// - SL_ERR_CAL_BOARD: the name differs from the nominal board's.
/// - SL_ERR_CAL_AZIMUTHS: azimuth count differs from the nominal board's (or exceeds
///   SL_CFG_MAX_AZIMUTHS).
/// - SL_ERR_CAL_BOARD: the identity hash differs (same name, another installation).
/// - SL_ERR_CAL_VALUE: a value out of range: radar height outside [0.2, 20] m; theta outside
///   [SL_INCLINE_THETA_MIN_CDEG, lower_bound_cdeg]; a geometry entry the estimator rejects
///   (sl_incline_geom_ok) or whose theta (bam32) differs from theta_cdeg by more than
///   0.01 deg or whose beta differs from the board's; shadow_um not within 1 % of
///   H / tan(theta) (checked as shadow_um x sin = H x cos); shadow_bins not
///   floor(shadow_um / bin) - 1 (+-1) or beyond roi_bins; near_exclusion_bins >= roi_bins;
///   elongation table not ascending, r > 200 m, |d| > 5 m (the board file's bounds), or too many points; theta_sigma > 10 deg;
///   flags other than SL_CALBLOB_FLAG_RESPONSE ("flags"); a response section whose tap
///   count is not SL_RESP_TAPS ("response_taps") or whose shape fails sl_response_plausible
///   down to 20 dB ("response").
/// - SL_ERR_CAL_WORKSPACE: zero copy impossible (big-endian or misaligned) and `ws` NULL.
///
/// Cost: O(blob size): the CRC-32 is bitwise (no 1 KB table in flash: 8 shift/xor steps per
/// byte, 19 KB once at start), plus per azimuth the geometry check and two 64-bit products
/// for the shadow check. No state; reentrant.
#ifndef SHADOWLEAN_SL_CALBLOB_H
#define SHADOWLEAN_SL_CALBLOB_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_config.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_incline.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SL_CALBLOB_VERSION 1U
#define SL_CALBLOB_HEADER_BYTES 208U
#define SL_CALBLOB_NAME_BYTES 32U        ///< name field, NUL padded (31 characters + NUL)
#define SL_CALBLOB_ELONG_POINTS 16U      ///< fixed elongation slots in the format
#define SL_CALBLOB_GEOM_BYTES 40U        ///< one sl_incline_geom_t on the wire
#define SL_CALBLOB_AZ_BYTES 48U          ///< bytes per azimuth: geom + shadow_um + theta + bins
/// Total size of a blob for `az` azimuths without a response section.
#define SL_CALBLOB_BYTES(az) (SL_CALBLOB_HEADER_BYTES + SL_CALBLOB_AZ_BYTES * (size_t)(az))
/// Flags bit 0: a range response section follows the azimuth tables.
#define SL_CALBLOB_FLAG_RESPONSE 0x0001U
/// Size of the response section: its tap count and the drops.
#define SL_CALBLOB_RESPONSE_BYTES (2U + 2U * (size_t)SL_RESP_TAPS)
/// Largest blob this build can open (SL_CFG_MAX_AZIMUTHS, with a response section).
#define SL_CALBLOB_MAX_BYTES (SL_CALBLOB_BYTES(SL_CFG_MAX_AZIMUTHS) + SL_CALBLOB_RESPONSE_BYTES)

/// Decode workspace (used only when the blob cannot be read in place). Caller-owned.
typedef struct sl_calblob_ws {
    sl_incline_geom_t geom[SL_CFG_MAX_AZIMUTHS];
    uint32_t shadow_um[SL_CFG_MAX_AZIMUTHS];
    int16_t theta_cdeg[SL_CFG_MAX_AZIMUTHS];
    uint16_t shadow_bins[SL_CFG_MAX_AZIMUTHS];
    uint16_t response_q8[SL_RESP_TAPS];
} sl_calblob_ws_t;

/// What the check found (filled on success and on error; may be NULL).
typedef struct sl_calblob_info {
    uint16_t version;        ///< format version read (0 when the header was unreadable)
    uint16_t azimuths;       ///< azimuths of the blob
    uint32_t board_id;       ///< identity hash of the blob
    uint32_t crc;            ///< CRC-32 stored in the blob
    uint32_t index;          ///< azimuth / table entry of a SL_ERR_CAL_VALUE (else 0)
    const char *what;        ///< ROM string: the failed check ("crc", "theta_cdeg", ...), or NULL
    bool zero_copy;          ///< the view points into the blob (else into the workspace)
} sl_calblob_info_t;

/// Identity hash of a board: FNV-1a 32 over the name and the identity fields listed above,
/// each as little-endian bytes. O(name length).
uint32_t sl_calblob_board_id(const sl_board_t *board);

/// CRC-32 (IEEE) continuing `crc` (start with 0) over `len` bytes. Bitwise, no table.
uint32_t sl_calblob_crc32(uint32_t crc, const uint8_t *data, size_t len);

/// Serialise `board` (a nominal board, or one with calibrated tables) as a version-1 blob
/// into `buf` (`cap` bytes; needs SL_CALBLOB_BYTES(board->azimuths), plus
/// SL_CALBLOB_RESPONSE_BYTES when `board->response_calibrated` is set and its
/// `response_prior_q8` is not NULL: then the response section is written). The blob is made for
/// `board`'s identity (it opens against a nominal board with the same identity fields).
/// Does not validate the values (sl_calblob_open() does, on the reader's side).
/// @return the size written (> 0), or SL_ERR_ARG (NULL, name longer than 31 characters, more
/// elongation points than the format holds, NULL tables), SL_ERR_FULL (cap too small).
/// O(azimuths).
sl_ssize_t sl_calblob_write(const sl_board_t *board, uint8_t *buf, size_t cap);

/// Validate `blob` (`len` bytes) against `nominal` and, only when every check passes, fill
/// `*out` with the calibrated view (see the file comment for ownership, checks and cost).
/// @return SL_OK or the error of the first failed check (file comment); `*out` untouched on
/// error. `ws` may be NULL (then SL_ERR_CAL_WORKSPACE where zero copy is impossible).
sl_err_t sl_calblob_open(const uint8_t *blob, size_t len, const sl_board_t *nominal,
                         sl_calblob_ws_t *ws, sl_board_t *out, sl_calblob_info_t *info);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_CALBLOB_H
