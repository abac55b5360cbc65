// SPDX-License-Identifier: MIT
/// @file daemon_targets.h
/// @brief `--targets-out`: the pipeline's per-rotation results as JSON lines, the side
///        file tests compare the CAN output with.
///
/// Schema: docs/schema/targets.schema.json, documented in docs/JSON_OUTPUTS.md (every field,
/// units, versioning). The header's "schema" key names the output and its major version.
///
/// First line, once:
///     {"type":"header","schema":"shadowlean-targets/1","board":"paper-sim","azimuths":400,"radar_yaw_cdeg":0,
///      "confirm_hits":3,"bin_size_um":43800,"can_id_pole_lean":1568,...}
/// Then one line per completed rotation (`port.on_rotation`), written BEFORE the CAN
/// frames of that rotation:
///     {"type":"rotation","rotation":0,"now_us":...,"t_first_us":...,"t_last_us":...,
///      "valid":400,"missing":0,"end":0,"frames_eff":16,"level":0,"motion_valid":false,
///      "speed_mm_s":0,"yaw_rate_cdeg_s":0,
///      "targets":[{"az":..,"az_first":..,"az_count":..,"bin_first":..,"bin_last":..,
///                  "r1_raw_um":..,"r2_raw_um":..,"r1_um":..,"r2_um":..,"radius_um":..,
///                  "alpha_cdeg":..,"sigma_cdeg":..,"flag":..,"branch":..,"flags":..}],
///      "tracks":[{"slot":..,"id":..,"az":..,"r1_um":..,"r2_um":..,"alpha_cdeg":..,
///                 "sigma_cdeg":..,"hits":..,"valid_hits":..,"level":..,"last_flag":..,
///                 "updated":0|1}]}
/// `tracks` lists the live slots in slot order (the order of the PoleLean frames).
/// Integers only, in the core's units (suffix in the name). Cost: one fprintf per field.
#ifndef SHADOWLEAN_DAEMON_TARGETS_H
#define SHADOWLEAN_DAEMON_TARGETS_H

#include <stdio.h>

#include "shadowlean/sl_pipeline.h"

/// The header line's "schema": output name / major version (docs/JSON_OUTPUTS.md).
#define SLD_TARGETS_SCHEMA "shadowlean-targets/1"

#ifdef __cplusplus
extern "C" {
#endif

/// Header line. @return 0 or -1 (write error).
int sld_targets_write_header(FILE *fp, const sl_board_t *board, const sl_pipeline_cfg_t *cfg);

/// One rotation line. @return 0 or -1 (write error).
int sld_targets_write_rotation(FILE *fp, const sl_pipeline_rotation_t *r);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_DAEMON_TARGETS_H
