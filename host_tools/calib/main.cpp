// SPDX-License-Identifier: MIT
// sl-calib: calibration of a board from recorded (or simulated) radar data.
//
//   sl-calib shadow CAPTURE|OXFORD_DIR --board NAME [--out-ini FILE] [--png FILE] [--csv FILE]
//        [--bin-size-m M] [--height-m M] [--az-window N] [--search-max-m M]
//        [--edge foot|half] [--ground-window-m M]
//     The chassis shadow per azimuth from many rotations: near-field band, inner edge and
//     dark core of the ring, ground start; theta(az) = asin(H / ground start) (slant), i.e.
//     atan(H / R) with R the horizontal radius. Sectors without a clean shadow are reported
//     as unusable, never given a theta. --out-ini writes the [calib] fragment
//     (host_tools/calib/README.md), --png the comparison with the board's geometric theta,
//     --csv every per-azimuth number.
//
//   sl-calib elongation CAPTURE... --truth FILE [--truth FILE ...] [--board NAME]
//        [--out-ini FILE] [--png FILE] [--csv FILE] [--points N] [--mask-frames N]
//        [--threshold T] [--bin-size-m M]
//     The elongation bias d = r2_observed - r2_true (paper Sec. V-B: a target at many known
//     distances) as a table over the observed r2 (the core looks d up at the half-bin r2),
//     with its spread; --out-ini writes the board line `elongation = r:d, ...` under
//     [detect]. Truth: a list CSV (capture,range_m[,r2_m]) or one sl-sim truth CSV per
//     capture (README.md). Without --board: paper-bench (the paper's calibration set-up).
//
//   sl-calib response CAPTURE|OXFORD_DIR --board NAME [--out-ini FILE] [--min-m M] [--max-m M]
//        [--bin-size-m M] [--linear | --values-per-octave V] [--max-diff X [--down-to Y]]
//     The radar's range response and noise floor, measured by the core's learner
//     (sl_response.h) over every row from --min-m to --max-m (default 5-100 m; an Oxford folder
//     is read row by row in full, a capture as far as its region of interest): isolated strong returns,
//     the running median of their drop per offset; printed against the built-in CTS350-X
//     lobe; --out-ini writes it as an INI [response] section (drops_q8: the 41 values
//     sl_response_set() takes); --max-diff exits 1 when an offset
//     whose prior drop is at most --down-to values differs by more.
//
// Exit status: 0 done, 1 error (I/O, bad data), 2 usage.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>

#include "calib_cmds.h"
#include "sl_cli.h"

namespace {

void usage(FILE *out)
{
    std::fputs(
        "usage:\n"
        "  sl-calib shadow CAPTURE|OXFORD_DIR --board NAME [--out-ini FILE] [--png FILE]\n"
        "      [--csv FILE] [--bin-size-m M] [--height-m M] [--az-window N]\n"
        "      [--search-max-m M] [--edge foot|half] [--ground-window-m M]\n"
        "  sl-calib elongation CAPTURE... --truth FILE [--truth FILE...] [--board NAME]\n"
        "      [--out-ini FILE] [--png FILE] [--csv FILE] [--points N] [--mask-frames N]\n"
        "      [--threshold T] [--bin-size-m M]      (default board: paper-bench)\n"
        "  sl-calib response CAPTURE|OXFORD_DIR --board NAME [--out-ini FILE] [--min-m M]\n"
        "      [--max-m M] [--bin-size-m M] [--linear | --values-per-octave V]\n"
        "      [--max-diff VALUES [--down-to VALUES]]\n"
        "  Each takes -q/--quiet: no progress on stderr (shown only when it is a terminal).\n",
        out);
}

// An argument no branch took: a value option with a missing or bad value, or unknown.
int bad_arg(const std::string &o, bool has, const char *arg,
            std::initializer_list<const char *> with_value)
{
    for (const char *known : with_value) {
        if (o == known) {
            return sl_cli_bad_value("sl-calib", known, has ? "bad value" : "needs a value", usage);
        }
    }
    return sl_cli_unknown("sl-calib", arg, usage);
}

bool num(const char *s, double &v)
{
    char *e = nullptr;
    v = std::strtod(s, &e);
    return e != s && *e == '\0';
}

} // namespace

int main(int argc, char **argv)
{
    // --help/--version at top level (argv[1]) and after a subcommand (its own arguments).
    const int info = sl_cli_info(argc < 2 ? argc : 2, argv, "sl-calib", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    if (argc < 2) {
        return sl_cli_usage_error("sl-calib", "missing command (shadow, elongation or response)",
                                  usage);
    }
    const std::string cmd = argv[1];
    if (cmd == "shadow" || cmd == "elongation" || cmd == "response") {
        const int sub = sl_cli_info(argc - 1, argv + 1, "sl-calib", usage);
        if (sub != SL_CLI_CONTINUE) {
            return sub;
        }
    }
    if (cmd == "shadow") {
        sl::calib::ShadowArgs a;
        for (int i = 2; i < argc; i++) {
            const std::string o = argv[i];
            const bool has = i + 1 < argc;
            double v = 0;
            if (o == "--quiet" || o == "-q") {
                a.quiet = true;
            } else if (o == "--board" && has) {
                a.board = argv[++i];
            } else if (o == "--out-ini" && has) {
                a.out_ini = argv[++i];
            } else if (o == "--png" && has) {
                a.png = argv[++i];
            } else if (o == "--csv" && has) {
                a.csv = argv[++i];
            } else if (o == "--bin-size-m" && has && num(argv[i + 1], v) && v > 0) {
                a.bin_size_m = v;
                i++;
            } else if (o == "--height-m" && has && num(argv[i + 1], v) && v > 0) {
                a.height_m = v;
                i++;
            } else if (o == "--az-window" && has && num(argv[i + 1], v) && v >= 0 && v <= 20) {
                a.opt.az_half_window = static_cast<int>(v);
                i++;
            } else if (o == "--search-max-m" && has && num(argv[i + 1], v) && v > 1) {
                a.opt.search_max_m = v;
                i++;
            } else if (o == "--edge" && has && (std::strcmp(argv[i + 1], "foot") == 0 ||
                                                 std::strcmp(argv[i + 1], "half") == 0)) {
                a.opt.edge_half_rise = std::strcmp(argv[++i], "half") == 0;
            } else if (o == "--ground-window-m" && has && num(argv[i + 1], v) && v > 0) {
                a.opt.ground_window_m = v;
                i++;
            } else if ((o[0] != '-' || o == "-") && a.input.empty()) {
                a.input = o;
            } else {
                return bad_arg(o, has, argv[i],
                               {"--board", "--out-ini", "--png", "--csv", "--bin-size-m",
                                "--height-m", "--az-window", "--search-max-m", "--edge",
                                "--ground-window-m"});
            }
        }
        if (a.input.empty()) {
            return sl_cli_usage_error("sl-calib", "shadow: missing CAPTURE|OXFORD_DIR", usage);
        }
        if (a.board.empty()) {
            return sl_cli_usage_error("sl-calib", "shadow: missing --board NAME", usage);
        }
        return sl::calib::cmd_shadow(a);
    }
    if (cmd == "response") {
        sl::calib::ResponseArgs a;
        for (int i = 2; i < argc; i++) {
            const std::string o = argv[i];
            const bool has = i + 1 < argc;
            double v = 0;
            if (o == "--quiet" || o == "-q") {
                a.quiet = true;
            } else if (o == "--board" && has) {
                a.board = argv[++i];
            } else if (o == "--out-ini" && has) {
                a.out_ini = argv[++i];
            } else if (o == "--linear") {
                a.linear = true;
            } else if (o == "--bin-size-m" && has && num(argv[i + 1], v) && v > 0) {
                a.bin_size_m = v;
                i++;
            } else if (o == "--min-m" && has && num(argv[i + 1], v) && v >= 0) {
                a.min_range_m = v;
                i++;
            } else if (o == "--max-m" && has && num(argv[i + 1], v) && v > 0) {
                a.max_range_m = v;
                i++;
            } else if (o == "--values-per-octave" && has && num(argv[i + 1], v) && v >= 1 &&
                       v <= 16) {
                a.values_per_octave = v;
                i++;
            } else if (o == "--max-diff" && has && num(argv[i + 1], v) && v >= 0) {
                a.max_diff = v;
                i++;
            } else if (o == "--down-to" && has && num(argv[i + 1], v) && v > 0) {
                a.down_to = v;
                i++;
            } else if ((o[0] != '-' || o == "-") && a.input.empty()) {
                a.input = o;
            } else {
                return bad_arg(o, has, argv[i],
                               {"--board", "--out-ini", "--bin-size-m", "--min-m", "--max-m",
                                "--values-per-octave", "--max-diff", "--down-to"});
            }
        }
        if (a.input.empty()) {
            return sl_cli_usage_error("sl-calib", "response: missing CAPTURE|OXFORD_DIR", usage);
        }
        if (a.board.empty()) {
            return sl_cli_usage_error("sl-calib", "response: missing --board NAME", usage);
        }
        return sl::calib::cmd_response(a);
    }
#ifdef SL_CALIB_ELONG
    if (cmd == "elongation") {
        sl::calib::ElongArgs a;
        for (int i = 2; i < argc; i++) {
            const std::string o = argv[i];
            const bool has = i + 1 < argc;
            double v = 0;
            if (o == "--quiet" || o == "-q") {
                a.quiet = true;
            } else if (o == "--board" && has) {
                a.board = argv[++i];
            } else if (o == "--truth" && has) {
                a.truth.push_back(argv[++i]);
            } else if (o == "--out-ini" && has) {
                a.out_ini = argv[++i];
            } else if (o == "--png" && has) {
                a.png = argv[++i];
            } else if (o == "--csv" && has) {
                a.csv = argv[++i];
            } else if (o == "--bin-size-m" && has && num(argv[i + 1], v) && v > 0) {
                a.bin_size_m = v;
                i++;
            } else if (o == "--points" && has && num(argv[i + 1], v) && v >= 1 && v <= 16) {
                a.points = static_cast<int>(v);
                i++;
            } else if (o == "--mask-frames" && has && num(argv[i + 1], v) && v >= 1 && v <= 32) {
                a.mask_frames = static_cast<int>(v);
                i++;
            } else if (o == "--threshold" && has && num(argv[i + 1], v) && v >= 0 && v <= 255) {
                a.threshold = static_cast<int>(v);
                i++;
            } else if (o[0] != '-' || o == "-") {
                a.captures.push_back(o);
            } else {
                return bad_arg(o, has, argv[i],
                               {"--board", "--truth", "--out-ini", "--png", "--csv", "--bin-size-m",
                                "--points", "--mask-frames", "--threshold"});
            }
        }
        if (a.captures.empty()) {
            return sl_cli_usage_error("sl-calib", "elongation: missing CAPTURE", usage);
        }
        if (a.truth.empty()) {
            return sl_cli_usage_error("sl-calib", "elongation: missing --truth FILE", usage);
        }
        if (a.board.empty()) {
            a.board = "paper-bench";
        }
        return sl::calib::cmd_elongation(a);
    }
#endif
    return sl_cli_unknown("sl-calib", argv[1], usage);
}
