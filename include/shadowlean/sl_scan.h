// SPDX-License-Identifier: MIT
/// @file sl_scan.h
/// @brief Scan assembly: FFT messages -> per-azimuth rows of one rotation (a frame).
///
/// Input: Configuration and FFT events from sl_proto (`sl_scan_on_msg()`, or the typed
/// `sl_scan_on_config()` / `sl_scan_on_fft()`). Output: rows of power in a caller-owned,
/// fixed-size frame (`sl_scan_frame_t`, sized by SL_CFG_MAX_AZIMUTHS x SL_CFG_ROI_BINS),
/// a per-azimuth callback as each row is stored (so a pipeline can threshold it at once)
/// and a per-rotation callback when the frame is complete.
///
/// ## Azimuth index (the azimuth cell containing the encoder value)
/// Azimuth index i covers the encoder ticks [i * encoder_size / azimuths,
/// (i + 1) * encoder_size / azimuths): an FFT message's encoder value is mapped to the cell
/// it falls in (round down):
///     idx = (ticks * azimuths) / encoder_size
/// (exact integer arithmetic). Ticks >= encoder_size are rejected (`stats.bad_azimuth`).
/// Example, CTS350-X (400 azimuths, 5600 ticks, 14 ticks per cell): the Oxford data's
/// ticks 13, 27, ..., 5599 (= 14 i + 13, the END of each cell) land on indices 0, 1, ...,
/// 399, so one Oxford PNG is exactly one frame; a radar reporting the start of each cell
/// (0, 14, 28, ...) maps the same way. Frames always span indices 0..azimuths-1 of one
/// rotation. (Nearest-centre rounding was rejected: it moves the Oxford data's last row,
/// tick 5599, into index 0 of the NEXT rotation.)
///
/// ## Rotation boundaries, gaps, duplicates, reordering
/// Let `head` be the highest index stored in the current frame and W the reorder window
/// (`cfg.reorder_azimuths`, default azimuths / 8). For a new index `idx`, with the forward
/// circular distance fwd = (idx - head) mod azimuths:
/// - fwd == 0: duplicate of the head.
/// - 0 < fwd < azimuths - W (a forward step): if idx > head it belongs to this frame (the
///   indices jumped over stay missing); if idx < head it crossed index 0: the current frame
///   is COMPLETE (`SL_SCAN_END_WRAP`) and idx opens the next frame.
/// - fwd >= azimuths - W (a small step backwards): a late (out-of-order) message. If idx <
///   head its slot is filled when still empty (`SL_SCAN_AZ_LATE`, `out_of_order`), else it
///   is a duplicate (or, when its sweep counter is newer than the head's, the first message
///   of the next rotation). If idx > head it belongs to the previous, already completed
///   rotation: dropped and counted (`late_dropped`), unless its sweep counter is newer than
///   the head's (then it is this rotation's, stored as a forward step).
/// - idx < head with fwd < azimuths - W (a step back beyond the window): this closes the
///   rotation (`SL_SCAN_END_WRAP`) only when the azimuth was already stored in it, or the
///   sweep counters moved forward by fwd +- W messages with at most W rows stored behind the
///   head since it was set (an in-order gap across index 0). Otherwise it
///   is DISORDER (`disorder`): stored into its empty slot as a late row, the rotation stays
///   open. So shuffled or reversed azimuths close about one rotation per pass over every
///   index (one reversed rotation is one rotation, not many).
/// - Sweep counter (unless `cfg.ignore_sweep`): if the signed 16-bit sweep difference to the
///   head's message is >= azimuths (a whole rotation of packets lost), the frame completes
///   (`SL_SCAN_END_SWEEP_GAP`) before idx is stored, whatever the index says.
/// - Rows with 0 bins are not azimuths (`empty_rows`, SL_ERR_MALFORMED). A run of
///   `azimuths` consecutive FFT messages that give no row (out-of-range encoder values,
///   empty, malformed) adds one rotation's azimuths to `missing` (`blind_rotations`).
/// Duplicates keep the FIRST row (it may already have been thresholded downstream) and set
/// `SL_SCAN_AZ_DUP` on it. Missing rows are zero-filled at completion, flags 0.
///
/// ## Rows
/// - Bin count per azimuth comes from the payload length (contoured data is shorter):
///   `bins[idx]` = min(message bins, roi_bins). When the message holds fewer than roi_bins
///   bins the rest of the row is zero-filled and `SL_SCAN_AZ_SHORT` is set.
/// - Only the region of interest (first `roi_bins` bins) is read from the message.
/// - Frames hold uint8 power. 16-bit data (id 31) is reduced by a documented rule:
///   p8 = min(255, v16 >> cfg.pow16_shift) (default shift 8 = the high byte), and the row is
///   flagged `SL_SCAN_AZ_16BIT`; `stats.saturated16` counts clipped bins.
/// - Bytes [roi_bins, SL_CFG_ROI_BINS) of each row are never written (zero since init).
///   Rows >= the frame's `azimuths` are unspecified (left over from an earlier geometry).
/// - Timestamps: per azimuth, UNIX microseconds (seconds * 1e6 + ns / 1000).
///
/// ## Frames, ownership, double buffering
/// The caller owns one or two frames (passed to sl_scan_init, borrowed until re-init).
/// - One frame: rows are written in place; the frame passed to `on_frame` is valid until
///   `on_frame` returns (the next rotation then reuses it).
/// - Two frames (double buffering): rows go into the "filling" frame; on completion it
///   becomes the "last complete" frame (`sl_scan_last_frame()`) and the other one is filled.
///   A completed frame therefore stays intact until the NEXT `on_frame` call returns, a whole
///   rotation later (time to run detection on it while the next rotation arrives).
/// - A Configuration whose geometry (azimuths, encoder size) differs from the current one
///   completes the current frame (`SL_SCAN_END_CONFIG`); an identical one is only counted.
///   Call `sl_scan_flush()` on EOF / reconnect to emit a partial frame (`SL_SCAN_END_FLUSH`).
///
/// ## Frame-less mode (fill == NULL: no rows stored; what a small-RAM pipeline uses)
/// `sl_scan_init(s, cfg, NULL, NULL)`: the rotation bookkeeping above (index, wrap, gaps,
/// duplicates, reordering, sweep gaps, timestamps, statistics) is unchanged, but no row is
/// kept. Each stored azimuth is reported through `cfg.on_row` with an `sl_scan_row_t` whose
/// `power` is a view of `roi_bins` bytes:
/// - into the message itself when it is 8-bit and holds at least roi_bins bins (no copy);
/// - into the caller's row buffer (`cfg.row_buf`, >= roi_bins bytes, borrowed like the
///   frames) for 16-bit data (reduced as above) and for short rows (zero-filled).
/// The view is valid until `on_row` returns. A completed rotation is reported through
/// `cfg.on_rot` (`sl_scan_rot_t`: the frame's header, statistics and per-azimuth flags).
/// `on_row` and `on_rot` are also called in frame mode (there `power` points into the
/// frame row); `on_azimuth` / `on_frame` only in frame mode. In frame-less mode
/// `sl_scan_last_frame()` is NULL.
///
/// ## Cost
/// Per FFT message: O(roi_bins) (one memcpy of the ROI bytes; for 16-bit data a SWAR / block
/// loop) plus O(1) bookkeeping. Per rotation: O(azimuths) flag clearing plus zero-filling missing
/// rows. Stack < 128 bytes plus the callbacks'. RAM: sizeof(sl_scan_t) (624 bytes on x86-64
/// with 400 azimuths: the rotation bookkeeping keeps one flag byte per azimuth) plus the
/// caller's frame(s) (sizeof(sl_scan_frame_t) each: 210,848 bytes with the default
/// 400 azimuths x 512 ROI bins). Per azimuth O(ROI bins): one copy of the region of
/// interest (8-bit) or a 64-bit SWAR reduction (16-bit); frame-less, no copy (measured:
/// docs/PERFORMANCE.md, "Core modules").
/// Task context, not reentrant; callbacks must not feed the same instance.
#ifndef SHADOWLEAN_SL_SCAN_H
#define SHADOWLEAN_SL_SCAN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_config.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_proto.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Per-azimuth flags in `sl_scan_frame_t.flags`.
#define SL_SCAN_AZ_VALID 0x01U  ///< a message was stored for this azimuth
#define SL_SCAN_AZ_SHORT 0x02U  ///< fewer bins than roi_bins (contoured); rest zero-filled
#define SL_SCAN_AZ_LATE 0x04U   ///< stored out of order (after a higher index)
#define SL_SCAN_AZ_DUP 0x08U    ///< duplicates of this azimuth were seen and dropped
#define SL_SCAN_AZ_16BIT 0x10U  ///< reduced from 16-bit data (id 31)

/// Why a frame was completed.
typedef enum sl_scan_end {
    SL_SCAN_END_WRAP = 0,      ///< the azimuth index wrapped past 0 (normal)
    SL_SCAN_END_SWEEP_GAP = 1, ///< sweep counter jumped by a rotation or more
    SL_SCAN_END_CONFIG = 2,    ///< a Configuration with a different geometry arrived
    SL_SCAN_END_FLUSH = 3,     ///< sl_scan_flush() (EOF, reconnect)
} sl_scan_end_t;

/// Statistics of one frame (one rotation), final when `on_frame` is called.
typedef struct sl_scan_frame_stats {
    uint16_t valid;           ///< azimuths stored
    uint16_t missing;         ///< azimuths never received (azimuths - valid)
    uint16_t duplicates;      ///< duplicate messages dropped
    uint16_t out_of_order;    ///< late messages stored into an empty slot
    uint16_t short_azimuths;  ///< rows with fewer than roi_bins bins
    uint16_t wide_azimuths;   ///< rows reduced from 16-bit data
    uint16_t disorder;        ///< steps back beyond the reorder window stored (or dropped)
} sl_scan_frame_stats_t;

/// One rotation. Caller-owned (usually static: ~210 KB with the default capacities).
/// Fields read-only to the application; row `i` is `power[i][0 .. roi_bins)`.
typedef struct sl_scan_frame {
    uint32_t rotation;        ///< frame sequence number since sl_scan_init (0, 1, ...)
    uint16_t azimuths;        ///< azimuths per rotation (from the radar configuration)
    uint16_t encoder_size;    ///< encoder ticks per rotation
    uint16_t roi_bins;        ///< bins kept per row (cfg.roi_bins)
    uint8_t end;              ///< sl_scan_end_t, valid once complete
    uint16_t head;            ///< highest index stored (internal while filling)
    uint16_t head_sweep;      ///< sweep counter of the head's message (internal)
    uint64_t t_first_us;      ///< earliest azimuth timestamp in the frame (UNIX us)
    uint64_t t_last_us;       ///< latest azimuth timestamp in the frame (UNIX us)
    sl_scan_frame_stats_t stats;
    uint8_t flags[SL_CFG_MAX_AZIMUTHS];          ///< SL_SCAN_AZ_* per azimuth index
    uint16_t bins[SL_CFG_MAX_AZIMUTHS];          ///< bins stored per row (0..roi_bins)
    uint16_t ticks[SL_CFG_MAX_AZIMUTHS];         ///< raw encoder value of the stored message
    uint16_t sweep[SL_CFG_MAX_AZIMUTHS];         ///< sweep counter of the stored message
    uint64_t t_us[SL_CFG_MAX_AZIMUTHS];          ///< timestamp per azimuth, UNIX us
    uint8_t power[SL_CFG_MAX_AZIMUTHS][SL_CFG_ROI_BINS]; ///< uint8 power, row per azimuth
} sl_scan_frame_t;

/// Bookkeeping of the rotation being assembled / just completed (both modes). Fields as in
/// sl_scan_frame_t. Read-only to the application.
typedef struct sl_scan_rot {
    uint32_t rotation;        ///< sequence number since sl_scan_init (0, 1, ...)
    uint16_t azimuths;        ///< azimuths per rotation
    uint16_t encoder_size;    ///< encoder ticks per rotation
    uint16_t roi_bins;        ///< bins per row
    uint8_t end;              ///< sl_scan_end_t, valid once complete
    uint16_t head;            ///< highest index stored (internal while filling)
    uint16_t head_sweep;      ///< sweep counter of the head's message (internal)
    uint64_t t_first_us;      ///< earliest azimuth timestamp (UNIX us; 0 when none)
    uint64_t t_last_us;       ///< latest azimuth timestamp (UNIX us)
    sl_scan_frame_stats_t stats;
    uint8_t flags[SL_CFG_MAX_AZIMUTHS]; ///< SL_SCAN_AZ_* per azimuth index
} sl_scan_rot_t;

/// One stored azimuth (both modes). Lifetime: until the callback returns.
typedef struct sl_scan_row {
    uint32_t rotation;        ///< rotation it belongs to
    uint16_t idx;             ///< azimuth index 0 .. azimuths-1
    uint16_t bins;            ///< bins taken from the message (<= roi_bins; rest zero)
    uint16_t ticks;           ///< raw encoder value
    uint16_t sweep;           ///< sweep counter
    uint8_t flags;            ///< SL_SCAN_AZ_*
    uint64_t t_us;            ///< timestamp, UNIX us
    const uint8_t *power;     ///< roi_bins uint8 power values (see "Frame-less mode")
    const sl_proto_fft_t *fft; ///< the message the row came from (all its bins, wire format)
} sl_scan_row_t;

/// Row callback (both modes).
typedef void (*sl_scan_on_row_fn)(void *ctx, const sl_scan_row_t *row);

/// Rotation-complete callback (both modes): `rot->stats`, `rot->end` and `rot->flags` are
/// final. Valid until the callback returns.
typedef void (*sl_scan_on_rot_fn)(void *ctx, const sl_scan_rot_t *rot);

/// Per-azimuth callback: row `idx` of `frame` has just been stored (`frame->power[idx]`,
/// `frame->bins[idx]`, `frame->flags[idx]`). The frame is the one being filled; valid as
/// described in the file comment.
typedef void (*sl_scan_on_azimuth_fn)(void *ctx, const sl_scan_frame_t *frame, uint16_t idx);

/// Frame-complete callback: `frame` holds one rotation; `frame->stats` and `frame->end` are
/// final; missing rows are zero. Lifetime: see "double buffering" above.
typedef void (*sl_scan_on_frame_fn)(void *ctx, const sl_scan_frame_t *frame);

/// Configuration (copied by sl_scan_init).
typedef struct sl_scan_cfg {
    uint16_t roi_bins;          ///< bins kept per azimuth, 1 .. SL_CFG_ROI_BINS
    uint8_t pow16_shift;        ///< 16-bit -> 8-bit: p8 = min(255, v >> shift), 0..15
    uint16_t reorder_azimuths;  ///< reorder window W (< azimuths / 2); 0 = azimuths / 8
    uint16_t expect_azimuths;   ///< reject configurations with another count; 0 = any
    uint16_t expect_encoder_size; ///< reject configurations with another size; 0 = any
    uint16_t azimuths;          ///< initial geometry (captures without config); 0 = wait
    uint16_t encoder_size;      ///< initial geometry; 0 = wait for a Configuration
    bool ignore_sweep;          ///< do not use the sweep counter to detect lost rotations
                                ///< (sources whose sweep counter is meaningless)
    sl_scan_on_azimuth_fn on_azimuth; ///< optional
    sl_scan_on_frame_fn on_frame;     ///< optional
    sl_scan_on_row_fn on_row;         ///< optional (both modes)
    sl_scan_on_rot_fn on_rot;         ///< optional (both modes)
    uint8_t *row_buf;           ///< frame-less mode: row buffer (>= roi_bins bytes), borrowed
    uint16_t row_buf_size;      ///< its size in bytes
    void *ctx;                  ///< passed to every callback
} sl_scan_cfg_t;

/// Cumulative counters since sl_scan_init.
typedef struct sl_scan_stats {
    uint32_t fft;             ///< FFT messages offered
    uint32_t azimuths;        ///< rows stored
    uint32_t frames;          ///< frames completed (on_frame calls)
    uint32_t missing;         ///< sum of frame missing counts
    uint32_t duplicates;      ///< duplicate messages dropped
    uint32_t out_of_order;    ///< late messages stored
    uint32_t late_dropped;    ///< late messages of an already completed rotation
    uint32_t short_azimuths;  ///< rows shorter than roi_bins
    uint32_t wide_azimuths;   ///< rows from 16-bit data
    uint32_t saturated16;     ///< 16-bit bins clipped to 255
    uint32_t sweep_gaps;      ///< sweep counter not +1 from the previous message
    uint32_t bad_azimuth;     ///< encoder value >= encoder_size
    uint32_t malformed;       ///< FFT / Configuration messages the parser rejected
    uint32_t no_config;       ///< FFT messages dropped before any usable geometry
    uint32_t configs;         ///< Configuration messages accepted
    uint32_t config_changes;  ///< ... of which changed the geometry
    uint32_t config_rejected; ///< Configurations rejected (0 / oversized / unexpected geometry)
    uint32_t disorder;        ///< messages that stepped back beyond the reorder window
    uint32_t empty_rows;      ///< FFT messages with 0 bins (not azimuths; they stay missing)
    uint32_t blind_rotations; ///< runs of `azimuths` consecutive FFT messages without a row
                              ///< (out-of-range encoder values, empty, malformed): each adds
                              ///< a rotation's azimuths to `missing`
} sl_scan_stats_t;

/// Scan assembler. Caller-allocated; fields read-only to the application.
typedef struct sl_scan {
    sl_scan_cfg_t cfg;
    sl_scan_frame_t *fill;    ///< frame being filled
    sl_scan_frame_t *done;    ///< last complete frame (double buffering) or NULL
    bool done_valid;          ///< `done` holds a completed frame
    bool in_frame;            ///< `fill` holds at least one row
    uint16_t azimuths;        ///< current geometry (0 = none yet)
    uint16_t encoder_size;
    uint32_t az_recip;        ///< floor(azimuths 2^16 / encoder_size), set with the geometry
                              ///< (no division per azimuth); 0: azimuths > encoder_size
    uint16_t window;          ///< effective reorder window
    bool have_sweep;          ///< `last_sweep` valid
    uint16_t last_sweep;      ///< sweep counter of the previous FFT message
    uint32_t rotation;        ///< next frame's sequence number
    uint16_t unusable_run;    ///< FFT messages without a row since the last stored one
    uint16_t behind_head;     ///< rows stored behind the head since it was last set
    sl_scan_stats_t stats;
    sl_scan_rot_t rot;        ///< bookkeeping of the rotation being assembled (both modes)
} sl_scan_t;

#if defined(__cplusplus)
static_assert(sizeof(sl_scan_t) <= 320 + SL_CFG_MAX_AZIMUTHS,
              "sl_scan_t RAM budget (frames are separate)");
#else
_Static_assert(sizeof(sl_scan_t) <= 320 + SL_CFG_MAX_AZIMUTHS,
               "sl_scan_t RAM budget (frames are separate)");
#endif

/// Initialise. `fill` NULL selects the frame-less mode (then `spare` must be NULL and
/// `cfg.row_buf` hold >= roi_bins bytes); `spare` (the second frame for double buffering)
/// is optional. Frames are cleared once here (O(sizeof frame)).
/// @return SL_OK; SL_ERR_ARG (NULL s/cfg, roi_bins 0 or > SL_CFG_ROI_BINS, shift > 15, same
/// frame twice, spare without fill, frame-less without a large enough row_buf); SL_ERR_RANGE (initial geometry unusable: azimuths > SL_CFG_MAX_AZIMUTHS, ...).
sl_err_t sl_scan_init(sl_scan_t *s, const sl_scan_cfg_t *cfg, sl_scan_frame_t *fill,
                      sl_scan_frame_t *spare);

/// Nearest azimuth index of an encoder value (formula in the file comment), or -1 when
/// `ticks >= encoder_size`, `azimuths == 0` or `encoder_size == 0`. O(1).
int32_t sl_scan_az_index(uint16_t azimuths, uint16_t encoder_size, uint16_t ticks);

/// The same index for the scan's current geometry, without a division (the reciprocal
/// `az_recip` is set when the geometry is): what sl_scan_on_fft() uses per azimuth. Equal
/// to sl_scan_az_index(s->azimuths, s->encoder_size, ticks) for every input (-1 when there
/// is no geometry or ticks >= encoder_size). O(1): three 32-bit multiplies.
int32_t sl_scan_az_index_geo(const sl_scan_t *s, uint16_t ticks);

/// Set the geometry without a Configuration message (e.g. a capture that starts
/// mid-stream, geometry from the board). Same effect as a config with these values.
/// @return SL_OK, SL_ERR_ARG, SL_ERR_RANGE (0, > SL_CFG_MAX_AZIMUTHS, unexpected).
sl_err_t sl_scan_set_geometry(sl_scan_t *s, uint16_t azimuths, uint16_t encoder_size);

/// Apply a parsed Configuration (azimuths, encoder size). See the file comment.
/// @return SL_OK or SL_ERR_RANGE (rejected, counted in config_rejected), SL_ERR_ARG.
sl_err_t sl_scan_on_config(sl_scan_t *s, const sl_proto_config_t *c);

/// Store one parsed FFT message (may complete a frame first).
/// @return SL_OK (stored, or dropped as a counted duplicate / late message), SL_ERR_STATE
/// (no geometry yet), SL_ERR_RANGE (bad azimuth), SL_ERR_ARG.
sl_err_t sl_scan_on_fft(sl_scan_t *s, const sl_proto_fft_t *f);

/// Dispatch a decoded message: id 10 -> parse + sl_scan_on_config, ids 30/31 -> parse +
/// sl_scan_on_fft, others ignored (SL_OK). Parser failures count in `stats.malformed` and
/// return SL_ERR_MALFORMED.
sl_err_t sl_scan_on_msg(sl_scan_t *s, const sl_proto_msg_t *msg);

/// Ready-made sl_proto callback: `ctx` must be an `sl_scan_t *`. Wire as
/// `pcfg.on_msg = sl_scan_proto_sink; pcfg.ctx = &scan;`.
void sl_scan_proto_sink(void *ctx, const sl_proto_msg_t *msg);

/// Complete the current frame now if it holds any row (`SL_SCAN_END_FLUSH`). O(azimuths).
void sl_scan_flush(sl_scan_t *s);

/// Last completed frame when double buffering, else NULL. Valid until the next on_frame.
const sl_scan_frame_t *sl_scan_last_frame(const sl_scan_t *s);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_SCAN_H
