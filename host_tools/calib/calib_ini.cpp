// SPDX-License-Identifier: MIT
// calib_ini.cpp: see calib_ini.h.
#include "calib_ini.h"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <vector>

#include "shadowlean/sl_version.h"

namespace sl {

std::string calib_tool_version() { return std::string("sl-calib ") + SL_VERSION_STRING; }

std::string calib_utc_date()
{
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

namespace {

const char *const kMarker = "; --- sl-calib ";

struct Block {
    std::string cmd; // "" = text before the first marker
    std::string text;
};

std::vector<Block> split(const std::string &file)
{
    std::vector<Block> out{Block{}};
    std::istringstream in(file);
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind(kMarker, 0) == 0) {
            const std::string rest = line.substr(std::strlen(kMarker));
            out.push_back(Block{rest.substr(0, rest.find(' ')), ""});
        }
        out.back().text += line + "\n";
    }
    return out;
}

} // namespace

bool write_calib_block(const std::string &path, const std::string &cmd, const std::string &block,
                       const std::string &section_header, std::string *why)
{
    std::string old;
    {
        std::ifstream in(path, std::ios::binary);
        if (in) {
            std::ostringstream s;
            s << in.rdbuf();
            old = s.str();
        }
    }
    std::string out;
    for (const Block &b : split(old)) {
        if (b.cmd == cmd) {
            continue; // replaced below
        }
        if (b.cmd.empty() && b.text.find(section_header) != std::string::npos) {
            continue; // an older sl-calib's file of the same kind: replaced
        }
        out += b.text;
    }
    if (!out.empty() && out.back() != '\n') {
        out += "\n";
    }
    out += std::string(kMarker) + cmd + " ---\n" + block;
    if (!out.empty() && out.back() != '\n') {
        out += "\n";
    }
    std::ofstream o(path, std::ios::binary | std::ios::trunc);
    o << out;
    if (!o) {
        if (why != nullptr) {
            *why = std::strerror(errno);
        }
        return false;
    }
    return true;
}

} // namespace sl
