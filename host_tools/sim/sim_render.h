// SPDX-License-Identifier: MIT
// sim_render.h: the scene simulator. A Scene becomes the byte stream a CTS350-X would send
// (Colossus Configuration message, then one 8-bit FFT Data message per azimuth) plus a
// ground-truth table (sim_truth.h). Host only (C++17), double precision.
//
// Model, per azimuth (scenes/README.md has the long version):
// - Beam: a vertical fan of rays. Elevation gain G_el(e) (ideal: 1 on [bottom, top];
//   measured: a parabola in dB peaking at measured_peak_deg, measured_edge_db down at the
//   bounds, 0 outside), azimuth gain G_az(d) = exp(-d^2 / 2 sigma^2) inside a hard window
//   |d| <= cutoff (sigma from RadaRays' beam_width / p_in_cone), 0 outside.
// - Poles: the visible part of the AXIS is found exactly (sim_geom.h visible_axis); it is
//   integrated in elevation steps of pole_step_deg (plus the exact ends and the
//   perpendicular foot). Each step's energy refl * G_el * G_az * (angular width 2w, deg) *
//   (step, deg) is spread over the range interval the step covers, and across the
//   cylinder's cross-section: from the front surface (axis range - R / |sin(ray, axis)|) to
//   the silhouette (axis range), with the exact distribution of a circle's hit ranges
//   (8 quantiles). Partial fill is exact: every bin the visible surface reaches is "touched"
//   and gets at least `detect_floor` in the linear mapping. A 1 cm pole is therefore as
//   representable as a 20 cm one (no random rays that could miss it).
// - Ground: analytic per bearing sample (the elevation interval that lands in each bin,
//   integrated over G_el with shading ambient + (1 - ambient) sin(grazing)); the chassis
//   hides depressions steeper than theta(bearing). Cached per azimuth (vehicle-fixed).
// - Boxes/walls: a ray grid (ground_azimuth_samples x box_step_deg) with first-hit among
//   boxes and ground; azimuths with a box in the window render their ground this way too.
//   Poles are hidden by boxes and by other poles; poles do not hide ground or boxes
//   (slender: negligible).
// - Point returns ([point.<name>]): one scatterer each at its exact range, weighted by the
//   elevation and azimuth gains.
// - Range response (effects.range_response, optional): a window's FFT response or the
//   CTS350-X table of the core (sl_response_prior_cts350x); with physical speckle every
//   resolution cell (a bin of ground, 1/8 bin of a pole) is a circular complex Gaussian
//   amplitude and the field per bin is the coherent sum through sqrt(R) (exponential powers,
//   frozen when parked); without it the expected power. Knife-edge diffraction (optional)
//   replaces the chassis ray's hard cut by the two-way Fresnel loss |F(v)|^4.
// - Effects (optional): log-normal speckle on the scatterers' energy (frozen for a static
//   scene), the range response above, then the range smear kernel on energy (RadaRays' triangular kernel with mode
//   weight 1, or an exponential tail in dB per bin), near-field leakage (fixed pattern),
//   complex Gaussian noise, and the sensor's log-magnitude 8-bit mapping
//   value = round(c log10 N) with N an integer magnitude, or with output.log_quantity = power
//   an integer power (the CTS350-X: 0.5 dB per value, exponential noise) (Oxford: 0, 6, 9, 12, 14, 15, 17,
//   18 ...; 35 % zeros with the default noise sigma); output.log_curve = navtech: Navtech's
//   piecewise-linear log2 instead of log10.
// Randomness is counter-based (seed, rotation, azimuth, bin): rotations can be rendered in
// any order or in parallel and give identical bytes.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sim_geom.h"
#include "sim_scene.h"
#include "sim_truth.h"

namespace sl {

/// Sub-cells per bin of the poles' scatterers on the range-response path.
constexpr int kSimFineQ = 8;

/// An isolated point return on one azimuth: position in bins (bin j spans [j, j + 1)),
/// energy after the beam's gains, range (m, for its carrier phase).
struct SimPoint {
    double x_bins = 0, e = 0, r_m = 0;
};

/// Energies of one azimuth before effects (linear, deg^2 of lit solid angle x reflectivity).
struct SimColumn {
    std::vector<double> energy;   ///< per bin
    std::vector<float> peak;      ///< per bin, max ray energy (AmplitudeModel::Peak)
    std::vector<uint8_t> touched; ///< 1 where an object's visible extent reaches the bin
    /// Range-response path only (scene_physical_response): the poles' energy per sub-cell
    /// (index = bin * kSimFineQ + sub-cell; a cell may appear more than once) ...
    std::vector<std::pair<long, double>> fine;
    /// ... and the point returns (on every path).
    std::vector<SimPoint> points;
    void reset(int bins);
};

class Simulator {
public:
    /// Prepares the scene (validated copy). Precomputes the ground columns. Throws
    /// SceneError on an invalid scene.
    explicit Simulator(const Scene &scene);
    ~Simulator();
    Simulator(const Simulator &) = delete;
    Simulator &operator=(const Simulator &) = delete;

    const Scene &scene() const { return s_; }
    int azimuths() const { return s_.board.azimuths; }
    int bins() const { return s_.board.range_bins; }
    double bin_m() const { return s_.board.bin_size_m; }
    int rotations() const { return s_.rotations; }

    /// Seconds since the scene's start of rotation k, azimuth i.
    double time_of(int k, int i) const;
    /// Encoder ticks of azimuth i (round(i * encoder_size / azimuths)).
    uint16_t ticks_of(int i) const;

    /// The Configuration message (id 10) the radar sends first.
    std::vector<uint8_t> config_message() const;

    /// Renders rotation k: appends its FFT messages (one per azimuth, in azimuth order) to
    /// `bytes` and its ground-truth rows to `gt`. Const and thread-safe: call it for several
    /// rotations in parallel. Cost: O(azimuths * bins) plus the objects' quadratures.
    void render_rotation(int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &gt) const;

    /// The 8-bit bins of rotation k azimuth i (exactly what render_rotation encodes).
    std::vector<uint8_t> render_bins(int k, int i) const;
    /// Geometry only (before effects) of rotation k azimuth i.
    void geometry_column(int k, int i, SimColumn &col) const;
    /// Ground truth of rotation k (all poles, all azimuths on which they are visible).
    std::vector<GtRow> truth(int k) const;

    /// Elevation gain (power, peak 1) of the scene's beam at elevation e (deg).
    double elevation_gain(double e_deg) const;
    /// Azimuth gain at offset d (deg) from the beam centre (0 outside the window).
    double azimuth_gain(double d_deg) const;
    /// The range response in use (effects.range_response and the receiver tail): power at
    /// offset o bins from a point return's centre (1 at 0, 0 beyond the table). 0 when the
    /// scene has no range response.
    double range_response(double o_bins) const;
    /// The 8-bit value of an integer N (a power or magnitude) on the log mapping:
    /// round(c log10 N), or with output.log_curve = navtech round(c log10(2) (e + m)) for
    /// N = 2^e (1 + m); 0 for N <= 1.
    double log_value(long n) const;
    /// Half-width of the range response's table (bins).
    int range_response_half() const { return resp_half_; }
    /// Two-way knife-edge power factor |F(v)|^4 of a point at vehicle-frame azimuth az (deg),
    /// elevation e (deg) and range r (m) behind the chassis edge (1 when knife_edge is off
    /// or no edge is in that direction; the geometric shadow's hard cut is 0 / 1).
    double knife_edge_gain(double az_deg, double e_deg, double r_m) const;

private:
    struct PoleView;
    struct RotationGeom;
    void rotation_geom(int k, RotationGeom &rg) const;
    void column_from(const RotationGeom &rg, int i, SimColumn &col) const;
    void ground_analytic(int i, SimColumn &col) const;
    /// The ground of azimuth i with terrain and the vehicle's attitude (scene_terrain()):
    /// surface points marched outwards along the azimuth, each lit over the depressions it
    /// alone is the first hit of (nearer ground higher in the radar's view hides it).
    void ground_terrain(const RadarPose &r, int i, SimColumn &col) const;
    bool boxes_in_window(const RadarPose &r, int i) const;
    void grid_ground_boxes(const RadarPose &r, int i, SimColumn &col) const;
    void splat_pole(const PoleView &pv, int i, SimColumn *col, double *r1s, double *r2s) const;
    void map_column(int k, int i, const SimColumn &col, uint8_t *out) const;
    /// The range-response path: replaces the bin energies E (after log-normal speckle) by
    /// the power per bin of the field through the response, adding the poles' sub-cells
    /// and the point returns.
    void response_power(int k, int i, const SimColumn &col, std::vector<double> &E) const;
    void add_points(int k, int i, const RadarPose &pose, SimColumn &col) const;
    /// [clutter]: max(out, clutter value) on the band's cells of azimuth i, rotation k.
    void apply_clutter(int k, int i, uint8_t *out) const;

    Scene s_;
    std::vector<PoleGeom> poles_;
    std::vector<BoxGeom> boxes_;
    std::vector<double> az_deg_;     ///< vehicle-frame azimuth of each index
    std::vector<double> theta_deg_;  ///< board theta per azimuth index
    double sigma_az_ = 3, cut_az_ = 6;
    // ground: cumulative of G_el(-x) * shade(x) over depression x in [0, 90] deg
    std::vector<double> ground_cum_;
    double ground_cum_step_ = 0.001;
    std::vector<std::vector<double>> ground_cols_; ///< per azimuth (or 1 for a cylinder)
    bool terrain_moving_ = false; ///< terrain or attitude while moving: per column
    // static scenes (speed 0): the geometry of every azimuth, computed once
    std::vector<SimColumn> static_cols_;
    // deterministic output (no noise, no per-rotation speckle): the 8-bit bins of columns
    // without poles or boxes (moving scenes) or of every column (static scenes)
    bool deterministic_ = false;
    std::vector<std::vector<uint8_t>> out_cache_;
    // noise: integer magnitude distribution of pure noise
    std::vector<double> noise_cdf_;
    std::vector<uint8_t> noise_val_;
    std::vector<double> smear_kernel_;
    int smear_front_ = 0;
    // range response: R(o) and sqrt(R(o)) on o = -half .. +half in steps of 1 / kRespSub
    static constexpr int kRespSub = 64;
    int resp_half_ = 0;
    bool resp_delta_ = false; ///< physical speckle without a response: one bin per scatterer
    std::vector<double> resp_pow_, resp_amp_;
};

/// Fresnel knife-edge field |F(v)| (one way, free space 1): 0.5 at the geometric shadow
/// edge (v = 0), falling as ~0.225 / v deep in the shadow, rippling about 1 on the lit side
/// (v < 0). From the Fresnel integrals (tabulated once, |v| <= 12; asymptotic beyond).
double sim_knife_edge_field(double v);

/// Amplitude response of a cosine-sum window's FFT to a point target at f resolution cells
/// from the bin centre, normalised to 1 at f = 0 (rect, hann, hamming, blackman).
double sim_window_amplitude(RangeResponse w, double f);

/// Renders rotations [first, first + count) with `threads` workers (0 = hardware
/// concurrency) and hands each one to `sink` IN ROTATION ORDER on the calling thread
/// (bytes = its FFT messages, gt = its ground truth). `progress` (may be empty) is called
/// after each rotation is handed over. Memory: about 2 * threads rotations in flight.
void sim_run(const Simulator &sim, int first, int count, int threads,
             const std::function<void(int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &gt)> &sink,
             const std::function<void(int done, int total)> &progress = {});

/// Adds energy E of a thin cylinder whose axis range runs uniformly over [a, c] (m) to the
/// bins of `e` (bin `first_bin` at index 0, width `bin` m): each axis point's energy is spread
/// over its cross-section, from the front surface (axis - re) to the silhouette (axis), with
/// the exact distribution of a circle's hit ranges (P(hit <= r - q re) = sqrt(1 - q^2)).
/// re <= 1e-9: sharp (uniform over [a, c]). Exact, closed form (no sampling).
void sim_splat_profile(std::vector<double> &e, double bin, double a, double c, double re,
                       double E, int first_bin = 0);

/// The ground's height at world (x, y): the sum of the scene's terrain pieces (0: flat).
double scene_ground_z(const Scene &s, double x, double y);
/// The scene has terrain or a vehicle attitude (the ground is then marched, not analytic).
bool scene_terrain(const Scene &s);

/// Elevation gain (power, peak 1) of a scene's beam at elevation e (deg).
double sim_elevation_gain(const Scene &s, double e_deg);

/// Splits a unix time in seconds into the FFT timestamp fields (LE on the wire).
void sim_split_time(double unix_s, uint32_t *seconds, uint32_t *split_ns);

/// Counter-based random numbers (splitmix64 finaliser): uniform in [0, 1) and N(0, 1).
uint64_t sim_hash(uint64_t a, uint64_t b = 0, uint64_t c = 0, uint64_t d = 0);
double sim_uniform(uint64_t h);
double sim_normal(uint64_t h);

} // namespace sl
