// SPDX-License-Identifier: MIT
// view_tilt.h: sl-view's 3D tilt overlay: the core pipeline run over the capture with a
// constant motion input (`sl-view --motion V[,W]`, as `shadowleand --motion`), the fitted
// poles (sl_tiltobs.h, what PoleTilt carries) per rotation, drawn in the top view.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "shadowlean/sl_board.h"

namespace slv {

/// One fitted pole at the end of a rotation, vehicle frame (x forward, y left, m).
struct TiltMark {
    int id = 0;
    int quality = 0;          ///< sl_tilt_quality_t: FITTED or AMBIGUOUS
    double base_x_m = 0, base_y_m = 0;
    double psi_deg = 0, phi_deg = 0; ///< tilt; direction the top leans to, CCW from forward
};

/// Runs sl_pipeline over the capture at `path` (streamed in 64 KiB chunks, read_capture)
/// with the motion (speed m/s, yaw rate deg/s) and returns the fitted poles of every
/// rotation (index = rotation since the start).
/// false + err when the capture cannot be read or the pipeline rejects the board.
bool tilt_marks(const std::string &path, const sl_board_t *b, double speed_mps, double yaw_dps,
                std::vector<std::vector<TiltMark>> &out, std::string &err);

/// Draws `marks` with `to_px(x_m, y_m)` mapping vehicle-frame metres (relative to the radar)
/// to pixels: the base (filled circle), the lean as an arrow to where the top of a 4 m pole
/// is, and "psi / direction / quality". `radar_x_m/_y_m`: the radar's vehicle position.
template <class ToPx>
void draw_tilt_marks(cv::Mat &img, const std::vector<TiltMark> &marks, double radar_x_m,
                     double radar_y_m, ToPx to_px);

} // namespace slv

#include "view_tilt_draw.inl"
