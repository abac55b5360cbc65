// SPDX-License-Identifier: MIT
// sl-eval terrain: the ground from the shadow's edge (sl_ground.h) on simulated scenes with
// terrain and vehicle attitude, against the scene's truth.
#include "terrain.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_ground.h"
#include "shadowlean/sl_pipeline.h"
#include "sim_eval.h"
#include "sim_render.h"
#include "sim_scene.h"
#include "sl_cli.h"

namespace sl {
namespace {

void usage(FILE *out)
{
    std::fprintf(out,
                 "usage: sl-eval terrain SCENE.ini... [--rotations N] [--warmup N] [--front M]\n"
                 "                       [--threads N] [--json] [--json-out FILE] [--hazards]\n"
                 "  Runs the core pipeline with the ground module on each scene (the scene's\n"
                 "  speed as the motion input) and compares every rotation's plane and hazards\n"
                 "  with the scene's truth ([vehicle] pitch_deg, roll_deg, height_offset_m and\n"
                 "  the [terrain.*] pieces):\n"
                 "  - attitude: height, pitch and roll errors after --warmup rotations (default\n"
                 "    16): mean, max |error|, the share of rotations with quality GOOD;\n"
                 "  - hazards: a confirmed sector is true when the terrain along its bearing,\n"
                 "    from the radar to 1 m past its ring point, changes height by >= 5 cm the\n"
                 "    same way (DROP: down, STEP: up), else false; onsets of false hazards per\n"
                 "    hour of the scene's time; the detection rate of the terrain pieces the ring\n"
                 "    crossed;\n"
                 "  - drop-offs ahead (step pieces going down, crossing the path): the distance\n"
                 "    from the vehicle's front (--front M ahead of the radar; default the\n"
                 "    cylinder's radius, else 0) to the edge at the first DROP within 45 deg of\n"
                 "    forward, true and as reported.\n"
                 "  --rotations N: override the scene's; --json: one JSON object per scene;\n"
                 "  --json-out FILE: the same objects in one JSON document (schema\n"
                 "  shadowlean-eval-terrain/1, docs/JSON_OUTPUTS.md);\n"
                 "  --hazards: every hazard onset (rotation, sector, kind, residual, sigma,\n"
                 "  distance, true or false).\n"
                 "usage: sl-eval terrain --capture FILE [--board NAME] [--speed M/S]\n"
                 "  A raw capture (e.g. sl-replay from-oxford), board default robotcar-leaf: per\n"
                 "  rotation the plane (quality, sectors, height, pitch, roll with sigmas) and\n"
                 "  the confirmed hazards, then each sector's ground point; --speed: a constant\n"
                 "  motion input (default none).\n");
}

struct Hazard {
    int sector = 0, kind = 0;
};

// Does the terrain change along bearing (ux, uy) from the radar (ox, oy) to `len` m by at
// least `dz` m down (want < 0) or up (want > 0)?
bool terrain_change(const Scene &s, double ox, double oy, double ux, double uy, double len,
                    int want)
{
    const double z0 = scene_ground_z(s, ox, oy);
    for (double r = 0.02; r <= len; r += 0.02) {
        const double dz = scene_ground_z(s, ox + r * ux, oy + r * uy) - z0;
        if ((want < 0 && dz <= -0.05) || (want > 0 && dz >= 0.05)) {
            return true;
        }
    }
    return false;
}

struct SceneResult {
    std::string name;
    int rotations = 0, scored = 0, good = 0, planes = 0;
    double h_err_sum = 0, p_err_sum = 0, r_err_sum = 0;
    double h_err_max = 0, p_err_max = 0, r_err_max = 0;
    int true_onsets = 0, false_onsets = 0;
    int pieces = 0, pieces_found = 0;
    double hours = 0;
    bool drop_ahead = false, drop_warned = false;
    double drop_true_m = NAN, drop_reported_m = NAN;
    uint32_t samples = 0, occupied = 0, no_ground = 0, bad_edge = 0, short_rows = 0;
};

SceneResult run_scene(const std::string &path, int rotations, int warmup, double front_arg,
                      int threads, bool dump_hazards)
{
    Scene scene = load_scene(path);
    if (rotations > 0) {
        scene.rotations = rotations;
    }
    SceneResult res;
    res.name = path;
    const Simulator sim(scene);
    const PipeCfg pc = pipe_cfg_for_scene(scene);
    const sl_board_t *b = sl_board_find(pc.board.c_str());
    if (b == nullptr) {
        throw std::runtime_error("board " + pc.board + " is not linked in");
    }
    sl_pipeline_cfg_t cfg;
    sl_pipeline_cfg_default(&cfg, b);
    if (pc.beam_deg > 0) {
        cfg.detect.beam_width_cdeg = static_cast<uint16_t>(std::clamp(std::lround(pc.beam_deg * 100), 1L, 36000L));
    }
    if (pc.threshold >= 0) {
        cfg.threshold = static_cast<uint16_t>(pc.threshold);
    }
    if (pc.profile >= 0) {
        cfg.profile = pc.profile != 0;
    }
    cfg.ground = true;
    cfg.value_scale = scene_value_scale(scene);
    std::unique_ptr<sl_pipeline_t> p(new sl_pipeline_t());
    const sl_err_t e = sl_pipeline_init(p.get(), b, &cfg);
    if (e != SL_OK) {
        throw std::runtime_error(std::string("sl_pipeline_init: ") + sl_err_str(e));
    }
    const double front = front_arg >= 0 ? front_arg
                                        : (scene.board.chassis_type == "cylinder" ? scene.board.cylinder_radius_m : 0.0);
    const double H = scene.board.radar_height_m + scene.height_offset_m;
    const uint64_t period = static_cast<uint64_t>(std::llround(1e6 / scene.rotation_hz));
    const auto cfgmsg = sim.config_message();
    sl_pipeline_feed(p.get(), cfgmsg.data(), cfgmsg.size(), 1000000U);
    std::vector<int> prev_kind(SL_CFG_GROUND_SECTORS, SL_GROUND_FLAT);
    std::vector<bool> piece_found(scene.terrain.size(), false), piece_crossed(scene.terrain.size(), false);
    uint32_t done = 0;
    auto score = [&](int k) {
        const sl_ground_t &g = p->ground;
        const RadarPose pose = radar_pose_at(scene, (k + 1.0) / scene.rotation_hz);
        const double hd = sim_d2r(pose.heading_deg);
        const double fx = std::cos(hd), fy = std::sin(hd);
        res.rotations++;
        if (g.plane.quality != SL_GROUND_NONE) {
            res.planes++;
        }
        if (k >= warmup && g.plane.quality != SL_GROUND_NONE) {
            res.scored++;
            res.good += g.plane.quality == SL_GROUND_GOOD ? 1 : 0;
            const double eh = g.plane.height_mm * 1e-3 - H;
            const double ep = g.plane.pitch_cdeg * 0.01 - scene.pitch_deg;
            const double er = g.plane.roll_cdeg * 0.01 - scene.roll_deg;
            res.h_err_sum += eh;
            res.p_err_sum += ep;
            res.r_err_sum += er;
            res.h_err_max = std::max(res.h_err_max, std::fabs(eh));
            res.p_err_max = std::max(res.p_err_max, std::fabs(ep));
            res.r_err_max = std::max(res.r_err_max, std::fabs(er));
        }
        for (uint32_t s = 0; s < SL_CFG_GROUND_SECTORS; s++) {
            const sl_ground_sector_t &sec = g.sec[s];
            const int kind = sec.kind;
            const double cd = sl_ground_sector_cdeg(&g, s) * 0.01;
            // the sector's bearing in the world (vehicle frame: clockwise from forward)
            const double vx = std::cos(sim_d2r(cd)), vy = -std::sin(sim_d2r(cd));
            const double ux = vx * fx - vy * fy, uy = vx * fy + vy * fx;
            const double ring = sec.n > 0 ? std::hypot(sec.x_um, sec.y_um) * 1e-6 : H / std::tan(sim_d2r(scene.board.theta_deg(0)));
            for (size_t t = 0; t < scene.terrain.size(); t++) {
                Scene one = scene;
                one.terrain = {scene.terrain[t]};
                if (terrain_change(one, pose.o.x, pose.o.y, ux, uy, ring, -1) ||
                    terrain_change(one, pose.o.x, pose.o.y, ux, uy, ring, +1)) {
                    piece_crossed[t] = true;
                    if (kind != SL_GROUND_FLAT &&
                        terrain_change(one, pose.o.x, pose.o.y, ux, uy, ring + 1.0,
                                       kind == SL_GROUND_DROP ? -1 : +1)) {
                        piece_found[t] = true;
                    }
                }
            }
            if (kind != SL_GROUND_FLAT && prev_kind[s] != kind) {
                const bool ok = terrain_change(scene, pose.o.x, pose.o.y, ux, uy, ring + 1.0,
                                               kind == SL_GROUND_DROP ? -1 : +1);
                (ok ? res.true_onsets : res.false_onsets)++;
                if (dump_hazards) {
                    std::printf("  onset: rotation %d sector %u at %.1f deg %s residual %d mm sigma %u mm "
                                "distance %.2f m: %s\n",
                                k, s, cd, kind == SL_GROUND_DROP ? "DROP" : "STEP", sec.resid_mm, sec.sigma_mm,
                                sec.dist_um * 1e-6, ok ? "true" : "false");
                }
                // the first DROP ahead
                const double off = std::fabs(std::remainder(cd, 360.0));
                if (kind == SL_GROUND_DROP && ok && off <= 45.0 && !res.drop_warned) {
                    res.drop_warned = true;
                    res.drop_reported_m = sec.hx_um * 1e-6 - front;
                }
            }
            prev_kind[s] = kind;
        }
        // the true distance from the front to the nearest drop-off crossing the path ahead
        if (res.drop_warned && std::isnan(res.drop_true_m)) {
            double best = INFINITY;
            for (const auto &t : scene.terrain) {
                if (t.strip || t.height_m >= 0) {
                    continue;
                }
                const double a = sim_d2r(t.dir_deg);
                const double nx = std::cos(a), ny = std::sin(a);
                const double along = fx * nx + fy * ny;
                if (along <= 1e-6) {
                    continue;
                }
                const double dist = ((t.x_m - pose.o.x) * nx + (t.y_m - pose.o.y) * ny) / along;
                if (dist >= 0) {
                    best = std::min(best, dist - front);
                }
            }
            res.drop_true_m = best;
        }
    };
    for (const auto &t : scene.terrain) {
        res.drop_ahead = res.drop_ahead || (!t.strip && t.height_m < 0);
    }
    sim_run(sim, 0, scene.rotations, threads, [&](int k, std::vector<uint8_t> &bytes, std::vector<GtRow> &) {
        const uint64_t now = 1000000U + static_cast<uint64_t>(k) * period;
        sl_pipeline_set_motion(p.get(), static_cast<int32_t>(std::lround(scene.speed_mps * 1000)), true,
                               static_cast<int32_t>(std::lround(scene.yaw_rate_dps * 100)), true, now);
        sl_pipeline_feed(p.get(), bytes.data(), bytes.size(), now + period / 2);
        while (done < p->stats.rotations) {
            score(static_cast<int>(done));
            done++;
        }
    });
    for (size_t t = 0; t < scene.terrain.size(); t++) {
        if (piece_crossed[t]) {
            res.pieces++;
            res.pieces_found += piece_found[t] ? 1 : 0;
        }
    }
    res.hours = scene.rotations / scene.rotation_hz / 3600.0;
    const sl_ground_stats_t &st = p->ground.stats;
    res.samples = st.samples;
    res.occupied = st.occupied;
    res.no_ground = st.no_ground;
    res.bad_edge = st.bad_edge;
    res.short_rows = st.short_rows;
    return res;
}

// A JSON number, null when not finite.
std::string num(double v, int decimals)
{
    if (!std::isfinite(v)) {
        return "null";
    }
    char b[48];
    std::snprintf(b, sizeof b, "%.*f", decimals, v);
    return b;
}

double mean(double s, int n)
{
    return n > 0 ? s / n : NAN;
}

// A capture (a real radar's stream): the plane and the hazards per rotation, no truth.
int run_capture(const std::string &path, const std::string &board, double speed_mps)
{
    const sl_board_t *b = sl_board_find(board.c_str());
    if (b == nullptr) {
        throw std::runtime_error("board " + board + " is not linked in");
    }
    sl_pipeline_cfg_t cfg;
    sl_pipeline_cfg_default(&cfg, b);
    cfg.ground = true;
    std::unique_ptr<sl_pipeline_t> p(new sl_pipeline_t());
    if (sl_pipeline_init(p.get(), b, &cfg) != SL_OK) {
        throw std::runtime_error("sl_pipeline_init failed");
    }
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) {
        throw std::runtime_error("cannot open " + path);
    }
    std::vector<uint8_t> buf(65536);
    uint64_t now = 1000000U;
    uint32_t done = 0;
    std::printf("%s (board %s): rotation, quality, sectors, height mm (sigma), pitch deg (sigma), "
                "roll deg (sigma), hazards\n",
                path.c_str(), board.c_str());
    size_t n = 0;
    while ((n = std::fread(buf.data(), 1, buf.size(), f)) > 0) {
        if (speed_mps >= 0) {
            sl_pipeline_set_motion(p.get(), static_cast<int32_t>(std::lround(speed_mps * 1000)), true, 0, true,
                                   now);
        }
        sl_pipeline_feed(p.get(), buf.data(), n, now);
        now += 10000U;
        while (done < p->stats.rotations) {
            const sl_ground_t &g = p->ground;
            std::printf("  %u: %s %u %d (%u) %.2f (%.2f) %.2f (%.2f)", done,
                        g.plane.quality == SL_GROUND_GOOD ? "GOOD"
                                                          : (g.plane.quality == SL_GROUND_COARSE ? "COARSE" : "NONE"),
                        g.plane.sectors, g.plane.height_mm, g.plane.height_sigma_mm, g.plane.pitch_cdeg * 0.01,
                        g.plane.pitch_sigma_cdeg * 0.01, g.plane.roll_cdeg * 0.01, g.plane.roll_sigma_cdeg * 0.01);
            for (uint32_t s = 0; s < SL_CFG_GROUND_SECTORS; s++) {
                if (g.sec[s].kind != SL_GROUND_FLAT) {
                    std::printf(" %s@%.1fdeg:%dmm", g.sec[s].kind == SL_GROUND_DROP ? "DROP" : "STEP",
                                sl_ground_sector_cdeg(&g, s) * 0.01, g.sec[s].resid_mm);
                }
            }
            std::printf("\n");
            done++;
        }
    }
    std::fclose(f);
    sl_pipeline_finish(p.get(), now);
    const sl_ground_stats_t &st = p->ground.stats;
    std::printf("  edges: %u samples, %u occupied, %u no ground, %u bad, %u short; decay n %.2f\n", st.samples,
                st.occupied, st.no_ground, st.bad_edge, st.short_rows, p->ground.decay_q8 / 256.0);
    for (uint32_t s = 0; s < SL_CFG_GROUND_SECTORS; s++) {
        const sl_ground_sector_t &sec = p->ground.sec[s];
        std::printf("  sector %2u at %5.1f deg: n %u, ground point x %.2f y %.2f m, residual %d mm\n", s,
                    sl_ground_sector_cdeg(&p->ground, s) * 0.01, sec.n, sec.x_um * 1e-6, sec.y_um * 1e-6,
                    sec.resid_mm);
    }
    return 0;
}

} // namespace
} // namespace sl

int cmd_terrain(int argc, char **argv)
{
    using namespace sl;
    std::vector<std::string> scenes;
    int rotations = 0, warmup = 16, threads = 0;
    double front = -1;
    bool json = false, dump = false;
    std::string json_out;
    std::string capture, board = "robotcar-leaf";
    double speed = -1;
    for (int i = 0; i < argc; i++) {
        const std::string a = argv[i];
        const bool has = i + 1 < argc;
        if (a == "--rotations" && has) {
            rotations = std::atoi(argv[++i]);
        } else if (a == "--warmup" && has) {
            warmup = std::atoi(argv[++i]);
        } else if (a == "--front" && has) {
            front = std::atof(argv[++i]);
        } else if (a == "--threads" && has) {
            threads = std::atoi(argv[++i]);
        } else if (a == "--json") {
            json = true;
        } else if (a == "--json-out" && has) {
            json_out = argv[++i];
        } else if (a == "--hazards") {
            dump = true;
        } else if (a == "--capture" && has) {
            capture = argv[++i];
        } else if (a == "--board" && has) {
            board = argv[++i];
        } else if (a == "--speed" && has) {
            speed = std::atof(argv[++i]);
        } else if (a == "-q" || a == "--quiet") {
        } else if (!a.empty() && a[0] == '-') {
            return sl_cli_unknown("sl-eval terrain", argv[i], usage);
        } else {
            scenes.push_back(a);
        }
    }
    if (!capture.empty()) {
        return run_capture(capture, board, speed);
    }
    if (scenes.empty()) {
        return sl_cli_usage_error("sl-eval terrain", "no scene", usage);
    }
    std::vector<std::string> objs;
    for (const auto &path : scenes) {
        const SceneResult r = run_scene(path, rotations, warmup, front, threads, dump);
        const double fph = r.hours > 0 ? r.false_onsets / r.hours : NAN;
        {
            char line[2048];
            std::snprintf(line, sizeof line, "{\"scene\": \"%s\", \"rotations\": %d, \"scored\": %d, \"good\": %d, "
                        "\"height_err_mean_mm\": %s, \"height_err_max_mm\": %s, "
                        "\"pitch_err_mean_deg\": %s, \"pitch_err_max_deg\": %s, "
                        "\"roll_err_mean_deg\": %s, \"roll_err_max_deg\": %s, "
                        "\"true_hazard_onsets\": %d, \"false_hazard_onsets\": %d, \"false_per_hour\": %s, "
                        "\"terrain_pieces\": %d, \"terrain_pieces_found\": %d, "
                        "\"drop_warned\": %s, \"drop_true_m\": %s, \"drop_reported_m\": %s}\n",
                        r.name.substr(r.name.find_last_of('/') + 1).c_str(), r.rotations, r.scored, r.good, num(1e3 * mean(r.h_err_sum, r.scored), 1).c_str(),
                        num(1e3 * r.h_err_max, 1).c_str(), num(mean(r.p_err_sum, r.scored), 3).c_str(),
                        num(r.p_err_max, 3).c_str(), num(mean(r.r_err_sum, r.scored), 3).c_str(),
                        num(r.r_err_max, 3).c_str(), r.true_onsets, r.false_onsets, num(fph, 2).c_str(), r.pieces,
                        r.pieces_found, r.drop_warned ? "true" : "false", num(r.drop_true_m, 2).c_str(),
                        num(r.drop_reported_m, 2).c_str());
            objs.push_back(line);
            if (json) {
                std::printf("%s", line);
            }
        }
        if (json) {
            continue;
        }
        std::printf("%s: %d rotations, plane in %d, scored %d (GOOD %d)\n", r.name.c_str(), r.rotations,
                    r.planes, r.scored, r.good);
        std::printf("  height error: mean %+.1f mm, max |%.1f| mm\n", 1e3 * mean(r.h_err_sum, r.scored),
                    1e3 * r.h_err_max);
        std::printf("  pitch error: mean %+.3f deg, max |%.3f| deg; roll error: mean %+.3f deg, max |%.3f| deg\n",
                    mean(r.p_err_sum, r.scored), r.p_err_max, mean(r.r_err_sum, r.scored), r.r_err_max);
        std::printf("  hazard onsets: %d true, %d false (%.2f per hour); terrain pieces crossed by the ring: "
                    "%d, found %d\n",
                    r.true_onsets, r.false_onsets, fph, r.pieces, r.pieces_found);
        if (r.drop_ahead) {
            if (r.drop_warned) {
                std::printf("  drop-off ahead: first warned %.2f m before the front (reported %.2f m)\n",
                            r.drop_true_m, r.drop_reported_m);
            } else {
                std::printf("  drop-off ahead: not warned\n");
            }
        }
        std::printf("  edges: %u samples, %u occupied, %u no ground, %u bad, %u short\n", r.samples, r.occupied,
                    r.no_ground, r.bad_edge, r.short_rows);
    }
    if (!json_out.empty()) {
        std::FILE *o = std::fopen(json_out.c_str(), "w");
        if (o == nullptr) {
            std::fprintf(stderr, "sl-eval terrain: cannot write %s\n", json_out.c_str());
            return 1;
        }
        std::fprintf(o, "{\"schema\": \"shadowlean-eval-terrain/1\", \"experiment\": \"terrain\", \"scenes\": [\n");
        for (size_t i = 0; i < objs.size(); i++) {
            std::string l = objs[i];
            while (!l.empty() && l.back() == '\n') {
                l.pop_back();
            }
            std::fprintf(o, "  %s%s\n", l.c_str(), i + 1 < objs.size() ? "," : "");
        }
        std::fprintf(o, "]}\n");
        if (std::fclose(o) != 0) {
            return 1;
        }
    }
    return 0;
}
