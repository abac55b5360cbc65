// SPDX-License-Identifier: MIT
// Board files: parsed with inih (ini_parse), validated field by field, and the chassis
// shadow geometry derived from them (MATH.md s.1).
#include "sl_board_spec.h"

#include <ini.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "shadowlean/sl_config.h"
#include "sl_paths.h"

namespace sl {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double deg2rad(double d) { return d * kPi / 180.0; }
constexpr double rad2deg(double r) { return r * 180.0 / kPi; }

using KeyMap = std::map<std::string, std::string>; // "section.key" -> value

int on_entry(void *user, const char *section, const char *name, const char *value)
{
    auto *m = static_cast<KeyMap *>(user);
    const std::string key = std::string(section) + "." + name;
    if (m->count(key) != 0U) {
        return 0; // duplicate key: report as a parse error on this line
    }
    (*m)[key] = value;
    return 1;
}

// Every key a board file may contain. Anything else is a typo and an error.
const std::set<std::string> kKnown = {
    "board.name", "board.description",
    "radar.height_m", "radar.x_m", "radar.y_m", "radar.yaw_deg", "radar.beta_up_deg",
    "radar.lower_bound_deg", "radar.azimuths", "radar.encoder_size", "radar.bin_size_m",
    "radar.range_bins", "radar.max_message_bytes",
    "chassis.type", "chassis.radius_m", "chassis.top_m", "chassis.vertices",
    "roi.bins", "roi.near_exclusion_m",
    "detect.threshold", "detect.mask_frames", "detect.max_targets", "detect.pole_radius_m",
    "detect.range_sigma_m", "detect.theta_sigma_deg", "detect.caution_lean_deg",
    "detect.danger_lean_deg", "detect.track_timeout_s", "detect.elongation",
    "can.bitrate", "can.id_pole_lean", "can.id_lean_warning", "can.id_status",
    "can.id_vehicle_motion", "can.id_health", "can.id_pole_tilt", "can.id_ground_plane",
    "can.id_ground_hazard",
    "can.data_id_pole_lean", "can.data_id_lean_warning", "can.data_id_status",
    "can.data_id_vehicle_motion", "can.data_id_health", "can.data_id_pole_tilt",
    "can.data_id_ground_plane", "can.data_id_ground_hazard",
    "can.data_id_mode_pole_lean", "can.data_id_mode_lean_warning", "can.data_id_mode_status",
    "can.data_id_mode_vehicle_motion", "can.data_id_mode_health", "can.data_id_mode_pole_tilt",
    "can.data_id_mode_ground_plane", "can.data_id_mode_ground_hazard",
    "can.max_delta_counter_vehicle_motion",
    "response.value_scale", "response.values_per_octave", "response.prior",
};

// The board keys' message names, in sl_can_msg_t order.
const char *const kCanMsgKeys[8] = {"pole_lean", "lean_warning", "status",       "vehicle_motion",
                                    "health",    "pole_tilt",    "ground_plane", "ground_hazard"};

class Reader {
public:
    Reader(std::string file, KeyMap m) : file_(std::move(file)), m_(std::move(m)) {}

    [[noreturn]] void fail(const std::string &key, const std::string &what) const
    {
        throw BoardError(file_ + ": " + key + ": " + what);
    }
    bool has(const std::string &key) const { return m_.count(key) != 0U; }
    std::string str(const std::string &key, const char *def = nullptr) const
    {
        auto it = m_.find(key);
        if (it == m_.end()) {
            if (def == nullptr) {
                fail(key, "missing (required)");
            }
            return def;
        }
        return it->second;
    }
    double real(const std::string &key, double lo, double hi, const double *def = nullptr) const
    {
        if (!has(key)) {
            if (def == nullptr) {
                fail(key, "missing (required)");
            }
            return *def;
        }
        const std::string s = str(key);
        char *end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) {
            fail(key, "'" + s + "' is not a number");
        }
        if (v < lo || v > hi) {
            std::ostringstream o;
            o << v << " outside [" << lo << ", " << hi << "]";
            fail(key, o.str());
        }
        return v;
    }
    double real(const std::string &key, double lo, double hi, double def) const
    {
        return real(key, lo, hi, &def);
    }
    long integer(const std::string &key, long lo, long hi, const long *def = nullptr) const
    {
        if (!has(key)) {
            if (def == nullptr) {
                fail(key, "missing (required)");
            }
            return *def;
        }
        const std::string s = str(key);
        char *end = nullptr;
        const long v = std::strtol(s.c_str(), &end, 0);
        if (end == s.c_str() || *end != '\0') {
            fail(key, "'" + s + "' is not an integer");
        }
        if (v < lo || v > hi) {
            fail(key, std::to_string(v) + " outside [" + std::to_string(lo) + ", " +
                          std::to_string(hi) + "]");
        }
        return v;
    }
    long integer(const std::string &key, long lo, long hi, long def) const
    {
        return integer(key, lo, hi, &def);
    }
    const KeyMap &map() const { return m_; }

private:
    std::string file_;
    KeyMap m_;
};

std::vector<std::string> split(const std::string &s, char sep)
{
    std::vector<std::string> out;
    std::string cur;
    std::istringstream in(s);
    while (std::getline(in, cur, sep)) {
        const auto b = cur.find_first_not_of(" \t");
        const auto e = cur.find_last_not_of(" \t");
        if (b != std::string::npos) {
            out.push_back(cur.substr(b, e - b + 1));
        }
    }
    return out;
}

std::vector<double> numbers(const Reader &r, const std::string &key, const std::string &item,
                            char sep, size_t count)
{
    std::vector<double> v;
    for (const auto &tok : split(item, sep)) {
        char *end = nullptr;
        const double d = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end != '\0' || !std::isfinite(d)) {
            r.fail(key, "'" + tok + "' in '" + item + "' is not a number");
        }
        v.push_back(d);
    }
    if (v.size() != count) {
        r.fail(key, "'" + item + "' needs " + std::to_string(count) + " numbers");
    }
    return v;
}

} // namespace

double BoardSpec::azimuth_vehicle_deg(int az_index) const
{
    return radar_yaw_deg + 360.0 * az_index / azimuths;
}

void BoardSpec::edge_along(int az_index, double *dist_m, double *edge_height_m) const
{
    *dist_m = std::numeric_limits<double>::quiet_NaN();
    *edge_height_m = std::numeric_limits<double>::quiet_NaN();
    if (chassis_type == "cylinder") {
        *dist_m = cylinder_radius_m;
        *edge_height_m = cylinder_top_m;
        return;
    }
    // Ray from the radar, clockwise from forward seen from above: (cos a, -sin a) in x-fwd
    // y-left. Among all polygon edges it crosses, the grazing one is the point of least
    // depression atan2(H - h, w): it bounds the shadow.
    const double a = deg2rad(azimuth_vehicle_deg(az_index));
    const double dx = std::cos(a), dy = -std::sin(a);
    double best_dep = std::numeric_limits<double>::infinity();
    const size_t n = polygon.size();
    for (size_t k = 0; k < n; k++) {
        const ChassisVertex &p = polygon[k];
        const ChassisVertex &q = polygon[(k + 1) % n];
        const double ex = q.x_m - p.x_m, ey = q.y_m - p.y_m;
        const double det = dx * (-ey) - dy * (-ex);
        if (std::fabs(det) < 1e-12) {
            continue; // parallel
        }
        const double wx = p.x_m - radar_x_m, wy = p.y_m - radar_y_m;
        const double t = (wx * (-ey) - wy * (-ex)) / det; // along the ray
        const double u = (dx * wy - dy * wx) / det;       // along the edge
        if (t <= 1e-9 || u < -1e-12 || u > 1.0 + 1e-12) {
            continue;
        }
        const double h = p.edge_height_m + u * (q.edge_height_m - p.edge_height_m);
        const double dep = std::atan2(radar_height_m - h, t);
        if (dep < best_dep) {
            best_dep = dep;
            *dist_m = t;
            *edge_height_m = h;
        }
    }
}

double BoardSpec::theta_deg(int az_index) const
{
    double w = 0, h = 0;
    edge_along(az_index, &w, &h);
    if (!std::isfinite(w)) {
        return std::numeric_limits<double>::quiet_NaN();
    }
    return rad2deg(std::atan2(radar_height_m - h, w));
}

double BoardSpec::shadow_radius_m(int az_index) const
{
    return radar_height_m / std::tan(deg2rad(theta_deg(az_index)));
}

BoardSpec load_board(const std::string &name_or_path)
{
    std::string file = name_or_path;
    if (file.size() < 4 || file.compare(file.size() - 4, 4, ".ini") != 0) {
        file = board_dir(name_or_path) + "/board.ini";
    }
    KeyMap m;
    const int rc = ini_parse(file.c_str(), on_entry, &m);
    if (rc < 0) {
        throw BoardError(file + ": cannot open board file");
    }
    if (rc > 0) {
        throw BoardError(file + ":" + std::to_string(rc) +
                         ": syntax error or duplicate key on this line");
    }
    Reader r(file, m);
    for (const auto &kv : r.map()) {
        if (kKnown.count(kv.first) == 0U) {
            r.fail(kv.first, "unknown key (typo?)");
        }
    }

    BoardSpec b;
    b.source_file = file;
    b.name = r.str("board.name");
    b.description = r.str("board.description", "");
    for (char c : b.name) {
        if (!(std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '-')) {
            r.fail("board.name", "'" + b.name + "' must be lower-case letters, digits and '-'");
        }
    }

    b.radar_height_m = r.real("radar.height_m", 0.2, 10.0);
    b.radar_x_m = r.real("radar.x_m", -20, 20, 0.0);
    b.radar_y_m = r.real("radar.y_m", -20, 20, 0.0);
    b.radar_yaw_deg = r.real("radar.yaw_deg", -360, 360, 0.0);
    b.beta_up_deg = r.real("radar.beta_up_deg", 0, 10);
    b.lower_bound_deg = r.real("radar.lower_bound_deg", 5, 89);
    b.azimuths = static_cast<int>(r.integer("radar.azimuths", 8, SL_CFG_MAX_AZIMUTHS));
    b.encoder_size = static_cast<int>(r.integer("radar.encoder_size", b.azimuths, 65535));
    b.bin_size_m = r.real("radar.bin_size_m", 0.0005, 1.0);
    b.range_bins = static_cast<int>(r.integer("radar.range_bins", 32, 65535));
    b.max_message_bytes = static_cast<int>(r.integer("radar.max_message_bytes", 64, 1 << 20, 65536L));

    b.chassis_type = r.str("chassis.type");
    if (b.chassis_type == "cylinder") {
        b.cylinder_radius_m = r.real("chassis.radius_m", 0.01, 20);
        b.cylinder_top_m = r.real("chassis.top_m", 0, b.radar_height_m - 1e-6);
        if (r.has("chassis.vertices")) {
            r.fail("chassis.vertices", "only for type = polygon");
        }
    } else if (b.chassis_type == "polygon") {
        for (const auto &item : split(r.str("chassis.vertices"), ';')) {
            const auto v = numbers(r, "chassis.vertices", item, ',', 3);
            if (v[2] < 0 || v[2] >= b.radar_height_m) {
                r.fail("chassis.vertices", "edge height in '" + item +
                                               "' must be in [0, radar.height_m)");
            }
            b.polygon.push_back({v[0], v[1], v[2]});
        }
        if (b.polygon.size() < 3) {
            r.fail("chassis.vertices", "a polygon needs at least 3 vertices");
        }
        if (r.has("chassis.radius_m") || r.has("chassis.top_m")) {
            r.fail("chassis.radius_m", "only for type = cylinder");
        }
    } else {
        r.fail("chassis.type", "'" + b.chassis_type + "' is not cylinder or polygon");
    }

    b.roi_bins = static_cast<int>(r.integer("roi.bins", 32, SL_CFG_ROI_BINS));
    if (b.roi_bins % 32 != 0 || b.roi_bins > b.range_bins) {
        r.fail("roi.bins", "must be a multiple of 32 and <= radar.range_bins");
    }
    b.near_exclusion_m = r.real("roi.near_exclusion_m", 0, 20);

    // Rows are 8-bit power (16-bit data is reduced to 8 bits first): 1..255.
    b.threshold = static_cast<int>(r.integer("detect.threshold", 1, 255));
    b.mask_frames = static_cast<int>(r.integer("detect.mask_frames", 1, SL_CFG_MASK_FRAMES_MAX));
    b.max_targets = static_cast<int>(r.integer("detect.max_targets", 1, SL_CFG_MAX_TARGETS));
    b.pole_radius_m = r.real("detect.pole_radius_m", 0, 1, 0.0);
    b.range_sigma_m = r.real("detect.range_sigma_m", 0, 1, b.bin_size_m / std::sqrt(12.0));
    b.theta_sigma_deg = r.real("detect.theta_sigma_deg", 0, 10, 0.2);
    b.caution_lean_deg = r.real("detect.caution_lean_deg", 0, 45, 5.0);
    b.danger_lean_deg = r.real("detect.danger_lean_deg", b.caution_lean_deg, 60, 10.0);
    b.track_timeout_s = r.real("detect.track_timeout_s", 0.1, 60, 2.0);
    if (r.has("detect.elongation")) {
        for (const auto &item : split(r.str("detect.elongation"), ',')) {
            const auto v = numbers(r, "detect.elongation", item, ':', 2);
            if (!b.elongation.empty() && v[0] <= b.elongation.back().range_m) {
                r.fail("detect.elongation", "ranges must ascend");
            }
            if (v[0] < 0 || v[0] > 200 || std::fabs(v[1]) > 5) {
                r.fail("detect.elongation", "'" + item + "' out of range (0..200 m : |d| <= 5 m)");
            }
            b.elongation.push_back({v[0], v[1]});
        }
        if (b.elongation.size() > SL_CFG_MAX_ELONG_POINTS) {
            r.fail("detect.elongation", "more than SL_CFG_MAX_ELONG_POINTS entries");
        }
    }

    b.can_bitrate = static_cast<int>(r.integer("can.bitrate", 10000, 1000000, 500000L));
    // An id is 11-bit ("0x5C0"), or 29-bit with the suffix "ext" ("0x18FF5A00 ext"), stored
    // DBC style (bit 31 set).
    auto can_id = [&](const char *key, unsigned def) {
        if (!r.has(key)) {
            return def;
        }
        std::string s = r.str(key);
        bool ext = false;
        const size_t sp = s.find_first_of(" \t");
        if (sp != std::string::npos) {
            const std::string word = s.substr(s.find_first_not_of(" \t", sp));
            if (word != "ext") {
                r.fail(key, "'" + s + "': an id is a number, optionally followed by 'ext' (29-bit)");
            }
            ext = true;
            s = s.substr(0, sp);
        }
        char *end = nullptr;
        const unsigned long v = std::strtoul(s.c_str(), &end, 0);
        if (end == s.c_str() || *end != '\0' || s[0] == '-') {
            r.fail(key, "'" + s + "' is not an integer");
        }
        if (ext) {
            if (v > 0x1FFFFFFFUL) {
                r.fail(key, s + " does not fit a 29-bit id (0 .. 0x1FFFFFFF)");
            }
            return static_cast<unsigned>(v | 0x80000000UL);
        }
        if (v > 0x7FFUL) {
            r.fail(key, s + " does not fit an 11-bit id (0 .. 0x7FF); a 29-bit id needs the "
                            "suffix 'ext' (e.g. " + s + " ext)");
        }
        return static_cast<unsigned>(v);
    };
    b.can_id_pole_lean = can_id("can.id_pole_lean", 0x5C0);
    b.can_id_lean_warning = can_id("can.id_lean_warning", 0x5C1);
    b.can_id_status = can_id("can.id_status", 0x5C2);
    b.can_id_vehicle_motion = can_id("can.id_vehicle_motion", 0x5B0);
    if (!r.has("can.id_health")) {
        r.fail("can.id_health", "missing (required: the Health message's CAN id, e.g. 0x5C3)");
    }
    b.can_id_health = can_id("can.id_health", 0x5C3);
    if (!r.has("can.id_pole_tilt")) {
        r.fail("can.id_pole_tilt",
               "missing (required: the PoleTilt message's CAN id, e.g. 0x5C4)");
    }
    b.can_id_pole_tilt = can_id("can.id_pole_tilt", 0x5C4);
    if (!r.has("can.id_ground_plane")) {
        r.fail("can.id_ground_plane",
               "missing (required: the GroundPlane message's CAN id, e.g. 0x5C5)");
    }
    b.can_id_ground_plane = can_id("can.id_ground_plane", 0x5C5);
    if (!r.has("can.id_ground_hazard")) {
        r.fail("can.id_ground_hazard",
               "missing (required: the GroundHazard message's CAN id, e.g. 0x5C6)");
    }
    b.can_id_ground_hazard = can_id("can.id_ground_hazard", 0x5C6);
    std::set<unsigned> data_ids;
    for (unsigned m = 0; m < 8U; m++) {
        const std::string msg = kCanMsgKeys[m];
        const std::string kid = "can.data_id_" + msg, kmode = "can.data_id_mode_" + msg;
        b.can_data_id[m] = static_cast<unsigned>(
            r.integer(kid, 0, 0xFFFF, static_cast<long>(b.can_data_id[m])));
        if (r.has(kmode)) {
            const std::string mode = r.str(kmode);
            if (mode == "both") {
                b.can_data_id_mode[m] = 0;
            } else if (mode == "nibble") {
                b.can_data_id_mode[m] = 1;
            } else {
                r.fail(kmode, "'" + mode + "': both (Profile 11A) or nibble (Profile 11C)");
            }
        }
        if (b.can_data_id_mode[m] == 1U && b.can_data_id[m] > 0x0FFFU) {
            r.fail(kid, "mode nibble (11C) sends bits 8..11 of the Data ID: it must be <= 0x0FFF");
        }
        if (b.can_data_id_mode[m] == 1U && msg != "health") {
            r.fail(kmode, "nibble (11C) sends the Data ID in frame bits 12..15, where this "
                          "message has signals; only health has them free");
        }
        if (!data_ids.insert(b.can_data_id[m]).second) {
            r.fail(kid, "every message needs its own Data ID");
        }
    }
    b.can_max_delta_counter_motion = static_cast<unsigned>(
        r.integer("can.max_delta_counter_vehicle_motion", 1, 14, 2L));
    const std::string scale = r.str("response.value_scale", "log2");
    if (scale != "log2" && scale != "linear") {
        r.fail("response.value_scale", "'" + scale + "' is not log2 or linear");
    }
    b.value_scale_linear = scale == "linear";
    b.values_per_octave = r.real("response.values_per_octave", 1.0, 16.0, 6.02);
    if (b.value_scale_linear && r.has("response.values_per_octave")) {
        r.fail("response.values_per_octave", "only for value_scale = log2");
    }
    b.response_prior = r.str("response.prior", "cts350x");
    if (b.response_prior != "cts350x" && b.response_prior != "ideal") {
        r.fail("response.prior", "'" + b.response_prior + "' is not cts350x or ideal");
    }
    const std::set<unsigned> ids = {b.can_id_pole_lean, b.can_id_lean_warning, b.can_id_status,
                                    b.can_id_vehicle_motion, b.can_id_health,
                                    b.can_id_pole_tilt, b.can_id_ground_plane,
                                    b.can_id_ground_hazard};
    if (ids.size() != 8U) {
        r.fail("can", "the eight CAN ids must differ");
    }

    for (int i = 0; i < b.azimuths; i++) {
        const double t = b.theta_deg(i);
        if (!std::isfinite(t)) {
            r.fail("chassis", "azimuth " + std::to_string(i) +
                                  ": no chassis edge around the radar on this azimuth");
        }
        if (t < 1.0 || t >= b.lower_bound_deg) {
            std::ostringstream o;
            o << "azimuth " << i << ": theta " << t << " deg outside [1, lower_bound_deg "
              << b.lower_bound_deg << "): the beam must clear the body";
            r.fail("chassis", o.str());
        }
    }
    return b;
}

} // namespace sl
