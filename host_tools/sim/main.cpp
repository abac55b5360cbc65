// SPDX-License-Identifier: MIT
// sl-sim: simulate a scene (scenes/README.md) into a raw Colossus capture -- exactly the
// bytes a CTS350-X sends: one Configuration message, then one 8-bit FFT Data message per
// azimuth -- and a ground-truth CSV (one row per rotation, pole and azimuth it is seen on).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "sim_render.h"
#include "sl_cli.h"
#include "sl_progress.h"
#include "sim_scene.h"
#include "sim_truth.h"

namespace {

void usage(FILE *out)
{
    std::fprintf(out,
                 "usage: sl-sim SCENE.ini -o OUT.colossus [--gt OUT.csv] [--rotations N]\n"
                 "              [--first K] [--seed S] [--threads N] [--quiet]\n"
                 "  Simulates SCENE (format: scenes/README.md) into a raw Colossus capture and a\n"
                 "  ground-truth CSV (default: OUT with .gt.csv). --rotations/--seed override the\n"
                 "  scene's values; --threads 0 = all cores (default). Progress goes to stderr\n"
                 "  when it is a terminal; -q/--quiet silences it and the summary.\n");
}

} // namespace

int main(int argc, char **argv)
{
    std::string scene_path, out, gt_path;
    int rotations = -1, threads = 0, first = 0;
    long long seed = -1;
    bool quiet = false;
    const int info = sl_cli_info(argc, argv, "sl-sim", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::exit(sl_cli_bad_value("sl-sim", a.c_str(), "needs a value", usage));
            }
            return argv[++i];
        };
        if (a == "-o" || a == "--out") {
            out = next();
        } else if (a == "--gt") {
            gt_path = next();
        } else if (a == "--rotations") {
            rotations = std::atoi(next().c_str());
        } else if (a == "--first") {
            first = std::atoi(next().c_str());
        } else if (a == "--seed") {
            seed = std::atoll(next().c_str());
        } else if (a == "--threads") {
            threads = std::atoi(next().c_str());
        } else if (a == "--quiet" || a == "-q") {
            quiet = true;
        } else if (!a.empty() && a[0] == '-') {
            return sl_cli_unknown("sl-sim", argv[i], usage);
        } else if (scene_path.empty()) {
            scene_path = a;
        } else {
            return sl_cli_unknown("sl-sim", argv[i], usage);
        }
    }
    if (scene_path.empty()) {
        return sl_cli_usage_error("sl-sim", "missing SCENE.ini", usage);
    }
    if (out.empty()) {
        return sl_cli_usage_error("sl-sim", "missing -o OUT.colossus", usage);
    }
    if (gt_path.empty()) {
        gt_path = out;
        const auto dot = gt_path.rfind('.');
        if (dot != std::string::npos && gt_path.find('/', dot) == std::string::npos) {
            gt_path.resize(dot);
        }
        gt_path += ".gt.csv";
    }
    try {
        sl::Scene s = sl::load_scene(scene_path);
        if (rotations > 0) {
            s.rotations = rotations;
        }
        if (seed >= 0) {
            s.seed = static_cast<uint64_t>(seed);
        }
        if (first < 0) {
            first = 0;
        }
        const sl::Simulator sim(s);
        // Plain stdio (the capture library's writer pulls in libpcap; a raw capture is
        // just the bytes).
        std::FILE *wf = std::fopen(out.c_str(), "wb");
        if (wf == nullptr) {
            std::fprintf(stderr, "sl-sim: cannot write %s\n", out.c_str());
            return 1;
        }
        unsigned long long written = 0;
        auto write = [&](const uint8_t *d, size_t n) {
            written += n;
            return std::fwrite(d, 1, n, wf) == n;
        };
        std::FILE *gf = std::fopen(gt_path.c_str(), "w");
        if (gf == nullptr) {
            std::fprintf(stderr, "sl-sim: cannot write %s\n", gt_path.c_str());
            return 1;
        }
        sl::gt_write_header(gf);
        const auto cfg = sim.config_message();
        if (!write(cfg.data(), cfg.size())) {
            throw sl::SceneError("write error on " + out);
        }
        sl::Progress progress("sl-sim", quiet); // stderr, only on a terminal
        size_t gt_rows = 0;
        sl::sim_run(
            sim, first, s.rotations, threads,
            [&](int, std::vector<uint8_t> &bytes, std::vector<sl::GtRow> &gt) {
                if (!write(bytes.data(), bytes.size())) {
                    throw sl::SceneError("write error on " + out);
                }
                for (const auto &r : gt) {
                    sl::gt_write_row(gf, r);
                }
                gt_rows += gt.size();
            },
            [&](int done, int total) { progress.update(done, total, "rotation"); });
        progress.finish();
        std::fclose(gf);
        if (std::fclose(wf) != 0) {
            std::fprintf(stderr, "sl-sim: write error on %s\n", out.c_str());
            return 1;
        }
        if (!quiet) {
            std::fprintf(stderr, "sl-sim: wrote %s (%llu bytes, %d rotations x %d azimuths x %d bins) and %s (%zu rows)\n",
                         out.c_str(), written, s.rotations,
                         sim.azimuths(), sim.bins(), gt_path.c_str(), gt_rows);
        }
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sl-sim: %s\n", e.what());
        return 1;
    }
    return 0;
}
