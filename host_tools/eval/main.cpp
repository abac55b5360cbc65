// SPDX-License-Identifier: MIT
// sl-eval: runs the core decoder and the core estimator on simulated captures and compares
// with the ground truth. Until the detection pipeline lands, bounds come from a bounding box
// on the pole's ground-truth azimuth ("bbox extraction (detection pipeline not used)").
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <string>

#include "capture.h"
#include "driveby.h"
#include "model_eval.h"
#include "sim_eval.h"
#include "sl_cli.h"
#include "sl_progress.h"
#include "sim_render.h"
#include "terrain.h"

namespace {

void usage(FILE *out)
{
    std::fprintf(out,
                 "usage:\n"
                 "  sl-eval table1 [--rotations N] [--quick] [--json] [--json-out FILE] [--plot FILE.png]\n"
                 "                [--threads N] [--range-bins N] [--extract bbox|pipeline|both]\n"
                 "      The six conditions of the paper's Table I at -10/0/+10 deg, the paper's\n"
                 "      numbers beside ours, then the same captures with our improvements.\n"
                 "      --extract bbox (default): bounding box on the true azimuth (paper columns);\n"
                 "      pipeline: only the core pipeline (sl_pipeline: mask + detection + corrections +\n"
                 "      alpha; n_eff from motion) on the real-resolution captures; both: the two.\n"
                 "  sl-eval realistic [--quick] [--json] [--json-out FILE] [--positions N] [--reps N] [--frames N]\n"
                 "                   [--calib N] [--range-bins N] [--threads N] [--extract bbox|pipeline|both]\n"
                 "                   [--pipe-last N] [--smear-decay DB] [--speckle-per-frame] [--no-profile]\n"
                 "                   [--cold | --r2-offset MM] [--hard] [--hard-set NAME=VALUE]... [--power-scale]\n"
                 "      Smear, speckle, noise floor, leakage, measured emission, n-frame\n"
                 "      segmentation, poles at 2.2-2.6 m: beside the paper's Table II.\n"
                 "      --extract pipeline|both: also the core pipeline (board paper-bench, speed 0, the\n"
                 "      board's n) on every measurement: targets of the last N rotations (default 4).\n"
                 "      --smear-decay DB: exponential smear decay per bin (default 3.3); --speckle-per-frame:\n"
                 "      speckle drawn anew every frame (default frozen); --no-profile: the pipeline's mask\n"
                 "      bounds with the board's d(r) instead of the range-profile bounds; --frames N is\n"
                 "      also the pipeline's window n. The pipeline first runs the --calib N vertical\n"
                 "      calibration poles (own seeds) as one radar's stream; the walk-end offset of r2 its\n"
                 "      range profile learns there is every measurement's prior (--cold: none;\n"
                 "      --r2-offset MM: this one, as shadowleand --r2-offset, no calibration pass).\n"
                 "      --power-scale: rendered on the CTS350-X's value scale (0.5 dB per value, the noise\n"
                 "      exponential in power; output.log_quantity = power) with the effects' dB halved, so\n"
                 "      their values per bin are the same (also sl-eval driveby --realistic --power-scale).\n"
                 "      --hard: the harder condition (issue 11): two-component smear (fast_decay_db 3.3 dB/bin\n"
                 "      plus a slow_decay_db 1.5 dB/bin component at slow_db -15 dB; both amp_decay_db 0.5 dB/bin\n"
                 "      slower per 20 dB of level), a one-bin front skirt at front_db -6 dB; speckle_frame_db 1 dB\n"
                 "      per-frame speckle on the frozen 2 dB; az_jitter_deg +-0.1 deg per azimuth; a segmented\n"
                 "      pole (segment_fill_m 0.02 m reflectors every segment_m 0.06 m, segment_gap 0.1 between);\n"
                 "      per measurement the true installation off the board (theta_tol_deg +-0.3, beta_tol_deg\n"
                 "      +-0.2, height_tol_m +-0.01) and the pole as placed by hand (bearing_tol_deg +-0.45 off\n"
                 "      the azimuth, refl_tol_db +-3 dB return), uniform draws; the processing uses the nominal\n"
                 "      board; calibration poles (own seeds) at 1.75-2.15 and 2.65-3.0 m only. Prints mean, std,\n"
                 "      median and p90 of the error, missed and ambiguous rates per angle and path.\n"
                 "      --hard-set NAME=VALUE (implies --hard): one of those parameters, by the name above.\n"
                 "  sl-eval run CAPTURE.colossus GT.csv [--board NAME] [--scene SCENE.ini]\n"
                 "             [--threshold T] [--beta DEG] [--raw|--half-bin] [--r1-add M] [--d M]\n"
                 "             [--extract bbox|pipeline|fit|model] [--beam-deg DEG] [--speed M/S]\n"
                 "             [--no-width-radius]\n"
                 "             [--calibration FILE] [--looks N] [--prior]\n"
                 "      Evaluates one capture made by sl-sim against its ground truth (raw or pcap, streamed;\n"
                 "      - = stdin). --extract pipeline: the core pipeline (beam, threshold and speed from\n"
                 "      --scene, or the options); --calibration: on the board's calibrated view (a vehicle's\n"
                 "      INI or blob). --extract fit: the pipeline with its bounds from the fit of the sensor\n"
                 "      model to each target's range profile (cfg.fit; the range response in use: the\n"
                 "      board's prior, the calibration's, or learned). --extract model: the forward model of the return (the core's sensor\n"
                 "      model learned from the capture's rows beyond the poles, or the CTS350-X prior with\n"
                 "      --prior) fitted per pole and azimuth over the rotations summed (--looks: independent\n"
                 "      speckle looks in the sum, default 1: frozen); the value scale from --scene.\n"
                 "  sl-eval driveby [--board NAME] [--quick] [--realistic] [--power-scale] [--no-profile]\n"
                 "                  [--speeds A,B] [--check]\n"
                 "                  [--plot FILE.png] [--psi DEG] [--phi DEG] [--offset M] [--dump]\n"
                 "                  [--obs-log FILE] [--cold] [--json] [--json-out FILE]\n"
                 "      3D tilt (psi, phi, base offset) fitted over simulated drive-bys against the truth.\n"
                 "      Noise-free passes render no smear: the board's elongation table d(r) is not applied.\n"
                 "      --realistic: the tail slope self-fitted on a calibration pass first (--cold: none).\n"
                 "      --psi/--phi/--offset (repeatable): only those passes of the sweep; --dump: per pass\n"
                 "      the rejection counters, the observations behind the result and the fold's\n"
                 "      interval readings and the mirror's separation at the truth; --obs-log: every fit\n"
                 "      of the pass as one JSON line.\n"
                 "  sl-eval terrain SCENE.ini... [--rotations N] [--warmup N] [--front M] [--threads N] [--json]\n"
                 "      The ground from the shadow's edge (attitude, height, DROP/STEP, distance of the\n"
                 "      first warning of a drop-off ahead) against the scene's terrain and attitude\n"
                 "      (sl-eval terrain --help).\n"
                 "Progress goes to stderr when it is a terminal; -q/--quiet silences it.\n");
}

// The last argument of table1/realistic: a value option without its value, or unknown.
int bad_arg(const std::string &a, int i, int argc, char **argv)
{
    static const char *const with_value[] = {"--rotations", "--range-bins", "--json-out", "--plot",
                                             "--threads", "--extract", "--positions", "--reps",
                                             "--calib", "--frames", "--smear-decay", "--pipe-last", "--hard-set"};
    for (const char *o : with_value) {
        if (a == o && i + 1 >= argc) {
            return sl_cli_bad_value("sl-eval", o, "needs a value", usage);
        }
    }
    return sl_cli_unknown("sl-eval", argv[i], usage);
}

bool write_text(const std::string &path, const std::string &text)
{
    std::FILE *f = std::fopen(path.c_str(), "w");
    if (f == nullptr || std::fputs(text.c_str(), f) < 0 || std::fclose(f) != 0) {
        std::fprintf(stderr, "sl-eval: cannot write %s\n", path.c_str());
        return false;
    }
    return true;
}

int cmd_table1(int argc, char **argv)
{
    sl::Table1Options o;
    o.progress = sl::progress_wanted(false); // only when stderr is a terminal
    bool json = false;
    std::string plot, json_out;
    for (int i = 0; i < argc; i++) {
        const std::string a = argv[i];
        if (a == "--rotations" && i + 1 < argc) {
            o.rotations = std::atoi(argv[++i]);
        } else if (a == "--quick") {
            o.rotations = 40;
        } else if (a == "--range-bins" && i + 1 < argc) {
            o.range_bins = std::atoi(argv[++i]);
        } else if (a == "--json") {
            json = true;
        } else if (a == "--json-out" && i + 1 < argc) {
            json_out = argv[++i];
        } else if (a == "--plot" && i + 1 < argc) {
            plot = argv[++i];
        } else if (a == "--threads" && i + 1 < argc) {
            o.threads = std::atoi(argv[++i]);
        } else if (a == "--quiet" || a == "-q") {
            o.progress = false;
        } else if (a == "--extract" && i + 1 < argc) {
            const std::string m = argv[++i];
            if (m == "bbox") {
                o.extract = sl::Extract::BBox;
                o.bbox_table = true;
            } else if (m == "pipeline") {
                o.extract = sl::Extract::Pipeline;
                o.bbox_table = false;
            } else if (m == "both") {
                o.extract = sl::Extract::Pipeline;
                o.bbox_table = true;
            } else {
                return sl_cli_bad_value("sl-eval", "--extract", "must be bbox, pipeline or both", usage);
            }
        } else {
            return bad_arg(a, i, argc, argv);
        }
    }
    if (o.extract == sl::Extract::Pipeline && !o.bbox_table) {
        o.captures &= ~1U; // the ideal capture (2 mm bins) cannot go through the board's pipeline
    }
    const sl::Table1Result r = sl::run_table1(o);
    if (!json_out.empty() && !write_text(json_out, sl::table1_json(r))) {
        return 1;
    }
    if (json) {
        std::fputs(sl::table1_json(r).c_str(), stdout);
    } else {
        sl::print_table1(stdout, r);
    }
    if (!plot.empty()) {
        std::string err;
        if (!sl::plot_table1(plot, r, err)) {
            std::fprintf(stderr, "sl-eval: %s\n", err.c_str());
            return 1;
        }
        std::fprintf(stderr, "sl-eval: wrote %s\n", plot.c_str());
    }
    return 0;
}

int cmd_realistic(int argc, char **argv)
{
    sl::RealisticOptions o;
    o.progress = sl::progress_wanted(false);
    bool json = false;
    std::string json_out;
    for (int i = 0; i < argc; i++) {
        const std::string a = argv[i];
        if (a == "--quick") {
            o.positions = 3;
            o.reps = 2;
            o.calib_positions = 6;
        } else if (a == "--positions" && i + 1 < argc) {
            o.positions = std::atoi(argv[++i]);
        } else if (a == "--reps" && i + 1 < argc) {
            o.reps = std::atoi(argv[++i]);
        } else if (a == "--calib" && i + 1 < argc) {
            o.calib_positions = std::atoi(argv[++i]);
        } else if (a == "--range-bins" && i + 1 < argc) {
            o.range_bins = std::atoi(argv[++i]);
        } else if (a == "--frames" && i + 1 < argc) {
            o.frames = std::atoi(argv[++i]);
        } else if (a == "--threads" && i + 1 < argc) {
            o.threads = std::atoi(argv[++i]);
        } else if (a == "--json") {
            json = true;
        } else if (a == "--json-out" && i + 1 < argc) {
            json_out = argv[++i];
        } else if (a == "--quiet" || a == "-q") {
            o.progress = false;
        } else if (a == "--smear-decay" && i + 1 < argc) {
            o.smear_decay_db = std::atof(argv[++i]);
        } else if (a == "--hard") {
            o.hard = true;
        } else if (a == "--hard-set" && i + 1 < argc) {
            const std::string kv = argv[++i];
            const size_t eq = kv.find('=');
            char *end = nullptr;
            const double v = eq == std::string::npos ? 0.0 : std::strtod(kv.c_str() + eq + 1, &end);
            if (eq == std::string::npos || end == nullptr || *end != '\0' ||
                !o.hard_cond.set(kv.substr(0, eq), v)) {
                return sl_cli_bad_value("sl-eval", "--hard-set", "must be NAME=VALUE with a known name in range (see usage)", usage);
            }
            o.hard = true;
        } else if (a == "--speckle-per-frame") {
            o.speckle_static = 0;
        } else if (a == "--power-scale") {
            o.power_scale = true;
        } else if (a == "--no-profile") {
            o.pipe_profile = false;
        } else if (a == "--cold") {
            o.cold = true;
        } else if (a == "--r2-offset" && i + 1 < argc) {
            char *end = nullptr;
            const double mm = std::strtod(argv[++i], &end);
            if (end == argv[i] || *end != '\0' || !(mm >= -100.0 && mm <= 100.0)) {
                return sl_cli_bad_value("sl-eval", "--r2-offset", "must be -100 .. +100 mm", usage);
            }
            o.have_r2_offset = true;
            o.r2_offset_um = static_cast<int32_t>(std::lround(mm * 1000.0));
        } else if (a == "--pipe-last" && i + 1 < argc) {
            { const int n = std::atoi(argv[++i]); o.pipe_last = n > 0 ? n : 1; }
        } else if (a == "--extract" && i + 1 < argc) {
            const std::string m = argv[++i];
            if (m == "bbox") {
                o.extract = sl::Extract::BBox;
                o.bbox_table = true;
            } else if (m == "pipeline") {
                o.extract = sl::Extract::Pipeline;
                o.bbox_table = false;
            } else if (m == "both") {
                o.extract = sl::Extract::Pipeline;
                o.bbox_table = true;
            } else {
                return sl_cli_bad_value("sl-eval", "--extract", "must be bbox, pipeline or both", usage);
            }
        } else {
            return bad_arg(a, i, argc, argv);
        }
    }
    if (o.hard && o.hard_cond.segment_m > 0 && o.hard_cond.segment_fill_m > o.hard_cond.segment_m) {
        return sl_cli_bad_value("sl-eval", "--hard-set", "segment_fill_m must not exceed segment_m", usage);
    }
    const sl::RealisticResult r = sl::run_realistic(o);
    if (!json_out.empty() && !write_text(json_out, sl::realistic_json(r))) {
        return 1;
    }
    if (json) {
        std::fputs(sl::realistic_json(r).c_str(), stdout);
    } else {
        sl::print_realistic(stdout, r);
    }
    return 0;
}

// Streams CAPTURE (raw or pcap/pcapng; a pipe, FIFO or "-" too) to `on_data`, with
// `on_break` at each gap or new TCP session (capture.h read_capture: bounded memory).
bool stream_file(const std::string &path, const sl::CaptureDataFn &on_data, const sl::CaptureBreakFn &on_break)
{
    sl::Capture info;
    uint64_t bytes = 0;
    std::string err;
    if (!sl::read_capture(path, on_data, on_break, info, bytes, err)) {
        std::fprintf(stderr, "sl-eval: %s\n", err.c_str());
        return false;
    }
    if (!info.discontinuities.empty()) {
        std::fprintf(stderr, "sl-eval: %s: %zu discontinuities (gaps or new TCP sessions) in the stream\n",
                     path.c_str(), info.discontinuities.size());
    }
    return true;
}

int cmd_run(int argc, char **argv)
{
    std::string cap, gtp, board, scene_path, calibration;
    double threshold = -1, beta = 0, r1_add = 0, d = 0;
    sl::Proc::Bounds bounds = sl::Proc::Bounds::HalfBin;
    bool pipeline = false, model = false, no_width_radius = false, model_learn = true, fit = false;
    double beam_deg = -1, speed = -1, looks = 1;
    for (int i = 0; i < argc; i++) {
        const std::string a = argv[i];
        bool missing = false;
        auto next = [&]() -> std::string {
            if (i + 1 < argc) {
                return argv[++i];
            }
            missing = true;
            return "";
        };
        if (a == "--extract") {
            const std::string m = next();
            if (missing) {
                return sl_cli_bad_value("sl-eval", "--extract", "needs a value", usage);
            }
            if (m != "pipeline" && m != "bbox" && m != "model" && m != "fit") {
                return sl_cli_bad_value("sl-eval", "--extract",
                                        "must be bbox, pipeline, fit or model", usage);
            }
            pipeline = m == "pipeline" || m == "fit";
            fit = m == "fit";
            model = m == "model";
        } else if (a == "--looks") {
            looks = std::atof(next().c_str());
            if (!missing && !(looks >= 1 && looks <= 255)) {
                return sl_cli_bad_value("sl-eval", "--looks", "must be in [1, 255]", usage);
            }
        } else if (a == "--prior") {
            model_learn = false;
        } else if (a == "--beam-deg") {
            beam_deg = std::atof(next().c_str());
        } else if (a == "--speed") {
            speed = std::atof(next().c_str());
        } else if (a == "--no-width-radius") {
            no_width_radius = true;
        } else if (a == "--board") {
            board = next();
        } else if (a == "--calibration") {
            calibration = next();
        } else if (a == "--scene") {
            scene_path = next();
        } else if (a == "--threshold") {
            threshold = std::atof(next().c_str());
        } else if (a == "--beta") {
            beta = std::atof(next().c_str());
        } else if (a == "--r1-add") {
            r1_add = std::atof(next().c_str());
        } else if (a == "--d") {
            d = std::atof(next().c_str());
        } else if (a == "--raw") {
            bounds = sl::Proc::Bounds::Raw;
        } else if (a == "--half-bin") {
            bounds = sl::Proc::Bounds::HalfBin;
        } else if (!a.empty() && (a[0] != '-' || a == "-") && cap.empty()) {
            cap = a;
        } else if (!a.empty() && a[0] != '-' && gtp.empty()) {
            gtp = a;
        } else {
            return sl_cli_unknown("sl-eval", argv[i], usage);
        }
        if (missing) {
            return sl_cli_bad_value("sl-eval", a.c_str(), "needs a value", usage);
        }
    }
    if (cap.empty() || gtp.empty()) {
        return sl_cli_usage_error("sl-eval", "run needs CAPTURE and GT.csv", usage);
    }
    std::vector<sl::GtRow> gt;
    std::string err;
    if (!sl::gt_read(gtp, gt, err)) {
        std::fprintf(stderr, "sl-eval: %s\n", err.c_str());
        return 1;
    }
    sl::BoardSpec b;
    if (!scene_path.empty()) {
        b = sl::load_scene(scene_path).board;
    } else {
        b = sl::load_board(board.empty() ? "paper-sim" : board);
    }
    if (model) {
        // The value scale of the capture: its scene's output mapping (linear energy, or
        // round(c log10 N) of a power or a magnitude), the CTS350-X's without a scene.
        sl::ModelEvalOptions mo;
        mo.scale = sl_vscale_t{(uint8_t)SL_VSCALE_LOG2, 1541U};
        if (!scene_path.empty()) {
            mo.scale = sl::scene_value_scale(sl::load_scene(scene_path));
        }
        mo.looks = looks;
        mo.learn = model_learn;
        sl::ModelEval me(gt, b.bin_size_m, mo);
        sl::CaptureRows rows([&](int rot, int az, const uint8_t *v, uint32_t n) { me.row(rot, az, v, n); });
        if (!stream_file(
                cap,
                [&](const uint8_t *data, size_t n) {
                    rows.feed(data, n);
                    return true;
                },
                [&](const sl::Discontinuity &) { rows.finish(); })) {
            return 1;
        }
        rows.finish();
        std::string note;
        const auto res = me.finish(note);
        std::printf("model extraction: the forward model of the return fitted per pole and azimuth "
                    "(rotations summed, %.0f look%s); %s\n", looks, looks == 1 ? "" : "s",
                    note.c_str());
        sl::print_model_eval(stdout, res);
        return 0;
    }
    if (pipeline) {
        sl::PipeCfg pc;
        if (!scene_path.empty()) {
            pc = sl::pipe_cfg_for_scene(sl::load_scene(scene_path));
        } else {
            pc.board = b.name;
        }
        pc.calibration = calibration; // the vehicle's calibration (INI or blob), if any
        pc.fit = fit;
        if (beam_deg > 0) {
            pc.beam_deg = beam_deg;
        }
        if (speed >= 0) {
            pc.speed_mps = speed;
        }
        if (threshold >= 0) {
            pc.threshold = static_cast<int>(threshold);
        }
        if (no_width_radius) {
            pc.radius_from_width = 0;
        }
        sl::PipelineEval pe(pc);
        for (const auto &g : gt) {
            if (g.nominal == 1 && g.valid == 1) {
                pe.add_truth(g);
            }
        }
        // The pipeline decodes the bytes itself and resynchronises after a gap.
        if (!stream_file(
                cap,
                [&](const uint8_t *data, size_t n) {
                    pe.feed(0, data, n);
                    return true;
                },
                nullptr)) {
            return 1;
        }
        pe.finish();
        const auto res = pe.result();
        std::printf("%s\n", sl::kPipelineLabel);
        std::printf("capture %s: board %s, speed %.3f m/s, beam %.2f deg, threshold %d%s\n", cap.c_str(),
                    pc.board.c_str(), pc.speed_mps, pc.beam_deg, pc.threshold,
                    no_width_radius ? ", radius_from_width off" : "");
        for (const auto &kv : res) {
            const sl::PipeEval &e = kv.second;
            std::printf("pole %d: rotations %d, truth rows %d, detected %d (rate %.1f%%), n_eff %d-%d, targets %d "
                        "(unmatched %d), ambiguous %d, invalid %d: error mean %.3f std %.3f rmse %.3f max %.3f deg\n",
                        kv.first, e.rotations, e.truth_rows, e.detected, 100.0 * e.rate(), e.frames_eff_min,
                        e.frames_eff_max, e.targets, e.unmatched, e.err.ambiguous, e.err.invalid, e.err.mean,
                        e.err.std, e.err.rmse, e.err.maxabs);
        }
        return 0;
    }
    std::map<std::pair<int, int>, const sl::GtRow *> want;
    for (const auto &g : gt) {
        if (g.nominal == 1 && g.valid == 1) {
            want[{g.rotation, g.azimuth}] = &g;
        }
    }
    std::map<int, sl::ErrStats> per_pole;
    sl::Proc proc;
    proc.bounds = bounds;
    proc.beta_model_deg = beta;
    proc.r1_add_m = r1_add;
    proc.d_const_m = d;
    double bin = b.bin_size_m;
    sl::CaptureRows dec([&](int rot, int az, const uint8_t *v, uint32_t n) {
        auto it = want.find({rot, az});
        if (it == want.end()) {
            return;
        }
        const sl::GtRow &g = *it->second;
        std::vector<double> dv(v, v + n);
        const int ground_bin = static_cast<int>(std::floor(b.radar_height_m / std::sin(g.theta_deg * 3.14159265358979 / 180) / bin));
        const int lo = std::max(0, static_cast<int>(std::floor(std::min(g.r1_surf_m - 0.5, b.near_exclusion_m) / bin)));
        const sl::Est e = sl::estimate_row(dv.data(), static_cast<int>(n), g, b,
                                           threshold >= 0 ? threshold : 1.0, lo,
                                           d > 0 ? ground_bin + static_cast<int>(1.5 / bin) : ground_bin - 1,
                                           proc, nullptr);
        per_pole[g.pole].add(e, g.alpha_deg);
    });
    if (!stream_file(
            cap,
            [&](const uint8_t *data, size_t n) {
                dec.feed(data, n);
                return true;
            },
            [&](const sl::Discontinuity &) { dec.finish(); })) {
        return 1;
    }
    dec.finish();
    if (dec.have_config()) {
        bin = dec.bin_m();
    }
    std::printf("bbox extraction (detection pipeline not used); core decoder + core estimator\n");
    std::printf("capture %s: %u messages, %u FFT rows, %d rotations, bin %.4f m (config)\n",
                cap.c_str(), dec.stats().messages, dec.stats().fft8, dec.rotations_seen(), bin);
    for (auto &kv : per_pole) {
        kv.second.finish();
        std::printf("pole %d: rows %d, estimates %zu (missed %d, ambiguous %d, invalid %d): error mean %.3f std %.3f rmse %.3f max %.3f deg\n",
                    kv.first, kv.second.rows, kv.second.err.size(), kv.second.missed,
                    kv.second.ambiguous, kv.second.invalid, kv.second.mean, kv.second.std,
                    kv.second.rmse, kv.second.maxabs);
    }
    return 0;
}

} // namespace

int main(int argc, char **argv)
{
    // --help/--version at top level (argv[1]) and after a subcommand (its own arguments).
    const int info = sl_cli_info(argc < 2 ? argc : 2, argv, "sl-eval", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    if (argc < 2) {
        return sl_cli_usage_error("sl-eval", "missing command (table1, realistic or run)", usage);
    }
    const std::string cmd = argv[1];
    if (cmd == "table1" || cmd == "realistic" || cmd == "run" || cmd == "driveby" || cmd == "terrain") {
        const int sub = sl_cli_info(argc - 1, argv + 1, "sl-eval", usage);
        if (sub != SL_CLI_CONTINUE) {
            return sub;
        }
    }
    try {
        if (cmd == "table1") {
            return cmd_table1(argc - 2, argv + 2);
        }
        if (cmd == "realistic") {
            return cmd_realistic(argc - 2, argv + 2);
        }
        if (cmd == "run") {
            return cmd_run(argc - 2, argv + 2);
        }
        if (cmd == "driveby") {
            return cmd_driveby(argc - 2, argv + 2);
        }
        if (cmd == "terrain") {
            return cmd_terrain(argc - 2, argv + 2);
        }
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sl-eval: %s\n", e.what());
        return 1;
    }
    return sl_cli_unknown("sl-eval", argv[1], usage);
}
