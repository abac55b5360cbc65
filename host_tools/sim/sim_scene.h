// SPDX-License-Identifier: MIT
// sim_scene.h: the scene a simulation runs (scenes/README.md is the file format's manual).
//
// A scene is a board (the vehicle + radar installation, boards/<name>/board.ini), a vehicle
// path, world objects (poles, boxes, walls, the ground plane), a beam model, the effects of a
// real sensor (smear, speckle, noise floor, near-field leakage) and how energies become 8-bit
// bins. It is parsed with inih (ini_parse / ini_parse_string), validated key by key, and can
// also be built in code (the experiments of sl-eval do that) and then checked with
// `validate_scene()`.
//
// World frame: x, y horizontal, z up, ground at z = 0; angles in the world are degrees
// counter-clockwise from +x. The vehicle frame is the board's (x forward, y left); the
// radar's azimuths are clockwise from vehicle forward (BoardSpec::azimuth_vehicle_deg).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "sl_board_spec.h"

namespace sl {

/// A straight cylinder standing on the ground (its axis starts at z = 0).
struct ScenePole {
    std::string name;
    double x_m = 0, y_m = 0;    ///< world position of the axis point at height `at_height_m`
    double at_height_m = 0;     ///< 0: (x, y) is the base; e.g. the radar height (paper s.IV-A)
    double length_m = 4.0;      ///< along the axis, from the ground
    double radius_m = 0.005;    ///< cylinder radius (1 cm pole: 0.005)
    double tilt_deg = 0;        ///< psi: angle of the axis from vertical, [0, 60]
    double lean_deg = 0;        ///< phi: direction the top leans towards, world CCW from +x
    double reflectivity = 1.0;  ///< energy per unit solid angle (deg^2) of the lit surface
    /// Segmented pole (the paper's: corner reflectors along it): > 0 = a reflector of
    /// `segment_fill_m` every `segment_m` along the axis from the base; between them the
    /// surface returns `segment_gap` of its reflectivity. 0 = a uniform cylinder.
    double segment_m = 0;
    double segment_fill_m = 0.02;
    double segment_gap = 0.1;
};

/// A piece of terrain ([terrain.<name>]): the ground's height changes by `height_m` (> 0 up:
/// a kerb, a step, a bank; < 0 down: a ditch, a drop-off) beyond the line through (x, y)
/// across the direction `dir_deg` (world, CCW from +x): kind step, everywhere beyond it;
/// kind strip, for `width_m` beyond it (a ditch, a kerb of that width). Heights add up.
struct SceneTerrain {
    std::string name;
    bool strip = false;
    double x_m = 0, y_m = 0, dir_deg = 0, width_m = 0.5, height_m = 0;
};

/// An oriented box on (or above) the ground; walls are thin boxes.
struct SceneBox {
    std::string name;
    double cx_m = 0, cy_m = 0;  ///< centre of the footprint, world
    double size_x_m = 1, size_y_m = 1; ///< footprint along the box's own axes
    double yaw_deg = 0;         ///< rotation of the box's x axis, world CCW from +x
    double z0_m = 0, height_m = 1; ///< bottom and height
    double reflectivity = 0.5;
};

/// An isolated point return (a post, a sign, a kerb stone): one scatterer at a world point.
struct ScenePoint {
    std::string name;
    double x_m = 0, y_m = 0, z_m = 0.5; ///< world position
    double energy = 1000;               ///< return at the beam's peak gain, in the scene's
                                        ///< energy units (output.log_ref_energy reads
                                        ///< output.log_ref_value)
};

/// The range response a return is spread with (effects.range_response).
enum class RangeResponse { None, Rect, Hann, Hamming, Blackman, Cts350x };

enum class ElevationProfile { Ideal, Measured };
enum class AmplitudeModel { Integral, Peak };
enum class OutputMapping { Linear, Log };
enum class Normalize { Column, None };

/// noise_sigma giving the same 35 % of zeros as the magnitude default (1.62) when N is a
/// power (output.log_quantity = power): 1 - exp(-1.5 / 2 s^2) = 0.35.
constexpr double kNoiseSigmaPower = 1.32;

struct Scene {
    std::string source;         ///< file it came from ("" when built in code)
    // [scene]
    std::string board_name = "paper-sim";
    BoardSpec board;            ///< loaded from board_name, then the overrides below applied
    double bin_size_override_m = 0;  ///< > 0: replaces the board's bin size
    int range_bins_override = 0;     ///< > 0: replaces the board's bins per azimuth
    int rotations = 4;
    double rotation_hz = 4.0;
    uint64_t seed = 1;
    double start_time_s = 1700000000.0; ///< UNIX time of rotation 0, azimuth 0
    // [vehicle]
    double vehicle_x_m = 0, vehicle_y_m = 0, heading_deg = 90.0, speed_mps = 0;
    double yaw_rate_dps = 0; ///< constant yaw rate, deg/s CCW (a circular path)
    /// attitude over the ground, rotating about the radar (ISO 8855: pitch nose down > 0,
    /// roll right side down > 0) and the radar's height above the board's (body raised > 0)
    double pitch_deg = 0, roll_deg = 0, height_offset_m = 0;
    std::vector<SceneTerrain> terrain; ///< [terrain.<name>]
    // objects
    std::vector<ScenePole> poles;
    std::vector<SceneBox> boxes;
    std::vector<ScenePoint> points; ///< [point.<name>]: isolated point returns
    // [ground]
    bool ground = true;
    double ground_reflectivity = 0.05;
    double ground_ambient = 0.0;   ///< shading = ambient + (1 - ambient) sin(grazing)
    double ground_max_range_m = 40;
    // [beam]
    ElevationProfile elevation = ElevationProfile::Ideal;
    double elev_top_deg = 0;       ///< upper emission bound (ideal 0, measured +3)
    double elev_bottom_deg = -35;  ///< lower emission bound
    double measured_edge_db = 5;   ///< measured profile: gain at the bounds, dB below peak
    double measured_peak_deg = -10;///< measured profile: elevation of the gain peak
    double az_width_deg = 8.0;     ///< full width of the normal cone (RadaRays beam_width)
    double az_p_in_cone = 0.8;     ///< fraction of the normal inside +-width/2 (RadaRays)
    double az_cutoff_deg = 0;      ///< hard window half-width; 0 = 2 sigma
    double az_jitter_deg = 0;      ///< > 0: each azimuth of each rotation points off by a
                                   ///< uniform draw in +-this (encoder/motor jitter); the
                                   ///< reported azimuth stays nominal
    double pole_step_deg = 0.05;   ///< elevation step of the pole quadrature
    int ground_az_samples = 33;    ///< bearing samples across the beam for ground/boxes
    double box_step_deg = 0.05;    ///< elevation step of the box ray grid
    // [output]
    AmplitudeModel amplitude = AmplitudeModel::Integral;
    OutputMapping mapping = OutputMapping::Linear;
    Normalize normalize = Normalize::Column;
    double peak_counts = 250;      ///< Column: the column's maximum energy maps to this
    double linear_scale = 100;     ///< None + Linear: counts per unit energy
    int detect_floor = 1;          ///< Linear: a bin touched by an object reads >= this
    double log_db_per_decade = 19.8; ///< Log: value = round(c log10(N)), N an integer ...
    bool log_power = false;        ///< ... power |a|^2 (true: the CTS350-X, 0.5 dB per value,
                                   ///< exponential noise) or magnitude |a| (false: 1 dB per
                                   ///< value, Rayleigh noise; the round-1 model, the default)
    double log_ref_energy = 1.0;   ///< Log: this energy (deg^2) ...
    double log_ref_value = 100;    ///< ... reads this value (noise-free)
    bool log_navtech = false;      ///< Log: value = round(cpo (e + m)) for N = 2^e (1 + m),
                                   ///< cpo = log_db_per_decade log10 2 (Navtech's piecewise-
                                   ///< linear log2; output.log_curve = navtech) instead of
                                   ///< round(c log10 N)
    // [effects]
    bool smear = false;
    int smear_shape = 0;           ///< 0 triangular (RadaRays), 1 exponential tail,
                                   ///< 2 two-component (fast + slow exponential, decay
                                   ///< depending on the source bin's level, front skirt),
                                   ///< 3 Gaussian, 4 Maxwell-Boltzmann (RadaRays' other
                                   ///< two kernel families, mode weight 1 at mode_frac),
                                   ///< 5 power law (1 + j)^-p behind the target, p such
                                   ///< that the first bin falls by smear_decay_db
    double smear_width_bins = 20;  ///< kernel length (RadaRays triangular: 50, MulRan 35)
    double smear_mode_frac = 0.0;  ///< fraction of the kernel in front of the target (RadaRays 0.35)
    double smear_decay_db = 3.0;   ///< exponential: power decay per bin behind the target (dB);
                                   ///< power law: the decay of the first bin (dB)
    // two-component (smear_shape 2): kernel(j > 0) = 10^(-d_f j / 10) + 10^((L_s - d_s j) / 10),
    // kernel(0) = 1 + 10^(L_s / 10), kernel(-1) = 10^(front_db / 10); d_f = smear_decay_db - a x,
    // d_s = smear_slow_decay_db - a x, x = clamp(10 log10(E / log_ref_energy) / 20, -1, 1)
    // (E = the source bin's energy: strong returns decay slower), a = smear_amp_decay_db
    double smear_slow_db = -15;    ///< L_s: level of the slow component at the target (dB)
    double smear_slow_decay_db = 1.5; ///< d_s at the reference level (dB per bin)
    double smear_amp_decay_db = 0.5;  ///< a: decay change per 20 dB of level (dB per bin)
    double smear_front_db = -6;    ///< one-bin front skirt (dB); <= -100: none
    bool speckle = false;
    double speckle_db = 2.0;       ///< log-normal power fluctuation per bin, 1 sigma
    int speckle_static = -1;       ///< 1: fixed over time (static scene), 0: per rotation, -1 auto
    double speckle_frame_db = 0;   ///< > 0: a further log-normal fluctuation drawn anew every
                                   ///< rotation (1 sigma, dB), on top of the pattern above
    uint64_t speckle_seed = 0;     ///< 0: derived from seed
    bool speckle_physical = false; ///< speckle_model = physical: complex Gaussian scatterer
                                   ///< amplitudes summed coherently through the range
                                   ///< response (fully developed: exponential power)
    // physical range response: the field per bin is the sum of the scatterers' complex
    // amplitudes times the amplitude response sqrt(R) at their offset (see scenes/README.md)
    RangeResponse range_response = RangeResponse::None;
    double range_cell_bins = 6;    ///< window responses: bins per resolution cell (1 / T)
    double range_skirt_bins = 0;   ///< cts350x: the lobe goes on this many bins beyond the
                                   ///< table's +-20 taps at the slope of its last two (0: ends)
    double receiver_tail_db = -30; ///< receiver tail: R(o > 0) += 10^(db/10) exp(-o / bins) ...
    double receiver_tail_bins = 0; ///< ... its e-folding length in bins (0: no tail)
    bool knife_edge = false;       ///< Fresnel knife-edge diffraction at the chassis edge
    double carrier_ghz = 76.5;     ///< carrier frequency of the diffraction (CTS350-X: 76-77)
    bool noise = false;
    double noise_sigma = 1.62;     ///< complex Gaussian per component: 35 % of the noise reads
                                   ///< 0 (P(round N <= 1)); default 1.62 for magnitude, 1.32 for
                                   ///< power (log_quantity)
    bool leakage = false;
    double leak_level = 38;        ///< output value of the bright band (0 .. leak_edge_m)
    double leak_shoulder = 19;     ///< value of the shoulder
    double leak_edge_m = 1.5;      ///< end of the bright band
    double leak_shoulder_end_m = 2.2; ///< end of the shoulder
    double leak_jitter = 0.08;     ///< fixed per-pixel relative amplitude variation
    // [clutter]: weak, changing returns in a band just inside the shadow edge (verge,
    // gravel, vegetation), in the 8-bit output domain, fixed to the vehicle frame
    bool clutter = false;
    int clutter_value_min = 20;    ///< 8-bit values drawn uniformly in [min, max]
    int clutter_value_max = 45;
    double clutter_inner_m = 0.8;  ///< band starts this far inside the shadow edge (slant)
    double clutter_outer_m = 0.05; ///< ... and ends this far inside it
    double clutter_density = 1.0;  ///< fraction of the band's cells that return
    int clutter_change_rotations = 1; ///< a cell is redrawn every N rotations (0: never)
};

struct SceneError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Parses a scene file (INI, scenes/README.md). Loads its board. Throws SceneError with
/// "<file>:<line> ..." or "<file>: <section>.<key>: <problem>" on the first problem.
Scene load_scene(const std::string &path);
/// Same from text (tests); `name` is used in messages.
Scene parse_scene_string(const std::string &text, const std::string &name = "<string>");

/// Loads the board (if `s.board` is empty or its name differs), applies the overrides and
/// checks every field's range and the combinations. Throws SceneError.
void validate_scene(Scene &s);

/// The CTS350-X's value scale on a log-mapped scene (output.log_quantity = power: 0.5 dB per
/// value, exponential noise) with the effects' VALUES kept: every dB level and slope of the
/// smear, the speckle and the return spread is halved, so a smear tail, speckle and
/// per-placement spread read the same values per bin as on the magnitude scale (their
/// calibrations, e.g. the paper's d at threshold 40, were made in values); the geometry's
/// energy ratios (partly lit bins, the elevation pattern, range) read twice the values and
/// the noise has the real sensor's statistics. noise_sigma 1.62 (the magnitude default)
/// becomes 1.32 (35 % zeros either way). No-op on a scene already on the power scale.
void scene_to_power_scale(Scene &s);

/// The scene's range resolution and bins (board values or the overrides).
double scene_bin_size_m(const Scene &s);
int scene_range_bins(const Scene &s);
/// Hard half-width of the azimuth window (deg) and the normal sigma (deg).
double scene_az_sigma_deg(const Scene &s);
double scene_az_cutoff_deg(const Scene &s);
/// True when speckle is frozen over rotations (static scene or speckle_static = 1).
bool scene_speckle_static(const Scene &s);
/// True when returns go through the coherent range-response path (a range response or
/// physical speckle).
bool scene_physical_response(const Scene &s);

} // namespace sl
