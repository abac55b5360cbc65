// SPDX-License-Identifier: MIT
// sl-eval driveby: the 3D tilt fit (sl_tilt.h, sl_tiltobs.h) end to end on simulated
// drive-bys. One pole per pass: the simulator renders the capture (sim_render.h), the core
// pipeline (sl_pipeline_feed, the board's defaults) gets it with the pass's speed as its
// motion input (sl_pipeline_set_motion, as the daemon's --motion does), and after every
// rotation the pole's track's fit is read in the vehicle frame (sl_tiltobs_vehicle, what
// PoleTilt carries). The LAST FITTED result of the pass is compared with the simulator's
// truth: psi (tilt_deg), phi (lean_deg - heading, CCW from forward), the base's lateral
// offset; an AMBIGUOUS result's two readings (sl_tiltobs_vehicle and _vehicle_mirror, the
// PoleTilt frames AMBIGUOUS and MIRROR) are both compared: the pass is answered when the
// truth is one of them. Prints one line per pole and a summary against the bounds,
// on every pass and on the passes whose observations separate the mirror (mirror_separation
// >= 9), and how many AMBIGUOUS passes held observations that cannot tell the mirror.
#include "driveby.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_pipeline.h"
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim_render.h"
#include "sim_scene.h"
#include "sl_cli.h"

namespace {

struct Case {
    double speed, psi, phi_v, offset; // m/s, deg, deg (vehicle frame, CCW from forward), m (left +)
};

struct Outcome {
    bool fitted = false, ambiguous = false;
    double psi = 0, phi = 0, base_y = 0;
    bool has_other = false;           // AMBIGUOUS: the other reading (PoleTilt MIRROR)
    double psi2 = 0, phi2 = 0;
    int quality = -1, n_obs = 0, rotation = -1;
    uint16_t slope_q8 = 0, cal_n = 0; // the profile's tail calibration at the end of the pass
    double separation = -1;           // mirror_separation() of the result's observations
                                      // (-1: no ring; HUGE_VAL: no other reading differs)
};

// One pass's material for the plot: the fitted ring's observations and fit at the end of the
// pass, and the simulator's truth curve alpha(y).
struct PlotData {
    bool have = false;
    sl_tiltobs_ring_t ring{};
    double H = 0;
    std::vector<std::pair<double, double>> truth; // (along_m, alpha_deg), nominal rows
};

struct RunCtx {
    sl_pipeline_t *p = nullptr;
    PlotData *plot = nullptr;
    // Every ring as of the previous rotation (what the fit read at the end of it), and the
    // one behind the pass's reported result (--dump prints it; the separation reads it).
    bool dump = false;
    sl_tiltobs_ring_t prev[SL_CFG_TILT_TRACKS]{};
    sl_tiltobs_ring_t fitted_ring{};
    sl_tiltobs_ring_t other_ring{}; // the fullest ring when no fit was FITTED/AMBIGUOUS
    FILE *obs_log = nullptr; // --obs-log: every new fit of the pole's ring, one JSON line
    const Case *kase = nullptr;
    sl_tilt_result_t logged[SL_CFG_TILT_TRACKS]{};
    double want_y = 0; // truth base offset, vehicle frame
    Outcome last;      // last FITTED (or, failing that, last AMBIGUOUS) result
    int other_q = -1;  // last quality of the fullest ring (INSUFFICIENT_MOTION, TOO_FEW, ...)
    int other_n = 0;
};

const char *quality_name(int q)
{
    switch (q) {
    case SL_TILT_FITTED: return "FITTED";
    case SL_TILT_AMBIGUOUS: return "AMBIGUOUS";
    case SL_TILT_INSUFFICIENT_MOTION: return "INSUF_MOT";
    case SL_TILT_TOO_FEW: return "TOO_FEW";
    case SL_TILT_INCONSISTENT: return "INCONSIST";
    default: return "no track";
    }
}

// The PoleTilt Quality value table's name ("none": no track), for --json.
const char *quality_json(int q)
{
    switch (q) {
    case SL_TILT_FITTED: return "FITTED";
    case SL_TILT_AMBIGUOUS: return "AMBIGUOUS";
    case SL_TILT_INSUFFICIENT_MOTION: return "INSUFFICIENT_MOTION";
    case SL_TILT_TOO_FEW: return "TOO_FEW";
    case SL_TILT_INCONSISTENT: return "INCONSISTENT";
    default: return "none";
    }
}

// --obs-log: one JSON line per new fit of a ring placed within 1 m of the pole: the case,
// the observations the fit read (the ring as of the previous rotation) and the result.
void log_fits(RunCtx *c)
{
    const sl_tiltobs_t *t = &c->p->tilt;
    for (size_t i = 0; i < SL_CFG_TILT_TRACKS; ++i) {
        const sl_tiltobs_ring_t &ring = t->ring[i];
        sl_tiltobs_vehicle_t v;
        if (ring.track_id == 0U || !sl_tiltobs_vehicle(t, &ring, &v) ||
            std::memcmp(&ring.res, &c->logged[i], sizeof ring.res) == 0) {
            continue;
        }
        c->logged[i] = ring.res;
        if (ring.res.n_obs < SL_TILT_MIN_OBS || std::fabs(v.base_y_um * 1e-6 - c->want_y) > 1.0) {
            continue;
        }
        const sl_tiltobs_ring_t &pr = c->prev[i];
        if (pr.track_id != ring.track_id || pr.count != ring.res.n_obs) {
            continue; // not the observations this fit read
        }
        std::vector<sl_tilt_obs_t> obs(pr.obs, pr.obs + pr.count);
        if (pr.count == SL_CFG_TILT_OBS_PER_TRACK) {
            std::rotate(obs.begin(), obs.begin() + pr.head, obs.end());
        }
        const Case &k = *c->kase;
        std::fprintf(c->obs_log,
                     "{\"v\":%.1f,\"psi\":%.1f,\"phi\":%.1f,\"off\":%.1f,\"q\":%d,"
                     "\"psi_fit\":%.2f,\"phi_fit\":%.2f,\"psi_sig\":%.2f,\"phi_sig\":%.2f,"
                     "\"lean\":%.2f,\"lean_sig\":%.2f,\"chi2\":%.3f,\"other\":%.3f,\"mask\":%u,\"obs\":[",
                     k.speed, k.psi, k.phi_v, k.offset, v.quality, v.psi_cdeg / 100.0,
                     v.phi_cdeg / 100.0, v.psi_sigma_cdeg / 100.0, v.phi_sigma_cdeg / 100.0,
                     v.lean_path_cdeg / 100.0, v.lean_path_sigma_cdeg / 100.0, ring.res.chi2_q8 / 256.0, ring.res.chi2_other_q8 / 256.0,
                     ring.res.mirrored_mask);
        for (size_t j = 0; j < obs.size(); ++j) {
            const sl_tilt_obs_t &o = obs[j];
            std::fprintf(c->obs_log, "%s[%d,%d,%u,%d,%d,%d,%d,%u,%u]", j ? "," : "", o.radar_x_um,
                         o.radar_y_um, o.r1_um, o.cos_a_q15, o.sin_a_q15, o.tan_q12,
                         o.tan_mirror_q12, o.sigma_q16, o.mirrorable);
        }
        std::fprintf(c->obs_log, "]}\n");
    }
}

void on_rotation(void *ctx, const sl_pipeline_rotation_t *r)
{
    auto *c = static_cast<RunCtx *>(ctx);
    const sl_tiltobs_t *t = &c->p->tilt;
    if (c->obs_log != nullptr) {
        log_fits(c);
    }
    // The ring nearest to the pole's true lateral offset (one pole per pass).
    const sl_tiltobs_ring_t *best = nullptr;
    sl_tiltobs_vehicle_t bv{};
    double be = 1e9;
    for (const sl_tiltobs_ring_t &ring : t->ring) {
        sl_tiltobs_vehicle_t v;
        if (ring.track_id == 0U || !sl_tiltobs_vehicle(t, &ring, &v)) {
            continue;
        }
        if (ring.count >= c->other_n) {
            c->other_n = ring.count;
            c->other_q = v.quality;
            c->other_ring = c->prev[static_cast<size_t>(&ring - &t->ring[0])];
            c->other_ring.res = ring.res;
        }
        if (v.quality != SL_TILT_FITTED && v.quality != SL_TILT_AMBIGUOUS) {
            continue;
        }
        const double e = std::fabs(v.base_y_um * 1e-6 - c->want_y);
        if (e < be) {
            be = e;
            best = &ring;
            bv = v;
        }
    }
    if (best == nullptr || be > 1.0) {
        std::copy(std::begin(t->ring), std::end(t->ring), std::begin(c->prev));
        return;
    }
    Outcome o;
    o.fitted = bv.quality == SL_TILT_FITTED;
    o.ambiguous = bv.quality == SL_TILT_AMBIGUOUS;
    o.psi = bv.psi_cdeg / 100.0;
    o.phi = bv.phi_cdeg / 100.0;
    o.base_y = bv.base_y_um * 1e-6;
    o.quality = bv.quality;
    o.n_obs = best->count;
    o.rotation = static_cast<int>(r->rotation);
    sl_tiltobs_vehicle_t mv;
    if (sl_tiltobs_vehicle_mirror(t, best, &mv)) {
        o.has_other = true;
        o.psi2 = mv.psi_cdeg / 100.0;
        o.phi2 = mv.phi_cdeg / 100.0;
    }
    if (o.fitted || !c->last.fitted) {
        c->last = o;
        if (c->plot != nullptr) { // the last FITTED fit, else the last AMBIGUOUS one
            c->plot->have = true;
            c->plot->ring = *best;
        }
        // the observations the fit read: the ring as of the previous rotation
        const auto idx = static_cast<size_t>(best - &t->ring[0]);
        c->fitted_ring = c->prev[idx];
        c->fitted_ring.res = best->res;
    }
    std::copy(std::begin(t->ring), std::end(t->ring), std::begin(c->prev));
}

// A ring's observations in the order they were recorded (oldest first).
std::vector<sl_tilt_obs_t> ring_obs(const sl_tiltobs_ring_t &r)
{
    std::vector<sl_tilt_obs_t> obs(r.obs, r.obs + r.count); // ring order: oldest at head when full
    if (r.count == SL_CFG_TILT_OBS_PER_TRACK) {
        std::rotate(obs.begin(), obs.begin() + r.head, obs.end());
    }
    return obs;
}

// What the fold's readings are solved from, one entry per observation: a: bearing (rad);
// t0 / t1: tan alpha as read / its mirror; sg: sigma of tan alpha; mir: mirrorable.
struct FoldInput {
    std::vector<double> a, t0, t1, sg;
    std::vector<int> mir;
};

// The observations as the fit read them.
FoldInput fold_input(const std::vector<sl_tilt_obs_t> &obs)
{
    const size_t n = obs.size();
    FoldInput f{std::vector<double>(n), std::vector<double>(n), std::vector<double>(n),
                std::vector<double>(n), std::vector<int>(n)};
    for (size_t k = 0; k < n; ++k) {
        const sl_tilt_obs_t &o = obs[k];
        f.a[k] = std::atan2(o.sin_a_q15, o.cos_a_q15);
        f.t0[k] = o.tan_q12 / 4096.0;
        f.t1[k] = o.tan_mirror_q12 / 4096.0;
        f.sg[k] = o.sigma_q16 / 65536.0;
        f.mir[k] = o.mirrorable;
    }
    return f;
}

// One reading of the fold: bit k of `ch` set = measurement k read as its mirror; the tilt
// vector solved for it and its chi-square with the stated sigmas.
struct FoldCand {
    uint64_t ch;
    double tx, ty, x2;
};

// Every reading sl_tilt_fit considers (sl_tilt.h, "The fold": the mirrored measurements are
// one circular interval of the mirrorable ones in bearing order, or none, or all), each
// solved by weighted least squares in double: the estimator's weights (sigma_min / sigma)^2,
// chi-square with the stated sigmas. Sorted by chi-square, best first.
std::vector<FoldCand> fold_readings(const FoldInput &f)
{
    const std::vector<double> &a = f.a, &t0 = f.t0, &t1 = f.t1, &sg = f.sg;
    const std::vector<int> &mir = f.mir;
    const size_t n = a.size();
    double w0 = 1e300;
    for (size_t k = 0; k < n; ++k) {
        w0 = std::min(w0, sg[k]);
    }
    std::vector<unsigned> ord;
    double mc = 0, ms = 0;
    for (unsigned k = 0; k < n; ++k) {
        if (mir[k] != 0) {
            ord.push_back(k);
            mc += std::cos(a[k]);
            ms += std::sin(a[k]);
        }
    }
    const double ref = std::atan2(ms, mc);
    std::stable_sort(ord.begin(), ord.end(), [&](unsigned x, unsigned y) {
        return std::remainder(a[x] - ref, 2 * M_PI) < std::remainder(a[y] - ref, 2 * M_PI);
    });
    std::vector<FoldCand> cs;
    const size_t m = ord.size();
    for (size_t len = 0; len <= m; ++len) {
        const size_t starts = (len == 0 || len == m) ? 1 : m;
        for (size_t i = 0; i < starts; ++i) {
            uint64_t ch = 0;
            for (size_t j = 0; j < len; ++j) {
                ch |= uint64_t{1} << ord[(i + j) % m];
            }
            double A = 0, B = 0, C = 0, U = 0, V = 0;
            for (size_t k = 0; k < n; ++k) {
                const double w = (w0 / sg[k]) * (w0 / sg[k]);
                const double cc = std::cos(a[k]), ss = std::sin(a[k]);
                const double tt = ((ch >> k) & 1U) ? t1[k] : t0[k];
                A += w * cc * cc; B += w * cc * ss; C += w * ss * ss; U += w * cc * tt; V += w * ss * tt;
            }
            const double det = A * C - B * B;
            if (!(det > 1e-12 * A * C)) {
                continue; // one bearing: no reading determines t
            }
            const double tx = -(C * U - B * V) / det, ty = -(A * V - B * U) / det;
            double x2 = 0;
            for (size_t k = 0; k < n; ++k) {
                const double tt = ((ch >> k) & 1U) ? t1[k] : t0[k];
                const double res = (tt + tx * std::cos(a[k]) + ty * std::sin(a[k])) / sg[k];
                x2 += res * res;
            }
            cs.push_back({ch, tx, ty, x2});
        }
    }
    std::sort(cs.begin(), cs.end(), [](const FoldCand &x, const FoldCand &y) { return x.x2 < y.x2; });
    return cs;
}

// The mirror's separation at the truth: how far the observations of a pass could tell the
// fold's other readings from the true pole if every reading were exact. The observations'
// bearings, stated sigmas and fold (which are mirrorable, and each one's mirror line
// beta - theta_k = alpha + alpha', from its two readings) are kept; the readings are
// replaced by the true pole's in-plane inclination (each mirrorable one on the side of the
// fold it was read on) and its mirror. The smallest chi-square of a reading whose tilt
// vector is a different answer to sl_tilt_fit's ambiguity test (|t' - t| > max(0.035,
// 0.3 |t|)) is the noncentrality of the mirror test: the chi-square difference the fit sees
// on average when the errors are as stated. Below 9, no 3-sigma rule tells the mirror from
// the truth on these observations; HUGE_VAL when no other reading differs (nothing read on
// the fold's far branch). Straight passes only: the odometry frame is the vehicle's.
double mirror_separation(const std::vector<sl_tilt_obs_t> &obs, const Case &kc)
{
    const double tn = std::tan(kc.psi * M_PI / 180), ph = kc.phi_v * M_PI / 180;
    const double tx = tn * std::cos(ph), ty = tn * std::sin(ph);
    FoldInput f = fold_input(obs);
    for (size_t k = 0; k < obs.size(); ++k) {
        const double m0 = f.t0[k], m1 = f.t1[k]; // as read
        const double tt = -(tx * std::cos(f.a[k]) + ty * std::sin(f.a[k]));
        f.t0[k] = f.t1[k] = tt;
        if (f.mir[k] != 0) {
            const double mt = std::tan(std::atan(m0) + std::atan(m1) - std::atan(tt));
            if (std::fabs(mt - m0) < std::fabs(tt - m0)) { // read as the mirror of the truth
                f.t0[k] = mt;
            } else {
                f.t1[k] = mt;
            }
        }
    }
    const double apart = std::max(0.035, 0.3 * tn);
    for (const FoldCand &c : fold_readings(f)) {
        if (std::hypot(c.tx - tx, c.ty - ty) > apart) {
            return c.x2; // the best such reading (sorted)
        }
    }
    return HUGE_VAL;
}

// --dump: the observations behind a pass's result and every interval reading of the fold,
// solved in double (sl_tilt.h's estimator: weights (sigma_min / sigma)^2, chi-square with
// the stated sigmas), best first; and the fixed-point fit re-run on them.
void dump_ring(const sl_tiltobs_ring_t &r, const sl_tilt_params_t &prm, const Case &kc)
{
    const double ttrue = std::tan(kc.psi * M_PI / 180), ptrue = kc.phi_v * M_PI / 180;
    const unsigned n = r.count;
    const std::vector<sl_tilt_obs_t> obs = ring_obs(r);
    sl_tilt_work_t wk;
    sl_tilt_result_t re;
    (void)sl_tilt_fit(obs.data(), obs.size(), &prm, &wk, &re);
    std::printf("  dump: %u obs; reported q %d psi %.2f phi %.2f chi2 %.2f other %.2f mask %08x; "
                "re-fit q %d psi %.2f phi %.2f chi2 %.2f other %.2f mask %08x%s\n",
                n, r.res.quality, r.res.psi_cdeg / 100.0, r.res.phi_cdeg / 100.0,
                r.res.chi2_q8 / 256.0, r.res.chi2_other_q8 / 256.0, r.res.mirrored_mask,
                re.quality, re.psi_cdeg / 100.0, re.phi_cdeg / 100.0, re.chi2_q8 / 256.0,
                re.chi2_other_q8 / 256.0, re.mirrored_mask,
                (re.tx_q24 == r.res.tx_q24 && re.ty_q24 == r.res.ty_q24) ? " (same)" : " (DIFFERS)");
    const FoldInput f = fold_input(obs);
    const std::vector<double> &a = f.a, &t0 = f.t0, &t1 = f.t1, &sg = f.sg;
    for (unsigned k = 0; k < n; ++k) {
        const sl_tilt_obs_t &o = obs[k];
        std::printf("  obs %2u: radar (%8.3f, %8.3f) m bearing %8.3f deg r1 %6.3f m alpha %7.3f "
                    "mirror %7.3f sigma %6.3f deg m%d%s true %7.3f {%d,%d,%u,%d,%d,%d,%d,%u,%u},\n",
                    k, o.radar_x_um * 1e-6, o.radar_y_um * 1e-6, a[k] * 180 / M_PI, o.r1_um * 1e-6,
                    std::atan(t0[k]) * 180 / M_PI, std::atan(t1[k]) * 180 / M_PI,
                    sg[k] / (1 + t0[k] * t0[k]) * 180 / M_PI, o.mirrorable,
                    (o.mark & SL_TILT_OBS_RAMP) != 0U ? " ramp" : "",
                    -std::atan(ttrue * std::cos(a[k] - ptrue)) * 180 / M_PI,
                    o.radar_x_um, o.radar_y_um, o.r1_um, o.cos_a_q15, o.sin_a_q15, o.tan_q12,
                    o.tan_mirror_q12, o.sigma_q16, o.mirrorable);
    }
    const std::vector<FoldCand> cs = fold_readings(f);
    for (size_t i = 0; i < cs.size() && i < 12; ++i) {
        std::printf("  cand mask %08llx chi2 %9.2f psi %6.2f phi %7.1f\n",
                    static_cast<unsigned long long>(cs[i].ch), cs[i].x2,
                    std::atan(std::hypot(cs[i].tx, cs[i].ty)) * 180 / M_PI,
                    std::atan2(cs[i].ty, cs[i].tx) * 180 / M_PI);
    }
    if (n >= SL_TILT_MIN_OBS) {
        std::printf("  separation at the truth: %.2f (below 9 these observations cannot tell the "
                    "mirror from the truth at 3 sigma)\n", mirror_separation(obs, kc));
    }
}


double wrap180(double d)
{
    while (d > 180.0) {
        d -= 360.0;
    }
    while (d <= -180.0) {
        d += 360.0;
    }
    return d;
}

std::string scene_text(const std::string &board, const Case &k, bool realistic, int seed,
                       int *rotations)
{
    // Vehicle along world +y (heading 90), starting 6 m before the pole, ending 6 m after.
    const double run_m = 12.0;
    *rotations = static_cast<int>(std::ceil(run_m / k.speed * 4.0));
    const double lean_world = wrap180(k.phi_v + 90.0); // heading 90: world = vehicle + 90
    char buf[2048];
    std::snprintf(buf, sizeof buf,
                  "[scene]\nboard = %s\nrotations = %d\nrotation_hz = 4\nseed = %d\nrange_bins = 512\n"
                  "[vehicle]\nx_m = 0\ny_m = -6.0\nheading_deg = 90\nspeed_mps = %.3f\n"
                  "[pole.p]\nx_m = %.3f\ny_m = 0.0\nlength_m = 4.0\nradius_m = 0.005\n"
                  "tilt_deg = %.3f\nlean_deg = %.3f\nreflectivity = 1.0\n"
                  "[ground]\nreflectivity = 0.05\n"
                  "[beam]\nelevation = ideal\nazimuth_width_deg = 2\n"
                  "[output]\namplitude = integral\nmapping = %s\nnormalize = %s\n",
                  board.c_str(), *rotations, seed, k.speed, -k.offset, k.psi, lean_world,
                  realistic ? "log" : "linear", realistic ? "none" : "column");
    std::string s = buf;
    if (realistic) {
        // The sensor's output (the Table II bench's effects): 8-bit log magnitude with its
        // noise floor and near-field leakage, a smear tail, speckle drawn anew each rotation.
        s += "[effects]\nsmear = on\nsmear_shape = exponential\nsmear_width_bins = 40\n"
             "smear_decay_db = 3.3\nspeckle = on\nspeckle_static = no\nnoise = on\n"
             "leakage = on\n";
    }
    return s;
}

// --no-profile: the pipeline's mask bounds with the board's d(r) (no range profiles).
bool g_no_profile = false;
// --power-scale (with --realistic): the sensor's value scale (sl::scene_to_power_scale).
bool g_power_scale = false;
// The tail slope every --realistic pass starts from (sl_profile_cfg_t.prior_slope_q8): what
// the calibration pass self-fitted, as a vehicle that has driven before has it saved; 0 with
// --cold.
uint16_t g_prior_slope_q8 = 0;

Outcome run_case(const std::string &board_name, const Case &k, bool realistic, int seed,
                 PlotData *plot = nullptr, bool dump = false, FILE *obs_log = nullptr)
{
    int rotations = 0;
    sl::Scene scene =
        sl::parse_scene_string(scene_text(board_name, k, realistic, seed, &rotations), "driveby");
    if (realistic && g_power_scale) {
        sl::scene_to_power_scale(scene);
    }
    sl::Simulator sim(scene);
    const sl_board_t *linked = sl_board_find(board_name.c_str());
    if (linked == nullptr) {
        throw std::runtime_error("board " + board_name + " is not linked into the core");
    }
    // The noise-free passes render no smear: a board's elongation table d(r) (measured on a
    // smearing sensor) would cut that much off every smear-free return.
    sl_board_t nf = *linked;
    if (!realistic) {
        nf.elong_points = 0U;
    }
    const sl_board_t *b = &nf;
    auto p = std::make_unique<sl_pipeline_t>();
    RunCtx ctx;
    ctx.p = p.get();
    ctx.want_y = k.offset;
    ctx.plot = plot;
    ctx.dump = dump;
    ctx.obs_log = obs_log;
    ctx.kase = &k;
    if (plot != nullptr) {
        plot->H = b->radar_height_um * 1e-6;
    }
    sl_pipeline_cfg_t cfg;
    sl_pipeline_cfg_default(&cfg, b);
    cfg.port.ctx = &ctx;
    cfg.port.on_rotation = on_rotation;
    // Range profiles read the sensor's log values; the noise-free passes are the paper's
    // linear rendering (no smear): the mask's bounds (sim_eval.h, pipe_cfg_for_scene).
    cfg.profile = realistic && !g_no_profile;
    cfg.profile_cfg.prior_slope_q8 = g_prior_slope_q8;
    if (sl_pipeline_init(p.get(), b, &cfg) != SL_OK) {
        throw std::runtime_error("sl_pipeline_init failed for board " + board_name);
    }
    const std::vector<uint8_t> conf = sim.config_message();
    (void)sl_pipeline_feed(p.get(), conf.data(), conf.size(), 0U);
    const int32_t v_mm_s = static_cast<int32_t>(std::lround(k.speed * 1000.0));
    for (int r = 0; r < rotations; ++r) {
        std::vector<uint8_t> bytes;
        std::vector<sl::GtRow> gt;
        sim.render_rotation(r, bytes, gt);
        if (plot != nullptr) {
            for (const sl::GtRow &g : gt) {
                if (g.nominal == 1) {
                    plot->truth.emplace_back(g.along_m, g.alpha_deg);
                }
            }
        }
        const uint64_t now = 1000000ULL + static_cast<uint64_t>(r) * 250000ULL;
        sl_pipeline_set_motion(p.get(), v_mm_s, true, 0, true, now);
        (void)sl_pipeline_feed(p.get(), bytes.data(), bytes.size(), now);
    }
    (void)sl_pipeline_finish(p.get(), 1000000ULL + static_cast<uint64_t>(rotations) * 250000ULL);
    if (dump) { // why a pass has no track: detection's rejections, the tracker, the rings
        const sl_detect_stats_t &d = p->detect.stats;
        const sl_track_stats_t &t = p->tracker.stats;
        const sl_tiltobs_stats_t &o = p->tilt.stats;
        std::printf("  stats: groups %u targets %u rejected near %u shadow %u wide %u broken %u short %u "
                    "rho %u weak %u; tracks created %u confirmed %u associated %u inconsistent %u "
                    "dropped %u; tilt obs %u rejected %u no_target %u outliers %u gross %u\n",
                    d.groups, d.targets, d.rejected[SL_DETECT_REJ_NEAR], d.rejected[SL_DETECT_REJ_SHADOW],
                    d.rejected[SL_DETECT_REJ_WIDE], d.rejected[SL_DETECT_REJ_BROKEN],
                    d.rejected[SL_DETECT_REJ_SHORT], d.rejected[SL_DETECT_REJ_RHO],
                    d.rejected[SL_DETECT_REJ_WEAK], t.created, t.confirmations, t.associated,
                    t.inconsistent, t.dropped, o.observations, o.rejected, o.no_target, o.outliers, o.gross);
        const sl_profile_stats_t &f = p->prof.stats;
        std::printf("  profile: refined %u (from neighbouring azimuths %u); fallback no_slot %u "
                    "lead_cut %u no_run %u tail_cut %u no_tail %u few_frames %u; claims %u "
                    "full %u; reserved %u full %u; tail slope %.2f values/bin\n",
                    f.extracted, f.spatial, f.fallback[SL_PROFILE_NO_SLOT],
                    f.fallback[SL_PROFILE_LEAD_CUT], f.fallback[SL_PROFILE_NO_RUN],
                    f.fallback[SL_PROFILE_TAIL_CUT], f.fallback[SL_PROFILE_NO_TAIL],
                    f.fallback[SL_PROFILE_FEW_FRAMES], f.claims, f.claim_full, f.reserved,
                    f.reserve_full, p->prof.slope_q8 / 256.0);
        const uint8_t *ln = p->prof.lead_n;
        std::printf("  front part: %u bins (r1 moved on %u targets); rises of leaning-away "
                    "returns 0..7+: %u %u %u %u %u %u %u %u\n",
                    p->prof.front_bins, f.front_skipped, ln[0], ln[1], ln[2], ln[3], ln[4], ln[5],
                    ln[6], ln[7]);
    }
    if (dump && ctx.fitted_ring.track_id != 0U) {
        dump_ring(ctx.fitted_ring, p->tilt.prm, k);
    } else if (dump && ctx.other_ring.track_id != 0U) {
        dump_ring(ctx.other_ring, p->tilt.prm, k); // e.g. INCONSISTENT: what the fit read
    }
    Outcome o = ctx.last;
    if (o.quality < 0) {
        o.quality = ctx.other_q; // no FITTED / AMBIGUOUS result: why not
        o.n_obs = ctx.other_n;
        o.base_y = k.offset;     // not measured: no offset error counted
    }
    o.slope_q8 = p->prof.slope_q8;
    o.cal_n = p->prof.cal_n;
    const sl_tiltobs_ring_t &rr = ctx.fitted_ring.track_id != 0U ? ctx.fitted_ring : ctx.other_ring;
    if (rr.track_id != 0U && rr.count >= SL_TILT_MIN_OBS) {
        o.separation = mirror_separation(ring_obs(rr), k);
    }
    return o;
}

// alpha(y) of one pass: measured (the ring's observations, as read; the ones the fit read as
// the fold's mirror drawn hollow at their mirrored value too), the fitted curve
// atan(-(t . e(y))) and the simulator's truth. y: radar position along the path relative to
// the pole's point at radar height (the paper's y).
bool plot_pass(const std::string &png, const PlotData &d, const Case &k, std::string &err)
{
    const sl_tiltobs_ring_t &r = d.ring;
    const double tx = r.res.tx_q24 / 16777216.0, ty = r.res.ty_q24 / 16777216.0;
    const double qx = r.res.base_x_um * 1e-6 + d.H * tx, qy = r.res.base_y_um * 1e-6 + d.H * ty;
    struct Pt {
        double y, a, mirror;
        bool mirrored;
    };
    std::vector<Pt> pts;
    double ry = 0;
    for (unsigned i = 0; i < r.count; ++i) {
        const sl_tilt_obs_t &o = r.obs[i];
        const bool m = ((r.res.mirrored_mask >> i) & 1U) != 0U;
        pts.push_back({o.radar_x_um * 1e-6 - qx, std::atan(o.tan_q12 / 4096.0) * 180.0 / M_PI,
                       std::atan(o.tan_mirror_q12 / 4096.0) * 180.0 / M_PI, m});
        ry += o.radar_y_um * 1e-6 / r.count;
    }
    auto fit_at = [&](double y) {
        const double ex = -y, ey = qy - ry, n = std::hypot(ex, ey);
        return std::atan(-(tx * ex / n + ty * ey / n)) * 180.0 / M_PI;
    };
    const int W = 900, Hh = 540, ml = 70, mr = 20, mt = 80, mb = 50;
    cv::Mat img(Hh, W, CV_8UC3, cv::Scalar(255, 255, 255));
    double xmin = -6, xmax = 6, amin = 1e9, amax = -1e9;
    for (const Pt &p : pts) {
        amin = std::min({amin, p.a, p.mirrored ? p.mirror : p.a});
        amax = std::max({amax, p.a, p.mirrored ? p.mirror : p.a});
    }
    for (const auto &t : d.truth) {
        amin = std::min(amin, t.second);
        amax = std::max(amax, t.second);
    }
    amin = std::floor(amin - 1.0);
    amax = std::ceil(amax + 1.0);
    const int w = W - ml - mr, h = Hh - mt - mb;
    auto X = [&](double x) { return ml + static_cast<int>(std::lround((x - xmin) / (xmax - xmin) * w)); };
    auto Y = [&](double a) { return mt + h - static_cast<int>(std::lround((a - amin) / (amax - amin) * h)); };
    const cv::Scalar black(0, 0, 0), grid(225, 225, 225), cTruth(40, 150, 40), cFit(200, 90, 20),
        cMeas(40, 40, 220);
    char title[200];
    std::snprintf(title, sizeof title,
                  "alpha(y): pole %.1f m %s of the path, psi %.0f, phi %.0f deg, %.0f m/s; fitted psi %.2f, phi %.1f deg%s",
                  std::fabs(k.offset), k.offset > 0 ? "left" : "right", k.psi, k.phi_v, k.speed,
                  r.res.psi_cdeg / 100.0, r.res.phi_cdeg / 100.0,
                  r.res.quality == SL_TILT_AMBIGUOUS ? " (AMBIGUOUS)" : ""); // straight path: odometry = vehicle frame
    cv::putText(img, title, {10, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.5, black, 1, cv::LINE_AA);
    cv::putText(img, "truth (green), measured per rotation (red; hollow: read as the fold's mirror), "
                     "fitted curve (blue)",
                {10, 44}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1, cv::LINE_AA);
    for (int gx = -6; gx <= 6; ++gx) {
        cv::line(img, {X(gx), mt}, {X(gx), mt + h}, grid);
        cv::putText(img, std::to_string(gx), {X(gx) - 6, mt + h + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.4, black, 1, cv::LINE_AA);
    }
    const double step = (amax - amin) > 16 ? 4.0 : (amax - amin) > 8 ? 2.0 : 1.0;
    for (double ga = amin; ga <= amax + 1e-9; ga += step) {
        cv::line(img, {ml, Y(ga)}, {ml + w, Y(ga)}, grid);
        char t[16];
        std::snprintf(t, sizeof t, "%.0f", ga);
        cv::putText(img, t, {ml - 35, Y(ga) + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4, black, 1, cv::LINE_AA);
    }
    cv::rectangle(img, {ml, mt}, {ml + w, mt + h}, black);
    cv::putText(img, "y (m): radar along the path relative to the pole", {ml + w - 330, mt + h + 38},
                cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1, cv::LINE_AA);
    cv::putText(img, "alpha (deg)", {4, mt - 6}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1, cv::LINE_AA);
    std::vector<std::pair<double, double>> tr = d.truth;
    std::sort(tr.begin(), tr.end());
    for (size_t i = 1; i < tr.size(); ++i) {
        if (tr[i].first - tr[i - 1].first < 1.0) {
            cv::line(img, {X(tr[i - 1].first), Y(tr[i - 1].second)}, {X(tr[i].first), Y(tr[i].second)},
                     cTruth, 2, cv::LINE_AA);
        }
    }
    double ylo = 1e9, yhi = -1e9;
    for (const Pt &p : pts) {
        ylo = std::min(ylo, p.y);
        yhi = std::max(yhi, p.y);
    }
    for (int i = 1; i <= 200 && yhi > ylo; ++i) {
        const double y0 = ylo + (yhi - ylo) * (i - 1) / 200.0, y1 = ylo + (yhi - ylo) * i / 200.0;
        cv::line(img, {X(y0), Y(fit_at(y0))}, {X(y1), Y(fit_at(y1))}, cFit, 2, cv::LINE_AA);
    }
    for (const Pt &p : pts) {
        cv::circle(img, {X(p.y), Y(p.a)}, 4, cMeas, p.mirrored ? 1 : cv::FILLED, cv::LINE_AA);
        if (p.mirrored) {
            cv::circle(img, {X(p.y), Y(p.mirror)}, 4, cMeas, cv::FILLED, cv::LINE_AA);
            cv::line(img, {X(p.y), Y(p.a)}, {X(p.y), Y(p.mirror)}, cv::Scalar(170, 170, 240), 1, cv::LINE_AA);
        }
    }
    try {
        if (!cv::imwrite(png, img)) {
            err = "cannot write " + png;
            return false;
        }
    } catch (const cv::Exception &e) {
        err = e.what();
        return false;
    }
    return true;
}

void usage(FILE *out)
{
    std::fprintf(out,
                 "usage: sl-eval driveby [--board NAME] [--quick] [--realistic] [--power-scale] [--no-profile] [--cold]\n"
                 "                       [--speeds A,B,..]\n"
                 "                       [--check] [--check-separated] [--plot FILE.png] [--psi DEG] [--phi DEG]\n"
                 "                       [--offset M] [--dump] [--obs-log FILE] [--json] [--json-out FILE]\n"
                 "  Simulated drive-bys, one pole per pass, through the core pipeline with the pass's\n"
                 "  speed as motion input; the last FITTED 3D tilt of each pass against the truth.\n"
                 "  Default sweep: speeds 1, 2, 3 m/s; psi 3, 5, 10, 20 deg; phi every 45 deg; offsets\n"
                 "  2, 3, 4 m on both sides (--quick: 1 and 3 m/s, psi 5 and 15, phi every 90 deg, 3 m).\n"
                 "  --realistic: the sensor's output (8-bit log magnitude, noise floor, near-field\n"
                 "  leakage) with a smear tail and speckle drawn anew each rotation (without it:\n"
                 "  the paper's noise-free linear rendering).\n"
                 "  --no-profile: the pipeline's mask bounds with the board's d(r) instead of the\n"
                 "  range profiles (while moving: one rotation's rows of neighbouring azimuths).\n"
                 "  With --realistic, a calibration pass (an upright pole, its own seed) runs first\n"
                 "  and the tail slope its stream self-fitted is every pass's starting value, as a\n"
                 "  vehicle that has driven before has it saved (shadowleand --tail-slope);\n"
                 "  --cold: every pass starts with nothing calibrated.\n"
                 "  --power-scale (with --realistic): the CTS350-X's value scale (0.5 dB per value,\n"
                 "  exponential noise), the effects' values per bin kept (sl::scene_to_power_scale).\n"
                 "  --check: exit 1 unless every pole with psi >= 5 is FITTED within the issue's\n"
                 "  bounds (1 deg / 10 deg noise-free; 2 deg / 20 deg with --realistic).\n"
                 "  --check-separated: exit 1 unless every pole with psi >= 5 whose observations\n"
                 "  separate the mirror (separation >= 9) is answered (FITTED within the bounds, or\n"
                 "  AMBIGUOUS with the truth one of its two readings within them) and no pole with\n"
                 "  psi >= 5 is FITTED outside the bounds.\n"
                 "  --plot FILE.png: instead of the sweep, one pass (1 m/s, a pole 3 m left of the\n"
                 "  path leaning 15 deg away from it: beyond the fold) drawn as alpha(y): measured,\n"
                 "  fitted curve, truth.\n"
                 "  --psi DEG, --phi DEG, --offset M (signed, left +): only the passes of the sweep\n"
                 "  with that value (repeatable; each pass keeps its seed of the whole sweep).\n"
                 "  --dump: after each pass, detection's rejections, the tracker's and the rings'\n"
                 "  counters (why a pass has no track), the observations behind its result and the\n"
                 "  fit's interval readings of the fold (double precision), best first, and the\n"
                 "  mirror's separation at the truth (below 9 the observations cannot tell it).\n"
                 "  --obs-log FILE: every new fit of the pole's ring during each pass as one JSON line\n"
                 "  (the case, the observations the fit read as stored, the result).\n"
                 "  --json: print one JSON object (schema shadowlean-eval-driveby/1, docs/JSON_OUTPUTS.md)\n"
                 "  instead of the table; --json-out FILE: write it to FILE as well as the table.\n"
                 "  An AMBIGUOUS pass's row shows its other reading (other psi^, phi^) and which\n"
                 "  of the two holds the truth. The summary counts the passes answered (FITTED\n"
                 "  within the bounds, or AMBIGUOUS with the truth one of its readings), on all\n"
                 "  of them and on the ones whose observations separate the mirror, and the\n"
                 "  AMBIGUOUS passes whose observations could not tell the mirror from the truth\n"
                 "  even if every reading were exact (the separation: the smallest chi-square,\n"
                 "  with the stated sigmas, of a reading of the fold with a different answer, on\n"
                 "  the true pole's readings at the pass's bearings).\n");
}

} // namespace

int cmd_driveby(int argc, char **argv)
{
    std::string board = "paper-sim";
    bool quick = false, realistic = false, check = false, check_sep = false, cold = false;
    std::string plot;
    std::vector<double> speeds = {1.0, 2.0, 3.0};
    std::vector<double> only_psi, only_phi, only_off;
    bool dump = false, json = false;
    std::string obs_log_path, json_out;
    auto num = [](const char *s, double *v) {
        char *end = nullptr;
        *v = std::strtod(s, &end);
        return end != s && *end == '\0';
    };
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--board" && i + 1 < argc) {
            board = argv[++i];
        } else if (a == "--quick") {
            quick = true;
        } else if (a == "--realistic") {
            realistic = true;
        } else if (a == "--no-profile") {
            g_no_profile = true;
        } else if (a == "--cold") {
            cold = true;
        } else if (a == "--power-scale") {
            g_power_scale = true;
        } else if (a == "--check") {
            check = true;
        } else if (a == "--check-separated") {
            check_sep = true;
        } else if (a == "--plot" && i + 1 < argc) {
            plot = argv[++i];
        } else if (a == "--obs-log" && i + 1 < argc) {
            obs_log_path = argv[++i];
        } else if (a == "--json") {
            json = true;
        } else if (a == "--json-out" && i + 1 < argc) {
            json_out = argv[++i];
        } else if (a == "--dump") {
            dump = true;
        } else if (a == "--quiet" || a == "-q") {
            // accepted as by every sl-eval command; a sweep prints no progress to silence
        } else if ((a == "--psi" || a == "--phi" || a == "--offset") && i + 1 < argc) {
            double v = 0;
            if (!num(argv[++i], &v)) {
                return sl_cli_bad_value("sl-eval", a.c_str(), "must be a number", usage);
            }
            (a == "--psi" ? only_psi : a == "--phi" ? only_phi : only_off).push_back(v);
        } else if (a == "--speeds" && i + 1 < argc) {
            speeds.clear();
            for (const char *s = argv[++i]; *s != '\0';) {
                char *end = nullptr;
                const double v = std::strtod(s, &end);
                if (end == s || v <= 0.0) {
                    return sl_cli_bad_value("sl-eval", "--speeds", "must be positive numbers, comma separated", usage);
                }
                speeds.push_back(v);
                s = (*end == ',') ? end + 1 : end;
            }
        } else {
            return sl_cli_unknown("sl-eval", argv[i], usage);
        }
    }
    if (realistic && !g_no_profile && !cold) {
        // Calibration pass: an upright pole 2.5 m right of the path at 1 m/s, with a seed
        // no pass of the sweep uses; what its stream self-fitted is every pass's prior.
        const Case cal{1.0, 0.0, 0.0, -2.5};
        const Outcome c = run_case(board, cal, realistic, 100000);
        g_prior_slope_q8 = c.cal_n != 0U ? c.slope_q8 : 0U;
        if (!json) {
            std::printf("tail slope prior: %.2f values/bin, self-fitted %u times on a calibration pass "
                        "(an upright pole 2.5 m right of the path, its own seed; --cold: none)\n",
                        g_prior_slope_q8 / 256.0, static_cast<unsigned>(c.cal_n));
        }
        if (g_prior_slope_q8 == 0U) {
            std::fprintf(stderr, "sl-eval: driveby: the calibration pass fitted no tail slope\n");
            return 1;
        }
    }
    if (!plot.empty()) {
        const Case k{1.0, 15.0, 90.0, 3.0};
        PlotData d;
        const Outcome o = run_case(board, k, realistic, 1, &d);
        if (!d.have) {
            std::fprintf(stderr, "sl-eval: driveby --plot: the pass has no FITTED or AMBIGUOUS result\n");
            return 1;
        }
        std::string err;
        if (!plot_pass(plot, d, k, err)) {
            std::fprintf(stderr, "sl-eval: %s\n", err.c_str());
            return 1;
        }
        std::printf("driveby plot: %s (%s: psi %.2f deg, phi %.1f deg; truth 15, 90)\n", plot.c_str(),
                    quality_name(o.quality), o.psi, o.phi);
        return 0;
    }
    FILE *obs_log = nullptr;
    if (!obs_log_path.empty() && (obs_log = std::fopen(obs_log_path.c_str(), "w")) == nullptr) {
        std::fprintf(stderr, "sl-eval: cannot write %s\n", obs_log_path.c_str());
        return 1;
    }
    std::vector<double> psis = {3.0, 5.0, 10.0, 20.0}, offsets = {2.0, 3.0, 4.0};
    double phi_step = 45.0;
    if (quick) {
        if (speeds.size() == 3U) {
            speeds = {1.0, 3.0};
        }
        psis = {5.0, 15.0};
        offsets = {3.0};
        phi_step = 90.0;
    }
    const double psi_tol = realistic ? 2.0 : 1.0, phi_tol = realistic ? 20.0 : 10.0;
    FILE *const txt = json ? nullptr : stdout; // --json: the JSON object alone on stdout
    if (txt != nullptr) {
        std::fprintf(txt, "sl-eval driveby: board %s, %s, bounds for psi >= 5 deg: |psi err| <= %.1f deg, "
                          "|phi err| <= %.0f deg\n",
                     board.c_str(), realistic ? "smear + speckle" : "noise-free", psi_tol, phi_tol);
        std::fprintf(txt, "%5s %5s %6s %6s | %-9s %3s %6s %6s %7s %7s %7s | %6s %7s %s\n", "v", "psi", "phi",
                     "offset", "quality", "n", "psi^", "err", "phi^", "err", "off err", "other", "phi^",
                     "truth");
    }
    std::string jpasses; // --json / --json-out: one object per pass
    auto jnum = [](double x) {
        char b[48];
        if (!std::isfinite(x)) {
            return std::string("null");
        }
        std::snprintf(b, sizeof b, "%.4f", x);
        return std::string(b);
    };
    int n = 0, n_check = 0, n_ok = 0, n_fitted = 0, n_amb = 0;
    int amb5 = 0, amb5_insep = 0, ok_insep = 0; // psi >= 5: AMBIGUOUS; separation below 9
    // psi >= 5: answered (FITTED within, or AMBIGUOUS with the truth one of its readings);
    // the same on separated passes (separation >= 9); AMBIGUOUS with the truth as its best /
    // other reading; FITTED outside the bounds
    int n_ans = 0, n_sep = 0, n_sep_ans = 0, n_sep_fitted = 0, n_sep_amb = 0;
    int amb_best = 0, amb_other = 0, fitted_out = 0;
    double max_psi = 0, max_phi = 0, max_off = 0;
    int seed = 1;
    for (double v : speeds) {
        for (double psi : psis) {
            for (double phi = 0; phi < 360.0 - 1e-9; phi += phi_step) {
                for (double off : offsets) {
                    for (int side = -1; side <= 1; side += 2) {
                        const Case k{v, psi, phi, side * off};
                        auto picked = [](const std::vector<double> &only, double x) {
                            return only.empty() || std::any_of(only.begin(), only.end(), [x](double y) {
                                       return std::fabs(x - y) < 1e-6;
                                   });
                        };
                        const int pass_seed = seed++;
                        if (!picked(only_psi, psi) || !picked(only_phi, phi) || !picked(only_off, k.offset)) {
                            continue;
                        }
                        const Outcome o = run_case(board, k, realistic, pass_seed, nullptr, dump, obs_log);
                        ++n;
                        const double e_psi = o.psi - psi, e_phi = wrap180(o.phi - phi);
                        const double e_off = o.base_y - k.offset;
                        const char *q = quality_name(o.quality);
                        n_fitted += o.fitted ? 1 : 0;
                        n_amb += o.ambiguous ? 1 : 0;
                        bool ok = true;
                        auto within = [&](double p, double f) {
                            return std::fabs(p - psi) <= psi_tol && std::fabs(wrap180(f - phi)) <= phi_tol;
                        };
                        const bool best_in = (o.fitted || o.ambiguous) && within(o.psi, o.phi);
                        const bool other_in = !best_in && o.has_other && within(o.psi2, o.phi2);
                        const char *truth = !o.ambiguous ? "" : best_in ? "best" : other_in ? "other" : "neither";
                        if (psi >= 5.0) {
                            ++n_check;
                            ok = o.fitted && std::fabs(e_psi) <= psi_tol && std::fabs(e_phi) <= phi_tol;
                            n_ok += ok ? 1 : 0;
                            const bool answered = o.fitted ? best_in : (o.ambiguous && (best_in || other_in));
                            const bool sep = o.separation >= 9.0;
                            n_ans += answered ? 1 : 0;
                            n_sep += sep ? 1 : 0;
                            n_sep_ans += (sep && answered) ? 1 : 0;
                            n_sep_fitted += (sep && o.fitted) ? 1 : 0;
                            n_sep_amb += (sep && o.ambiguous) ? 1 : 0;
                            amb_best += (o.ambiguous && best_in) ? 1 : 0;
                            amb_other += (o.ambiguous && other_in) ? 1 : 0;
                            fitted_out += (o.fitted && !best_in) ? 1 : 0;
                            const bool insep = o.separation >= 0 && o.separation < 9.0;
                            amb5 += o.ambiguous ? 1 : 0;
                            amb5_insep += (o.ambiguous && insep) ? 1 : 0;
                            ok_insep += (ok && insep) ? 1 : 0;
                            if (o.fitted) {
                                max_psi = std::max(max_psi, std::fabs(e_psi));
                                max_phi = std::max(max_phi, std::fabs(e_phi));
                            }
                        }
                        if (o.fitted) {
                            max_off = std::max(max_off, std::fabs(e_off));
                        }
                        if (txt != nullptr) {
                            char other[64] = "      -       -";
                            if (o.has_other) {
                                std::snprintf(other, sizeof other, "%6.2f %7.1f", o.psi2, o.phi2);
                            }
                            std::fprintf(txt, "%5.1f %5.1f %6.0f %+6.1f | %-9s %3d %6.2f %+6.2f %7.1f %+7.1f %+7.2f | %s %s%s\n",
                                         v, psi, phi, k.offset, q, o.n_obs, o.psi, e_psi, o.phi, e_phi,
                                         e_off, other, *truth != '\0' ? truth : "-", ok ? "" : "  OUT");
                            std::fflush(txt);
                        }
                        if (json || !json_out.empty()) {
                            const bool est = o.fitted || o.ambiguous;
                            jpasses += std::string(jpasses.empty() ? "" : ",\n") + "    {\"speed_mps\": " + jnum(v) +
                                       ", \"psi_deg\": " + jnum(psi) + ", \"phi_deg\": " + jnum(phi) +
                                       ", \"offset_m\": " + jnum(k.offset) + ", \"quality\": \"" + quality_json(o.quality) +
                                       "\", \"observations\": " + std::to_string(o.n_obs) +
                                       ", \"psi_est_deg\": " + (est ? jnum(o.psi) : "null") +
                                       ", \"phi_est_deg\": " + (est ? jnum(o.phi) : "null") +
                                       ", \"psi_err_deg\": " + (est ? jnum(e_psi) : "null") +
                                       ", \"phi_err_deg\": " + (est ? jnum(e_phi) : "null") +
                                       ", \"offset_err_m\": " + (est ? jnum(e_off) : "null") +
                                       ", \"checked\": " + (psi >= 5.0 ? "true" : "false") +
                                       ", \"within_bounds\": " + (psi >= 5.0 && ok ? "true" : "false") +
                                       ", \"separation\": " +
                                       (o.separation < 0 ? "null" : jnum(std::min(o.separation, 1e9))) +
                                       ", \"psi_other_deg\": " + (o.has_other ? jnum(o.psi2) : "null") +
                                       ", \"phi_other_deg\": " + (o.has_other ? jnum(o.phi2) : "null") +
                                       ", \"truth_reading\": " + (o.ambiguous ? "\"" + std::string(truth) + "\"" : "null") + "}";
                        }
                    }
                }
            }
        }
    }
    if (txt != nullptr) {
        std::fprintf(txt, "driveby: %d passes, %d FITTED, %d AMBIGUOUS; psi >= 5: %d of %d within bounds; "
                          "max |err| of FITTED: psi %.2f deg, phi %.1f deg, offset %.2f m\n",
                     n, n_fitted, n_amb, n_ok, n_check, max_psi, max_phi, max_off);
        std::fprintf(txt, "driveby separation: psi >= 5: %d AMBIGUOUS, %d of them on observations whose "
                          "mirror's separation at the truth is below 9 (no 3-sigma rule tells it from the "
                          "truth); %d within bounds on such observations\n",
                     amb5, amb5_insep, ok_insep);
        std::fprintf(txt, "driveby answered: psi >= 5: %d of %d (FITTED within bounds, or AMBIGUOUS with the "
                          "truth one of its two readings within them); %d AMBIGUOUS: the truth is the best "
                          "reading in %d, the other in %d; %d FITTED outside the bounds\n",
                     n_ans, n_check, amb5, amb_best, amb_other, fitted_out);
        std::fprintf(txt, "driveby separated: psi >= 5 and separation >= 9: %d passes, %d answered; %d ended "
                          "FITTED, %d AMBIGUOUS\n",
                     n_sep, n_sep_ans, n_sep_fitted, n_sep_amb);
    }
    if (json || !json_out.empty()) {
        const std::string doc =
            std::string("{\n  \"schema\": \"shadowlean-eval-driveby/1\",\n  \"experiment\": \"driveby\",\n") +
            "  \"board\": \"" + board + "\",\n  \"condition\": \"" + (realistic ? "realistic" : "noise-free") +
            "\",\n  \"value_scale\": \"" + (g_power_scale ? "power" : "linear") + "\",\n  \"extraction\": \"" +
            (g_no_profile ? "mask" : "profile") + "\",\n  \"quick\": " + (quick ? "true" : "false") +
            ",\n  \"tail_slope_prior\": " + jnum(g_prior_slope_q8 / 256.0) + ",\n  \"bounds\": {\"psi_deg\": " +
            jnum(psi_tol) + ", \"phi_deg\": " + jnum(phi_tol) + "},\n  \"summary\": {\"passes\": " +
            std::to_string(n) + ", \"fitted\": " + std::to_string(n_fitted) + ", \"ambiguous\": " +
            std::to_string(n_amb) + ", \"checked\": " + std::to_string(n_check) + ", \"within_bounds\": " +
            std::to_string(n_ok) + ", \"max_abs_err_psi_deg\": " + jnum(max_psi) +
            ", \"max_abs_err_phi_deg\": " + jnum(max_phi) + ", \"max_abs_err_offset_m\": " + jnum(max_off) +
            ", \"ambiguous_checked\": " + std::to_string(amb5) + ", \"ambiguous_inseparable\": " +
            std::to_string(amb5_insep) + ", \"within_bounds_inseparable\": " + std::to_string(ok_insep) +
            ", \"answered\": " + std::to_string(n_ans) + ", \"ambiguous_truth_best\": " + std::to_string(amb_best) +
            ", \"ambiguous_truth_other\": " + std::to_string(amb_other) + ", \"fitted_outside\": " +
            std::to_string(fitted_out) + ", \"separated\": " + std::to_string(n_sep) +
            ", \"separated_answered\": " + std::to_string(n_sep_ans) + ", \"separated_fitted\": " +
            std::to_string(n_sep_fitted) + ", \"separated_ambiguous\": " + std::to_string(n_sep_amb) +
            "},\n  \"passes\": [\n" + jpasses + "\n  ]\n}\n";
        if (json) {
            std::fputs(doc.c_str(), stdout);
        }
        if (!json_out.empty()) {
            FILE *f = std::fopen(json_out.c_str(), "w");
            if (f == nullptr || std::fputs(doc.c_str(), f) < 0 || std::fclose(f) != 0) {
                std::fprintf(stderr, "sl-eval: cannot write %s\n", json_out.c_str());
                return 1;
            }
        }
    }
    if (obs_log != nullptr) {
        std::fclose(obs_log);
    }
    if (check_sep && (n_sep_ans != n_sep || fitted_out != 0)) {
        return 1;
    }
    return (check && n_ok != n_check) ? 1 : 0;
}
