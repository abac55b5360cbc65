// SPDX-License-Identifier: MIT
/// @file calib_file.h
/// @brief A vehicle's calibration file (INI or blob) -> the core's calibration blob.
///
/// One reader for everyone: the daemon (`shadowleand --calibration FILE`), `sl-tables
/// --calibration FILE` (bakes it into tables or writes `--blob OUT`), sl-view and sl-eval.
///
/// Two file kinds, told apart by the first four bytes:
/// - a blob (`SLCB`, sl_calblob.h), as `sl-tables --blob` writes it: returned as read (the
///   caller validates it with sl_calblob_open());
/// - a calibration INI, as `sl-calib shadow --out-ini` / `sl-calib elongation --out-ini`
///   write it (host_tools/calib/README.md), parsed with inih:
///
///       [calib]                   written by sl-calib shadow
///       version = 1               format version (optional; 1 when absent)
///       board = NAME              must be the nominal board's name
///       azimuths = N              must be the nominal board's
///       radar_height_m = H        the height theta was computed with (default: the board's)
///       theta_table = az:deg, ... measured theta per azimuth index (continuation lines);
///                                 azimuths not listed keep the board's values
///       theta_sigma_deg = S       (optional) calibration uncertainty of theta
///       pole_radius_m = R         (optional) radius prior of the poles
///       near_exclusion_m = M      (optional) near-field band end: bins [0, M / bin) ignored
///       tool, date, source, frames, bin_size_m, az_half_window, usable_azimuths,
///       ground_start_m, near_end_m, board_theta_table, unusable: provenance and
///       diagnostics, read and ignored
///       [detect]                  written by sl-calib elongation
///       elongation = r:d, ...     the elongation table d(r) (metres), as in a board file
///
///   Unknown sections and keys, malformed numbers, an azimuth index out of range or a theta
///   outside [1, 60] deg are errors naming the line. The calibrated board is the nominal one
///   with these values; each measured azimuth gets its geometry entry, shadow radius
///   R = H / tan(theta) and shadow bins computed exactly as sl-tables computes a board's
///   (slp_geom_make(), geom.h: the same function sl::make_geom calls).
///
/// Host/port only (libm, stdio, malloc); not part of the core. Reentrant (no static state).
#ifndef SHADOWLEAN_PORT_CALIB_FILE_H
#define SHADOWLEAN_PORT_CALIB_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_incline.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Read `path` (blob or INI) for `nominal` and return a malloc'd blob in `*blob` (`*len`
/// bytes; free() it). On error returns -1 with a message in `err` (file, line, key) and
/// `*blob` NULL. The blob is NOT validated here beyond what building it needs: open it with
/// sl_calblob_open() (a blob file is returned as read).
int slp_calib_file_load(const char *path, const sl_board_t *nominal, uint8_t **blob, size_t *len,
                    char *err, size_t err_size);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_CALIB_FILE_H
