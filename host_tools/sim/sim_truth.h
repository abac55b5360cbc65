// SPDX-License-Identifier: MIT
// sim_truth.h: the simulator's ground truth, one row per (rotation, pole, azimuth on which
// the pole is visible), and its CSV file format (scenes/README.md documents every column).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

namespace sl {

struct GtRow {
    int rotation = 0;        ///< rotation index in the capture (0 = first)
    int azimuth = 0;         ///< azimuth index 0 .. azimuths-1
    int nominal = 0;         ///< 1 on the azimuth nearest to the pole's visible segment
    int pole = 0;            ///< pole index (scene order)
    std::string pole_name;
    double t_s = 0;          ///< UNIX time of this azimuth
    double radar_x_m = 0, radar_y_m = 0, heading_deg = 0; ///< radar pose (world)
    double az_center_deg = 0;///< azimuth centre, vehicle frame (clockwise from forward)
    double bearing_deg = 0;  ///< vehicle-frame azimuth of the visible segment's midpoint
    double theta_deg = 0;    ///< board theta on this azimuth index (what the tables hold)
    double beta_deg = 0;     ///< upper emission bound of the scene's beam
    double r1_m = 0, r2_m = 0;           ///< exact range extremes of the visible AXIS
    double r1_surf_m = 0, r2_surf_m = 0; ///< extremes over the pole's surface (front/silhouette)
    std::string r1_end, r2_end; ///< what bounds them: top, foot, wedge, ground, tip, beam, occluded
    int runs = 0;            ///< visible runs (1 normally; 2+ when partly occluded)
    double alpha_deg = 0;    ///< in-plane inclination, e_r towards the segment's midpoint
    double alpha_az_deg = 0; ///< same with e_r along the azimuth centre (MATH.md s.5 literally)
    double alpha_model_deg = 0; ///< closed form (MATH.md s.2) from r1_m, r2_m, theta, beta
    double alpha_paper_deg = 0; ///< the paper's alpha_gt(y) (Sec. IV-A)
    double psi_deg = 0, phi_deg = 0; ///< tilt from vertical; lean direction CCW from forward
    double offset_m = 0;     ///< lateral offset of the axis point at radar height (left +)
    double along_m = 0;      ///< radar position along the path relative to that point (paper y)
    double radius_m = 0;
    int valid = 0;           ///< 1: r1 on top/foot, r2 on the -theta ray, one run
};

/// Writes the header line.
void gt_write_header(std::FILE *f);
/// Writes one row.
void gt_write_row(std::FILE *f, const GtRow &r);
/// Reads a ground-truth CSV. false + err on I/O or format problems.
bool gt_read(const std::string &path, std::vector<GtRow> &rows, std::string &err);

} // namespace sl
