// SPDX-License-Identifier: MIT
/// @file sl_config.h
/// @brief Compile-time capacities of the core (`SL_CFG_*`).
///
/// Every buffer in the core is an array inside a caller-owned struct, sized by these
/// knobs, so `sizeof` of a top-level object is its whole RAM. Override any knob with a
/// compiler definition (`-DSL_CFG_ROI_BINS=256`) or by providing `sl_config_user.h` on
/// the include path and defining `SL_CFG_USER_HEADER`. Each board's generated header
/// checks at compile time that the board fits these capacities.
#ifndef SHADOWLEAN_SL_CONFIG_H
#define SHADOWLEAN_SL_CONFIG_H

#ifdef SL_CFG_USER_HEADER
#include "sl_config_user.h"
#endif

/// Azimuths per rotation the core can hold (CTS350-X: 400).
#ifndef SL_CFG_MAX_AZIMUTHS
#define SL_CFG_MAX_AZIMUTHS 400
#endif
#if SL_CFG_MAX_AZIMUTHS < 8 || SL_CFG_MAX_AZIMUTHS > 4096
#error "SL_CFG_MAX_AZIMUTHS must be in [8, 4096]"
#endif

/// Range bins kept per azimuth (the region of interest, nearest bins only). Multiple of 32.
#ifndef SL_CFG_ROI_BINS
#define SL_CFG_ROI_BINS 512
#endif
#if SL_CFG_ROI_BINS < 32 || SL_CFG_ROI_BINS > 4096 || (SL_CFG_ROI_BINS % 32) != 0
#error "SL_CFG_ROI_BINS must be a multiple of 32 in [32, 4096]"
#endif

/// Bins per row the consistency mask can hold (its planes are sized by this), a multiple of
/// 32, <= SL_CFG_ROI_BINS. The detection pipeline thresholds and masks only the bins
/// detection reads (sl_detect_bins_needed(): the farthest shadow edge, 119..141 bins on the
/// boards carried today) and rejects a board that needs more at init (SL_ERR_RANGE).
/// Default: the whole ROI (host tools mask whole rows). A firmware build sets 160 (or
/// 192): the mask then takes 400 x 5 x 160 / 8 = 40,000 bytes at n <= 16 instead of
/// 128,000, which is what keeps sizeof(sl_pipeline_t) under 64 KiB.
#ifndef SL_CFG_MASK_BINS
#define SL_CFG_MASK_BINS SL_CFG_ROI_BINS
#endif
#if SL_CFG_MASK_BINS < 32 || SL_CFG_MASK_BINS > SL_CFG_ROI_BINS || (SL_CFG_MASK_BINS % 32) != 0
#error "SL_CFG_MASK_BINS must be a multiple of 32 in [32, SL_CFG_ROI_BINS]"
#endif

/// Largest consistency window n (frames) the mask supports; the board picks n <= this.
#ifndef SL_CFG_MASK_FRAMES_MAX
#define SL_CFG_MASK_FRAMES_MAX 32
#endif
#if SL_CFG_MASK_FRAMES_MAX < 1 || SL_CFG_MASK_FRAMES_MAX > 32
#error "SL_CFG_MASK_FRAMES_MAX must be in [1, 32]"
#endif

/// Targets reported per rotation and tracks kept over rotations.
#ifndef SL_CFG_MAX_TARGETS
#define SL_CFG_MAX_TARGETS 32
#endif
#if SL_CFG_MAX_TARGETS < 1 || SL_CFG_MAX_TARGETS > 255
#error "SL_CFG_MAX_TARGETS must be in [1, 255]"
#endif

/// Entries in a board's elongation table d(r).
#ifndef SL_CFG_MAX_ELONG_POINTS
#define SL_CFG_MAX_ELONG_POINTS 16
#endif

/// 3D tilt while driving (sl_tiltobs.h): tracks with an observation history, and the
/// observations each keeps (<= SL_TILT_MAX_OBS, 32). The firmware configuration (masked bins
/// <= 192) keeps 4 x 16 (2,472 B); the host 8 x 32 (7,368 B).
#ifndef SL_CFG_TILT_TRACKS
#if SL_CFG_MASK_BINS <= 192
#define SL_CFG_TILT_TRACKS 4
#else
#define SL_CFG_TILT_TRACKS 8
#endif
#endif
#ifndef SL_CFG_TILT_OBS_PER_TRACK
#if SL_CFG_MASK_BINS <= 192
#define SL_CFG_TILT_OBS_PER_TRACK 16
#else
#define SL_CFG_TILT_OBS_PER_TRACK 32
#endif
#endif
#if SL_CFG_TILT_TRACKS < 1 || SL_CFG_TILT_TRACKS > 32 || SL_CFG_TILT_OBS_PER_TRACK < 5
#error "SL_CFG_TILT_TRACKS must be in [1, 32] and SL_CFG_TILT_OBS_PER_TRACK >= 5"
#endif
/// Fits per rotation at most (the rest wait for their turn, round robin).
#ifndef SL_CFG_TILT_FITS_PER_ROTATION
#define SL_CFG_TILT_FITS_PER_ROTATION 2
#endif

/// The fit of the sensor model to a target's range profile (sl_profile_refine_fit, the
/// pipeline's `cfg.fit`) compiled in: 1 in the host configuration, 0 in the firmware
/// configuration (masked bins <= 192), whose stack budget (the fit runs at the rotation's
/// end, inside the decoder's callbacks) and per-azimuth instruction budget it does not fit
/// yet: there the profile carries no fit buffers and `cfg.fit` is refused.
#ifndef SL_CFG_FIT
#if SL_CFG_MASK_BINS <= 192
#define SL_CFG_FIT 0
#else
#define SL_CFG_FIT 1
#endif
#endif

/// The ground from the shadow's edge (sl_ground.h) compiled in, and on in
/// sl_pipeline_cfg_default(): 1 in the host configuration, 0 in the firmware configuration
/// (masked bins <= 192), whose flash, stack and per-azimuth instruction budgets
/// (docs/INTEGRATION.md, "Footprint") it does not fit: there ground.c compiles to nothing
/// and the pipeline carries no sl_ground_t.
#ifndef SL_CFG_GROUND
#if SL_CFG_MASK_BINS <= 192
#define SL_CFG_GROUND 0
#else
#define SL_CFG_GROUND 1
#endif
#endif

#endif // SHADOWLEAN_SL_CONFIG_H
