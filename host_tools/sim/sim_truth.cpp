// SPDX-License-Identifier: MIT
// sim_truth.cpp: ground-truth CSV (see sim_truth.h).
#include "sim_truth.h"

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

namespace sl {
namespace {

const char *kCols[] = {
    "rotation", "azimuth", "nominal", "pole", "pole_name", "t_s", "radar_x_m", "radar_y_m",
    "heading_deg", "az_center_deg", "bearing_deg", "theta_deg", "beta_deg", "r1_m", "r2_m",
    "r1_surf_m", "r2_surf_m", "r1_end", "r2_end", "runs", "alpha_deg", "alpha_az_deg",
    "alpha_model_deg", "alpha_paper_deg", "psi_deg", "phi_deg", "offset_m", "along_m",
    "radius_m", "valid"};

} // namespace

void gt_write_header(std::FILE *f)
{
    const size_t n = sizeof(kCols) / sizeof(kCols[0]);
    for (size_t i = 0; i < n; i++) {
        std::fprintf(f, "%s%s", kCols[i], i + 1 < n ? "," : "\n");
    }
}

void gt_write_row(std::FILE *f, const GtRow &r)
{
    std::fprintf(f,
                 "%d,%d,%d,%d,%s,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f,"
                 "%s,%s,%d,%.9f,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f,%.6f,%.6f,%d\n",
                 r.rotation, r.azimuth, r.nominal, r.pole, r.pole_name.c_str(), r.t_s,
                 r.radar_x_m, r.radar_y_m, r.heading_deg, r.az_center_deg, r.bearing_deg,
                 r.theta_deg, r.beta_deg, r.r1_m, r.r2_m, r.r1_surf_m, r.r2_surf_m,
                 r.r1_end.c_str(), r.r2_end.c_str(), r.runs, r.alpha_deg, r.alpha_az_deg,
                 r.alpha_model_deg, r.alpha_paper_deg, r.psi_deg, r.phi_deg, r.offset_m,
                 r.along_m, r.radius_m, r.valid);
}

bool gt_read(const std::string &path, std::vector<GtRow> &rows, std::string &err)
{
    std::ifstream in(path);
    if (!in) {
        err = path + ": cannot open";
        return false;
    }
    std::string line;
    if (!std::getline(in, line)) {
        err = path + ": empty";
        return false;
    }
    std::map<std::string, size_t> col;
    {
        std::istringstream h(line);
        std::string c;
        size_t i = 0;
        while (std::getline(h, c, ',')) {
            col[c] = i++;
        }
    }
    for (const char *c : kCols) {
        if (col.count(c) == 0U) {
            err = path + ": missing column '" + c + "'";
            return false;
        }
    }
    size_t lineno = 1;
    while (std::getline(in, line)) {
        lineno++;
        if (line.empty()) {
            continue;
        }
        std::vector<std::string> v;
        std::istringstream ls(line);
        std::string c;
        while (std::getline(ls, c, ',')) {
            v.push_back(c);
        }
        if (v.size() < col.size()) {
            err = path + ":" + std::to_string(lineno) + ": too few columns";
            return false;
        }
        auto S = [&](const char *k) { return v[col[k]]; };
        auto D = [&](const char *k) { return std::strtod(v[col[k]].c_str(), nullptr); };
        auto I = [&](const char *k) { return static_cast<int>(std::strtol(v[col[k]].c_str(), nullptr, 10)); };
        GtRow r;
        r.rotation = I("rotation");
        r.azimuth = I("azimuth");
        r.nominal = I("nominal");
        r.pole = I("pole");
        r.pole_name = S("pole_name");
        r.t_s = D("t_s");
        r.radar_x_m = D("radar_x_m");
        r.radar_y_m = D("radar_y_m");
        r.heading_deg = D("heading_deg");
        r.az_center_deg = D("az_center_deg");
        r.bearing_deg = D("bearing_deg");
        r.theta_deg = D("theta_deg");
        r.beta_deg = D("beta_deg");
        r.r1_m = D("r1_m");
        r.r2_m = D("r2_m");
        r.r1_surf_m = D("r1_surf_m");
        r.r2_surf_m = D("r2_surf_m");
        r.r1_end = S("r1_end");
        r.r2_end = S("r2_end");
        r.runs = I("runs");
        r.alpha_deg = D("alpha_deg");
        r.alpha_az_deg = D("alpha_az_deg");
        r.alpha_model_deg = D("alpha_model_deg");
        r.alpha_paper_deg = D("alpha_paper_deg");
        r.psi_deg = D("psi_deg");
        r.phi_deg = D("phi_deg");
        r.offset_m = D("offset_m");
        r.along_m = D("along_m");
        r.radius_m = D("radius_m");
        r.valid = I("valid");
        rows.push_back(r);
    }
    return true;
}

} // namespace sl
