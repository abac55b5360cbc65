// SPDX-License-Identifier: MIT
// candump_roundtrip: the candump log writer and reader (host_tools/capture/candump_log.h).
//
//   candump_roundtrip OUT.log OUT.expect [N]
//
// 1. Known lines parse to known frames, known frames format to known text (can-utils
//    style), malformed lines are rejected with a reason.
// 2. N random frames (11/29-bit, RTR, error frames, DLC 0..8) written through the writer's
//    sink interface and read back with read_candump_log: every field equal.
// The written OUT.log is then fed to can-utils' log2long and python-can's
// CanutilsLogReader by candump_external.sh; OUT.expect lists the frames for that check
// ("t_us id flags dlc data_hex" per line).
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <string>

#include "candump_log.h"
#include "check.hpp"

namespace {

using sl_test::failures;

bool same(const sl_can_frame_t &a, const sl_can_frame_t &b)
{
    if (a.id != b.id || a.dlc != b.dlc || a.flags != b.flags) {
        return false;
    }
    if ((a.flags & SL_CAN_FLAG_RTR) != 0U) {
        return true;
    }
    for (unsigned i = 0; i < a.dlc; i++) {
        if (a.data[i] != b.data[i]) {
            return false;
        }
    }
    return true;
}

sl_can_frame_t frame(uint32_t id, uint8_t flags, std::initializer_list<uint8_t> data, int dlc = -1)
{
    sl_can_frame_t f{};
    f.id = id;
    f.flags = flags;
    for (uint8_t b : data) {
        f.data[f.dlc++] = b;
    }
    if (dlc >= 0) {
        f.dlc = static_cast<uint8_t>(dlc);
    }
    return f;
}

void known_lines()
{
    struct Case {
        const char *line;
        uint64_t t_us;
        const char *iface;
        sl_can_frame_t f;
    } ok[] = {
        {"(1795345663.532485) can0 123#DEADBEEF", 1795345663532485ULL, "can0",
         frame(0x123, 0, {0xDE, 0xAD, 0xBE, 0xEF})},
        {"(1795345663.660173) can0 1ABCDE10#0102", 1795345663660173ULL, "can0",
         frame(0x1ABCDE10, SL_CAN_FLAG_EFF, {0x01, 0x02})},
        {"(0000000001.000002) vcan0 7FF#", 1000002ULL, "vcan0", frame(0x7FF, 0, {})},
        {"(0000000001.000002) vcan0 000#R", 1000002ULL, "vcan0", frame(0, SL_CAN_FLAG_RTR, {})},
        {"(0000000001.000002) vcan0 123#R7", 1000002ULL, "vcan0", frame(0x123, SL_CAN_FLAG_RTR, {}, 7)},
        {"(0000000001.000002) vcan0 20000040#0000000000000000", 1000002ULL, "vcan0",
         frame(0x40, SL_CAN_FLAG_ERR, {0, 0, 0, 0, 0, 0, 0, 0})},
        // python-can writer style: no zero padding, direction token, lowercase, '.' separators
        {"(12.5) can1 1ab#de.ad.be.ef R", 12500000ULL, "can1", frame(0x1AB, 0, {0xDE, 0xAD, 0xBE, 0xEF})},
        {"(3.123456789) can1 00000001#11 T\n", 3123456ULL, "can1", frame(1, SL_CAN_FLAG_EFF, {0x11})},
    };
    for (const Case &c : ok) {
        sl::CandumpRecord r;
        std::string err;
        const bool parsed = sl::parse_candump_line(c.line, &r, &err);
        if (!parsed) {
            std::cerr << "rejected: " << c.line << ": " << err << "\n";
        }
        CHECK(parsed);
        CHECK(r.t_us == c.t_us);
        CHECK(r.iface == c.iface);
        CHECK(same(r.frame, c.f));
    }
    // Formatting is candump's own.
    CHECK(sl::format_candump_line({1795345663532485ULL, "can0", frame(0x123, 0, {0xDE, 0xAD, 0xBE, 0xEF})}) ==
          "(1795345663.532485) can0 123#DEADBEEF");
    CHECK(sl::format_candump_line({1000002ULL, "vcan0", frame(0x1ABCDE0F, SL_CAN_FLAG_EFF, {1, 2})}) ==
          "(0000000001.000002) vcan0 1ABCDE0F#0102");
    CHECK(sl::format_candump_frame(frame(0x5, 0, {})) == "005#");
    CHECK(sl::format_candump_frame(frame(0x123, SL_CAN_FLAG_RTR, {}, 0)) == "123#R");
    CHECK(sl::format_candump_frame(frame(0x123, SL_CAN_FLAG_RTR, {}, 8)) == "123#R8");
    CHECK(sl::format_candump_frame(frame(0x40, SL_CAN_FLAG_ERR, {0, 0, 0, 0, 0, 0, 0, 0})) ==
          "20000040#0000000000000000");
    bool threw = false;
    try {
        (void)sl::format_candump_frame(frame(0x800, 0, {}));
    } catch (const sl::CandumpError &) {
        threw = true;
    }
    CHECK(threw);

    const char *bad[] = {
        "",
        "junk",
        "1.5 can0 123#00",                    // no parentheses
        "(1.5 can0 123#00",                   // no ')'
        "(1) can0 123#00",                    // no fraction
        "(1.x) can0 123#00",                  // bad fraction
        "(1.000000) can0",                    // no frame
        "(1.000000) can0 12#00",              // 2-digit id
        "(1.000000) can0 1234#00",            // 4-digit id
        "(1.000000) can0 800#00",             // 11-bit id too large
        "(1.000000) can0 123#0",              // odd data digits
        "(1.000000) can0 123#0G",             // bad hex
        "(1.000000) can0 123#001122334455667788", // 9 bytes
        "(1.000000) can0 123##10011",         // CAN FD
        "(1.000000) can0 123#R9",             // RTR length > 8
        "(1.000000) can0 123#00 X",           // unknown trailing token
        "(1.000000) can0 123DEAD",            // no '#'
    };
    for (const char *l : bad) {
        sl::CandumpRecord r;
        std::string err;
        const bool parsed = sl::parse_candump_line(l, &r, &err);
        if (parsed) {
            std::cerr << "accepted bad line: '" << l << "'\n";
        }
        CHECK(!parsed && !err.empty());
    }
}

} // namespace

int main(int argc, char **argv)
{
    if (argc < 3) {
        std::cerr << "usage: candump_roundtrip OUT.log OUT.expect [N]\n";
        return 2;
    }
    const long n = argc > 3 ? std::stol(argv[3]) : 5000;
    known_lines();

    std::mt19937_64 rng(12345);
    auto uni = [&](uint64_t lo, uint64_t hi) {
        return std::uniform_int_distribution<uint64_t>(lo, hi)(rng);
    };
    std::vector<sl::CandumpRecord> sent;
    sl::CandumpWriter w;
    w.open(argv[1], "vcan0");
    const slp_can_sink_t sink = w.sink();
    std::ofstream ex(argv[2]);
    uint64_t t = 1700000000000000ULL;
    for (long i = 0; i < n; i++) {
        sl_can_frame_t f{};
        const uint64_t kind = uni(0, 9);
        if (kind < 5) {
            f.id = static_cast<uint32_t>(uni(0, 0x7FF));
        } else if (kind < 8) {
            f.id = static_cast<uint32_t>(uni(0, 0x1FFFFFFF));
            f.flags = SL_CAN_FLAG_EFF;
        } else if (kind < 9) {
            f.id = static_cast<uint32_t>(uni(0, 0x7FF));
            f.flags = SL_CAN_FLAG_RTR;
            if (uni(0, 1) != 0U) {
                f.id = static_cast<uint32_t>(uni(0, 0x1FFFFFFF));
                f.flags |= SL_CAN_FLAG_EFF;
            }
        } else {
            f.id = static_cast<uint32_t>(uni(1, 0x1FF)); // error classes
            f.flags = SL_CAN_FLAG_ERR;
        }
        f.dlc = static_cast<uint8_t>((f.flags & SL_CAN_FLAG_ERR) != 0U ? 8 : uni(0, 8));
        if ((f.flags & SL_CAN_FLAG_RTR) == 0U) {
            for (unsigned k = 0; k < f.dlc; k++) {
                f.data[k] = static_cast<uint8_t>(uni(0, 255));
            }
        }
        t += uni(0, 3000000);
        CHECK(sink.send(sink.ctx, &f, t) == SL_OK);
        sent.push_back({t, "vcan0", f});
        char line[96];
        std::snprintf(line, sizeof line, "%llu %lu %u %u ", static_cast<unsigned long long>(t),
                      static_cast<unsigned long>(f.id), f.flags, f.dlc);
        ex << line;
        for (unsigned k = 0; (f.flags & SL_CAN_FLAG_RTR) == 0U && k < f.dlc; k++) {
            std::snprintf(line, sizeof line, "%02x", f.data[k]);
            ex << line;
        }
        ex << "\n";
    }
    sink.poll(sink.ctx, t);
    slp_can_sink_stats_t st{};
    sink.get_stats(sink.ctx, &st);
    CHECK(st.sent == static_cast<uint32_t>(n) && st.dropped == 0 && st.errors == 0);
    w.close();
    ex.close();

    const std::vector<sl::CandumpRecord> back = sl::read_candump_log(argv[1]);
    CHECK(back.size() == sent.size());
    for (size_t i = 0; i < back.size() && i < sent.size(); i++) {
        if (back[i].t_us != sent[i].t_us || back[i].iface != sent[i].iface ||
            !same(back[i].frame, sent[i].frame)) {
            std::cerr << "line " << i + 1 << " differs: " << sl::format_candump_line(back[i])
                      << " vs " << sl::format_candump_line(sent[i]) << "\n";
            failures++;
            break;
        }
    }
    // A writer that is not open drops and counts; a bad file path throws.
    sl::CandumpWriter closed;
    sl_can_frame_t f0{};
    CHECK(closed.write(f0, 0) == SL_ERR_PORT && closed.stats().dropped == 1);
    bool threw = false;
    try {
        closed.open("/nonexistent-dir/x.log", "can0");
    } catch (const sl::CandumpError &) {
        threw = true;
    }
    CHECK(threw);
    std::cout << "candump_roundtrip: " << n << " frames written and read back, " << failures
              << " failures\n";
    return failures == 0 ? 0 : 1;
}
