// SPDX-License-Identifier: MIT
// sl-calib response: the radar's range response and noise floor measured from a capture by
// the core's own learner (sl_response.h), row by row over every rotation.
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "calib_cmds.h"
#include "calib_ini.h"
#include "oxford.h"
#include "sl_board_spec.h"
#include "sl_progress.h"
#include "view_frames.h"

extern "C" {
#include "shadowlean/sl_response.h"
#include "shadowlean/sl_scan.h"
}

namespace sl::calib {

namespace {

// Drop in the scale's values (counts) for a drop in log2 Q8.
double drop_counts(const sl_vscale_t &s, uint16_t drop_q8)
{
    if (s.kind == SL_VSCALE_LOG2) {
        return drop_q8 / 256.0 * (s.cpo_q8 / 256.0);
    }
    return drop_q8 / 256.0 * 3.0103; // a linear scale: report dB
}

// The [response] block of the vehicle's calibration file (calib_ini.h).
std::string ini_block(const sl_response_t &r, const std::string &source)
{
    std::string o = "; The radar's range response: the drop below a point return's centre at\n"
                    "; offsets -" + std::to_string(SL_CFG_RESP_HALF) + "..+" +
                    std::to_string(SL_CFG_RESP_HALF) + " bins, in 1/256 octave of power.\n"
                    "[response]\ntool = " + sl::calib_tool_version() + "\ndate = " + sl::calib_utc_date() +
                    "\nsource = " + source + "\npeaks = " + std::to_string(r.learn_n) +
                    "\ndrops_q8 =";
    for (int i = 0; i < SL_RESP_TAPS; i++) { // continuation lines: inih's 200-character limit
        o += (i > 0 && i % 12 == 0 ? "\n   " : "") + std::string(" ") +
             std::to_string(r.drop_q8[i]) + (i + 1 < SL_RESP_TAPS ? "," : "");
    }
    return o + "\n";
}

} // namespace

int cmd_response(const ResponseArgs &a)
{
    BoardSpec board;
    try {
        board = load_board(a.board);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "sl-calib: %s\n", e.what());
        return 1;
    }
    sl_vscale_t scale{};
    scale.kind = a.linear ? (uint8_t)SL_VSCALE_LINEAR : (uint8_t)SL_VSCALE_LOG2;
    scale.cpo_q8 = (uint16_t)std::lround(a.values_per_octave * 256.0);
    sl_response_cfg_t cfg;
    sl_response_cfg_default(&cfg);
    cfg.min_peaks = 1;
    sl_response_t r;
    if (sl_response_init(&r, &scale, nullptr, &cfg) != SL_OK) {
        std::fprintf(stderr, "sl-calib: response: bad value scale\n");
        return 2;
    }
    FrameOptions fo;
    fo.azimuths = board.azimuths;
    fo.encoder_size = board.encoder_size;
    fo.roi_bins = SL_CFG_ROI_BINS;
    fo.bin_size_m = a.bin_size_m;
    std::string err;
    Progress progress("sl-calib", a.quiet);
    progress.update(0, 1, "reading the capture");
    uint32_t rows = 0;
    auto learn = [&](const uint8_t *row, int bins, double b) {
        const int min_bin = (int)std::ceil(a.min_range_m / b);
        const int max_bin = std::min(bins, (int)std::floor(a.max_range_m / b));
        if (max_bin <= min_bin + 2 * (SL_CFG_RESP_HALF + 32)) {
            return;
        }
        (void)sl_response_learn_row(&r, row, (uint32_t)bins, (uint32_t)min_bin, (uint32_t)max_bin);
        rows++;
    };
    struct stat st {};
    const bool is_dir = ::stat(a.input.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
    if (is_dir) {
        // An Oxford folder: whole rows (the PNG's 11 columns of metadata, then every bin), so
        // the far range a capture's region of interest leaves out is read too.
        const std::vector<std::string> files = oxford_list_pngs(a.input, err);
        if (files.empty()) {
            std::fprintf(stderr, "sl-calib: %s\n", err.c_str());
            return 1;
        }
        const double b = a.bin_size_m > 0 ? a.bin_size_m : board.bin_size_m;
        for (const std::string &f : files) {
            const cv::Mat m = cv::imread(f, cv::IMREAD_GRAYSCALE);
            if (m.empty() || m.cols < 12 + 2 * SL_CFG_RESP_HALF) {
                std::fprintf(stderr, "sl-calib: %s: not an Oxford radar PNG\n", f.c_str());
                return 1;
            }
            for (int az = 0; az < m.rows; az++) {
                learn(m.ptr<uint8_t>(az) + 11, m.cols - 11, b);
            }
        }
    } else {
        FrameSet fs;
        const bool ok = for_each_frame(a.input, fo, fs, [&](RadarFrame &f, const FrameSet &meta) {
            const double b = meta.bin_size_m > 0 ? meta.bin_size_m : board.bin_size_m;
            const int bins = std::min(f.widest_row, f.power.cols);
            for (int az = 0; az < f.power.rows; az++) {
                if (f.flags[(size_t)az] & SL_SCAN_AZ_VALID) {
                    learn(f.power.ptr<uint8_t>(az), bins, b);
                }
            }
            return true;
        }, err);
        if (!ok) {
            std::fprintf(stderr, "sl-calib: %s\n", err.c_str());
            return 1;
        }
    }
    progress.finish();
    const bool adopted = sl_response_update(&r);
    uint16_t prior[SL_RESP_TAPS];
    sl_response_prior_cts350x(prior);
    std::printf("sl-calib response: %s: %u rows, %u isolated peaks (%u with a rival), %s\n",
                a.input.c_str(), rows, r.stats.peaks, r.stats.rivals,
                adopted || r.source == SL_RESPONSE_LEARNED ? "learned"
                : r.learn_n == 0                          ? "no peak: nothing learned"
                                                          : "implausible: not adopted");
    std::printf("half-power width %.2f bins, speckle correlation length %.2f bins\n",
                sl_response_hpw_q8(&r) / 256.0, r.ncorr_q8 / 256.0);
    const char *unit = a.linear ? "dB" : "values";
    std::printf("offset  measured drop (%s)  CTS350-X prior  difference\n", unit);
    int bad = 0;
    for (int o = -SL_CFG_RESP_HALF; o <= SL_CFG_RESP_HALF; o++) {
        const int i = o + SL_CFG_RESP_HALF;
        const double got = drop_counts(scale, r.drop_q8[i]);
        const double want = drop_counts(scale, prior[i]);
        const bool checked = a.max_diff >= 0 && want <= a.down_to;
        const bool off = checked && std::fabs(got - want) > a.max_diff;
        bad += off ? 1 : 0;
        std::printf("%+6d  %10.2f          %10.2f   %+8.2f%s\n", o, got, want, got - want,
                    off ? "  <- beyond the tolerance" : "");
    }
    std::printf("floor (mean noise power) per %d-bin band, %s above the scale's zero:\n",
                SL_RESP_FLOOR_BAND, unit);
    for (uint32_t band = 0; band < SL_CFG_RESP_FLOOR_BANDS; band++) {
        const int32_t lp = sl_response_floor_lp(&r, band * SL_RESP_FLOOR_BAND);
        if (lp != INT32_MIN) {
            std::printf("  bins %4u-%4u  %6.1f\n", band * SL_RESP_FLOOR_BAND,
                        (band + 1) * SL_RESP_FLOOR_BAND - 1,
                        a.linear ? lp / 256.0 * 3.0103 : lp / 256.0 * scale.cpo_q8 / 256.0);
        }
    }
    if (!a.out_ini.empty() && r.source == SL_RESPONSE_LEARNED) {
        std::string why;
        if (!sl::write_calib_block(a.out_ini, "response", ini_block(r, a.input), "[response]", &why)) {
            std::fprintf(stderr, "sl-calib: %s\n", why.c_str());
            return 1;
        }
    } else if (!a.out_ini.empty()) {
        std::fprintf(stderr, "sl-calib: response: too few isolated peaks (%u of %u) or an "
                             "implausible shape: %s not written\n",
                     r.learn_n, r.cfg.min_peaks, a.out_ini.c_str());
    }
    if (r.learn_n == 0) {
        std::fprintf(stderr, "sl-calib: response: no isolated strong return in %s\n",
                     a.input.c_str());
        return 1;
    }
    if (bad > 0) {
        std::fprintf(stderr,
                     "sl-calib: response: %d offsets differ from the prior by more than %.2f "
                     "%s (down to %.1f)\n",
                     bad, a.max_diff, unit, a.down_to);
        return 1;
    }
    return 0;
}

} // namespace sl::calib
