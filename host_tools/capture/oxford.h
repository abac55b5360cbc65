// SPDX-License-Identifier: MIT
// oxford.h: Oxford Radar RobotCar polar PNGs -> Colossus messages (host only, C++17).
//
// PNG layout (NAVTECH_PROTOCOL.md s.9): one 8-bit grey PNG per rotation, one row per
// azimuth; row bytes 0-7 = int64 little-endian UNIX microseconds, 8-9 = uint16 little-endian
// encoder azimuth, 10 = valid flag (255 = original reading, anything else = interpolated),
// 11.. = power per range bin (uint8). Read with OpenCV imread(IMREAD_UNCHANGED).
//
// Conversion: one Configuration message (id 10: azimuths = rows of the first PNG, range bins
// = width - 11, encoder size, bin size, rotation, packet rate; range gain 1.0, offset 0.0;
// protobuf: datawidth 1 and rangeresolutionmetres = the bin size), then one 8-bit FFT data
// message (id 30) per row, in file-name order then row order: the row's encoder azimuth,
// its timestamp as seconds + nanoseconds (little-endian on the wire), a sweep counter that
// starts at 0 and increments per row (wrapping at 65536), the row's bins. All bytes come from
// the core's encoders (sl_proto_encode_config / sl_proto_encode_fft8).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sl {

struct OxfordOptions {
    double bin_size_m = 0.0432;   ///< Oxford SDK value (boards/robotcar-leaf); written as round(m * 10000) in 0.1 mm units + protobuf
    uint16_t encoder_size = 5600;
    uint16_t rotation_mhz = 4000;
    uint16_t packet_rate = 1600;
};

struct OxfordReport {
    std::string png_dir;              ///< directory the PNGs were taken from
    uint32_t scans = 0;               ///< PNG files converted
    uint64_t rows = 0;                ///< FFT messages written
    uint64_t invalid_rows = 0;        ///< rows whose valid flag != 255 (still written)
    uint64_t azimuth_out_of_range = 0;///< rows whose azimuth >= encoder_size (still written)
    uint64_t time_not_increasing = 0; ///< rows whose timestamp <= the previous row's
    uint64_t negative_time = 0;       ///< rows with a timestamp < 0 (written as 0)
    uint32_t azimuths = 0;            ///< rows per PNG (from the first PNG)
    uint32_t range_bins = 0;          ///< width - 11
    uint16_t bin_size_100um = 0;
    int64_t first_time_us = 0, last_time_us = 0;
    uint64_t bytes = 0;               ///< capture size
};

/// The PNG files of an Oxford sequence: DIR/radar/*.png if that folder exists, else
/// DIR/*.png, sorted by file name. Empty (and `err` set) when there is none.
std::vector<std::string> oxford_list_pngs(const std::string &dir, std::string &err);

/// Converts every PNG of `dir` (see oxford_list_pngs) into a Colossus byte stream appended
/// to `out`. Fails (false + err) on an unreadable PNG, a PNG that is not 8-bit single
/// channel, a width < 12, or a PNG whose shape differs from the first one.
bool oxford_to_colossus(const std::string &dir, const OxfordOptions &opt,
                        std::vector<uint8_t> &out, OxfordReport &rep, std::string &err);

} // namespace sl
