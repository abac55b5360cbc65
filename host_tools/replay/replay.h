// SPDX-License-Identifier: MIT
// replay.h: the sl-replay subcommands (serve, record, from-oxford, to-pcapng).
#pragma once

#include <csignal>
#include <cstdint>
#include <string>

#include "pcapng_writer.h"

namespace sl::replay {

/// Set by SIGINT/SIGTERM; every loop polls it (poll() is interrupted: no SA_RESTART).
extern volatile std::sig_atomic_t g_stop;
void install_signal_handlers();

struct ServeOptions {
    std::string capture;
    int port = 6317;                 ///< 0 = any free port (printed)
    std::string bind = "127.0.0.1";  ///< other addresses only with --bind
    bool realtime = true;            ///< false: --rate max
    bool loop = false;
    uint32_t keepalive_ms = 1000;    ///< 0 = none
    unsigned max_clients = 3;
    size_t queue_bytes = 4u << 20;   ///< per-client output queue bound
    uint64_t junk_every = 0;         ///< junk after every N-th FFT message (0 = off)
    unsigned split = 0;              ///< send each message in this many writes (0/1 = off)
    uint64_t close_after = 0;        ///< close a connection after N FFT messages (0 = off)
    uint64_t stall_after = 0;        ///< go silent on a connection after N FFT messages
    uint32_t max_gap_ms = 1000;      ///< realtime: longer timestamp gaps are shortened to this
    // Fault injection (each recovery of the client has a test: tests/system/daemon/faults.sh)
    uint64_t cut_after = 0;          ///< after N FFT messages: half a message, then close
    bool cut_rst = false;            ///< ... with a TCP RST (SO_LINGER 0) instead of FIN
    bool keepalive_only = false;     ///< accept Start FFT but never send FFT data
    uint32_t trickle_bps = 0;        ///< send at most this many bytes per second (slowloris)
    int config_azimuths = -1;        ///< rewrite the served Configuration's azimuth count
    int config_encoder = -1;         ///< ... encoder size
    double config_bin_size_m = 0;    ///< ... bin size (fixed part and protobuf field 10)
    unsigned shuffle = 0;            ///< permute FFT messages within blocks of N (fixed seed)
    double timeout_s = 0;            ///< exit by itself after this long (0 = never)
    bool verbose = false;
};
int serve(const ServeOptions &o);

struct RecordOptions {
    std::string host;
    uint16_t port = 6317;
    std::string out;
    double duration_s = 0;          ///< 0 = until Ctrl-C
    bool non_contour = false;
    uint32_t silence_ms = 3000;
    uint32_t connect_timeout_ms = 2000;
    uint32_t backoff_max_ms = 5000;
    bool verbose = false;
};
int record(const RecordOptions &o);

struct PcapngOptions {
    std::string input;         ///< raw .colossus capture, or "-" for stdin
    std::string out;           ///< pcapng file, or "-" for stdout
    PcapngSession session{};   ///< addresses, ports, segment size
    bool non_contour = false;  ///< the client's command is 140 instead of 21
};
/// Converts a raw capture into a pcapng of one TCP session. 0 ok, 1 error (unreadable input,
/// write failure, or no radar message in the input).
int to_pcapng(const PcapngOptions &o);

} // namespace sl::replay
