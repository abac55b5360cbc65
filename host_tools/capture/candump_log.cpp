// SPDX-License-Identifier: MIT
// candump_log.cpp: can-utils log format for the host tools (see candump_log.h), over the
// port's C module firmware/port/linux/candump.h.
#include "candump_log.h"

#include "candump.h"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace sl {

// Formatting and parsing are the port's C module (firmware/port/linux/candump.h); this is
// the C++ face of it (strings, exceptions, a writer class) for the host tools and tests.
std::string format_candump_frame(const sl_can_frame_t &f)
{
    if (f.dlc > 8) {
        throw CandumpError("DLC above 8");
    }
    if (!slp_candump_frame_ok(&f)) {
        throw CandumpError((f.flags & (SL_CAN_FLAG_EFF | SL_CAN_FLAG_ERR)) != 0U ? "29-bit id above 0x1FFFFFFF"
                                                                                : "11-bit id above 0x7FF");
    }
    char buf[40];
    return slp_candump_format_frame(&f, buf, sizeof buf);
}

std::string format_candump_line(const CandumpRecord &r)
{
    char ts[48];
    std::snprintf(ts, sizeof ts, "(%010llu.%06llu) ",
                  static_cast<unsigned long long>(r.t_us / 1000000U),
                  static_cast<unsigned long long>(r.t_us % 1000000U));
    return ts + r.iface + " " + format_candump_frame(r.frame);
}

bool parse_candump_line(const std::string &line, CandumpRecord *out, std::string *err)
{
    slp_candump_record_t rec;
    const char *why = nullptr;
    if (line.find('\0') != std::string::npos ||
        slp_candump_parse_record(line.c_str(), &rec, &why) != SL_OK) {
        if (err != nullptr) {
            *err = why != nullptr ? why : "malformed line";
        }
        return false;
    }
    out->t_us = rec.t_us;
    out->iface = rec.iface;
    out->frame = rec.frame;
    return true;
}

std::vector<CandumpRecord> read_candump_log(const std::string &path)
{
    std::ifstream in(path);
    if (!in) {
        throw CandumpError(path + ": cannot open: " + std::strerror(errno));
    }
    std::vector<CandumpRecord> v;
    std::string line, err;
    size_t n = 0;
    while (std::getline(in, line)) {
        n++;
        if (line.find_first_not_of(" \t\r") == std::string::npos) {
            continue;
        }
        CandumpRecord r;
        if (!parse_candump_line(line, &r, &err)) {
            throw CandumpError(path + ":" + std::to_string(n) + ": " + err);
        }
        v.push_back(std::move(r));
    }
    if (in.bad()) {
        throw CandumpError(path + ": read error");
    }
    return v;
}

CandumpWriter::~CandumpWriter()
{
    close();
}

void CandumpWriter::open(const std::string &path, const std::string &iface)
{
    close();
    if (path == "-") {
        fp_ = stdout;
        own_ = false;
    } else {
        fp_ = std::fopen(path.c_str(), "w");
        if (fp_ == nullptr) {
            throw CandumpError(path + ": cannot create: " + std::strerror(errno));
        }
        own_ = true;
    }
    iface_ = iface;
    stats_ = slp_can_sink_stats_t{};
}

sl_err_t CandumpWriter::write(const sl_can_frame_t &f, uint64_t t_us)
{
    if (fp_ == nullptr) {
        stats_.dropped++;
        return SL_ERR_PORT;
    }
    std::string line;
    try {
        line = format_candump_line(CandumpRecord{t_us, iface_, f});
    } catch (const CandumpError &) {
        stats_.dropped++;
        return SL_ERR_ARG;
    }
    line += '\n';
    if (std::fwrite(line.data(), 1, line.size(), fp_) != line.size()) {
        stats_.dropped++;
        stats_.errors++;
        return SL_ERR_PORT;
    }
    stats_.sent++;
    return SL_OK;
}

void CandumpWriter::flush()
{
    if (fp_ != nullptr && std::fflush(fp_) != 0) {
        stats_.errors++;
    }
}

void CandumpWriter::close()
{
    if (fp_ == nullptr) {
        return;
    }
    flush();
    if (own_ && std::fclose(fp_) != 0) {
        stats_.errors++;
    }
    fp_ = nullptr;
    own_ = false;
}

slp_can_sink_t CandumpWriter::sink()
{
    slp_can_sink_t k{};
    k.name = "candump";
    k.ctx = this;
    k.send = [](void *ctx, const sl_can_frame_t *f, uint64_t t_us) -> sl_err_t {
        return static_cast<CandumpWriter *>(ctx)->write(*f, t_us);
    };
    k.poll = [](void *ctx, uint64_t) { static_cast<CandumpWriter *>(ctx)->flush(); };
    k.get_stats = [](void *ctx, slp_can_sink_stats_t *out) {
        *out = static_cast<CandumpWriter *>(ctx)->stats();
    };
    return k;
}

} // namespace sl
