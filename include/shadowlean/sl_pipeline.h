// SPDX-License-Identifier: MIT
/// @file sl_pipeline.h
/// @brief The detection pipeline: radar bytes in, targets, tracks and CAN frames out.
///
/// One `sl_pipeline_t` owns one of each core stage, all inside the struct (no allocation,
/// nothing borrowed except the board and the port's context):
///
///     bytes -> sl_proto (decoder, reassembly buffer inside, long payloads truncated to
///              the bytes the pipeline reads) -> sl_scan (frame-less: one row view per
///              azimuth) -> sl_thresh (first `mask_bins` bins only) -> sl_mask (n-frame
///              consistency, window shortened with vehicle speed) -> sl_detect (runs in
///              the shadow, corrections, alpha) -> sl_profile (bounds re-extracted from
///              the summed 8-bit rows of the azimuths that show something in the shadow,
///              smear tail removed; while moving, one rotation's rows of the target's
///              azimuth and its neighbours, in slots reserved after the tracker where each
///              track is expected; cfg.profile; a target is then rejected SHADOW when
///              its refined r2 (else, for a target whose tail crosses the shadow edge,
///              SL_TARGET_TAIL_EDGE, its r2 less d(r2)) reaches the edge, so the board's
///              d decides nothing once a profile exists; the profiles' calibrated tail
///              slope goes back to sl_detect for the next rotation's edge rule)
///              -> sl_track -> CAN (sl_can_tx_t)
///
/// so `sizeof(sl_pipeline_t)` is the whole RAM of the module (see the budget below).
///
/// ## Inputs (all push-driven; time is passed in, the core never reads a clock)
/// - `sl_pipeline_feed()`: any chunking of the radar's TCP stream (or a capture file).
/// - `sl_pipeline_on_msg()`: or messages already decoded by the caller (decode once).
/// - `sl_pipeline_on_can_rx()`: frames from the vehicle bus; VehicleMotion (board id) is
///   E2E-checked and used, other ids are counted and ignored.
/// - `sl_pipeline_set_motion()`: the same motion input without CAN (direct setter).
/// - `sl_pipeline_set_link_state()`: the TCP link state (the port knows it, the core does
///   not) reported in the Status frame.
/// - `sl_pipeline_finish()`: end of stream (EOF, peer closed, before a reconnect).
///
/// ## Outputs (house style s.6: a const vtable + context, copied at init)
/// For every completed rotation, in this order, from inside the feed/finish call that
/// completed it:
/// 1. `port.on_rotation(ctx, r)` (optional): this rotation's targets (raw and corrected
///    r1/r2, alpha, sigma, flags, representative azimuth: `sl_target_t`) and the tracker's
///    tracks (filtered alpha, sigma, warning level: `sl_track_t`, live slots only matter).
/// 2. `port.can_tx(ctx, f)` (optional) for: one PoleLean per *confirmed* track (live,
///    matched this rotation, `hits >= cfg.confirm_hits` and `confirmed` by the tracker's
///    static-object evidence, sl_track.h), in slot order, each followed by its PoleTilt
///    when the track has an observation history with a fit (only while a motion input is
///    present: see "3D tilt while driving"); a track whose update was a pole leaning across
///    the beam (`last_slant`, sl_detect.h stage 4: no one azimuth holds its run) sends its
///    PoleTilt without a PoleLean; one LeanWarning
///    (the most severe confirmed track: highest level, then largest |filtered alpha|;
///    HasTarget = 0 when there is none); with the ground on (`cfg.ground`, SL_CFG_GROUND),
///    one GroundPlane (this rotation's plane; Quality NONE without one) and one
///    GroundHazard per sector with a confirmed DROP or STEP, in sector order (sl_ground.h);
///    one Status (link state, rotations, missing
///    azimuths, decoder resyncs, CAN drops; LinkState STREAMING only while usable rows
///    arrive: none since the previous Status and none within `cfg.row_timeout_us` -> SILENT), then one Health (Fault bits, Reconnects,
///    CandidatesDropped; sl_can.h). Every frame passes the hard output ceiling (token
///    buckets on `now_us`: SL_CAN_MAX_*_FRAMES_PER_100MS per 100 ms sustained, bursts up to
///    SL_CAN_BURST_WINDOWS times that; withheld frames are counted in
///    `stats.can_rate_limited` and raise CAN_RATE_LIMITED). `can_tx` must not block: SL_ERR_BUSY (or any
///    other error) counts the frame as dropped (`stats.can_dropped`, reported in the next
///    Status frame) and the pipeline moves on. Drops the port notices later (after can_tx
///    returned SL_OK) are added with `sl_pipeline_add_can_dropped()`. Between rotations
///    the port sends Status + Health frames with `sl_pipeline_send_status()` (same E2E
///    sequences).
/// Callbacks must not call back into the same pipeline (not reentrant).
///
/// ## Mapping to CAN (sl_can.h)
/// Azimuth = az x 36000 / azimuths + board->radar_yaw_cdeg (vehicle frame, clockwise).
/// TargetId = track id mod 16. Quality = FILTERED when the track has a valid alpha
/// (Lean/LeanSigma = the filtered values), else the mapping of the last target's incline
/// flag (AMBIGUOUS, OUT_OF_MODEL, INVALID). Bin size: the radar's Configuration's (its
/// `rangeresolutionmetres`, else the fixed field): detection runs on `det_board`, a copy of
/// the board with that bin size, so ranges and corrections follow the radar; a difference
/// of more than 1 % from the board's (the expected value) raises RANGE_RESOLUTION_MISMATCH.
/// Ranges: the track's last corrected r1 / r2, passed
/// in um and rounded once, by the encoder, to the signal's step (0.02 m / 0.01 m).
///
/// ## 3D tilt while driving (sl_tiltobs.h, sl_tilt.h)
/// After the tracker's update, every rotation WITH a motion input advances the fixed-point
/// odometry by the measured rotation period and adds one observation (radar pose at the
/// detection group's centre azimuth, bearing, r1, alpha, sigma, branch of the group's union
/// extent: sl_tiltobs.h; detection fills `ext_grow` only while a motion input is present)
/// to the ring of every confirmed track matched with a VALID alpha; at most SL_CFG_TILT_FITS_PER_ROTATION rings are fitted
/// per rotation (round robin). A rotation without motion input clears every ring (the
/// odometry has a hole), so without motion nothing changes on CAN.
/// PoleTilt: the ring's latest fit in the vehicle frame at the rotation's end (sl_can.h).
/// LeanWarning and the fitted tilt: for a confirmed track whose fit is FITTED or AMBIGUOUS
/// (of an AMBIGUOUS fit's two readings, the more dangerous one: the higher level, then the
/// larger lean towards the path, among the readings within the detector's largest lean
/// whose path-lean sigma is within cfg.track.max_sigma_cdeg; with neither, the track's
/// values as below), the warning uses the tilt TOWARDS THE VEHICLE'S PATH instead of the in-plane
/// alpha: lean = atan(-sign(base_y) t_y) with t the tilt vector and base_y the base's
/// lateral offset in the vehicle frame (> 0: the top leans over the path, the sign
/// convention of Lean), its sigma that of the path lean (sl_tiltobs_vehicle_t
/// .lean_path_sigma_cdeg), its level the board's thresholds applied to it directly (DANGER at lean >= danger, CAUTION at |lean| (or lean, per
/// cfg.track.caution_abs) >= caution; no hysteresis: the fit is already an average over the
/// pass), Quality FILTERED. This is what resolves the fold: a pole leaning away beyond
/// (theta - beta) / 2 reads as leaning towards on every single rotation, its fit does not.
/// Other tracks use the tracker's level, filtered alpha and sigma as before. The most
/// severe track is chosen on these values.
///
/// ## Motion (the paper assumed a static vehicle; see `sl_pipeline_window()`)
/// The consistency mask needs the same (azimuth, bin) cell occupied in the last n rotations.
/// A static point seen from a vehicle moving at speed v with yaw rate w moves, per
/// rotation of period T, by at most v T + r_max |w| T (r_max = the farthest shadow edge),
/// radially and tangentially. It stays in its cell over n_eff rotations only if
/// (n_eff - 1) x that <= D (the cell size budget, `cfg.motion_budget_um`, default one range
/// bin, which is also about one azimuth step x 2.8 m), so
///
///     n_eff = clamp(floor(D / (v T + r_max |w| T)) + 1, cfg.min_frames, n)
///
/// computed once per rotation in 64-bit integers, with T the measured rotation period
/// (radar timestamps; default 250 ms). The mask keeps counting with the full n; only the
/// stable test changes (k <= n - n_eff instead of k == 0: sl_mask_set_window()), so no
/// history is lost when the vehicle stops again. Without a (fresh) motion input the board's
/// n is used. Limits: above D / T (0.175 m/s for 4.38 cm bins at 4 Hz) n_eff is 1, i.e.
/// single-frame thresholding; rejecting transient returns is then up to the tracker (a
/// PoleLean is only sent for a track seen `confirm_hits` times), whose gates are widened by
/// the ego displacement per rotation (v T radially, v T / r + |w| T in azimuth).
/// Why not shift the consistency test by the ego motion instead: a polar bit cell moves to
/// a different (azimuth, bin) per rotation as a function of its own range and bearing, so
/// the shift is a per-cell resampling of every stored plane (not a word operation), and the
/// azimuth quantisation (0.9 deg = 4.4 cm at 2.8 m) would smear the planes anyway.
///
/// Derivation of the bound: a static point at range r and bearing b (from the direction of
/// travel) changes range by -v T cos b and bearing by v T sin b / r - w T per rotation; both
/// components are bounded by v T (+ r |w| T), so |d range| and r |d bearing| <= v T + r |w| T.
/// The cells are one bin (b = 43.8 mm) deep and one azimuth step (r x 15.7 mrad, 44 mm at
/// 2.8 m) wide, hence D = one bin. Limits: the bound is conservative (a point straight ahead
/// or abeam moves in one direction only), it ignores the pole's own extent (a long return
/// moves as a whole), and a yaw rate enters with the farthest range of interest.
///
/// Missing azimuths while moving: a lost row is not a frame (the mask holds the azimuth's
/// state); for detection its held stable row is used only while it is still within the
/// budget, i.e. when (missed + 1) x disp <= D <=> missed + 2 <= n_eff. At n_eff = 1 a lost
/// azimuth is simply absent from that rotation (never a ghost at the old position).
///
/// Detection runs while the rotation arrives (one row per azimuth, increasing order); a late
/// (out-of-order) row updates the mask but this rotation's detection used the azimuth's
/// held row.
///
/// ## RAM budget (sizeof(sl_pipeline_t)); asserted below for the firmware configuration
/// Dominated by the mask: SL_CFG_MAX_AZIMUTHS x (1 + ceil(log2 SL_CFG_MASK_FRAMES_MAX)) x
/// SL_CFG_MASK_BINS / 8 bytes; then detection (8,424 B), the tracker (1,864 B), the scan
/// bookkeeping (624 B), the range profiles (sl_profile.h, 2.3 KB), the 3D tilt history
/// (sl_tiltobs.h: 2,480 B firmware, 7.4 KB host default), the reassembly buffer
/// (SL_PIPELINE_REASM_BYTES), a row buffer, the theta drift watch (sl_drift.h, 60 B) and,
/// with SL_CFG_GROUND (host configuration), the ground (sl_ground.h, SL_PIPELINE_GROUND_BYTES),
/// with SL_CFG_FIT (host configuration) the fit's buffers (SL_PIPELINE_FIT_BYTES).
///
/// Measured sizes per configuration: docs/PERFORMANCE.md ("Core modules").
///
/// The boards carried today need 135 (paper-sim), 119 (paper-bench) and 141 (robotcar-leaf)
/// masked bins (sl_detect_bins_needed(), rounded up to 160).
///
/// ## Cost
/// - Per azimuth O(ROI bins / 32 x mask planes): threshold, mask update, decoder, scan and
///   one detection row; per rotation O(azimuths) plus O(targets) estimates and tracking.
///   Budgets per CPU (firmware/size_budget.txt and the `thumb` tests; the table is
///   docs/INTEGRATION.md, "Footprint"); on x86-64 the `bench_*` ctests hold their own.
/// - Latency: the rotation is complete when the next rotation's first azimuth arrives (one
///   azimuth period, 0.625 ms at 1600 Hz), then O(targets) work in that feed call.
/// - Measured instruction counts, latency and throughput: docs/PERFORMANCE.md ("Core
///   modules", "Pipeline").
/// Stack (computed from the call graph by ctest check_stack_cortex_m0/_m4f, libgcc frames
/// included, Cortex-M -Os firmware configuration): the worst case from sl_pipeline_feed()
/// is held to the budget in docs/INTEGRATION.md ("Footprint"; the ctests print the measured
/// depth and the depth at the port callbacks' call site), plus the callbacks' own stack.
///
/// ## Execution context: which call may run where
/// One pipeline belongs to one execution context (a task, or the main loop), the *owner*:
/// - Owner only, never concurrently with each other: sl_pipeline_init(), _feed(),
///   _finish(), _on_can_rx(), _set_motion(), _set_link_state(), _send_status(),
///   _add_can_dropped(). None is reentrant or interrupt-safe: they share the decoder,
///   tracker, E2E counters and stats without locks.
/// - Never from an interrupt while the owner may be inside the pipeline. In particular do
///   not call sl_pipeline_on_can_rx() from the CAN receive ISR: the ISR copies the frame
///   (sl_can_frame_t, 16 bytes) into a queue, the owner drains it between feeds. Likewise
///   a CAN TX-complete/error ISR counts drops in its own counter and the owner passes the
///   total to sl_pipeline_add_can_dropped().
/// - `port.can_tx` and `port.on_rotation` run in the owner's context, inside the feed /
///   finish / send_status call that produced them. They must not call back into the same
///   pipeline, must not block (can_tx: queue into the driver's TX FIFO or return
///   SL_ERR_BUSY), and their stack adds to the figure above.
/// - No floating point anywhere in the core (built with -mgeneral-regs-only on Cortex-M,
///   checked by check_core_no_vfp_cortex_m4f): under an RTOS the owner task needs no FP
///   context, and the core runs with the FPU still off after reset.
/// - Different pipelines (separate sl_pipeline_t objects) are independent and may run in
///   different contexts; the core has no global state (no .data/.bss: size budget).
#ifndef SHADOWLEAN_SL_PIPELINE_H
#define SHADOWLEAN_SL_PIPELINE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_config.h"
#include "shadowlean/sl_detect.h"
#include "shadowlean/sl_drift.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_ground.h"
#include "shadowlean/sl_mask.h"
#include "shadowlean/sl_port.h"
#include "shadowlean/sl_profile.h"
#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_response.h"
#include "shadowlean/sl_scan.h"
#include "shadowlean/sl_thresh.h"
#include "shadowlean/sl_tiltobs.h"
#include "shadowlean/sl_track.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Reassembly buffer of the decoder: the largest payload prefix the pipeline reads (an FFT
/// message's fixed part plus the masked bins as 16-bit values; at least 256 bytes so that a
/// Configuration's protobuf fits). Longer payloads (a whole 3768-bin FFT message) are
/// truncated to this and the rest is consumed uncopied (sl_proto `truncate_long`), never
/// rejected.
#ifndef SL_PIPELINE_REASM_BYTES
#define SL_PIPELINE_REASM_BYTES                                                              \
    ((SL_PROTO_FFT_FIXED_BYTES + 2U * SL_CFG_MASK_BINS) > 256U                               \
         ? (SL_PROTO_FFT_FIXED_BYTES + 2U * SL_CFG_MASK_BINS)                                \
         : 256U)
#endif

/// Why init failed (in addition to the return code). ROM strings in `last_err_msg`.
typedef enum sl_pipeline_reason {
    SL_PIPELINE_OK = 0,
    SL_PIPELINE_BAD_ARG = 1,          ///< NULL pointer or cfg value out of range
    SL_PIPELINE_BOARD_AZIMUTHS = 2,   ///< board azimuths > SL_CFG_MAX_AZIMUTHS
    SL_PIPELINE_BOARD_ROI = 3,        ///< board roi_bins > SL_CFG_ROI_BINS
    SL_PIPELINE_MASK_BINS = 4,        ///< detection needs more bins than SL_CFG_MASK_BINS
    SL_PIPELINE_MASK_FRAMES = 5,      ///< n > SL_CFG_MASK_FRAMES_MAX
    SL_PIPELINE_STAGE_INIT = 6,       ///< a stage's init rejected the board (see err)
} sl_pipeline_reason_t;

/// Output port: sl_port_t (shadowlean/sl_port.h).

/// Pipeline configuration. Get defaults from sl_pipeline_cfg_default(), change fields,
/// pass to sl_pipeline_init() (copied).
typedef struct sl_pipeline_cfg {
    sl_port_t port;              ///< outputs
    sl_detect_cfg_t detect;      ///< detection parameters (beam width, gaps, ...). Default:
                                 ///< sl_detect_cfg_default (CTS350-X, 1.8 deg beam). For the
                                 ///< simulator (host_tools/sim: an 8 deg cone, RadaRays style,
                                 ///< column-normalised) set beam_width_cdeg to the return's
                                 ///< azimuth spread at the threshold: a 1 cm pole at ~3 m
                                 ///< spans ~14 azimuths (12.6 deg) in scenes/paper_pass_*.ini,
                                 ///< so ~1200; else groups are rejected WIDE and the
                                 ///< width-based radius is biased (radius_from_width)
    sl_track_cfg_t track;        ///< tracker parameters
    uint16_t threshold;          ///< occupied = power >= this (8-bit scale); default board's
    uint8_t mask_frames;         ///< n, 1..SL_CFG_MASK_FRAMES_MAX; default board's
    uint8_t max_missed;          ///< mask: rotations an azimuth is held through (default 2)
    uint8_t pow16_shift;         ///< 16-bit power -> 8-bit: v >> shift (default 8)
    bool ignore_sweep;           ///< scan: do not use sweep counters (captures without them)
    uint8_t confirm_hits;        ///< track hits before PoleLean frames are sent (default 3)
    // --- motion (see "Motion" above)
    bool motion_adapt;           ///< shorten the window with speed (default true)
    uint8_t min_frames;          ///< floor of n_eff (default 1)
    uint32_t motion_budget_um;   ///< D: displacement allowed over the window (default: bin)
    uint32_t motion_timeout_us;  ///< motion older than this is ignored (default 500 ms)
    uint32_t rotation_us;        ///< rotation period when timestamps are unusable (250000)
    uint32_t row_timeout_us;     ///< Status says STREAMING (and Health has no NO_USABLE_ROWS)
                                 ///< only while a usable row arrived within this (1 s; 0 = 1 s)
    // --- the sensor model (sl_response.h)
    sl_vscale_t value_scale;     ///< what the 8-bit values are (default the board's; a board
                                 ///< without one, kind LOG2 with 0 values per octave: the
                                 ///< CTS350-X's)
    bool learn;                  ///< the model reads one row per rotation (default true; the
                                 ///< azimuth moves by 247 of 400 each rotation, so successive
                                 ///< rows spread over the turn, or by one after a row that
                                 ///< gave a peak); false: the board's prior and no floor,
                                 ///< detection at `threshold`
    bool learn_fast;             ///< with `fit` (the extraction that reads the response),
                                 ///< while the shape in use is the board's prior, in the
                                 ///< stream's first 64 rotations, the
                                 ///< sensor model reads every row and adopts a learned
                                 ///< shape at the first rotation end it passes the gates
                                 ///< (then one row per rotation and every 16 rotations);
                                 ///< default true with SL_CFG_FIT (host configuration: a few
                                 ///< thousand instructions per row); without SL_CFG_FIT
                                 ///< (firmware: its per-azimuth budget) not read
    uint16_t floor_margin_lp;    ///< occupied also needs the learned noise floor's mean plus
                                 ///< this, log2 power Q8 (default 851: 10 dB, an exponential
                                 ///< noise sample exceeds it with probability e^-10)
    // --- extraction
    bool profile;                ///< refine bounds from range profiles (sl_profile.h;
                                 ///< default true); false = the mask's bounds and d(r)
    sl_profile_cfg_t profile_cfg; ///< profile parameters (sl_profile_cfg_default)
    bool fit;                    ///< bounds from a fit of the sensor model to the profile
                                 ///< (sl_profile_refine_fit; default false) instead of the
                                 ///< profile's walk (sl_profile_refine); SL_CFG_FIT only
                                 ///< (else sl_pipeline_init refuses it). The fit reads the
                                 ///< range response in use (`resp`): a board prior or a
                                 ///< calibration that matches the radar, or one learned
                                 ///< from the stream
#if SL_CFG_GROUND
    // --- the ground from the shadow's edge (sl_ground.h; with SL_CFG_GROUND only)
    bool ground;                 ///< attitude, terrain, DROP/STEP (default true)
    sl_ground_cfg_t ground_cfg;  ///< its parameters (sl_ground_cfg_default; threshold 0:
                                 ///< the pipeline's `threshold`; its scale is replaced by
                                 ///< `value_scale`)
#endif
} sl_pipeline_cfg_t;

/// Defaults for `board` (threshold, n from the board; detection and tracker defaults;
/// everything else as documented per field). `board` NULL: board-independent defaults
/// (threshold 40, n 16). O(1).
void sl_pipeline_cfg_default(sl_pipeline_cfg_t *cfg, const sl_board_t *board);

/// One completed rotation, handed to `port.on_rotation`. All pointers are borrowed for
/// the duration of the callback.
struct sl_pipeline_rotation {
    uint32_t rotation;           ///< sequence number since init (0, 1, ...)
    uint64_t now_us;             ///< `now_us` of the call that completed it
    uint64_t t_first_us;         ///< radar timestamps (UNIX us) of the earliest / latest
    uint64_t t_last_us;          ///< azimuth in the rotation (0 when unknown)
    uint16_t azimuths;           ///< azimuths per rotation (radar geometry)
    uint16_t valid;              ///< azimuths received this rotation
    uint16_t missing;            ///< azimuths missing this rotation
    uint8_t end;                 ///< sl_scan_end_t: why the rotation ended
    uint8_t frames_eff;          ///< consistency window used for this rotation (n_eff)
    bool motion_valid;           ///< a fresh motion input was used
    int32_t speed_mm_s;          ///< motion used (0 when !motion_valid)
    int32_t yaw_rate_cdeg_s;
    const sl_target_t *targets;  ///< this rotation's targets (sl_detect.h)
    uint16_t n_targets;
    const sl_track_t *tracks;    ///< tracker slots (sl_track.h); use those with `live`
    uint16_t n_track_slots;      ///< SL_CFG_MAX_TARGETS
    uint8_t level;               ///< sl_warn_level_t: highest level over live tracks
    const sl_response_t *model;  ///< the sensor model after this rotation (sl_response.h)
    const uint8_t *threshold;    ///< occupied threshold per band of SL_RESP_FLOOR_BAND bins
    uint16_t bands;              ///< bands over the masked bins (entries of `threshold`)
};

/// Counters (cumulative since init; never asserted). The stage stats are in the stages
/// themselves (`p->proto.stats`, `p->scan.stats`, `p->mask.stats`, `p->detect.stats`, ...).
typedef struct sl_pipeline_stats {
    uint32_t rotations;          ///< rotations processed (on_rotation calls)
    uint32_t azimuths;           ///< azimuth rows processed
    uint32_t azimuths_missing;   ///< sum of missing azimuths over rotations
    uint32_t targets;            ///< targets reported
    uint32_t can_frames;         ///< frames accepted by can_tx
    uint32_t can_dropped;        ///< frames can_tx refused (BUSY or error), plus drops the
                                 ///< port reported later (sl_pipeline_add_can_dropped);
                                 ///< saturates at UINT32_MAX
    uint32_t can_rx;             ///< frames given to sl_pipeline_on_can_rx
    uint32_t motion_accepted;    ///< VehicleMotion frames accepted from CAN (E2E OK,
                                 ///< OK_SOME_LOST or INITIAL)
    uint32_t motion_set_calls;   ///< sl_pipeline_set_motion() calls (not counted above)
    uint32_t motion_rejected;    ///< VehicleMotion frames rejected by E2E (ERROR, REPEATED,
                                 ///< WRONG_SEQUENCE): Health fault MOTION_E2E
    uint32_t geometry_rejected;  ///< Configurations whose geometry does not match the board
    uint32_t rows_dropped;       ///< rows ignored after such a Configuration (until one matches)
    uint32_t restarts;           ///< radar restarts seen (geometry change, finish)
    uint32_t reconnects;         ///< sl_pipeline_add_reconnect() calls (Health.Reconnects)
    uint32_t can_rate_limited;   ///< frames withheld by the output ceiling (sl_can.h)
    uint32_t bin_size_mismatch;  ///< Configurations whose bin size is > 1 % off the board's
    uint32_t blind_rotations;    ///< rotations' worth of FFT messages without a usable row
    uint32_t bin_size_changes;   ///< detection moved to the radar's bin size (Configuration)
    uint32_t bin_size_unserved;  ///< radar bin size too small for the masked bins: board's kept
    uint32_t refused_rotations;  ///< rotations whose rows were all refused (config mismatch):
                                 ///< not counted in `rotations`, their azimuths are missing
} sl_pipeline_stats_t;

/// The pipeline. Caller-allocated (static); fields read-only to the application. Stage
/// members are public for inspection (stats, mask, last targets) but must not be changed.
typedef struct sl_pipeline {
    const sl_board_t *board;     ///< borrowed until re-init
    sl_pipeline_cfg_t cfg;
    uint8_t reason;              ///< sl_pipeline_reason_t of the last failed init
    const char *last_err_msg;    ///< ROM string for the first error, or NULL
    sl_err_t last_err;           ///< first error code seen (SL_OK when none)
    uint16_t mask_bins;          ///< bins thresholded and masked (sl_detect_bins_needed)
    uint16_t mask_words;         ///< SL_BITS_WORDS(mask_bins)
    uint8_t link_state;          ///< sl_can_link_state_t for Status
    uint8_t frames_eff;          ///< current n_eff
    uint8_t in_rotation;         ///< internal: a rotation is being assembled
    bool ready;                  ///< init succeeded
    bool geometry_bad;           ///< the radar's last Configuration did not match the board
    uint16_t next_az;            ///< internal: next azimuth detection expects
    uint16_t learn_az;           ///< internal: the azimuth the sensor model reads this rotation
    bool thr_flat;               ///< every band's threshold is cfg.threshold (thr_band)
    bool learn_hit;              ///< internal: this rotation's learning row gave a peak
    uint32_t r_max_um;           ///< farthest range detection reads (for the yaw term)
    uint32_t rotation_us;        ///< last measured rotation period
    bool motion_valid;           ///< motion used for the current rotation
    int32_t speed_mm_s;          ///< ... its speed (0 when invalid)
    int32_t yaw_cdeg_s;          ///< ... its yaw rate (0 when invalid)
    uint64_t last_t_last_us;     ///< previous rotation's t_last_us (0 = none)
    uint64_t now_us;             ///< now_us of the current call
    // motion input
    sl_can_motion_rx_t motion_rx; ///< CAN VehicleMotion receiver (E2E)
    sl_can_vehicle_motion_t motion; ///< last motion from the setter
    uint64_t motion_t_us;        ///< time of the setter's value
    bool motion_set;             ///< the setter was used
    // stages
    sl_proto_t proto;
    const sl_proto_stats_t *decoder_stats; ///< counters Status reports: &proto.stats, or the
                                           ///< caller's decoder (sl_pipeline_set_decoder_stats)
    sl_scan_t scan;
    sl_mask_t mask;
    sl_detect_t detect;
    sl_profile_t prof;           ///< range profiles of the azimuths showing something
    sl_tracker_t tracker;
    sl_tiltobs_t tilt;           ///< per-track observation history + 3D tilt fits (sl_tiltobs.h)
    sl_can_tx_t can;
    sl_pipeline_stats_t stats;
    sl_board_t det_board;        ///< the board as detection uses it: bin size from the radar's
                                 ///< Configuration (the board's until one arrives)
    // health (Status link state, Health frame)
    bool bin_size_bad;           ///< the radar's bin size is > 1 % off the board's
    uint32_t radar_bin_um;       ///< bin size of the last Configuration (0: none yet)
    uint32_t rows_since_status;  ///< usable rows since the last Status
    uint32_t rows_since_health;  ///< usable rows since the last Health
    bool have_row;               ///< a usable row arrived since init
    uint64_t last_row_us;        ///< now_us of the last usable row
    uint16_t fault_latched;      ///< fault bits raised since the last Health
    uint16_t last_faults;        ///< Fault of the last Health frame
    uint16_t faults_seen;        ///< every Fault bit sent since init
    uint8_t reconnect_next;      ///< internal: ring index
    bool can_clock_set;          ///< output ceiling: buckets initialised (full)
    uint32_t can_tokens_data;    ///< output ceiling: data frame tokens (PoleLean,
                                 ///< LeanWarning, PoleTilt, GroundPlane, GroundHazard; 1/1000)
    uint32_t can_tokens_status;  ///< output ceiling: Status/Health tokens (1/1000)
    uint64_t can_clock_us;       ///< output ceiling: now_us of the last refill
    uint64_t reconnect_t_us[SL_CAN_FLAP_RECONNECTS]; ///< times of the last reconnects
    struct {
        uint32_t fft, resyncs, malformed, bad_azimuth, empty_rows, can_dropped, disorder,
            target_overflow, motion_rejected;
    } snap;                      ///< internal: counters at the last Health
    uint32_t bits[SL_MASK_WORDS]; ///< thresholded row (internal)
    uint32_t occ[SL_MASK_WORDS];  ///< stable-occupied row (internal)
    uint8_t row8[SL_CFG_MASK_BINS]; ///< scan's row buffer (16-bit reduction, short rows)
    uint8_t reasm[SL_PIPELINE_REASM_BYTES]; ///< decoder reassembly buffer
    sl_drift_t drift;            ///< theta drift watch (sl_drift.h): Health.ThetaDrift, THETA_DRIFT
    // the sensor model (last: the hot fields keep their offsets)
    sl_response_t resp;          ///< range response and noise floor (sl_response.h): the
                                 ///< board's prior, learned from one row per rotation
    uint8_t thr_band[SL_CFG_RESP_FLOOR_BANDS]; ///< occupied threshold per band of
                                 ///< SL_RESP_FLOOR_BAND bins: max(threshold, floor + margin)
#if SL_CFG_GROUND
    sl_ground_t ground;          ///< the ground from the shadow's edge (sl_ground.h), with
                                 ///< cfg.ground
#endif
} sl_pipeline_t;

/// RAM budget of the firmware configuration (CTS350-X: 400 azimuths, n <= 16, masked bins
/// <= 192, the default target/candidate capacities): the whole pipeline in 64 KiB.
#if SL_CFG_MAX_AZIMUTHS <= 400 && SL_CFG_MASK_FRAMES_MAX <= 16 && SL_CFG_MASK_BINS <= 192 &&   \
    SL_CFG_MAX_TARGETS <= 32 && SL_CFG_DETECT_MAX_CANDIDATES <= 32 &&                          \
    SL_CFG_DETECT_MAX_SPAN <= 24
#if defined(__cplusplus)
static_assert(sizeof(sl_pipeline_t) <= 65536U, "sl_pipeline_t: 64 KiB RAM budget");
#else
_Static_assert(sizeof(sl_pipeline_t) <= 65536U, "sl_pipeline_t: 64 KiB RAM budget");
#endif
#endif
/// The ground's share of the pipeline (its state and configuration), 0 without it.
#if SL_CFG_GROUND
#define SL_PIPELINE_GROUND_BYTES (sizeof(sl_ground_t) + sizeof(sl_ground_cfg_t))
#else
#define SL_PIPELINE_GROUND_BYTES 0U
#endif
/// The fit's buffers in the profile and its results per slot (SL_CFG_FIT), 0 without it.
#if SL_CFG_FIT
#define SL_PIPELINE_FIT_BYTES \
    (8U * SL_CFG_PROFILE_BINS + sizeof(sl_rfit_ws_t) +                                     \
     (32U + 4U * SL_CFG_PROFILE_BINS) * SL_CFG_PROFILE_SLOTS)
#else
#define SL_PIPELINE_FIT_BYTES 0U
#endif
/// Any azimuth count, bins and n with the default target/candidate capacities: the mask
/// dominates; everything else except the tilt history (sl_tiltobs_t, sized by
/// SL_CFG_TILT_TRACKS x SL_CFG_TILT_OBS_PER_TRACK: 2.5 KB firmware, 7.4 KB host) and the
/// sensor model (sl_response_t, about 2.6 KB) and the ground (sl_ground_t and its
/// configuration, sized by SL_CFG_GROUND_SECTORS) and the fit's buffers
/// (SL_PIPELINE_FIT_BYTES) stays under 17,600 B (17,452 B in the host configuration, with
/// detection's link table, 168 B, its per-azimuth peaks, 776 B, the CAN sender's ids, E2E
/// configuration and counters for its eight messages, 80 B, and the
/// VehicleMotion receiver with its Profile 11 state, 104 B).
#if SL_CFG_MAX_TARGETS <= 32 && SL_CFG_DETECT_MAX_CANDIDATES <= 32 && SL_CFG_DETECT_MAX_SPAN <= 24 \
    && SL_CFG_MAX_AZIMUTHS <= 400
#if defined(__cplusplus)
static_assert(sizeof(sl_pipeline_t) <= sizeof(sl_mask_t) + sizeof(sl_tiltobs_t) +
                                             sizeof(sl_response_t) + SL_PIPELINE_GROUND_BYTES +
                                             SL_PIPELINE_FIT_BYTES + 17600U,
              "sl_pipeline_t budget");
#else
_Static_assert(sizeof(sl_pipeline_t) <= sizeof(sl_mask_t) + sizeof(sl_tiltobs_t) +
                                             sizeof(sl_response_t) + SL_PIPELINE_GROUND_BYTES +
                                             SL_PIPELINE_FIT_BYTES + 17600U,
               "sl_pipeline_t budget");
#endif
#endif

/// Initialise (or completely reset) for `board` (borrowed, usually static const; or a
/// vehicle's calibrated view from sl_calblob_open(), whose blob must then outlive the
/// pipeline) with `cfg` (copied; NULL = sl_pipeline_cfg_default(board)).
/// @return SL_OK; SL_ERR_ARG (NULL, cfg out of range); SL_ERR_RANGE when the board does
/// not fit the compile-time capacities, in particular when detection needs more bins than
/// SL_CFG_MASK_BINS (the reason is in `p->reason` / `p->last_err_msg`, e.g. "detection
/// needs more bins than SL_CFG_MASK_BINS"). The pipeline is unusable after an error.
/// Cost: O(sizeof(sl_pipeline_t)) clearing + O(azimuths) detection tables.
sl_err_t sl_pipeline_init(sl_pipeline_t *p, const sl_board_t *board,
                          const sl_pipeline_cfg_t *cfg);

/// Feed `len` bytes of the radar stream (any chunking). Rotations completed by these bytes
/// are processed and reported (port callbacks) before it returns.
/// @return SL_OK, or SL_ERR_ARG (NULL p, NULL data with len > 0). Stream errors are
/// counted in the stage stats, never returned.
sl_err_t sl_pipeline_feed(sl_pipeline_t *p, const uint8_t *data, size_t len, uint64_t now_us);

/// Decode once: one message the caller's own sl_proto decoder produced (its on_msg
/// callback), processed exactly as if the pipeline's decoder had produced it from the same
/// bytes with sl_pipeline_feed(): same rows, rotations, callbacks and CAN frames. For a port
/// that decodes the stream anyway (the Linux radar client and capture reader, for their
/// state machine and pacing); the MCU path keeps sl_pipeline_feed(). Call from inside the
/// caller's on_msg (the payload view ends there). Do not mix with sl_pipeline_feed() in one
/// stream; sl_pipeline_finish() still ends a stream (call it where the caller finishes its
/// decoder). The caller's decoder may keep whole payloads (no truncate_long): only the
/// region of interest is read. Status.DecoderResyncs: see sl_pipeline_set_decoder_stats().
/// @return SL_OK, or SL_ERR_ARG (NULL p or msg, not initialised). O(1) + the stages' cost.
sl_err_t sl_pipeline_on_msg(sl_pipeline_t *p, const sl_proto_msg_t *msg, uint64_t now_us);

/// Which decoder's counters Status frames report (DecoderResyncs): `stats` (borrowed; the
/// caller's decoder used with sl_pipeline_on_msg(), must outlive its use), or NULL for the
/// pipeline's own decoder (the default after init). O(1).
void sl_pipeline_set_decoder_stats(sl_pipeline_t *p, const sl_proto_stats_t *stats);

/// End of stream (EOF, connection lost, before reconnecting): drops a partial message,
/// completes and reports the partial rotation if any. The next byte fed starts a new
/// stream; mask history is kept (a radar restart is handled like a gap). O(azimuths).
sl_err_t sl_pipeline_finish(sl_pipeline_t *p, uint64_t now_us);

/// One frame from the vehicle bus. VehicleMotion (board id): E2E-checked (Profile 11 with
/// the board's Data ID, mode and max delta counter; sl_can_motion_rx_feed()), then used.
/// @return SL_OK (accepted), SL_ERR_ARG (NULL or another id: ignored), or the E2E error
/// (SL_ERR_MALFORMED / SL_ERR_STATE: rejected, counted). O(1).
sl_err_t sl_pipeline_on_can_rx(sl_pipeline_t *p, const sl_can_frame_t *f, uint64_t now_us);

/// Direct motion input (no CAN): speed in mm/s (> 0 forward), yaw rate in 0.01 deg/s
/// (> 0 counter-clockwise from above), valid flags as in VehicleMotion. Overrides older
/// CAN values; the newest input of either kind is used. Counted in
/// `stats.motion_set_calls` (not in `motion_accepted`, which counts CAN frames). O(1).
void sl_pipeline_set_motion(sl_pipeline_t *p, int32_t speed_mm_s, bool speed_valid,
                            int32_t yaw_rate_cdeg_s, bool yaw_rate_valid, uint64_t now_us);

/// Link state for the Status frame (sl_can_link_state_t, set by the port). O(1).
void sl_pipeline_set_link_state(sl_pipeline_t *p, uint8_t link_state);

/// One Status frame now, between rotations (e.g. the port's 1 Hz idle Status while no
/// rotation completes): the current link state and counters, encoded with the pipeline's
/// own sender so the Status E2E counter continues the rotations' sequence, sent through
/// `port.can_tx` (a refusal is counted in `stats.can_dropped` like any frame; no can_tx:
/// nothing is sent). `now_us` is the port's clock (stored as the call's time only).
/// @return SL_OK, or SL_ERR_ARG (NULL or not initialised). O(1).
sl_err_t sl_pipeline_send_status(sl_pipeline_t *p, uint64_t now_us);

/// The port re-opened the radar link (a reconnect after a drop, or after the data watchdog
/// gave up on a silent link). Counted in `stats.reconnects` (Health.Reconnects, saturating
/// at 255 on the wire); SL_CAN_FLAP_RECONNECTS within SL_CAN_FLAP_WINDOW_MS raise
/// LINK_FLAPPING. O(1).
void sl_pipeline_add_reconnect(sl_pipeline_t *p, uint64_t now_us);

/// The Fault bits (SL_CAN_FAULT_*) the next Health frame would carry now: faults raised
/// since the last Health plus those that still hold (configuration mismatches; no usable
/// row since the last Health while the link is up or FFT messages arrive). O(1).
uint16_t sl_pipeline_faults(const sl_pipeline_t *p);

/// Add `n` frames the port lost AFTER `can_tx` accepted them (a sink's stale or bus-off
/// drops, gs_usb frames never confirmed) to `stats.can_dropped` (saturating at UINT32_MAX),
/// so that the next Status frame's CanDropped includes them. Drops `can_tx` reported by
/// its return value are already counted: do not add those again. O(1).
void sl_pipeline_add_can_dropped(sl_pipeline_t *p, uint32_t n);

/// The consistency window n_eff for a motion (formula in the file comment): pure, for
/// tests and tools. `speed_mm_s`/`yaw_rate_cdeg_s` signed (magnitudes are used);
/// `rotation_us` the period; `budget_um` D; `r_max_um` the farthest range of interest.
/// O(1), 64-bit integer arithmetic.
uint8_t sl_pipeline_window(uint8_t n, uint8_t min_frames, int32_t speed_mm_s,
                           int32_t yaw_rate_cdeg_s, uint32_t rotation_us, uint32_t budget_um,
                           uint32_t r_max_um);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_PIPELINE_H
