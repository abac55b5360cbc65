// SPDX-License-Identifier: MIT
// calib_cmds.h: the subcommands of sl-calib (main.cpp parses the arguments).
#pragma once

#include <string>
#include <vector>

#include "calib_shadow.h"

namespace sl::calib {

struct ShadowArgs {
    std::string input;      ///< capture file or Oxford folder
    std::string board;
    std::string out_ini, png, csv;
    double bin_size_m = 0;  ///< > 0: override the capture's / board's bin size
    double height_m = 0;    ///< > 0: override the board's radar height
    ShadowCalibOptions opt; ///< estimator knobs (H and b are filled in)
    bool quiet = false;     ///< no progress on stderr (sl_progress.h)
};
int cmd_shadow(const ShadowArgs &a);

struct ElongArgs {
    std::vector<std::string> captures;
    std::vector<std::string> truth;   ///< one list file, or one sl-sim truth per capture
    std::string board;
    std::string out_ini, png, csv;
    double bin_size_m = 0;
    int points = 0;                   ///< table points (0 = automatic)
    int mask_frames = 0;              ///< consistency window (0 = board's, capped by frames)
    int threshold = -1;               ///< occupancy threshold (-1 = board's)
    bool quiet = false;               ///< no progress on stderr (sl_progress.h)
};
int cmd_elongation(const ElongArgs &a);

struct ResponseArgs {
    std::string input;              ///< capture file or Oxford folder
    std::string board;              ///< geometry for streams without a Configuration
    std::string out_ini;            ///< the measured drops as a [response] section
    double bin_size_m = 0;          ///< > 0: override the capture's / board's bin size
    double min_range_m = 5.0;       ///< peaks and floor from this range on (beyond the body)
    double max_range_m = 100.0;     ///< ... up to this range
    bool linear = false;            ///< the value scale: linear in power (else log2)
    double values_per_octave = 6.02; ///< log2 scale: values per octave of power
    double max_diff = -1;           ///< >= 0: exit 1 when an offset differs from the
    double down_to = 40;            ///< CTS350-X prior by more (down to this drop)
    bool quiet = false;
};
int cmd_response(const ResponseArgs &a);

} // namespace sl::calib
