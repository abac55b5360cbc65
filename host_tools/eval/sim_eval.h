// SPDX-License-Identifier: MIT
// sim_eval.h: accuracy evaluation of the inclination estimator on simulated captures.
//
// Chain: Colossus bytes -> core decoder (sl_proto_feed / sl_proto_parse_fft) -> the bins of
// the pole's nominal azimuth (from the ground truth) -> bounding-box extraction (first/last
// bin above threshold of the run that overlaps the true segment, inside the ground shadow;
// "bbox extraction (detection pipeline not used)") -> corrections (half-bin, sub-bin from the
// partial-fill amplitude, elongation d, radius) -> core estimator sl_incline_estimate()
// with the board's theta and a chosen beta (sl::make_geom) -> error against the truth.
#pragma once

#include <cstdint>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "capture.h"
#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_response.h"
#include "sim_scene.h"
#include "sim_truth.h"
#include "sl_board_spec.h"

namespace sl {

/// Decodes a radar byte stream with the core decoder and hands every FFT row over with its
/// rotation index (0 = first FFT message; +1 whenever the azimuth index does not increase).
class CaptureRows {
public:
    using RowFn = std::function<void(int rotation, int azimuth, const uint8_t *bins, uint32_t n)>;
    explicit CaptureRows(RowFn on_row);
    CaptureRows(const CaptureRows &) = delete;
    CaptureRows &operator=(const CaptureRows &) = delete;
    void feed(const uint8_t *data, size_t n);
    void finish();
    bool have_config() const { return have_cfg_; }
    const sl_proto_config_t &config() const { return cfg_; }
    double bin_m() const { return bin_um_ * 1e-6; }
    const sl_proto_stats_t &stats() const { return dec_.stats(); }
    uint32_t bad_fft() const { return bad_fft_; }
    int rotations_seen() const { return rot_ + 1; }

private:
    static void on_msg(void *ctx, const sl_proto_msg_t *m);
    RowFn on_row_;
    MessageDecoder dec_;
    sl_proto_config_t cfg_{};
    bool have_cfg_ = false;
    uint32_t bin_um_ = 0;
    int rot_ = -1, last_az_ = -1;
    uint32_t bad_fft_ = 0;
};

/// A run of bins [i1, i2] (inclusive); found = false when nothing qualifies.
struct BinRun {
    bool found = false;
    int i1 = -1, i2 = -1;
};

/// Bounding-box extraction on one azimuth: runs of bins with value >= threshold inside
/// [lo_bin, hi_bin], runs closer than `gap_bins` merged; returns the run with the largest
/// overlap with [want_lo, want_hi] (the true segment's bins).
BinRun bbox_run(const double *v, int n, double threshold, int lo_bin, int hi_bin, int want_lo,
                int want_hi, int gap_bins = 1);

/// Planar pole model for sub-bin bounds: the energy the renderer puts in each bin for a pole
/// of radius R whose axis spans elevations [-theta, beta] with bounds (r1, r2).
struct SubbinModel {
    double theta_deg = 26, beta_deg = 0, radius_m = 0.005, bin_m = 0.0438;
    std::function<double(double)> gain; ///< elevation gain G(e deg)
};

/// Sub-bin bounds from the partial-fill amplitudes of the edge bins: solves for the AXIS
/// r1 in bin i1 (front surface) and r2 in bin i2 such that the model's ratios
/// E(i1)/E(i1+1) and E(i2)/E(i2-1) match the observed ones (alternating bisections,
/// starting from the half-bin values). false (r1, r2 untouched) when the run is too short,
/// the pole is not thin (R > bin/4: its cross-section spreads the edge over several bins;
/// the caller falls back to half-bin + r1 += R) or the model has no valid inclination.
/// Needs a noise-free linear amplitude (simulation only: a real sensor's 8-bit log output,
/// noise and smear destroy this information).
bool subbin_bounds(const double *v, int n, int i1, int i2, const SubbinModel &m, double *r1,
                   double *r2);

/// Energies of bins [lo, hi] predicted by the planar model (relative units).
std::vector<double> subbin_model_bins(const SubbinModel &m, double r1, double r2, int lo, int hi);

/// How the bounds are formed from a run and passed to the estimator.
struct Proc {
    enum class Bounds { Raw, HalfBin, SubBin } bounds = Bounds::HalfBin;
    double r1_add_m = 0;        ///< radius correction: front surface -> axis (r1 += R)
    double beta_model_deg = 0;  ///< beta in the estimator's geometry (paper: 0)
    bool r2_raw = false;        ///< r2 from the raw back edge even with HalfBin (when d was
                                ///< calibrated against the back edge)
    double d_const_m = 0;       ///< elongation: r2 -= d
    std::vector<ElongPoint> d_table; ///< elongation table d(r2_obs) (overrides d_const when set)
    int gap_bins = 1;           ///< bbox: runs separated by at most this many bins are merged
};

/// Outcome of one estimate.
struct Est {
    bool extracted = false;     ///< a run was found
    int flag = 0;               ///< sl_incline_flag_t of the core estimator
    double alpha_deg = 0, sigma_deg = 0, r1_m = 0, r2_m = 0;
    double amb_bound_deg = 0;   ///< (beta - theta) / 2: the model's lower limit
};

/// Runs the core estimator (integer) on bounds in metres with the board's theta.
Est core_estimate(double r1_m, double r2_m, double theta_deg, double beta_deg,
                  double sigma_r_m, double sigma_theta_deg);

/// Extraction + corrections + estimator for one row. `v` are the azimuth's bins
/// (double: 8-bit values or means over frames).
Est estimate_row(const double *v, int n, const GtRow &gt, const BoardSpec &b, double threshold,
                 int lo_bin, int hi_bin, const Proc &proc, const SubbinModel *sub);

/// Error statistics of one condition.
struct ErrStats {
    std::vector<double> err;    ///< alpha_est - alpha_true (deg), valid estimates (and clipped
                                ///< ambiguous ones when clip_ambiguous)
    int rows = 0, missed = 0, ambiguous = 0, invalid = 0;
    bool clip_ambiguous = true; ///< count AMBIGUOUS as the bound (beta - theta)/2, like the
                                ///< paper's Table II ("clips at the theoretical limit")
    double mean = 0, std = 0, rmse = 0, maxabs = 0;
    void add(const Est &e, double truth);
    void finish();
};

/// Linear interpolation in an elongation table (clamped at the ends); 0 when empty.
double elong_at(const std::vector<ElongPoint> &t, double r_m);

/// Simulates `scene` in memory and decodes the bytes with the core decoder. `on_gt` gets
/// each rotation's ground truth before its bytes are decoded; `on_row` every decoded row;
/// `on_bytes` (optional) the same bytes (the configuration message first, as k = 0).
void simulate_decode(const Scene &scene, int threads,
                     const std::function<void(int k, const std::vector<GtRow> &gt)> &on_gt,
                     const CaptureRows::RowFn &on_row,
                     const std::function<void(int done, int total)> &progress = {},
                     const std::function<void(int k, const uint8_t *bytes, size_t n)> &on_bytes = {});

// ------------------------------------------------------------------------------------------
// Core detection pipeline on simulated captures ("--extract pipeline")

/// How alpha is obtained: a bounding box on the pole's ground-truth azimuth (the paper's
/// processing, "bbox extraction (detection pipeline not used)") or the core pipeline
/// (sl_pipeline: threshold, n-frame consistency mask with the motion-adapted window,
/// detection in the shadow, corrections, alpha), targets associated with the truth by azimuth.
enum class Extract { BBox, Pipeline };

/// The label printed wherever pipeline results appear.
extern const char *const kPipelineLabel;

/// Configuration of one pipeline evaluation.
struct PipeCfg {
    std::string board;          ///< core board (sl_board_find), e.g. "paper-sim"
    std::string calibration;    ///< the vehicle's calibration file (INI or blob; "" = none)
    double beam_deg = 0;        ///< detection beam width (cfg.detect.beam_width_cdeg); 0 = default 1.8
    int threshold = -1;         ///< occupied = value >= this; < 0 = the board's
    double speed_mps = 0;       ///< vehicle speed given to sl_pipeline_set_motion
    bool motion = true;         ///< pass the speed (false: no motion input, board's n)
    int mask_frames = 0;        ///< > 0: overrides the board's n
    int radius_from_width = -1; ///< cfg.detect.radius_from_width: -1 default (on), 0 off, 1 on
    int profile = -1;           ///< cfg.profile (range-profile bounds): -1 default (on), 0 off, 1 on
    bool fit = false;           ///< cfg.fit: bounds from the sensor model's fit (sl_profile_refine_fit)
    int assoc_az = 3;           ///< a target is the pole's when |az - truth azimuth| <= this
    bool clip_ambiguous = false; ///< ErrStats: count AMBIGUOUS as the model's bound
    double rotation_hz = 4;     ///< for now_us (the pipeline measures the period itself)
    int32_t prior_r2_offset_um = 0; ///< cfg.profile_cfg.prior_r2_offset_um (0: none)
    sl_vscale_t value_scale{0, 0}; ///< what the values are (LOG2 with 0 per octave: board's)
};

/// Pipeline defaults for a simulated scene: its board, the simulated azimuth window as the
/// beam (2 x scene_az_cutoff_deg: a touched bin reads >= detect_floor, so the return spans
/// the whole window), threshold = detect_floor for the linear mapping (else the board's),
/// range profiles only for the log mapping (their tail model reads log values), the value
/// scale of the scene's output mapping, speed = the scene's.
PipeCfg pipe_cfg_for_scene(const Scene &s);

/// The value scale of a scene's output mapping: linear energy, or round(c log10 N) of a
/// power or a magnitude N as a log2 scale of c log10(2) (power) or c log10(2) / 2
/// (magnitude) values per octave of power.
sl_vscale_t scene_value_scale(const Scene &s);

/// Result for one pole.
struct PipeEval {
    ErrStats err;               ///< alpha errors of the associated targets vs that rotation's truth
    int truth_rows = 0;         ///< rotations whose truth has the pole in the shadow (valid)
    int detected = 0;           ///< ... of which with an associated target
    int rotations = 0;          ///< rotations the pipeline reported
    int targets = 0;            ///< targets reported (all poles, all rotations)
    int unmatched = 0;          ///< targets associated with no truth row
    int frames_eff_min = 0, frames_eff_max = 0; ///< n_eff used
    uint32_t rejected[4] = {};  ///< sl_detect rejections (NEAR, SHADOW, WIDE, BROKEN)
    uint32_t geometry_rejected = 0;
    unsigned beam_cdeg = 0, threshold = 0;
    double rate() const { return truth_rows > 0 ? static_cast<double>(detected) / truth_rows : std::nan(""); }
};

/// Feeds a byte stream to a core pipeline and associates its per-rotation targets (raw
/// alpha per rotation, not the tracks) with ground-truth rows.
class PipelineEval {
public:
    explicit PipelineEval(const PipeCfg &c); ///< throws std::runtime_error (board, init)
    ~PipelineEval();
    PipelineEval(const PipelineEval &) = delete;
    PipelineEval &operator=(const PipelineEval &) = delete;
    /// A truth row to score (normally nominal == 1 && valid == 1). Rotation = capture rotation.
    void add_truth(const GtRow &g);
    /// Bytes of capture rotation `rotation` (any chunking; motion is set before them).
    void feed(int rotation, const uint8_t *data, size_t n);
    void finish();
    /// Association and statistics, per pole index.
    std::map<int, PipeEval> result() const;

    /// One raw per-rotation target (host units).
    struct Target {
        int rotation = 0, az = 0, flag = 0;
        double alpha_deg = 0, sigma_deg = 0;
        double r1_m = 0, r2_m = 0; ///< the target's bounds (axis)
        int bin_first = 0, bin_last = 0, tflags = 0;
    };
    /// One live tracker slot as reported after a rotation.
    struct Track {
        int rotation = 0, az = 0, id = 0, hits = 0, valid_hits = 0, last_flag = 0;
        int confirmed = 0;    ///< the pipeline sends PoleLean for it
        double alpha_deg = 0; ///< filtered alpha (meaningful when valid_hits > 0)
        double sigma_deg = 0; ///< its filtered sigma
        int level = 0;        ///< warning level (sl_warn_level_t)
    };
    /// All targets reported so far, in rotation order.
    std::vector<Target> targets() const;
    /// The live tracks after each reported rotation, in rotation order.
    std::vector<Track> tracks() const;
    /// n_eff per reported rotation.
    std::map<int, int> frames_eff() const;
    /// What the stream taught the range profile about its walk's end (sl_profile.h, "Online
    /// calibration"), carried over from `from` as the same radar going on to another scene:
    /// the residual histogram and the offset it gives.
    void carry_walk_calibration(const PipelineEval &from);
    /// The range profile's walk-end offset of r2 (um) and the upright residuals it counted.
    int32_t r2_offset_um() const;
    uint32_t resid_samples() const;

private:
    struct Impl;
    Impl *m_;
};

/// Simulates `scene` in memory and runs the pipeline on its bytes; truth rows are the
/// nominal valid ones whose r2 is not within a bin of the ground's first bin (the rows the
/// bbox path scores). `boundary` (optional) gets the count of rows left out that way.
std::map<int, PipeEval> simulate_pipeline(const Scene &scene, const PipeCfg &c, int threads,
                                          int *boundary = nullptr,
                                          const std::function<void(int done, int total)> &progress = {});

// ------------------------------------------------------------------------------------------
// Experiments (sl-eval table1 / realistic)

struct Table1Options {
    int rotations = 400;        ///< per pass (vehicle covers 10 m: speed = 10 m / (rot / 4 Hz))
    int threads = 0;
    bool progress = true;
    double lateral_m = 3.0;     ///< axis point at radar height, lateral offset (paper Fig. 7: 3 m)
    int range_bins = 0;         ///< > 0: bins per azimuth in the stream (contoured data; faster)
    unsigned captures = 0x1F;   ///< bit c: simulate capture c (0 ideal, 1 real res, 2 emission,
                                ///< 3 10 cm, 4 20 cm); rows of skipped captures stay empty
    Extract extract = Extract::BBox; ///< Pipeline: also run the core pipeline on every
                                ///< capture except the ideal one (its 2 mm bins are not the
                                ///< board's: the pipeline maps rows with the board's geometry)
    bool bbox_table = true;     ///< print the bbox table (false with --extract pipeline)
};

struct Table1Row {
    std::string name, paper_label;
    double paper_mean[3] = {0, 0, 0}, paper_std[3] = {0, 0, 0};
    ErrStats paper_style[3];    ///< the paper's processing (bbox, half-bin from "corrected" on, beta = 0)
    ErrStats improved_a[3];     ///< + beta in the model + radius correction r1 += R (half-bin)
    ErrStats improved_b[3];     ///< + beta + sub-bin bounds from the fill amplitude (R in the model)
    std::string paper_proc, a_proc, b_proc;
};

struct CurvePoint {
    double along_m, truth_deg, paper_deg, improved_deg;
};

struct Table1Result {
    std::vector<Table1Row> rows;
    int angles[3] = {-10, 0, 10};
    std::vector<CurvePoint> curves[2][3]; ///< [ideal, real corrected][angle]
    double model_err[5][3] = {};  ///< per capture and angle: mean(alpha_model - alpha), the
                                  ///< closed form's own error on the exact bounds (oblique poles)
    int boundary[5][3] = {};      ///< valid rows dropped: r2 within a bin of the ground's first bin
    int rotations = 0;
    double seconds = 0;
    bool have_pipe = false, bbox_table = true;
    /// core pipeline per variant, capture and angle (capture 0: not run). Variant 0: the
    /// detection defaults (radius from the azimuthal width); 1: radius_from_width off (the
    /// simulated 12.5 deg azimuth window makes the width measure the leaning pole's bearing
    /// extent, not its diameter).
    PipeEval pipe[2][5][3];
    PipeCfg pipe_cfg[5];          ///< variant 0's configuration per capture
};

Table1Result run_table1(const Table1Options &o);
void print_table1(std::FILE *f, const Table1Result &r);
std::string table1_json(const Table1Result &r);
/// Fig. 7-8 style plot (alpha(y) curves). false + err on failure.
bool plot_table1(const std::string &png, const Table1Result &r, std::string &err);

/// The harder realistic condition (sl-eval realistic --hard, issue 11). The sensor and the
/// installation differ from what the processing assumes; nothing here is fitted to a
/// processing path (values: docs/RESULTS.md and the paper's bench).
struct HardCondition {
    // smear (scene smear_shape two-component)
    double fast_decay_db = 3.3;  ///< main exponential (dB per bin), as the Table II condition
    double slow_db = -15;        ///< slow component's level at the target (dB)
    double slow_decay_db = 1.5;  ///< its decay (dB per bin)
    double amp_decay_db = 0.5;   ///< both decays change by this per 20 dB of level (strong: slower)
    double front_db = -6;        ///< one-bin front skirt
    double speckle_frame_db = 1.0; ///< per-frame speckle on top of the frozen 2 dB
    double az_jitter_deg = 0.1;  ///< uniform +- per azimuth and rotation
    double segment_m = 0.06, segment_fill_m = 0.02, segment_gap = 0.1; ///< reflectors 2 cm every 6 cm
    // the true installation, drawn per measurement (uniform +-); the processing uses the board
    double theta_tol_deg = 0.3, beta_tol_deg = 0.2, height_tol_m = 0.01;
    // the pole as placed by hand for each measurement (uniform +-): its bearing between two
    // azimuths (0.45 deg = half the 0.9 deg azimuth spacing) and the reflectors' return
    // (their orientation to the radar), in the radar plane as before
    double bearing_tol_deg = 0.45, refl_tol_db = 3.0;
    // ranges: measurements 2.2-2.6 m (as Table II); calibration (vertical poles, own seeds)
    // only outside them: 1.75-2.15 m and 2.65-3.0 m
    double calib_gap_lo_m = 2.15, calib_gap_hi_m = 2.65;
    /// Sets one field by name (the names of sl-eval realistic --hard-set, as in the JSON's
    /// "hard" object); false when the name is unknown or the value out of its range.
    bool set(const std::string &name, double value);
};

struct RealisticOptions {
    int positions = 11, reps = 4, frames = 16, threads = 0;
    int calib_positions = 12;   ///< vertical poles over 1.75-3.0 m for d(r)
    bool progress = true;
    int range_bins = 512;       ///< bins per azimuth in the simulated stream (contoured data)
    Extract extract = Extract::BBox; ///< Pipeline: also feed every measurement's bytes to the
                                ///< core pipeline (board paper-bench, speed 0: the board's n)
    bool bbox_table = true;     ///< print the bbox table (false with --extract pipeline)
    int pipe_last = 4;          ///< pipeline: use the targets of the last N rotations
    // Variations of the condition (defaults = the paper Table II condition)
    double smear_decay_db = 3.3; ///< exponential smear decay per bin (dB)
    int speckle_static = 1;     ///< 1: speckle frozen over the frames, 0: new every frame
    bool pipe_profile = true;   ///< pipeline: range-profile bounds (false: mask + d(r))
    int track_rotations = 0;    ///< pipeline: rotations simulated beyond the window's n (the
                                ///< tracker then sees several rotations of the same pole)
    bool hard = false;          ///< the harder condition (HardCondition; sl-eval realistic --hard)
    HardCondition hard_cond;    ///< its parameters (defaults: the documented condition)
    bool power_scale = false;   ///< the sensor's value scale (scene_to_power_scale; sl-eval
                                ///< realistic --power-scale)
    bool cold = false;          ///< pipeline: no calibration pass (the range profile's
                                ///< walk-end offset starts from nothing in every measurement)
    bool have_r2_offset = false; ///< pipeline: no calibration pass, every measurement starts
    int32_t r2_offset_um = 0;    ///< from this walk-end offset (sl-eval realistic --r2-offset)
};


/// Core-pipeline results for one true angle of the realistic bench (one estimate per
/// measurement = position x repetition).
struct RealisticPipe {
    std::vector<double> raw;    ///< per measurement: mean raw target alpha over the last
                                ///< rotations (ambiguous targets as the bound (beta - theta)/2)
    std::vector<double> filt;   ///< per measurement: tracker's filtered alpha after the last rotation
    std::vector<double> filt_sigma; ///< ... its filtered sigma (deg), parallel to `filt`
    std::vector<int> filt_level;    ///< ... its warning level (sl_warn_level_t), parallel
    std::vector<double> filt_truth; ///< ... the measurement's true alpha, parallel
    std::vector<double> raw_z;  ///< per VALID matched target: (alpha - truth) / its sigma
    int runs = 0;               ///< measurements
    int detected = 0;           ///< ... with >= 1 target at the pole's azimuth in the last rotations
    int rot_checked = 0, rot_detected = 0; ///< last rotations checked / with a matched target
    int valid = 0, ambiguous = 0, other = 0; ///< matched targets by incline flag
    int unmatched = 0;          ///< targets in the last rotations not at the pole's azimuth
    int frames_eff_min = 0, frames_eff_max = 0;
    double rate() const { return runs > 0 ? static_cast<double>(detected) / runs : std::nan(""); }
};

struct RealisticResult {
    int angles[5] = {-10, -5, 0, 5, 10};
    double paper_mean[5] = {-11.00, -3.80, 3.64, 1.82, 9.45};
    double paper_std[5] = {2.52, 3.91, 3.30, 3.59, 3.04};
    ErrStats paper_style[5], improved[5];
    std::vector<double> est_paper[5], est_improved[5]; ///< the estimates themselves
    double d_const_m = 0;       ///< paper-style calibration: mean d over 1.75-2.30 m
    std::vector<ElongPoint> d_table; ///< linear d(r2_obs) fit over 1.75-2.85 m (reference only)
    double tail_slope = 0;      ///< calibrated smear tail: values per bin
    double kernel_a = 0;        ///< per-bin power ratio of the exponential kernel
    double d_resid_m = 0;       ///< residual r2 offset after deconvolution (calibrated)
    std::vector<std::pair<double, double>> calib; ///< (r2_obs, d) samples
    double seconds = 0;
    int frames = 16, positions = 11, reps = 4;
    bool have_pipe = false, bbox_table = true;
    RealisticPipe pipe[5];      ///< core pipeline per true angle (have_pipe)
    PipeCfg pipe_cfg;           ///< the pipeline's configuration (first measurement's)
    int32_t pipe_r2_offset_um = 0; ///< walk-end offset learned on the calibration poles
    uint32_t pipe_resid_samples = 0; ///< ... from this many upright residuals (0: cold)
    int pipe_last = 4;
    unsigned pipe_mask_frames = 0; ///< board n (paper-bench)
    bool hard = false;          ///< the harder condition was run
    HardCondition hard_cond;
    bool power_scale = false;   ///< rendered on the sensor's value scale (--power-scale)
};

RealisticResult run_realistic(const RealisticOptions &o);
void print_realistic(std::FILE *f, const RealisticResult &r);
std::string realistic_json(const RealisticResult &r);

/// The realistic bench scene (paper-bench board): pole base `dist_m` ahead on azimuth 0,
/// tilt `alpha_deg` in the radar's plane (> 0 = towards it).
Scene realistic_scene(double dist_m, double alpha_deg, uint64_t seed, int frames, int range_bins);
/// Applies the harder condition to a realistic_scene: sensor effects, segmented pole and the
/// true installation perturbed (theta, beta, H drawn from `seed`).
void make_hard(Scene &s, const HardCondition &h, uint64_t seed);
/// The table-1 pass scene: `cond` 0 ideal, 1 real res, 2 measured emission, 3 10 cm, 4 20 cm.
Scene table1_scene(int cond, int angle_deg, int rotations, double lateral_m, int range_bins = 0);

} // namespace sl
