// SPDX-License-Identifier: MIT
// sim_scene.cpp: scene files (INI, parsed with inih) -> sl::Scene, with validation.
#include "sim_scene.h"

#include <filesystem>
#include <ini.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>

namespace sl {
namespace {

struct Entry {
    std::string value;
    int line = 0;
};

struct Parsed {
    std::string file;
    std::map<std::string, std::map<std::string, Entry>> sections; // section -> key -> value
    std::vector<std::string> order;                                // sections in file order
    std::string dup;                                               // first duplicate key
    int line = 0;
};

int on_entry(void *user, const char *section, const char *name, const char *value)
{
    auto *p = static_cast<Parsed *>(user);
    p->line++; // approximate (inih without line numbers); only used in messages
    auto &sec = p->sections[section];
    if (sec.empty()) {
        p->order.push_back(section);
    }
    if (sec.count(name) != 0U) {
        if (p->dup.empty()) {
            p->dup = std::string(section) + "." + name;
        }
        return 0;
    }
    sec[name] = Entry{value, p->line};
    return 1;
}

class Sec {
public:
    Sec(const std::string &file, const std::string &name,
        const std::map<std::string, Entry> *m)
        : file_(file), name_(name), m_(m)
    {
    }
    [[noreturn]] void fail(const std::string &key, const std::string &what) const
    {
        throw SceneError(file_ + ": " + name_ + "." + key + ": " + what);
    }
    bool has(const std::string &k) const { return m_ != nullptr && m_->count(k) != 0U; }
    std::string str(const std::string &k, const std::string &def) const
    {
        return has(k) ? m_->at(k).value : def;
    }
    double real(const std::string &k, double def, double lo, double hi) const
    {
        if (!has(k)) {
            return def;
        }
        const std::string &s = m_->at(k).value;
        char *end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) {
            fail(k, "'" + s + "' is not a number");
        }
        if (v < lo || v > hi) {
            std::ostringstream o;
            o << v << " outside [" << lo << ", " << hi << "]";
            fail(k, o.str());
        }
        return v;
    }
    long long integer(const std::string &k, long long def, long long lo, long long hi) const
    {
        if (!has(k)) {
            return def;
        }
        const std::string &s = m_->at(k).value;
        char *end = nullptr;
        const long long v = std::strtoll(s.c_str(), &end, 0);
        if (end == s.c_str() || *end != '\0') {
            fail(k, "'" + s + "' is not an integer");
        }
        if (v < lo || v > hi) {
            fail(k, std::to_string(v) + " outside [" + std::to_string(lo) + ", " +
                        std::to_string(hi) + "]");
        }
        return v;
    }
    bool boolean(const std::string &k, bool def) const
    {
        if (!has(k)) {
            return def;
        }
        const std::string &s = m_->at(k).value;
        if (s == "on" || s == "yes" || s == "true" || s == "1") {
            return true;
        }
        if (s == "off" || s == "no" || s == "false" || s == "0") {
            return false;
        }
        fail(k, "'" + s + "' is not on/off");
    }
    template <typename E>
    E choice(const std::string &k, E def, const std::map<std::string, E> &opts) const
    {
        if (!has(k)) {
            return def;
        }
        const std::string &s = m_->at(k).value;
        auto it = opts.find(s);
        if (it == opts.end()) {
            std::string all;
            for (const auto &o : opts) {
                all += (all.empty() ? "" : ", ") + o.first;
            }
            fail(k, "'" + s + "' is not one of " + all);
        }
        return it->second;
    }
    void only(const std::set<std::string> &known) const
    {
        if (m_ == nullptr) {
            return;
        }
        for (const auto &kv : *m_) {
            if (known.count(kv.first) == 0U) {
                fail(kv.first, "unknown key (typo?)");
            }
        }
    }

private:
    std::string file_, name_;
    const std::map<std::string, Entry> *m_;
};

Scene build(const Parsed &p)
{
    static const std::set<std::string> kSections = {"scene", "vehicle", "ground", "beam",
                                                    "output", "effects", "clutter"};
    for (const auto &name : p.order) {
        if (kSections.count(name) != 0U) {
            continue;
        }
        if (name.rfind("pole.", 0) == 0 || name.rfind("box.", 0) == 0 ||
            name.rfind("wall.", 0) == 0 || name.rfind("point.", 0) == 0 ||
            name.rfind("terrain.", 0) == 0) {
            if (name.find('.') + 1 >= name.size()) {
                throw SceneError(p.file + ": [" + name + "]: object sections need a name");
            }
            continue;
        }
        throw SceneError(p.file + ": [" + name +
                         "]: unknown section (scene, vehicle, ground, beam, output, effects, clutter, "
                         "pole.<name>, box.<name>, wall.<name>, point.<name>, terrain.<name>)");
    }
    auto sec = [&](const std::string &n) {
        auto it = p.sections.find(n);
        return Sec(p.file, n, it == p.sections.end() ? nullptr : &it->second);
    };

    Scene s;
    s.source = p.file;
    {
        Sec c = sec("scene");
        c.only({"board", "bin_size_m", "range_bins", "rotations", "rotation_hz", "seed",
                "start_time_s"});
        if (!c.has("board")) {
            c.fail("board", "missing (required)");
        }
        s.board_name = c.str("board", "");
        // A board file named by a relative path is found beside the scene file (a test's
        // vehicle whose true body differs from its nominal board), not in the caller's cwd.
        const std::filesystem::path bp(s.board_name);
        if (bp.extension() == ".ini" && bp.is_relative() && !p.file.empty()) {
            s.board_name = (std::filesystem::path(p.file).parent_path() / bp).lexically_normal().string();
        }
        s.bin_size_override_m = c.real("bin_size_m", 0, 0.0001, 1.0);
        s.range_bins_override = static_cast<int>(c.integer("range_bins", 0, 32, 65535));
        s.rotations = static_cast<int>(c.integer("rotations", s.rotations, 1, 1000000));
        s.rotation_hz = c.real("rotation_hz", s.rotation_hz, 0.1, 100);
        s.seed = static_cast<uint64_t>(c.integer("seed", 1, 0, (1LL << 62)));
        s.start_time_s = c.real("start_time_s", s.start_time_s, 0, 4.0e9);
    }
    {
        Sec c = sec("vehicle");
        c.only({"x_m", "y_m", "heading_deg", "speed_mps", "yaw_rate_dps", "pitch_deg", "roll_deg",
                "height_offset_m"});
        s.vehicle_x_m = c.real("x_m", 0, -1e5, 1e5);
        s.vehicle_y_m = c.real("y_m", 0, -1e5, 1e5);
        s.heading_deg = c.real("heading_deg", s.heading_deg, -360, 360);
        s.speed_mps = c.real("speed_mps", 0, -100, 100);
        s.yaw_rate_dps = c.real("yaw_rate_dps", 0, -180, 180);
        s.pitch_deg = c.real("pitch_deg", 0, -20, 20);
        s.roll_deg = c.real("roll_deg", 0, -20, 20);
        s.height_offset_m = c.real("height_offset_m", 0, -1, 1);
    }
    {
        Sec c = sec("ground");
        c.only({"enabled", "reflectivity", "ambient", "max_range_m"});
        s.ground = c.boolean("enabled", s.ground);
        s.ground_reflectivity = c.real("reflectivity", s.ground_reflectivity, 0, 1e6);
        s.ground_ambient = c.real("ambient", s.ground_ambient, 0, 1);
        s.ground_max_range_m = c.real("max_range_m", s.ground_max_range_m, 1, 1000);
    }
    {
        Sec c = sec("beam");
        c.only({"elevation", "top_deg", "bottom_deg", "measured_edge_db", "measured_peak_deg",
                "azimuth_width_deg", "azimuth_p_in_cone", "azimuth_cutoff_deg", "azimuth_jitter_deg",
                "pole_step_deg", "ground_azimuth_samples", "box_step_deg"});
        s.elevation = c.choice<ElevationProfile>(
            "elevation", ElevationProfile::Ideal,
            {{"ideal", ElevationProfile::Ideal}, {"measured", ElevationProfile::Measured}});
        s.elev_top_deg = c.real("top_deg", s.elevation == ElevationProfile::Ideal ? 0.0 : 3.0,
                                -30, 30);
        s.elev_bottom_deg = c.real("bottom_deg", -35, -89, 0);
        s.measured_edge_db = c.real("measured_edge_db", s.measured_edge_db, 0, 40);
        s.measured_peak_deg = c.real("measured_peak_deg", s.measured_peak_deg, -89, 30);
        s.az_width_deg = c.real("azimuth_width_deg", s.az_width_deg, 0.05, 60);
        s.az_p_in_cone = c.real("azimuth_p_in_cone", s.az_p_in_cone, 0.05, 0.999);
        s.az_cutoff_deg = c.real("azimuth_cutoff_deg", 0, 0, 90);
        s.az_jitter_deg = c.real("azimuth_jitter_deg", 0, 0, 5);
        s.pole_step_deg = c.real("pole_step_deg", s.pole_step_deg, 0.001, 1);
        s.ground_az_samples =
            static_cast<int>(c.integer("ground_azimuth_samples", s.ground_az_samples, 1, 1001));
        s.box_step_deg = c.real("box_step_deg", s.box_step_deg, 0.001, 2);
    }
    {
        Sec c = sec("output");
        c.only({"amplitude", "mapping", "normalize", "peak_counts", "linear_scale",
                "detect_floor", "log_db_per_decade", "log_quantity", "log_ref_energy",
                "log_ref_value", "log_curve"});
        s.amplitude = c.choice<AmplitudeModel>(
            "amplitude", s.amplitude,
            {{"integral", AmplitudeModel::Integral}, {"peak", AmplitudeModel::Peak}});
        s.mapping = c.choice<OutputMapping>(
            "mapping", s.mapping, {{"linear", OutputMapping::Linear}, {"log", OutputMapping::Log}});
        s.normalize = c.choice<Normalize>("normalize", s.normalize,
                                          {{"column", Normalize::Column}, {"none", Normalize::None}});
        s.peak_counts = c.real("peak_counts", s.peak_counts, 1, 255);
        s.linear_scale = c.real("linear_scale", s.linear_scale, 0, 1e12);
        s.detect_floor = static_cast<int>(c.integer("detect_floor", s.detect_floor, 0, 255));
        s.log_db_per_decade = c.real("log_db_per_decade", s.log_db_per_decade, 1, 100);
        s.log_power = c.choice<bool>("log_quantity", s.log_power,
                                     {{"magnitude", false}, {"power", true}});
        s.log_ref_energy = c.real("log_ref_energy", s.log_ref_energy, 1e-12, 1e12);
        s.log_ref_value = c.real("log_ref_value", s.log_ref_value, 1, 255);
        s.log_navtech = c.choice<bool>("log_curve", s.log_navtech,
                                       {{"log10", false}, {"navtech", true}});
    }
    {
        Sec c = sec("effects");
        c.only({"smear", "smear_shape", "smear_width_bins", "smear_mode_frac", "smear_decay_db", "smear_slow_db",
                "smear_slow_decay_db", "smear_amp_decay_db", "smear_front_db", "speckle", "speckle_db", "speckle_frame_db",
                "speckle_static", "speckle_seed", "noise", "noise_sigma", "leakage",
                "leak_level", "leak_shoulder", "leak_edge_m", "leak_shoulder_end_m",
                "leak_jitter", "speckle_model", "range_response", "range_cell_bins", "range_skirt_bins",
                "receiver_tail_db", "receiver_tail_bins", "knife_edge", "carrier_ghz"});
        s.smear = c.boolean("smear", false);
        s.smear_shape = c.choice<int>("smear_shape", 0, {{"triangular", 0}, {"exponential", 1}, {"two-component", 2},
                                                              {"gaussian", 3}, {"maxwell", 4}, {"powerlaw", 5}});
        s.smear_width_bins = c.real("smear_width_bins", s.smear_width_bins, 1, 500);
        s.smear_decay_db = c.real("smear_decay_db", s.smear_decay_db, 0.01, 100);
        s.smear_mode_frac = c.real("smear_mode_frac", s.smear_mode_frac, 0, 1);
        s.smear_slow_db = c.real("smear_slow_db", s.smear_slow_db, -100, 0);
        s.smear_slow_decay_db = c.real("smear_slow_decay_db", s.smear_slow_decay_db, 0.01, 100);
        s.smear_amp_decay_db = c.real("smear_amp_decay_db", s.smear_amp_decay_db, 0, 10);
        s.smear_front_db = c.real("smear_front_db", s.smear_front_db, -200, 0);
        s.speckle = c.boolean("speckle", false);
        s.speckle_db = c.real("speckle_db", s.speckle_db, 0, 20);
        s.speckle_frame_db = c.real("speckle_frame_db", s.speckle_frame_db, 0, 20);
        if (c.has("speckle_static")) {
            const std::string v = c.str("speckle_static", "auto");
            s.speckle_static = v == "auto" ? -1 : (c.boolean("speckle_static", false) ? 1 : 0);
        }
        s.speckle_seed = static_cast<uint64_t>(c.integer("speckle_seed", 0, 0, (1LL << 62)));
        s.speckle_physical = c.choice<bool>("speckle_model", s.speckle_physical,
                                            {{"lognormal", false}, {"physical", true}});
        s.range_response = c.choice<RangeResponse>(
            "range_response", s.range_response,
            {{"none", RangeResponse::None}, {"rect", RangeResponse::Rect},
             {"hann", RangeResponse::Hann}, {"hamming", RangeResponse::Hamming},
             {"blackman", RangeResponse::Blackman}, {"cts350x", RangeResponse::Cts350x}});
        s.range_cell_bins = c.real("range_cell_bins", s.range_cell_bins, 0.5, 9);
        s.range_skirt_bins = c.real("range_skirt_bins", s.range_skirt_bins, 0, 40);
        s.receiver_tail_db = c.real("receiver_tail_db", s.receiver_tail_db, -120, 0);
        s.receiver_tail_bins = c.real("receiver_tail_bins", s.receiver_tail_bins, 0, 200);
        s.knife_edge = c.boolean("knife_edge", false);
        s.carrier_ghz = c.real("carrier_ghz", s.carrier_ghz, 1, 1000);
        s.noise = c.boolean("noise", false);
        s.noise_sigma = c.real("noise_sigma", s.log_power ? kNoiseSigmaPower : s.noise_sigma, 0, 1e6);
        s.leakage = c.boolean("leakage", false);
        s.leak_level = c.real("leak_level", s.leak_level, 0, 255);
        s.leak_shoulder = c.real("leak_shoulder", s.leak_shoulder, 0, 255);
        s.leak_edge_m = c.real("leak_edge_m", s.leak_edge_m, 0, 50);
        s.leak_shoulder_end_m = c.real("leak_shoulder_end_m", s.leak_shoulder_end_m, 0, 50);
        s.leak_jitter = c.real("leak_jitter", s.leak_jitter, 0, 1);
    }
    {
        Sec c = sec("clutter");
        c.only({"enabled", "value_min", "value_max", "inner_m", "outer_m", "density",
                "change_rotations"});
        s.clutter = c.boolean("enabled", false);
        s.clutter_value_min = static_cast<int>(c.integer("value_min", s.clutter_value_min, 0, 255));
        s.clutter_value_max = static_cast<int>(c.integer("value_max", s.clutter_value_max, 0, 255));
        s.clutter_inner_m = c.real("inner_m", s.clutter_inner_m, 0, 50);
        s.clutter_outer_m = c.real("outer_m", s.clutter_outer_m, -5, 50);
        s.clutter_density = c.real("density", s.clutter_density, 0, 1);
        s.clutter_change_rotations =
            static_cast<int>(c.integer("change_rotations", s.clutter_change_rotations, 0, 1000000));
    }
    for (const auto &name : p.order) {
        const auto dot = name.find('.');
        const std::string kind = name.substr(0, dot), obj = name.substr(dot + 1);
        Sec c = sec(name);
        if (kind == "pole") {
            c.only({"x_m", "y_m", "at_height_m", "length_m", "radius_m", "tilt_deg",
                    "lean_deg", "reflectivity", "segment_m", "segment_fill_m", "segment_gap"});
            ScenePole q;
            q.name = obj;
            if (!c.has("x_m") || !c.has("y_m")) {
                c.fail("x_m", "x_m and y_m are required");
            }
            q.x_m = c.real("x_m", 0, -1e5, 1e5);
            q.y_m = c.real("y_m", 0, -1e5, 1e5);
            q.at_height_m = c.real("at_height_m", 0, 0, 100);
            q.length_m = c.real("length_m", q.length_m, 0.01, 200);
            q.radius_m = c.real("radius_m", q.radius_m, 0.0001, 5);
            q.tilt_deg = c.real("tilt_deg", 0, 0, 60);
            q.lean_deg = c.real("lean_deg", 0, -360, 360);
            q.reflectivity = c.real("reflectivity", q.reflectivity, 0, 1e9);
            q.segment_m = c.real("segment_m", 0, 0, 10);
            q.segment_fill_m = c.real("segment_fill_m", q.segment_fill_m, 0.001, 10);
            q.segment_gap = c.real("segment_gap", q.segment_gap, 0, 1);
            if (q.segment_m > 0 && q.segment_fill_m > q.segment_m) {
                c.fail("segment_fill_m", "must not exceed segment_m");
            }
            s.poles.push_back(q);
        } else if (kind == "box") {
            c.only({"cx_m", "cy_m", "size_x_m", "size_y_m", "yaw_deg", "z0_m", "height_m",
                    "reflectivity"});
            SceneBox b;
            b.name = obj;
            b.cx_m = c.real("cx_m", 0, -1e5, 1e5);
            b.cy_m = c.real("cy_m", 0, -1e5, 1e5);
            b.size_x_m = c.real("size_x_m", 1, 0.001, 1e4);
            b.size_y_m = c.real("size_y_m", 1, 0.001, 1e4);
            b.yaw_deg = c.real("yaw_deg", 0, -360, 360);
            b.z0_m = c.real("z0_m", 0, 0, 1000);
            b.height_m = c.real("height_m", 1, 0.001, 1000);
            b.reflectivity = c.real("reflectivity", b.reflectivity, 0, 1e9);
            s.boxes.push_back(b);
        } else if (kind == "terrain") {
            c.only({"kind", "x_m", "y_m", "dir_deg", "width_m", "height_m"});
            SceneTerrain t;
            t.name = obj;
            t.strip = c.choice<bool>("kind", false, {{"step", false}, {"strip", true}});
            t.x_m = c.real("x_m", 0, -1e5, 1e5);
            t.y_m = c.real("y_m", 0, -1e5, 1e5);
            t.dir_deg = c.real("dir_deg", 0, -360, 360);
            t.width_m = c.real("width_m", t.width_m, 0.01, 1e4);
            t.height_m = c.real("height_m", 0, -5, 5);
            s.terrain.push_back(t);
        } else if (kind == "point") {
            c.only({"x_m", "y_m", "z_m", "energy"});
            ScenePoint q;
            q.name = obj;
            if (!c.has("x_m") || !c.has("y_m")) {
                c.fail("x_m", "x_m and y_m are required");
            }
            q.x_m = c.real("x_m", 0, -1e5, 1e5);
            q.y_m = c.real("y_m", 0, -1e5, 1e5);
            q.z_m = c.real("z_m", q.z_m, 0, 1000);
            q.energy = c.real("energy", q.energy, 0, 1e15);
            s.points.push_back(q);
        } else if (kind == "wall") {
            c.only({"x1_m", "y1_m", "x2_m", "y2_m", "height_m", "thickness_m", "reflectivity"});
            const double x1 = c.real("x1_m", 0, -1e5, 1e5), y1 = c.real("y1_m", 0, -1e5, 1e5);
            const double x2 = c.real("x2_m", 1, -1e5, 1e5), y2 = c.real("y2_m", 0, -1e5, 1e5);
            const double len = std::hypot(x2 - x1, y2 - y1);
            if (len < 1e-3) {
                c.fail("x2_m", "wall end points coincide");
            }
            SceneBox b;
            b.name = obj;
            b.cx_m = 0.5 * (x1 + x2);
            b.cy_m = 0.5 * (y1 + y2);
            b.size_x_m = len;
            b.size_y_m = c.real("thickness_m", 0.2, 0.001, 100);
            b.yaw_deg = std::atan2(y2 - y1, x2 - x1) * 180.0 / 3.14159265358979323846;
            b.height_m = c.real("height_m", 2, 0.001, 1000);
            b.reflectivity = c.real("reflectivity", b.reflectivity, 0, 1e9);
            s.boxes.push_back(b);
        }
    }
    validate_scene(s);
    return s;
}

} // namespace

void scene_to_power_scale(Scene &s)
{
    if (s.log_power) {
        return;
    }
    s.log_power = true;
    if (s.noise_sigma == Scene().noise_sigma) {
        s.noise_sigma = kNoiseSigmaPower; // the default's 35 % zeros on the power scale
    }
    s.smear_decay_db *= 0.5;
    s.smear_slow_db *= 0.5;
    s.smear_slow_decay_db *= 0.5;
    s.smear_amp_decay_db *= 0.5;
    if (s.smear_front_db > -100) {
        s.smear_front_db *= 0.5;
    }
    s.speckle_db *= 0.5;
    s.speckle_frame_db *= 0.5;
}

void validate_scene(Scene &s)
{
    const std::string where = s.source.empty() ? std::string("<scene>") : s.source;
    auto fail = [&](const std::string &what) { throw SceneError(where + ": " + what); };
    if (s.board.name != s.board_name) {
        try {
            s.board = load_board(s.board_name);
        } catch (const BoardError &e) {
            fail(std::string("scene.board: ") + e.what());
        }
    }
    if (s.bin_size_override_m > 0) {
        s.board.bin_size_m = s.bin_size_override_m;
    }
    if (s.range_bins_override > 0) {
        s.board.range_bins = s.range_bins_override;
    }
    if (s.rotations < 1) {
        fail("scene.rotations: must be >= 1");
    }
    if (!(s.rotation_hz > 0)) {
        fail("scene.rotation_hz: must be > 0");
    }
    if (s.elev_top_deg <= s.elev_bottom_deg) {
        fail("beam.top_deg must be above beam.bottom_deg");
    }
    if (s.measured_peak_deg <= s.elev_bottom_deg || s.measured_peak_deg >= s.elev_top_deg) {
        if (s.elevation == ElevationProfile::Measured) {
            fail("beam.measured_peak_deg must lie between bottom_deg and top_deg");
        }
    }
    if ((s.noise || s.leakage) && s.mapping != OutputMapping::Log) {
        fail("effects.noise / effects.leakage need output.mapping = log (they are defined in "
             "the sensor's log-magnitude domain)");
    }
    if (s.amplitude == AmplitudeModel::Peak &&
        (s.smear || s.mapping == OutputMapping::Log || scene_physical_response(s))) {
        fail("output.amplitude = peak (RadaRays max-per-cell) works with mapping = linear and "
             "no smear only");
    }
    if (s.clutter_value_max < s.clutter_value_min) {
        fail("clutter.value_max must be >= value_min");
    }
    if (s.clutter_inner_m <= s.clutter_outer_m) {
        fail("clutter.inner_m must be > outer_m (the band spans edge - inner_m .. edge - outer_m)");
    }
    if (s.leak_shoulder_end_m < s.leak_edge_m) {
        fail("effects.leak_shoulder_end_m must be >= leak_edge_m");
    }
    for (const auto &p : s.poles) {
        const double c = std::cos(p.tilt_deg * 3.14159265358979323846 / 180.0);
        if (p.at_height_m > p.length_m * c) {
            fail("pole." + p.name + ": at_height_m is above the pole's top");
        }
        if (p.radius_m * 4 > p.length_m) {
            fail("pole." + p.name + ": radius too large for its length");
        }
    }
}

Scene load_scene(const std::string &path)
{
    Parsed p;
    p.file = path;
    const int rc = ini_parse(path.c_str(), on_entry, &p);
    if (rc < 0) {
        throw SceneError(path + ": cannot open scene file");
    }
    if (!p.dup.empty()) {
        throw SceneError(path + ": " + p.dup + ": duplicate key");
    }
    if (rc > 0) {
        throw SceneError(path + ":" + std::to_string(rc) + ": syntax error on this line");
    }
    return build(p);
}

Scene parse_scene_string(const std::string &text, const std::string &name)
{
    Parsed p;
    p.file = name;
    const int rc = ini_parse_string(text.c_str(), on_entry, &p);
    if (!p.dup.empty()) {
        throw SceneError(name + ": " + p.dup + ": duplicate key");
    }
    if (rc != 0) {
        throw SceneError(name + ":" + std::to_string(rc) + ": syntax error on this line");
    }
    return build(p);
}

bool scene_physical_response(const Scene &s)
{
    return s.range_response != RangeResponse::None || (s.speckle && s.speckle_physical);
}

double scene_bin_size_m(const Scene &s) { return s.board.bin_size_m; }
int scene_range_bins(const Scene &s) { return s.board.range_bins; }

double scene_az_sigma_deg(const Scene &s)
{
    // RadaRays D3: radius = N(0,1)/z * width/2 with z = sqrt(2) erfinv(p): p of the normal
    // lies inside +-width/2, so sigma = (width/2) / z. z from the normal quantile by bisection.
    const double p = s.az_p_in_cone;
    double lo = 0, hi = 10;
    for (int i = 0; i < 100; i++) {
        const double m = 0.5 * (lo + hi);
        if (std::erf(m / std::sqrt(2.0)) < p) {
            lo = m;
        } else {
            hi = m;
        }
    }
    return 0.5 * s.az_width_deg / (0.5 * (lo + hi));
}

double scene_az_cutoff_deg(const Scene &s)
{
    return s.az_cutoff_deg > 0 ? s.az_cutoff_deg : 2.0 * scene_az_sigma_deg(s);
}

bool scene_speckle_static(const Scene &s)
{
    if (s.speckle_static >= 0) {
        return s.speckle_static == 1;
    }
    return s.speed_mps == 0.0 && s.yaw_rate_dps == 0.0; // auto: frozen when the vehicle stands still
}

} // namespace sl
