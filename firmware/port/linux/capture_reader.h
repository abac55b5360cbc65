// SPDX-License-Identifier: MIT
/// @file capture_reader.h
/// @brief Streaming reader of radar captures (Linux port, C11 + POSIX + libpcap).
///
/// A capture holds the radar -> client byte stream of the Colossus protocol:
///   - raw `.colossus`: the bytes exactly as the radar sent them (`sl-replay record`,
///     `sl-replay from-oxford`, the simulator);
///   - pcap / pcapng (tcpdump, Wireshark): the radar -> client direction of the TCP session
///     (source port 6317 unless told otherwise; when no payload comes from that port, the
///     first flow carrying Colossus radar messages is taken and the port is reported as
///     auto-detected) is reassembled here, packet by packet.
///
/// Input: a path, or "-" for stdin. Pipes, FIFOs, character devices and regular files all
/// work the same way: the file is opened once and read sequentially; the format is sniffed
/// from the first bytes already read (pcap magic a1b2c3d4 / a1b23c4d in either byte order,
/// pcapng block type 0a0d0d0a; anything else is raw), which are then handed on, never
/// re-read (libpcap reads through a stdio stream that first returns them).
///
/// Output: a sequence of pieces, pulled with slp_capture_next(): DATA (stream bytes, in
/// order), BREAK (bytes are missing here, or a new TCP session starts: a decoder must be
/// finished before the next DATA so it does not glue two half messages), END, ERROR.
///
/// A raw capture in a regular file is sniffed with pread() and read through a read-only
/// mapping that slides over the file 16 MiB at a time (no copy; the size is taken at open,
/// so bytes appended later are not read; truncating the file while it is read is not
/// supported).
///
/// Memory: bounded whatever the capture's size. Raw: one SLP_CAPTURE_CHUNK read
/// buffer, or one 16 MiB mapped window. Pcap: libpcap's packet buffer, plus out-of-order
/// segments held until the hole before them fills, at most SLP_CAPTURE_PENDING_MAX
/// bytes per reassembled session (the selected one and at most one candidate successor); a
/// hole still open when that bound is reached is declared a gap. While the radar port is
/// not known yet (auto-detection), payload is kept (at most 4 MiB) and replayed into the
/// session of the flow that turns out to be the radar's. Flows are tracked in a fixed
/// table of SLP_CAPTURE_MAX_FLOWS entries (more are counted, not tracked); late
/// packets of a session already reassembled are ignored.
///
/// Differences from reading the whole file first (the host tools' reader before): the
/// radar port is auto-detected from the first flow carrying radar messages (not the best
/// score over the file); a mid-stream session starts at the lowest sequence number seen
/// before its first delivered byte; re-sent bytes older than the held tail are not compared.
///
/// Reassembly (same contract as the host tools' reader, streamed): retransmissions (full or
/// partial) are dropped and counted; re-sent bytes are compared with the first copy when
/// it is still held (out-of-order store or the last SLP_CAPTURE_TAIL delivered bytes)
/// and differences counted; missing bytes are never invented: each hole is a BREAK. A new
/// radar-side session is taken when the current one has ended (FIN/RST), or when the
/// current one sends nothing more for as long as the newcomer fills its out-of-order store
/// or until the end of the file; a session overlapping the one taken (the current one
/// keeps sending after the newcomer started) is counted in flows_ignored, as before.
///
/// Not thread-safe; one reader per thread. Errors: -1 from open with a message; a read
/// error during reading ends the stream with ERROR (raw) or is reported in
/// `report.read_error` and ends it with END after the packets read (pcap, as before).
#ifndef SHADOWLEAN_PORT_CAPTURE_READER_H
#define SHADOWLEAN_PORT_CAPTURE_READER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SLP_CAPTURE_CHUNK (1u << 20)        ///< raw read size, bytes
#define SLP_CAPTURE_PENDING_MAX (8u << 20)  ///< out-of-order bytes held per session
#define SLP_CAPTURE_PENDING_SEGS 8192u      ///< out-of-order segments held per session
#define SLP_CAPTURE_TAIL (64u << 10)        ///< delivered bytes kept to compare re-sends
#define SLP_CAPTURE_MAX_FLOWS 64u           ///< TCP flow directions tracked

typedef enum slp_capture_format {
    SLP_CAPTURE_RAW = 0,
    SLP_CAPTURE_PCAP,
    SLP_CAPTURE_PCAPNG,
} slp_capture_format_t;

typedef enum slp_capture_piece_kind {
    SLP_CAPTURE_DATA = 0,  ///< `data`/`size`: the next stream bytes
    SLP_CAPTURE_BREAK,     ///< bytes missing (gap) or a new session starts here
    SLP_CAPTURE_END,       ///< no more pieces
    SLP_CAPTURE_ERROR,     ///< read error (message in slp_capture_error()); no more pieces
} slp_capture_piece_kind_t;

typedef enum slp_capture_break_kind {
    SLP_CAPTURE_GAP = 0,
    SLP_CAPTURE_NEW_SESSION,
} slp_capture_break_kind_t;

/// One piece of the stream. `data` is valid until the next slp_capture_next() call.
typedef struct slp_capture_piece {
    slp_capture_piece_kind_t kind;
    const uint8_t *data;
    size_t size;
    slp_capture_break_kind_t brk;  ///< BREAK only
    uint64_t output_offset;            ///< stream offset (bytes delivered so far) of this piece
    uint64_t missing_bytes;            ///< GAP only: bytes absent from the capture
    uint64_t stream_offset;            ///< GAP only: TCP stream offset of the hole (from the
                                       ///< session's first byte, ISN + 1)
    uint32_t session;                  ///< BREAK: index of the session after it (0-based)
} slp_capture_piece_t;

/// Everything counted so far (final after END). Counts refer to the reassembled (selected)
/// direction unless the name says otherwise. Raw captures only fill bytes_in / stream_bytes.
typedef struct slp_capture_report {
    slp_capture_format_t format;
    uint64_t bytes_in;              ///< bytes read from the file (every byte counted)
    uint64_t stream_bytes;          ///< bytes delivered as DATA
    char link_type[32];             ///< libpcap DLT name, e.g. "EN10MB"
    uint16_t radar_port;            ///< TCP source port of the reassembled direction
    bool port_auto_detected;
    uint64_t packets_total;         ///< all packets in the file
    uint64_t packets_undecoded;     ///< not Ethernet/SLL/raw IP, not IPv4/IPv6, or not TCP
    uint64_t ip_fragments;          ///< IP fragments (skipped)
    uint64_t packets_truncated;     ///< captured length < TCP payload (snap length)
    uint64_t segments;              ///< selected-session TCP segments with payload
    uint64_t payload_bytes;         ///< their captured payload bytes
    uint64_t retransmitted_segments;///< segments whose bytes had all been seen before
    uint64_t retransmitted_bytes;   ///< bytes received more than once
    uint64_t partial_overlap_segments;
    uint64_t retransmit_mismatch_bytes; ///< re-sent bytes that differ from the held first copy
    uint64_t out_of_order_segments; ///< segments that arrived after a later segment
    uint64_t gaps;                  ///< holes in the byte stream
    uint64_t gap_bytes;             ///< bytes missing in those holes (0 when unknowable)
    uint64_t sessions;              ///< radar-side sessions reassembled
    uint64_t flows_ignored;         ///< radar-side sessions overlapping a selected one
    uint64_t flows_untracked;       ///< flow directions beyond SLP_CAPTURE_MAX_FLOWS
    bool started_mid_stream;        ///< a selected session has no SYN
    char read_error[256];           ///< libpcap error that ended reading early ("" if none)
} slp_capture_report_t;

typedef struct slp_capture_opts {
    uint16_t radar_port;  ///< 0 = 6317
    bool port_explicit;   ///< never auto-detect another port
} slp_capture_opts_t;

typedef struct slp_capture slp_capture_t;

/// Open `path` ("-" = stdin) and sniff its format. `opts` may be NULL.
/// @return the reader (malloc'd, bounded: see above), or NULL with `err` set (an
/// unreadable path, a pcap libpcap rejects). An empty input is a raw capture that ends at once.
slp_capture_t *slp_capture_open(const char *path, const slp_capture_opts_t *opts,
                                        char *err, size_t err_size);

/// The next piece. After END or ERROR every call returns the same kind again.
void slp_capture_next(slp_capture_t *c, slp_capture_piece_t *piece);

/// Counters so far (final after END).
const slp_capture_report_t *slp_capture_report(const slp_capture_t *c);

/// The error message after ERROR ("" otherwise).
const char *slp_capture_error(const slp_capture_t *c);

/// One direction of one TCP connection from the radar port (pcap), as tracked so far.
typedef struct slp_capture_flow {
    char src[64], dst[64];       ///< "addr:port" ("[v6]:port" for IPv6)
    uint64_t packets;            ///< packets of this direction
    uint64_t payload_bytes;      ///< TCP payload bytes captured (with retransmissions)
    uint64_t first_ts_us, last_ts_us; ///< capture timestamps (UNIX microseconds)
    bool syn, fin, rst;
    bool selected;               ///< part of the reassembled stream
} slp_capture_flow_t;

/// The radar-side flows that carried payload (pcap), in order of appearance: up to `max`
/// into `out`. @return their number (may exceed `max`). O(SLP_CAPTURE_MAX_FLOWS).
size_t slp_capture_flows(const slp_capture_t *c, slp_capture_flow_t *out, size_t max);

/// "raw", "pcap", "pcapng".
const char *slp_capture_format_name(slp_capture_format_t f);

/// One line summarising the pcap reassembly ("" for raw), as the daemon logs it.
void slp_capture_report_line(const slp_capture_t *c, char *buf, size_t size);

/// Close the file (not stdin) and free the reader. NULL is allowed.
void slp_capture_close(slp_capture_t *c);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_CAPTURE_READER_H
