// SPDX-License-Identifier: MIT
/// @file sl_mask.h
/// @brief Bit-packed n-frame consistency mask (paper Sec. III-C, MATH.md s.4).
///
/// The paper keeps a pixel only if it is equal in all of the last `n` frames (n = 16, 4 s
/// at 4 Hz). This module gives, per azimuth and range bin, two planes:
/// - **stable-occupied**: the bin was occupied in each of the azimuth's last `n` rows;
/// - **stable-free**: the bin was free in each of the azimuth's last `n` rows.
/// A bin that changed within the last `n` rows is in neither.
///
/// **Shorter windows at run time** (`sl_mask_set_window()`, used while the vehicle moves):
/// the counters always run with the full `n`, so after a bin's last change `k = n - m`
/// (m = rows since and including the change, k floored at 0). "Equal in the last w rows"
/// is therefore `k <= n - w`, a bit-sliced compare against a constant (2-3 operations per
/// plane). The stable planes are computed for the current window w (1..n); changing w
/// loses no history (a vehicle that stops gets its full-n mask back without waiting).
///
/// ## How (bit-sliced run counters instead of n stored planes)
/// Per azimuth the mask stores the last row `L` (1 plane) and, per bin, the number of rows
/// still needed before the bin counts as stable, `k` in `0..n-1`, bit-sliced over
/// `P = ceil(log2(n))` counter planes (bit p of every bin's k in plane p; P = 0 for n = 1).
/// A row `X` updates each 32-bin word (each 64-bin pair on 64-bit targets) with word
/// operations only:
///
///     d = X ^ L                      changed bins
///     k = (k > 0 && !d) ? k - 1      bit-sliced borrow chain, 3 operations per plane
///       : d ? n - 1 : k              one OR / AND-NOT per plane
///     L = X
///     stable = (k == 0)              OR over the planes
///     occupied = stable & X;  free = stable & ~X
///
/// The first row of an azimuth (after init or a reset) sets `L = X`, `k = n - 1`. Counting
/// down (rather than up to n) needs one plane fewer: n = 16 uses 4 counter planes, n = 32
/// uses 5, instead of ceil(log2(n + 1)) = 5 and 6. This is exactly equivalent to storing
/// the last n rows and intersecting them (tests/core/test_mask.c checks it bit for bit
/// against that naive reference for every n in 1..32, with missing azimuths).
///
/// ## Frames and missing azimuths
/// A frame is one row of one azimuth: `sl_mask_update()` at most once per azimuth per
/// rotation, then `sl_mask_end_rotation()` at each rotation boundary. An azimuth that got
/// no row in a rotation (lost packet, decoder resync) is **stale**: it is not counted as a
/// frame; its `L` and counters are **held** unchanged and its stable planes keep their
/// values, so a short gap neither fakes consistency nor throws away n rotations of history.
/// `missed(az)` counts consecutive rotations without a row; when it exceeds `max_missed`
/// the azimuth's history is dropped (both stable planes read 0 from then on) and its next
/// row starts a new run (stable again after n rows). So the "last n frames" of an azimuth
/// are its last n received rows, and (consecutive) gaps longer than `max_missed` rotations
/// restart the window. A second row for the same azimuth in one rotation is ignored and
/// counted (`stats.duplicate_rows`); an azimuth index out of range is ignored and counted.
///
/// ## Ownership, memory, cost
/// The caller owns `sl_mask_t` (static or on a large stack; no allocation). Storage is
/// sized by SL_CFG_MAX_AZIMUTHS x SL_CFG_MASK_BINS x (1 + SL_MASK_COUNTER_PLANES) bits
/// (the table is for SL_CFG_MASK_BINS = 512; a firmware build with 160 bins and n <= 16
/// needs 40,836 bytes):
///
/// | SL_CFG_MASK_FRAMES_MAX | planes | sizeof(sl_mask_t), 400 az x 512 bins | n full planes |
/// |---|---|---|---|
/// | 4  | 1 + 2 | 77,636 B  | 102,400 B |
/// | 16 | 1 + 4 | 128,836 B | 409,600 B |
/// | 32 | 1 + 5 | 154,436 B | 819,200 B |
///
/// (printed by `host_tools/bench_mask` for each configuration). A board may use any
/// n <= SL_CFG_MASK_FRAMES_MAX; the per-row cost follows its own P.
///
/// Per row: O(words x P) word operations, specialised per P and for n = 2^P (then the reset
/// to n - 1 is one OR per plane). A window of 1 copies the row; a window between 1 and n
/// adds a second pass for the stable planes (O(words)). Measured instruction counts per
/// n and row width: docs/PERFORMANCE.md, "Core modules".
/// sl_mask_end_rotation(): O(azimuths), a few instructions per azimuth.
/// sl_mask_stable(): O(words x P). Stack: a few words. Not reentrant on the same instance;
/// distinct instances are independent. Fields are read-only to the application.
#ifndef SHADOWLEAN_SL_MASK_H
#define SHADOWLEAN_SL_MASK_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_config.h"
#include "shadowlean/sl_err.h"
#include "shadowlean/sl_thresh.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Counter planes needed for a window of n frames: ceil(log2(n)) (0 for n = 1).
#define SL_MASK_PLANES_FOR(n)                                                                \
    ((n) <= 1 ? 0 : (n) <= 2 ? 1 : (n) <= 4 ? 2 : (n) <= 8 ? 3 : (n) <= 16 ? 4 : 5)

/// Words per mask row (SL_CFG_MASK_BINS is a multiple of 32).
#define SL_MASK_WORDS (SL_CFG_MASK_BINS / 32)

/// Counter planes stored per azimuth (for SL_CFG_MASK_FRAMES_MAX).
#define SL_MASK_COUNTER_PLANES SL_MASK_PLANES_FOR(SL_CFG_MASK_FRAMES_MAX)

/// Planes stored per azimuth: the last row, then the counter planes.
#define SL_MASK_PLANES (1 + SL_MASK_COUNTER_PLANES)

/// Default for `max_missed`: held through up to 2 consecutive missed rotations (0.5 s at 4 Hz).
#define SL_MASK_MAX_MISSED_DEFAULT 2U

/// Runtime drops and events, counted (never asserted).
typedef struct sl_mask_stats {
    uint32_t rows;           ///< rows applied (frames counted)
    uint32_t rotations;      ///< sl_mask_end_rotation() calls
    uint32_t stale_rows;     ///< azimuth x rotation without a row while it had history (held)
    uint32_t resets;         ///< histories dropped after more than max_missed missed rotations
    uint32_t duplicate_rows; ///< rows ignored: the azimuth already had one this rotation
    uint32_t bad_azimuth;    ///< rows ignored: azimuth index >= azimuths
} sl_mask_stats_t;

/// The mask. Caller-owned; all fields read-only to the application.
typedef struct sl_mask {
    /// planes[az][0] = last row L; planes[az][1 + p] = bit p of the per-bin counter k.
    /// Layout of each row: sl_thresh.h (bin 32w + b = bit b of word w).
    uint32_t planes[SL_CFG_MAX_AZIMUTHS][SL_MASK_PLANES][SL_MASK_WORDS];
    uint8_t missed[SL_CFG_MAX_AZIMUTHS]; ///< consecutive rotations without a row (sat. 255)
    uint8_t state[SL_CFG_MAX_AZIMUTHS];  ///< bit 0: has history; bit 1: row this rotation
    uint16_t azimuths;                   ///< azimuths in use
    uint16_t bins;                       ///< bins per row in use
    uint16_t words;                      ///< SL_BITS_WORDS(bins)
    uint8_t frames;                      ///< n
    uint8_t counter_planes;              ///< P = SL_MASK_PLANES_FOR(n)
    uint8_t max_missed;                  ///< see "Frames and missing azimuths"
    uint8_t window;                      ///< w: stable = equal in the last w rows (1..n)
    sl_mask_stats_t stats;
} sl_mask_t;

/// Initialise (or re-initialise) a mask: no azimuth has history.
/// @param azimuths   1..SL_CFG_MAX_AZIMUTHS
/// @param bins       1..SL_CFG_MASK_BINS (bins per row: the board's roi_bins, or only the
///                   bins detection reads, sl_detect_bins_needed())
/// @param frames     n, 1..SL_CFG_MASK_FRAMES_MAX (usually the board's mask_frames)
/// @param max_missed consecutive missed rotations an azimuth is held through (0..254)
/// @return SL_OK, or SL_ERR_ARG (NULL or a value out of range; the mask is then unusable).
/// Cost: clears the whole struct (memset of sizeof(sl_mask_t)).
sl_err_t sl_mask_init(sl_mask_t *m, uint16_t azimuths, uint16_t bins, uint8_t frames,
                      uint8_t max_missed);

/// Set the window w used for the stable planes from now on (1..n; see "Shorter windows").
/// Counters and history are unchanged. @return SL_OK, or SL_ERR_ARG (w out of range:
/// ignored). O(1).
sl_err_t sl_mask_set_window(sl_mask_t *m, uint8_t w);

/// Drop every azimuth's history (e.g. after a radar restart). Stats are kept. O(azimuths).
void sl_mask_reset(sl_mask_t *m);

/// Apply one thresholded row of azimuth `az` (one frame) and optionally write its stable
/// planes after the update.
/// @param bits  the row, `m->words` words (layout sl_thresh.h), borrowed for the call
/// @param occ   out, nullable: stable-occupied row (`m->words` words)
/// @param free_ out, nullable: stable-free row (`m->words` words)
/// @return SL_OK; SL_ERR_RANGE when az >= azimuths (counted, ignored, outputs untouched);
///         SL_ERR_STATE when az already had a row this rotation (counted, ignored, the
///         outputs get the current stable planes as sl_mask_stable() would).
/// Cost: O(words x P), see the file comment. Bits beyond `bins` are ignored.
sl_err_t sl_mask_update(sl_mask_t *m, uint16_t az, const uint32_t *bits, uint32_t *occ,
                        uint32_t *free_);

/// Close a rotation: azimuths without a row become stale (held) or, past max_missed, lose
/// their history (see the file comment). Call once per rotation, after its last row.
/// Cost: O(azimuths), about 10 instructions each.
void sl_mask_end_rotation(sl_mask_t *m);

/// Current stable planes of azimuth `az` (held values for a stale azimuth; zeros when it has
/// no history or az is out of range). Either output may be NULL.
/// @return true when the azimuth has history (its planes mean something). O(words x P).
bool sl_mask_stable(const sl_mask_t *m, uint16_t az, uint32_t *occ, uint32_t *free_);

/// As sl_mask_stable() for the first `words` words only (clamped to the mask's words):
/// consumers that need the near range only (detection) skip the rest. O(words x P).
bool sl_mask_stable_prefix(const sl_mask_t *m, uint16_t az, uint32_t words, uint32_t *occ,
                           uint32_t *free_);

/// Consecutive rotations azimuth `az` has gone without a row (0 = fresh; 255 saturated; 0
/// for an out-of-range az). O(1).
uint8_t sl_mask_missed(const sl_mask_t *m, uint16_t az);

/// True when azimuth `az` has history (its stable planes are meaningful). O(1).
bool sl_mask_has_history(const sl_mask_t *m, uint16_t az);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_MASK_H
