// SPDX-License-Identifier: MIT
// oxford.cpp: Oxford polar PNG -> Colossus capture (see oxford.h).
#include "oxford.h"

#include "shadowlean/sl_proto.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <dirent.h>
#include <sys/stat.h>

namespace sl {

namespace {

bool is_dir(const std::string &p)
{
    struct stat st {};
    return stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

uint32_t f32_bits(float f)
{
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

bool ends_with_png(const std::string &n)
{
    if (n.size() < 5) return false;
    std::string e = n.substr(n.size() - 4);
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char ch) { return std::tolower(ch); });
    return e == ".png";
}

} // namespace

std::vector<std::string> oxford_list_pngs(const std::string &dir, std::string &err)
{
    std::string d = dir;
    if (is_dir(dir + "/radar")) {
        d = dir + "/radar";
    }
    std::vector<std::string> names;
    DIR *dp = opendir(d.c_str());
    if (dp == nullptr) {
        err = d + ": cannot open directory";
        return {};
    }
    while (const dirent *e = readdir(dp)) {
        const std::string n = e->d_name;
        if (n[0] != '.' && ends_with_png(n)) {
            names.push_back(n);
        }
    }
    closedir(dp);
    std::sort(names.begin(), names.end());
    std::vector<std::string> out;
    for (const auto &n : names) {
        out.push_back(d + "/" + n);
    }
    if (out.empty()) {
        err = d + ": no .png files";
    }
    return out;
}

bool oxford_to_colossus(const std::string &dir, const OxfordOptions &opt, std::vector<uint8_t> &out,
                        OxfordReport &rep, std::string &err)
{
    rep = OxfordReport{};
    const auto files = oxford_list_pngs(dir, err);
    if (files.empty()) {
        return false;
    }
    rep.png_dir = files.front().substr(0, files.front().rfind('/'));
    const double bs = std::round(opt.bin_size_m * 10000.0);
    if (!(bs >= 1.0 && bs <= 65535.0)) {
        err = "bin size out of range (0.0001 .. 6.5535 m)";
        return false;
    }
    rep.bin_size_100um = static_cast<uint16_t>(bs);

    std::vector<uint8_t> msg;
    uint16_t sweep = 0;
    bool have_prev = false;
    int64_t prev_t = 0;
    for (const auto &path : files) {
        const cv::Mat img = cv::imread(path, cv::IMREAD_UNCHANGED);
        if (img.empty()) {
            err = path + ": cannot read PNG";
            return false;
        }
        if (img.type() != CV_8UC1) {
            err = path + ": not an 8-bit single-channel PNG";
            return false;
        }
        if (img.cols < 12 || img.rows < 1 || img.rows > 65535 || img.cols - 11 > 65535) {
            err = path + ": unexpected shape " + std::to_string(img.rows) + "x" + std::to_string(img.cols);
            return false;
        }
        if (rep.scans == 0) {
            rep.azimuths = static_cast<uint32_t>(img.rows);
            rep.range_bins = static_cast<uint32_t>(img.cols - 11);
            sl_proto_config_t c{};
            c.azimuths = static_cast<uint16_t>(img.rows);
            c.bin_size_100um = rep.bin_size_100um;
            c.range_bins = static_cast<uint16_t>(rep.range_bins);
            c.encoder_size = opt.encoder_size;
            c.rotation_mhz = opt.rotation_mhz;
            c.packet_rate = opt.packet_rate;
            c.range_gain_f32 = f32_bits(1.0f);
            c.range_offset_f32 = f32_bits(0.0f);
            c.has_data_width = true;
            c.data_width = 1;
            c.has_range_res = true;
            c.range_res_m_f32 = f32_bits(static_cast<float>(opt.bin_size_m));
            msg.resize(256);
            const sl_ssize_t n = sl_proto_encode_config(msg.data(), msg.size(), &c, sl_bytes_t{nullptr, 0});
            if (n <= 0) {
                err = std::string("encoding the Configuration failed: ") + sl_err_str(static_cast<sl_err_t>(n));
                return false;
            }
            out.insert(out.end(), msg.begin(), msg.begin() + n);
        } else if (static_cast<uint32_t>(img.rows) != rep.azimuths ||
                   static_cast<uint32_t>(img.cols - 11) != rep.range_bins) {
            err = path + ": shape differs from the first PNG";
            return false;
        }
        msg.resize(SL_PROTO_HEADER_BYTES + SL_PROTO_FFT_FIXED_BYTES + rep.range_bins);
        for (int r = 0; r < img.rows; ++r) {
            const uint8_t *row = img.ptr<uint8_t>(r);
            uint64_t tu = 0;
            for (int i = 7; i >= 0; --i) {
                tu = (tu << 8) | row[i];
            }
            const int64_t t_us = static_cast<int64_t>(tu);
            const uint16_t az = static_cast<uint16_t>(row[8] | (row[9] << 8));
            if (row[10] != 255) {
                ++rep.invalid_rows;
            }
            if (az >= opt.encoder_size) {
                ++rep.azimuth_out_of_range;
            }
            if (have_prev && t_us <= prev_t) {
                ++rep.time_not_increasing;
            }
            if (rep.rows == 0) {
                rep.first_time_us = t_us;
            }
            rep.last_time_us = t_us;
            have_prev = true;
            prev_t = t_us;
            uint64_t t = 0;
            if (t_us < 0) {
                ++rep.negative_time;
            } else {
                t = static_cast<uint64_t>(t_us);
            }
            sl_proto_fft_t f{};
            f.id = SL_PROTO_ID_FFT_DATA;
            f.bytes_per_bin = 1;
            f.data_offset = SL_PROTO_FFT_FIXED_BYTES;
            f.sweep_counter = sweep++;
            f.azimuth_ticks = az;
            f.seconds = static_cast<uint32_t>(t / 1000000u);
            f.split_ns = static_cast<uint32_t>((t % 1000000u) * 1000u);
            f.bins = rep.range_bins;
            const sl_ssize_t n = sl_proto_encode_fft8(msg.data(), msg.size(), &f, row + 11);
            if (n <= 0) {
                err = std::string("encoding an FFT message failed: ") + sl_err_str(static_cast<sl_err_t>(n));
                return false;
            }
            out.insert(out.end(), msg.begin(), msg.begin() + n);
            ++rep.rows;
        }
        ++rep.scans;
    }
    rep.bytes = out.size();
    return true;
}

} // namespace sl
