// SPDX-License-Identifier: MIT
/// @file sl_response.h
/// @brief The radar's sensor model as data: the value scale (8-bit value -> power), the range
/// response (a point return's power over neighbouring bins) and the noise floor per range,
/// with an online learner that measures both from the stream.
///
/// ## The value scale
/// An 8-bit value is a power through one of two mappings (`sl_vscale_t`):
/// - `SL_VSCALE_LOG2`: the Navtech mapping, value = round(cpo (e + m)) for a power
///   x = 2^e (1 + m), 0 <= m < 1: a piecewise-linear log2 with `cpo` values per octave of
///   power (the CTS350-X: 6.02, i.e. 0.5 dB per value). Its inverse is exact at powers of two.
/// - `SL_VSCALE_LINEAR`: power = value (a simulator's linear energy mapping).
/// Power is handled as `lp`, log2 of power in Q8 (uint16, value 0 of a LOG2 scale = 0), or as
/// linear power in a caller-chosen binary scale (sl_vscale_power).
///
/// ## The range response
/// `sl_response_t` holds the power a point return puts into the bins at offsets
/// -SL_CFG_RESP_HALF .. +SL_CFG_RESP_HALF from its centre, as the drop below the centre in
/// log2-power Q8 (`drop_q8`, 0 at offset 0; one octave = 3.01 dB = 256). The model is
/// continuous: power at a fractional offset is the linear interpolation of the linear taps.
/// From the drops, sl_response_update() derives what the fit of sl_rfit.h reads: the linear
/// taps (Q22, centre 2^22), their cumulative integral at 1/SL_RESP_SUB bin steps, the
/// speckle correlation length `ncorr_q8` = (sum tap)^2 / sum tap^2 in bins (Q8: how many
/// bins one independent speckle draw spans) and the correlation of speckled powers Delta
/// bins apart, `rho2_q15[Delta]` = |c(Delta)|^2 with c the normalised autocorrelation of the
/// amplitude response sqrt(R) (circular Gaussian speckle through the range processing).
///
/// The CTS350-X prior (sl_response_prior_cts350x) is the lobe measured on Oxford RobotCar
/// scans (docs/RANGE_RESPONSE.md): a power Gaussian of sigma ~3.4 bins, half-power width
/// ~8 bins, -20 dB at +-10 bins, a first sidelobe near -32 dB at 12-16 bins.
///
/// ## Learning from the stream
/// sl_response_learn_peaks() reads one row (one azimuth, the caller chooses which: the
/// pipeline samples a few per rotation) beyond the shadow, between `min_bin` and `max_bin`:
/// - peaks: bins whose lp is at least `cfg.peak_min_lp` above the row's floor estimate, that
///   are the maximum of +-`cfg.isolation` bins and have no second comparable peak (within
///   `cfg.rival_lp` of it behind a dip of `cfg.dip_lp`) within that distance; the centre is
///   the middle of the peak's flat top (equal maximum bins), which may be half a bin;
/// - each accepted peak updates, per offset, a running median of the drop below the peak
///   (a sign-driven quantile estimate whose step shrinks with the sample count, so a few
///   wrong peaks move it by at most a step each: robust aggregation);
/// - the learned response replaces the prior once `cfg.min_peaks` peaks are in and it is
///   plausible: non-decreasing drop away from the centre on each side down to
///   `cfg.plaus_drop_lp`, half-power width within [1, SL_CFG_RESP_HALF] bins on each side;
///   an implausible estimate keeps the prior and is counted (`stats.implausible`).
/// - the floor: per range band of `SL_RESP_FLOOR_BAND` bins, a running median of lp over
///   every 4th bin of the rows read (an exponential noise's median is its mean times ln 2:
///   sl_response_floor_lp returns the mean's lp), read by sl_response_learn_floor() over the
///   bins the caller gives (the pipeline: inside the shadow, where only the receiver's noise
///   and sparse targets are); bands are independent.
///
/// ## Ownership, memory, cost
/// Caller-owned, no allocation, no float. RAM: sizeof(sl_response_t) (about 2.6 KB with the
/// defaults). sl_response_learn_peaks: O(max_bin - min_bin) with a 2 x isolation window per
/// candidate peak (at most 2 x `cfg.max_peaks_per_row` candidates examined, at most
/// `cfg.max_peaks_per_row` accepted); sl_response_update: O(taps x
/// SL_RESP_SUB). Not reentrant per instance.
#ifndef SHADOWLEAN_SL_RESPONSE_H
#define SHADOWLEAN_SL_RESPONSE_H

#include <stdbool.h>
#include <stdint.h>

#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Taps each side of the centre.
#ifndef SL_CFG_RESP_HALF
#define SL_CFG_RESP_HALF 20
#endif
#if SL_CFG_RESP_HALF < 4 || SL_CFG_RESP_HALF > 48
#error "SL_CFG_RESP_HALF must be in [4, 48]"
#endif
#define SL_RESP_TAPS (2 * SL_CFG_RESP_HALF + 1)
/// Sub-bin steps of the cumulative response.
#define SL_RESP_SUB 8
#define SL_RESP_CUM (SL_RESP_TAPS * SL_RESP_SUB + 1)
/// Floor bands (each SL_RESP_FLOOR_BAND bins; bins beyond the last band share it).
#ifndef SL_CFG_RESP_FLOOR_BANDS
#define SL_CFG_RESP_FLOOR_BANDS 32
#endif
#define SL_RESP_FLOOR_BAND 64

/// How 8-bit values map to power.
typedef enum sl_vscale_kind {
    SL_VSCALE_LOG2 = 0,   ///< piecewise-linear log2, `cpo_q8` values per octave of power
    SL_VSCALE_LINEAR = 1, ///< power = value
} sl_vscale_kind_t;

typedef struct sl_vscale {
    uint8_t kind;    ///< sl_vscale_kind_t
    uint16_t cpo_q8; ///< LOG2: values per octave of power, Q8 (6.02 -> 1541); [256, 4096]
} sl_vscale_t;

/// The CTS350-X's scale: SL_VSCALE_LOG2, 6.02 values per octave (0.5 dB per value).
#define SL_VSCALE_CTS350X {(uint8_t)SL_VSCALE_LOG2, 1541U}

/// log2 of the power of `v`, Q8. LOG2: exact piecewise-linear inverse (256 (e + log2(1 + m))
/// with log2(1 + m) from a 257-entry table, error <= 1 LSB); LINEAR: 256 log2(v), v = 0 reads
/// as v = 1/2 (-256). Returns INT32_MIN for an invalid scale. O(1), one division (LOG2).
int32_t sl_vscale_lp(const sl_vscale_t *s, uint8_t v);

/// Power of `v` as round(x 2^-shift), saturating at UINT32_MAX, x the scale's power (LOG2:
/// 2^e (1 + m), value 0 = 1). `shift` may be negative (a left shift, for precision), in
/// [-16, 48]. 0 for an invalid scale. O(1).
uint32_t sl_vscale_power(const sl_vscale_t *s, uint8_t v, int shift);

/// 2^(lp / 256) for lp in Q8, as Q16 (lp in [-16 * 256, 15 * 256]; saturates). O(1).
uint32_t sl_lp_to_lin_q16(int32_t lp);
/// 256 log2(x) for x >= 1 (x = 0 reads -256 x 32); error <= 1 LSB. O(1).
int32_t sl_lin_to_lp(uint64_t x);
/// 65536 log2(x) for x >= 1 (x = 0 reads -65536 x 32); error <= 1 LSB (table of 257
/// entries, linear interpolation). O(1).
int32_t sl_lin_log2_q16(uint64_t x);

/// Where the response came from.
typedef enum sl_response_source {
    SL_RESPONSE_PRIOR = 0,      ///< the board's (or the built-in CTS350-X) prior
    SL_RESPONSE_LEARNED = 1,    ///< learned from this stream
    SL_RESPONSE_CALIBRATED = 2, ///< loaded from a calibration (a capture measured offline)
} sl_response_source_t;

typedef struct sl_response_cfg {
    int32_t peak_min_lp;   ///< a peak is at least this far above the floor (Q8 octaves;
                           ///< default 40 dB = 13.3 octaves)
    int32_t rival_lp;      ///< a second peak within this of the peak (default 5 dB) ...
    int32_t dip_lp;        ///< ... behind a dip of at least this (default 3 dB) rejects it
    uint16_t isolation;    ///< bins each side the peak must dominate (default 30)
    uint16_t min_peaks;    ///< peaks before a learned response is used (default 64)
    int32_t plaus_drop_lp; ///< plausibility checked down to this drop (default 20 dB)
    uint8_t max_peaks_per_row; ///< accepted peaks per row at most (default 4)
} sl_response_cfg_t;

typedef struct sl_response_stats {
    uint32_t rows;        ///< rows read by sl_response_learn_peaks
    uint32_t peaks;       ///< peaks accepted
    uint32_t rivals;      ///< candidate peaks rejected for a comparable neighbour
    uint32_t implausible; ///< updates where the learned shape failed the gates (prior kept)
} sl_response_stats_t;

/// The sensor model. Fields read-only to the application.
typedef struct sl_response {
    sl_vscale_t scale;
    sl_response_cfg_t cfg;
    int16_t lp_q8[256];                   ///< derived: sl_vscale_lp of every value
                                          ///< (saturating at 128 octaves)
    uint8_t source;                       ///< sl_response_source_t of `drop_q8`
    uint16_t drop_q8[SL_RESP_TAPS];       ///< in use: drop below the centre, log2 Q8
    int32_t learn_q8[SL_RESP_TAPS];       ///< running medians (learned drops), log2 Q8
    uint32_t learn_n;                     ///< peaks aggregated into learn_q8
    uint32_t tap_q22[SL_RESP_TAPS];       ///< derived: linear taps, centre 2^22
    uint32_t cum[SL_RESP_CUM];            ///< derived: cum[j] = integral of the linear
                                          ///< response from -HALF to -HALF + j/SUB bins, in
                                          ///< tap_q22 x (1/SUB bin)
    uint32_t area_q8;                     ///< derived: integral of the taps / 2^22, bins Q8
    uint16_t ncorr_q8;                    ///< derived: speckle correlation length, bins Q8
    uint16_t rho2_q15[SL_RESP_TAPS];      ///< derived: correlation of speckled powers
                                          ///< Delta bins apart (Delta = index), Q15
    uint32_t s4_q8;                       ///< derived: sum over all Delta of rho2^2, bins Q8
    int32_t floor_q8[SL_CFG_RESP_FLOOR_BANDS]; ///< running median lp per band (INT32_MIN: none)
    uint16_t floor_n[SL_CFG_RESP_FLOOR_BANDS]; ///< samples per band (saturating)
    sl_response_stats_t stats;
} sl_response_t;

/// Defaults above. O(1).
void sl_response_cfg_default(sl_response_cfg_t *cfg);

/// The built-in CTS350-X prior (measured lobe), drops in log2 Q8, offsets -HALF..+HALF.
void sl_response_prior_cts350x(uint16_t drop_q8[SL_RESP_TAPS]);

/// Init with a scale, a prior (NULL: the CTS350-X prior) and a configuration (NULL:
/// defaults). SL_ERR_ARG on NULL `r`/`scale`, an invalid scale, or a prior that is not 0 at
/// the centre. O(taps x SUB).
sl_err_t sl_response_init(sl_response_t *r, const sl_vscale_t *scale,
                          const uint16_t *prior_q8, const sl_response_cfg_t *cfg);

/// True when `drop_q8` is a plausible response: 0 at the centre, non-decreasing away from it
/// on each side down to a drop of `down_to_lp` (log2 Q8), below half power within
/// SL_CFG_RESP_HALF bins on each side (the gates of a learned shape). O(taps).
bool sl_response_plausible(const uint16_t drop_q8[SL_RESP_TAPS], int32_t down_to_lp);

/// Use `drop_q8` (a calibration's, SL_RESPONSE_CALIBRATED) instead of the prior / learned
/// shape. SL_ERR_ARG when it fails the plausibility gates. O(taps x SUB).
sl_err_t sl_response_set(sl_response_t *r, const uint16_t drop_q8[SL_RESP_TAPS], uint8_t source);

/// Reads one row of `bins` 8-bit values; learns the floor over [min_bin, max_bin). Returns 0
/// or SL_ERR_ARG. The pipeline reads it inside the shadow, where the floor is the receiver's
/// noise and the targets are sparse. O(max_bin - min_bin) / 4.
int sl_response_learn_floor(sl_response_t *r, const uint8_t *row, uint32_t bins,
                            uint32_t min_bin, uint32_t max_bin);

/// Reads one row of `bins` 8-bit values; learns the shape from the peaks whose +-isolation
/// window lies inside [min_bin, max_bin), against the floor learned in the peak's band, else
/// in the nearest band before it (no peak before any floor is learned). Returns the peaks accepted (>= 0) or
/// SL_ERR_ARG. Does not change the response in use: call sl_response_update() (e.g. once per
/// rotation). The pipeline reads it beyond the shadow, where a slender target's own extent
/// cannot be taken for the response.
int sl_response_learn_peaks(sl_response_t *r, const uint8_t *row, uint32_t bins,
                            uint32_t min_bin, uint32_t max_bin);

/// Samples a band's floor needs before sl_response_floor_resolved() vouches for it (the
/// running median starts at the first sample and moves by a shrinking step per sample).
#define SL_RESP_FLOOR_MIN_N 64U

/// True when the floor of `bin`'s band is learned from at least SL_RESP_FLOOR_MIN_N samples
/// and its median is above the scale's value 0: a floor whose median reads 0 is below the
/// quantiser's first step (a noise-free rendering, or a receiver whose noise the 8-bit scale
/// does not resolve), and its level is not known, only bounded. O(1).
bool sl_response_floor_resolved(const sl_response_t *r, uint32_t bin);

/// sl_response_learn_floor and sl_response_learn_peaks over the same bins (a tool measuring
/// the response of a capture's rows).
int sl_response_learn_row(sl_response_t *r, const uint8_t *row, uint32_t bins, uint32_t min_bin,
                          uint32_t max_bin);

/// Adopts the learned shape when it has `cfg.min_peaks` peaks and passes the gates (else
/// keeps the current one and counts). Returns true when the response in use changed.
/// O(taps x SUB).
bool sl_response_update(sl_response_t *r);

/// Mean noise power at `bin` as lp (Q8), from the band's median (+ log2(1/ln 2) for an
/// exponential noise). INT32_MIN when the band has no samples yet.
int32_t sl_response_floor_lp(const sl_response_t *r, uint32_t bin);

/// The linear response at offset x (bins, Q8, centre 0) in Q22 (centre 2^22): the taps
/// interpolated, 0 from the last tap on and before the first (as the cumulative integrates
/// it). 0 for NULL. O(1).
uint32_t sl_response_at_q22(const sl_response_t *r, int32_t x_q8);

/// Integral of the linear response over (-inf, u] (u in bins Q8), in tap_q22 x (1/SUB bin):
/// the cumulative table interpolated; 0 before -HALF, `cum[SL_RESP_CUM-1]` from +HALF on;
/// 0 for NULL. O(1).
uint32_t sl_response_cum(const sl_response_t *r, int32_t u_q8);

/// Half-power width of the response in use, bins Q8 (each side's -3 dB crossing, linear
/// interpolation of the drops).
uint32_t sl_response_hpw_q8(const sl_response_t *r);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_RESPONSE_H
