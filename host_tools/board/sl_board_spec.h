// SPDX-License-Identifier: MIT
// sl_board_spec.h: a board file (boards/<name>/board.ini) parsed into doubles, and the
// chassis-shadow geometry derived from it. Host-only (C++17); the core sees the generated
// integer tables (sl_board.h) instead. The INI is read with inih's INIReader, never by hand.
//
// Frames: vehicle frame x forward, y left, z up, origin on the ground below the vehicle's
// reference point. The radar sits at (radar_x, radar_y, radar_height). Azimuth index i is at
// angle az(i) = i * 360 / azimuths degrees from the radar's encoder zero, clockwise seen
// from above; encoder zero points at radar_yaw_deg clockwise from vehicle forward.
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace sl {

struct ChassisVertex {
    double x_m = 0, y_m = 0;   // vehicle frame, top view
    double edge_height_m = 0;  // height above ground of the occluding edge at this vertex
};

/// One point of the elongation table d(r): `range_m` is the OBSERVED outer bound r2 (slant,
/// after the half-bin correction, d not yet removed), `d_m` the outward bias there.
struct ElongPoint {
    double range_m = 0;
    double d_m = 0;
};

struct BoardSpec {
    std::string name, description, source_file;
    // radar
    double radar_height_m = 0, radar_x_m = 0, radar_y_m = 0, radar_yaw_deg = 0;
    double beta_up_deg = 0, lower_bound_deg = 35;
    int azimuths = 400, encoder_size = 5600, range_bins = 3768;
    double bin_size_m = 0.0438;
    int max_message_bytes = 65536;
    // chassis: cylinder (centred on the radar's vertical axis) or a top-view polygon
    std::string chassis_type;           // "cylinder" | "polygon"
    double cylinder_radius_m = 0, cylinder_top_m = 0;
    std::vector<ChassisVertex> polygon; // counter-clockwise or clockwise, closed implicitly
    // region of interest and detection
    int roi_bins = 512;
    double near_exclusion_m = 1.7;
    int threshold = 40, mask_frames = 16, max_targets = 16;
    double pole_radius_m = 0, range_sigma_m = 0.0126, theta_sigma_deg = 0.2;
    double caution_lean_deg = 5, danger_lean_deg = 10, track_timeout_s = 2.0;
    std::vector<ElongPoint> elongation;
    // CAN
    int can_bitrate = 500000;
    // CAN ids in board/DBC style: 11-bit as is, 29-bit with bit 31 set (board file:
    // "0x18FF5A00 ext"). Defaults: SL_CAN_ID_DEFAULT_* (sl_can.h).
    unsigned can_id_pole_lean = 0x5C0, can_id_lean_warning = 0x5C1, can_id_status = 0x5C2,
             can_id_vehicle_motion = 0x5B0, can_id_health = 0x5C3,
             can_id_pole_tilt = 0x5C4, can_id_ground_plane = 0x5C5, can_id_ground_hazard = 0x5C6;
    // E2E Profile 11 per message, indexed by sl_can_msg_t (PoleLean, LeanWarning, Status,
    // VehicleMotion, Health, PoleTilt, GroundPlane, GroundHazard): 16-bit Data ID and mode
    // (0 = 11A both, 1 = 11C nibble); the VehicleMotion receiver's max delta counter.
    unsigned can_data_id[8] = {0x0051, 0x0052, 0x0053, 0x0054, 0x0055, 0x0056, 0x0057, 0x0058};
    unsigned can_data_id_mode[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    unsigned can_max_delta_counter_motion = 2;
    // The sensor model's prior ([response]): the 8-bit values' scale and the range response
    // a point return makes before any is learned from the stream.
    bool value_scale_linear = false;   // value_scale = log2 (default) | linear
    double values_per_octave = 6.02;   // log2 scale: values per octave of power
    std::string response_prior = "cts350x"; // cts350x (the measured lobe) | ideal (one bin)

    /// Opening angle theta (deg) of azimuth index i: the depression of the ray that grazes
    /// the chassis edge. NaN when the chassis does not surround the radar on that azimuth.
    double theta_deg(int az_index) const;
    /// Azimuth angle (deg, clockwise from vehicle forward) of azimuth index i.
    double azimuth_vehicle_deg(int az_index) const;
    /// Horizontal distance (m) from the radar to the occluding edge along azimuth i, and
    /// the edge's height above ground (m).
    void edge_along(int az_index, double *dist_m, double *edge_height_m) const;
    /// Ground shadow radius H / tan(theta) in metres for azimuth i.
    double shadow_radius_m(int az_index) const;
};

struct BoardError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Parse a board by name (boards/<name>/board.ini) or by path; validates every field and
/// throws BoardError with "<file>: <section>.<key>: <problem>" on the first bad one.
BoardSpec load_board(const std::string &name_or_path);

} // namespace sl
