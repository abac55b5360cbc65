// SPDX-License-Identifier: MIT
// capture.h: reading and writing radar captures (host only, C++17).
//
// Two kinds of capture hold the radar -> client byte stream of the Colossus protocol:
//   - raw `.colossus`: the bytes exactly as the radar sent them (what `sl-replay record`
//     writes, what `sl-replay from-oxford` and the simulator produce);
//   - pcap / pcapng (tcpdump, Wireshark): the TCP session is reassembled here, in the
//     radar -> client direction (TCP source port 6317 by default; when no packet comes
//     from that port, the side that sends Colossus radar messages is auto-detected).
// The format is sniffed from the file's first bytes, never from its extension.
//
// Reassembly tolerates retransmissions (full or partial), out-of-order segments, missing
// segments, packets truncated by the snap length and files cut short (the packets before
// the read error are used); everything is counted in `PcapReport`. Bytes present more than
// once keep the copy that comes first in sequence order (ties: capture order); copies that
// differ are counted (`retransmit_mismatch_bytes`). Missing bytes are NOT invented: the stream skips them, and each gap is
// recorded as a `Discontinuity` at its position in the output so a decoder can be reset
// there instead of gluing two half messages together. Several sequential TCP sessions to
// the radar (reconnections) are concatenated in time order, with a discontinuity between
// them; sessions that overlap in time a session already taken are counted and ignored.
//
// Reading, sniffing and reassembly are the port's streaming reader
// (firmware/port/linux/capture_reader.h: "-" = stdin, pipes and FIFOs work, the streaming
// session rules are described there); load_capture collects its pieces. Memory: the whole
// stream is held in memory (raw: the file size; pcap: the payload of the selected
// direction); tools that can stream should use the reader directly. Cost: O(bytes).
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "shadowlean/sl_proto.h"

namespace sl {

/// Largest payload the host tools accept (reassembly buffer size): 1 MiB, the old SDK's
/// limit (the newer SDKs stop at 1,000,000 bytes).
constexpr size_t kHostMaxPayloadBytes = 1u << 20;

enum class CaptureFormat { Raw, Pcap, Pcapng, Unknown };

/// "raw", "pcap", "pcapng", "unknown".
const char *capture_format_name(CaptureFormat f);

/// Sniffs the format from the first bytes of `path` (pcap magic a1b2c3d4 / a1b23c4d in
/// either byte order, pcapng block type 0a0d0d0a; anything else is Raw; an unreadable or
/// empty file is Unknown).
CaptureFormat sniff_capture_format(const std::string &path);

/// One place in the reassembled stream where bytes are missing or a new TCP session
/// starts. `output_offset` is the index in `Capture::bytes` of the first byte after it.
struct Discontinuity {
    enum class Kind { Gap, NewSession };
    Kind kind = Kind::Gap;
    uint64_t output_offset = 0;
    uint64_t stream_offset = 0; ///< TCP stream offset (relative to the session's ISN + 1)
    uint64_t missing_bytes = 0; ///< bytes absent from the capture (0 for NewSession)
    uint32_t session = 0;       ///< index into PcapReport::flows
};

/// One direction of one TCP connection seen in a pcap.
struct PcapFlow {
    std::string src, dst;        ///< "addr:port"
    uint16_t src_port = 0, dst_port = 0;
    uint64_t packets = 0;        ///< packets with this 4-tuple and direction
    uint64_t payload_bytes = 0;  ///< TCP payload bytes captured (with retransmissions)
    double first_ts_s = 0, last_ts_s = 0;
    bool syn = false, fin = false, rst = false;
    bool selected = false;       ///< part of the reassembled stream
};

/// Everything the pcap reader counted. All counts refer to the selected direction unless
/// the name says otherwise.
struct PcapReport {
    std::string link_type;          ///< libpcap DLT name, e.g. "EN10MB"
    uint16_t radar_port = 0;        ///< TCP source port of the reassembled direction
    bool port_auto_detected = false;///< the default port had no traffic; found by content
    uint64_t packets_total = 0;     ///< all packets in the file
    uint64_t packets_undecoded = 0; ///< not Ethernet/SLL/raw IP, not IPv4/IPv6, or not TCP
    uint64_t ip_fragments = 0;      ///< IP fragments (not reassembled, skipped)
    uint64_t packets_truncated = 0; ///< captured length < TCP payload (snap length)
    uint64_t segments = 0;          ///< selected-direction TCP segments with payload
    uint64_t payload_bytes = 0;     ///< their captured payload bytes
    uint64_t stream_bytes = 0;      ///< bytes in the reassembled output
    uint64_t retransmitted_segments = 0; ///< segments whose bytes had all been seen before
    uint64_t retransmitted_bytes = 0;    ///< bytes received more than once (full + partial)
    uint64_t partial_overlap_segments = 0; ///< segments partly new, partly seen before
    uint64_t retransmit_mismatch_bytes = 0;///< re-sent bytes that differ from the first copy
    uint64_t out_of_order_segments = 0;  ///< segments that arrived after a later segment
    uint64_t gaps = 0;              ///< holes in the byte stream (missing segments)
    uint64_t gap_bytes = 0;         ///< total bytes missing in those holes
    uint64_t flows_ignored = 0;     ///< radar-side sessions overlapping a selected one
    bool started_mid_stream = false;///< a selected session has no SYN: the first bytes may
                                    ///< be the tail of a message
    std::string read_error;         ///< libpcap error that ended reading early (a truncated or
                                    ///< corrupt file); the packets before it are used
    std::vector<PcapFlow> flows;    ///< every radar-side direction found (selected or not)
    std::vector<Discontinuity> gap_list; ///< gaps only, in output order
};

struct PcapOptions {
    int radar_port = 6317;     ///< TCP source port of the radar side
    bool port_explicit = false;///< true: never auto-detect another port
};

/// A loaded capture: the radar -> client byte stream plus what was learnt reading it.
struct Capture {
    CaptureFormat format = CaptureFormat::Unknown;
    std::vector<uint8_t> bytes;
    std::vector<Discontinuity> discontinuities; ///< sorted by output_offset (pcap only)
    bool has_pcap_report = false;
    PcapReport pcap;
};

/// Loads `path` (format sniffed). Returns false and sets `err` on I/O or format errors
/// (an unreadable file, a pcap without any radar-side TCP payload, ...). Damaged streams
/// are not errors: they are reported.
bool load_capture(const std::string &path, Capture &out, std::string &err,
                  const PcapOptions &opt = PcapOptions{});

/// Reassembles a pcap/pcapng file (libpcap reads both). Same contract as load_capture.
bool load_pcap(const std::string &path, Capture &out, std::string &err,
               const PcapOptions &opt = PcapOptions{});

/// A piece of the radar -> client stream, valid only during the call. Returns false to stop
/// reading (not an error: the consumer has what it needs).
using CaptureDataFn = std::function<bool(const uint8_t *data, size_t size)>;
/// A place where the stream is not continuous (already appended to Capture::discontinuities).
using CaptureBreakFn = std::function<void(const Discontinuity &d)>;

/// Streams `path` ("-" = stdin, pipes and FIFOs work) in bounded memory, whatever its size:
/// `on_data` receives the reassembled stream piece by piece, in order; `on_break` (may be
/// empty) each discontinuity (a gap or a new TCP session) where it falls, so the consumer
/// resets its decoder there. This is the one way the host tools read a capture. `info`
/// receives the format, discontinuities and pcap report (its `bytes` stay empty); `bytes` the
/// stream size. false + `err` when the capture cannot be opened or ends with an error (the
/// part read before it has been handed over). Memory: the port reader's window (raw) or
/// its reassembly queue (pcap), not the capture. Cost: O(bytes).
bool read_capture(const std::string &path, const CaptureDataFn &on_data, const CaptureBreakFn &on_break,
                  Capture &info, uint64_t &bytes, std::string &err, const PcapOptions &opt = PcapOptions{});

/// Streams `path` ("-" = stdin) through decoder `p` in bounded memory: what load_capture +
/// feed_capture do, without holding the stream (`chunk` > 0: at most that many bytes per
/// sl_proto_feed). `info` receives the format, discontinuities and pcap report (its `bytes`
/// stay empty); `bytes` the stream size. false + `err` when the capture cannot be opened
/// or ends with an error (the part read before it has been fed).
bool stream_capture(const std::string &path, sl_proto_t *p, size_t chunk, Capture &info, uint64_t &bytes,
                    std::string &err, const PcapOptions &opt = PcapOptions{});

/// The core decoder as the host tools use it (1 MiB reassembly buffer, the largest payload
/// they accept), for bytes pushed in pieces of any size: a capture streamed by read_capture,
/// a stream rendered in memory. `on_msg` gets every message (valid during the call).
/// finish() at every discontinuity and at the end. Neither copyable nor movable (the core
/// decoder keeps a pointer to it).
class MessageDecoder {
public:
    using MsgFn = std::function<void(const sl_proto_msg_t &m)>;
    explicit MessageDecoder(MsgFn on_msg);
    MessageDecoder(const MessageDecoder &) = delete;
    MessageDecoder &operator=(const MessageDecoder &) = delete;
    void feed(const uint8_t *data, size_t size) { (void)sl_proto_feed(&p_, data, size, 0); }
    void finish() { (void)sl_proto_finish(&p_); }
    const sl_proto_stats_t &stats() const { return p_.stats; }

private:
    static void on_msg(void *ctx, const sl_proto_msg_t *m);
    MsgFn fn_;
    std::vector<uint8_t> reasm_;
    sl_proto_t p_{};
};

/// A capture as a sequence of whole messages, pulled one at a time in bounded memory: the
/// port's streaming reader (as read_capture: "-", FIFOs, pcap reassembly), the core decoder
/// (1 MiB reassembly buffer, reset at every gap or new TCP session), and the messages of the
/// piece of the stream being decoded (at most 1 MiB of it: a raw file's 16 MiB mapped window
/// is fed a megabyte at a time). For tools that need messages rather than bytes
/// (`sl-replay serve`, sl-view, sl-calib). Each message is returned whole (22-byte header + payload, the header
/// re-encoded, which is byte for byte the captured one: a valid header has no free field).
class MessageReader {
public:
    MessageReader();
    ~MessageReader();
    MessageReader(const MessageReader &) = delete;
    MessageReader &operator=(const MessageReader &) = delete;

    /// false + err when `path` cannot be opened.
    bool open(const std::string &path, std::string &err, const PcapOptions &opt = PcapOptions{});
    /// A raw Colossus stream already in memory (borrowed: it must outlive the reader).
    void open_memory(const uint8_t *data, size_t size);
    /// The next message (its id and bytes); false at the end of the capture (error() is not
    /// empty when it ended on a read error).
    bool next(uint8_t &id, std::vector<uint8_t> &msg);
    const std::string &error() const { return err_; }
    /// The decoder's counters so far (messages, bytes skipped, resyncs, truncated, ...).
    const sl_proto_stats_t &stats() const;
    /// The capture's format (sniffed at open; Raw for open_memory).
    CaptureFormat format() const;

private:
    struct Impl;
    Impl *m_;
    std::string err_;
};

/// Feeds the whole capture to decoder `p` (which must be freshly initialised so that its
/// stream offsets equal indexes into `cap.bytes`): one sl_proto_feed() per continuous piece,
/// sl_proto_finish() at every discontinuity (a partial message before a gap is dropped and
/// counted as truncated instead of swallowing the bytes after the gap) and at the end.
/// `chunk` > 0 feeds at most that many bytes per call (exercise reassembly). O(bytes).
void feed_capture(const Capture &cap, sl_proto_t *p, size_t chunk = 0, uint64_t now_us = 0);

/// One message found in a capture: `cap.bytes[offset, offset + size)` is the whole message
/// (22-byte header + payload), byte for byte as captured.
struct CaptureMessage {
    uint64_t offset = 0;
    uint32_t size = 0;
    uint8_t id = 0;
};

/// Decodes `cap` (feed_capture with a 1 MiB reassembly buffer) and lists its messages.
/// `stats` (optional) receives the decoder's counters.
std::vector<CaptureMessage> index_capture(const Capture &cap, sl_proto_stats_t *stats = nullptr);

/// Writes `size` bytes to `path` (created or truncated). false + err on failure.
bool write_raw_capture(const std::string &path, const uint8_t *data, size_t size,
                       std::string &err);

/// Streaming writer for raw `.colossus` captures (buffered; flush on close/destruction).
class RawCaptureWriter {
public:
    RawCaptureWriter() = default;
    ~RawCaptureWriter();
    RawCaptureWriter(const RawCaptureWriter &) = delete;
    RawCaptureWriter &operator=(const RawCaptureWriter &) = delete;

    bool open(const std::string &path, std::string &err);
    bool write(const uint8_t *data, size_t size); ///< false on a write error (sticky)
    bool close(std::string &err);                 ///< flushes; false if any write failed
    uint64_t bytes_written() const { return bytes_; }
    bool is_open() const { return f_ != nullptr; }

private:
    std::FILE *f_ = nullptr;
    uint64_t bytes_ = 0;
    bool failed_ = false;
    std::string path_;
};

} // namespace sl
