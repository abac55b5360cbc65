// SPDX-License-Identifier: MIT
// sl-alpha: run the core's fixed-point inclination estimator (sl_incline_estimate) on lines
// of text.
//
//   sl-alpha [--sigma-r METRES] [--sigma-theta DEG] [--quiet] < lines
//
// Input: one case per line, four numbers separated by blanks:
//   r1_m r2_m theta_deg beta_deg
// (inner and outer bound of the pole's return in metres, opening angle theta and upper
// emission bound beta in degrees). Output: exactly one line per input line, in order:
//   - alpha in degrees with 3 decimals, i.e. the core's alpha_cdeg (0.01 deg, rounded half
//     up) written as d.dd0; > 0 = top leans towards the radar. With --sigma-r or
//     --sigma-theta a second column gives sigma_cdeg in degrees (2 decimals).
//   - `ambiguous` when r2/r1 is below the model's minimum 1/cos((theta+beta)/2);
//   - `invalid` for everything else: r1 <= 0, r1 >= r2, r2/r1 > 10, theta/beta outside the
//     core's supported domain (sl_incline.h), and lines that do not parse (not exactly four
//     finite numbers; an empty line is unparsable too).
// The geometry entry is built by sl::make_geom (the same code path as the board tables).
// The ranges are passed to the core in a unit of max(r1, r2) / 2^31 (the core uses only
// r2/r1 and sigma_r/r1), so the CLI adds at most 2^-31 relative error to the ratio.
//
// A summary goes to stderr at the end (suppressed by --quiet):
//   sl-alpha: N lines: V valid, A ambiguous, I invalid (U unparsable)
// Exit status: 0 when all input was read and all output written, whatever the lines held
// (invalid lines are counted, not errors); 1 on an I/O error on stdin or stdout;
// 2 on a usage error.
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sl_cli.h"
#include "sl_geom.h"
#include "shadowlean/sl_incline.h"

namespace {

void usage(std::FILE *f)
{
    std::fputs("usage: sl-alpha [--sigma-r METRES] [--sigma-theta DEG] [--quiet] < lines\n"
               "  each input line: r1_m r2_m theta_deg beta_deg\n"
               "  each output line: alpha_deg (3 decimals) [sigma_deg] | ambiguous | invalid\n",
               f);
}

bool parse_double(const std::string &s, double *out)
{
    if (s.empty()) {
        return false;
    }
    errno = 0;
    char *end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
        return false;
    }
    *out = v;
    return true;
}

bool parse_line(const std::string &line, double v[4])
{
    std::istringstream in(line);
    std::string tok;
    int n = 0;
    while (in >> tok) {
        if (n == 4 || !parse_double(tok, &v[n])) {
            return false;
        }
        n++;
    }
    return n == 4;
}

uint32_t to_units(double x, double scale)
{
    const double u = std::llround(x * scale);
    return (u >= 4294967295.0) ? UINT32_MAX : (u <= 0.0) ? 0U : static_cast<uint32_t>(u);
}

std::string fmt_cdeg(int32_t cdeg, bool trailing_zero)
{
    char buf[32];
    const int64_t a = cdeg < 0 ? -static_cast<int64_t>(cdeg) : cdeg;
    std::snprintf(buf, sizeof buf, "%s%lld.%02lld%s", cdeg < 0 ? "-" : "",
                  static_cast<long long>(a / 100), static_cast<long long>(a % 100),
                  trailing_zero ? "0" : "");
    return buf;
}

} // namespace

int main(int argc, char **argv)
{
    double sigma_r_m = 0.0;
    double sigma_theta_deg = 0.0;
    bool with_sigma = false;
    bool quiet = false;
    const int info = sl_cli_info(argc, argv, "sl-alpha", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        if (a == "--sigma-r" || a == "--sigma-theta") {
            double v = 0.0;
            if (i + 1 >= argc || !parse_double(argv[i + 1], &v) || v < 0.0) {
                return sl_cli_bad_value("sl-alpha", a.c_str(), "needs a non-negative number", usage);
            }
            (a == "--sigma-r" ? sigma_r_m : sigma_theta_deg) = v;
            with_sigma = true;
            i++;
        } else if (a == "--quiet" || a == "-q") {
            quiet = true;
        } else {
            return sl_cli_unknown("sl-alpha", argv[i], usage);
        }
    }
    const double st_cdeg = std::llround(sigma_theta_deg * 100.0);
    const uint16_t sigma_theta_cdeg =
        st_cdeg >= 65535.0 ? UINT16_MAX : static_cast<uint16_t>(st_cdeg);

    long lines = 0, valid = 0, ambiguous = 0, invalid = 0, unparsable = 0;
    std::string line;
    while (std::getline(std::cin, line)) {
        lines++;
        double v[4];
        std::string out = "invalid";
        if (!parse_line(line, v)) {
            unparsable++;
            invalid++;
        } else {
            sl_incline_result_t r{};
            r.flag = SL_INCLINE_INVALID;
            try {
                const sl_incline_geom_t g = sl::make_geom(v[2], v[3]);
                if (v[0] >= 0.0 && v[1] >= 0.0) {
                    const double top = std::fmax(v[0], v[1]);
                    const double scale = top > 0.0 ? 2147483648.0 / top : 0.0;
                    r = sl_incline_estimate(to_units(v[0], scale), to_units(v[1], scale), &g,
                                            to_units(sigma_r_m, scale), sigma_theta_cdeg);
                }
            } catch (const std::domain_error &) {
                // theta or beta not an angle: invalid
            }
            if (r.flag == SL_INCLINE_VALID) {
                valid++;
                out = fmt_cdeg(r.alpha_cdeg, true);
                if (with_sigma) {
                    out += " " + fmt_cdeg(r.sigma_cdeg, false);
                }
            } else if (r.flag == SL_INCLINE_AMBIGUOUS) {
                ambiguous++;
                out = "ambiguous";
            } else {
                invalid++;
            }
        }
        std::cout << out << '\n';
        if (!std::cout) {
            std::fprintf(stderr, "sl-alpha: write error on stdout\n");
            return 1;
        }
    }
    if (std::cin.bad()) {
        std::fprintf(stderr, "sl-alpha: read error on stdin\n");
        return 1;
    }
    std::cout.flush();
    if (!std::cout) {
        std::fprintf(stderr, "sl-alpha: write error on stdout\n");
        return 1;
    }
    if (!quiet) {
        std::fprintf(stderr, "sl-alpha: %ld lines: %ld valid, %ld ambiguous, %ld invalid (%ld unparsable)\n",
                     lines, valid, ambiguous, invalid, unparsable);
    }
    return 0;
}
