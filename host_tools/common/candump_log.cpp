// candump_log.cpp: can-utils log format (see candump_log.h).
#include "candump_log.h"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace sl {
namespace {

const char kHex[] = "0123456789ABCDEF";

int hexval(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

void put_hex(std::string &s, uint32_t v, int digits)
{
    for (int i = digits - 1; i >= 0; i--) {
        s += kHex[(v >> (4 * i)) & 0xFU];
    }
}

bool fail(std::string *err, const char *why)
{
    if (err != nullptr) {
        *err = why;
    }
    return false;
}

// Parse the frame token "123#..." into *f.
bool parse_frame(const std::string &t, sl_can_frame_t *f, std::string *err)
{
    *f = sl_can_frame_t{};
    const size_t hash = t.find('#');
    if (hash == std::string::npos) {
        return fail(err, "no '#' in the frame");
    }
    if (hash != 3 && hash != 8) {
        return fail(err, "the id must have 3 (11-bit) or 8 (29-bit) hex digits");
    }
    uint32_t id = 0;
    for (size_t i = 0; i < hash; i++) {
        const int v = hexval(t[i]);
        if (v < 0) {
            return fail(err, "bad hex digit in the id");
        }
        id = (id << 4) | static_cast<uint32_t>(v);
    }
    if (hash == 3) {
        if (id > SL_CAN_SFF_MASK) {
            return fail(err, "11-bit id above 0x7FF");
        }
        f->id = id;
    } else if ((id & 0x20000000U) != 0U) {
        f->id = id & SL_CAN_EFF_MASK & ~0x20000000UL; // error class bits
        f->flags = SL_CAN_FLAG_ERR;
    } else {
        if (id > SL_CAN_EFF_MASK) {
            return fail(err, "29-bit id above 0x1FFFFFFF");
        }
        f->id = id;
        f->flags = SL_CAN_FLAG_EFF;
    }
    size_t p = hash + 1;
    if (p < t.size() && t[p] == '#') {
        return fail(err, "CAN FD frame (##): not supported, classic CAN only");
    }
    if (p < t.size() && (t[p] == 'R' || t[p] == 'r')) {
        f->flags |= SL_CAN_FLAG_RTR;
        p++;
        if (p < t.size()) {
            const int v = hexval(t[p]);
            if (v < 0 || v > 8 || p + 1 != t.size()) {
                return fail(err, "bad RTR length (one digit 0..8)");
            }
            f->dlc = static_cast<uint8_t>(v);
        }
        return true;
    }
    while (p < t.size()) {
        if (t[p] == '.') {
            p++;
            continue;
        }
        if (p + 1 >= t.size()) {
            return fail(err, "odd number of data hex digits");
        }
        const int hi = hexval(t[p]), lo = hexval(t[p + 1]);
        if (hi < 0 || lo < 0) {
            return fail(err, "bad hex digit in the data");
        }
        if (f->dlc >= 8) {
            return fail(err, "more than 8 data bytes (CAN FD is not supported)");
        }
        f->data[f->dlc++] = static_cast<uint8_t>(hi * 16 + lo);
        p += 2;
    }
    return true;
}

} // namespace

std::string format_candump_frame(const sl_can_frame_t &f)
{
    if (f.dlc > 8) {
        throw CandumpError("DLC above 8");
    }
    std::string s;
    if ((f.flags & SL_CAN_FLAG_ERR) != 0U) {
        if (f.id > (SL_CAN_EFF_MASK & ~0x20000000UL)) {
            throw CandumpError("error class above 0x1FFFFFFF");
        }
        put_hex(s, f.id | 0x20000000U, 8);
    } else if ((f.flags & SL_CAN_FLAG_EFF) != 0U) {
        if (f.id > SL_CAN_EFF_MASK) {
            throw CandumpError("29-bit id above 0x1FFFFFFF");
        }
        put_hex(s, f.id, 8);
    } else {
        if (f.id > SL_CAN_SFF_MASK) {
            throw CandumpError("11-bit id above 0x7FF");
        }
        put_hex(s, f.id, 3);
    }
    s += '#';
    if ((f.flags & SL_CAN_FLAG_RTR) != 0U && (f.flags & SL_CAN_FLAG_ERR) == 0U) {
        s += 'R';
        if (f.dlc > 0) {
            s += kHex[f.dlc];
        }
        return s;
    }
    for (unsigned i = 0; i < f.dlc; i++) {
        put_hex(s, f.data[i], 2);
    }
    return s;
}

std::string format_candump_line(const CandumpRecord &r)
{
    char ts[48];
    std::snprintf(ts, sizeof ts, "(%010llu.%06llu) ",
                  static_cast<unsigned long long>(r.t_us / 1000000U),
                  static_cast<unsigned long long>(r.t_us % 1000000U));
    return ts + r.iface + " " + format_candump_frame(r.frame);
}

bool parse_candump_line(const std::string &line_in, CandumpRecord *out, std::string *err)
{
    std::string line = line_in;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) {
        line.pop_back();
    }
    // (sec.frac)
    if (line.empty() || line[0] != '(') {
        return fail(err, "line does not start with '('");
    }
    const size_t close = line.find(')');
    if (close == std::string::npos) {
        return fail(err, "no ')' after the time stamp");
    }
    const std::string ts = line.substr(1, close - 1);
    const size_t dot = ts.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 >= ts.size() || ts.size() - dot - 1 > 9) {
        return fail(err, "time stamp is not <seconds>.<1..9 digits>");
    }
    uint64_t sec = 0, frac = 0;
    for (size_t i = 0; i < dot; i++) {
        if (ts[i] < '0' || ts[i] > '9' || sec > 18000000000000ULL) {
            return fail(err, "bad seconds in the time stamp");
        }
        sec = sec * 10 + static_cast<uint64_t>(ts[i] - '0');
    }
    size_t fd = 0;
    for (size_t i = dot + 1; i < ts.size(); i++, fd++) {
        if (ts[i] < '0' || ts[i] > '9') {
            return fail(err, "bad fraction in the time stamp");
        }
        if (fd < 6) {
            frac = frac * 10 + static_cast<uint64_t>(ts[i] - '0');
        }
    }
    for (; fd < 6; fd++) {
        frac *= 10;
    }
    out->t_us = sec * 1000000U + frac;

    // Tokens: iface, frame, optional direction.
    std::vector<std::string> tok;
    size_t p = close + 1;
    while (p < line.size()) {
        while (p < line.size() && (line[p] == ' ' || line[p] == '\t')) {
            p++;
        }
        size_t e = p;
        while (e < line.size() && line[e] != ' ' && line[e] != '\t') {
            e++;
        }
        if (e > p) {
            tok.push_back(line.substr(p, e - p));
        }
        p = e;
    }
    if (tok.size() < 2) {
        return fail(err, "expected '<iface> <frame>' after the time stamp");
    }
    if (tok.size() > 3 || (tok.size() == 3 && tok[2] != "R" && tok[2] != "T")) {
        return fail(err, "unexpected text after the frame");
    }
    out->iface = tok[0];
    return parse_frame(tok[1], &out->frame, err);
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
    stats_ = sl_can_sink_stats_t{};
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

sl_can_sink_t CandumpWriter::sink()
{
    sl_can_sink_t k{};
    k.name = "candump";
    k.ctx = this;
    k.send = [](void *ctx, const sl_can_frame_t *f, uint64_t t_us) -> sl_err_t {
        return static_cast<CandumpWriter *>(ctx)->write(*f, t_us);
    };
    k.poll = [](void *ctx, uint64_t) { static_cast<CandumpWriter *>(ctx)->flush(); };
    k.get_stats = [](void *ctx, sl_can_sink_stats_t *out) {
        *out = static_cast<CandumpWriter *>(ctx)->stats();
    };
    return k;
}

} // namespace sl
