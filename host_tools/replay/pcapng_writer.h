// SPDX-License-Identifier: MIT
// pcapng_writer.h: writes a radar TCP session as a pcapng file (host only, C++17).
//
// Radar engineers debug the Colossus stream in Wireshark; this turns a raw `.colossus`
// capture (the radar -> client bytes) into what tcpdump would have recorded on the
// companion computer's Ethernet port: one TCP session radar:6317 -> client, with the
// three-way handshake, the client's Start FFT command, the radar's bytes cut into
// MSS-sized segments (every byte of the raw capture, junk included, in order), pure ACKs
// from the client, and FIN/ACK at the end. IPv4 and TCP checksums are correct.
//
// File format: pcapng (IETF draft-ietf-opsawg-pcapng): one Section Header Block, one
// Interface Description Block (LINKTYPE_ETHERNET, microsecond timestamps), then one
// Enhanced Packet Block per frame. Blocks are written as they come: memory is one frame.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace sl::replay {

/// The session's endpoints (IPv4, host byte order) and segmentation.
struct PcapngSession {
    uint32_t radar_ip = 0xC0A80001u;  ///< 192.168.0.1 (the CTS350-X factory address)
    uint32_t client_ip = 0xC0A80002u; ///< 192.168.0.2
    uint16_t radar_port = 6317;
    uint16_t client_port = 50000;
    uint32_t mss = 1448;              ///< radar payload bytes per segment (1..65495)
};

class PcapngWriter {
public:
    PcapngWriter() = default;
    ~PcapngWriter();
    PcapngWriter(const PcapngWriter &) = delete;
    PcapngWriter &operator=(const PcapngWriter &) = delete;

    /// Creates `path` (or stdout for "-") and writes the section and interface headers.
    bool open(const std::string &path, const PcapngSession &s, std::string &err);
    /// SYN, SYN/ACK, ACK at `ts_us` (UNIX microseconds).
    bool handshake(uint64_t ts_us);
    /// Client -> radar payload (a command such as Start FFT), one segment.
    bool client_send(const uint8_t *data, size_t n, uint64_t ts_us);
    /// Radar -> client payload, cut into segments of at most `mss` bytes; the client ACKs
    /// every second segment, as a delayed-ACK TCP stack does.
    bool radar_send(const uint8_t *data, size_t n, uint64_t ts_us);
    /// FIN/ACK from the radar, FIN/ACK from the client, last ACK.
    bool close_session(uint64_t ts_us);
    /// Flushes and closes the file; false if any write failed.
    bool finish(std::string &err);

    uint64_t frames() const { return frames_; }
    uint64_t radar_bytes() const { return radar_bytes_; }

private:
    bool write_block(uint32_t type, const uint8_t *body, size_t n);
    bool frame(bool from_radar, uint8_t flags, const uint8_t *payload, size_t n, uint64_t ts_us);

    std::FILE *f_ = nullptr;
    bool own_ = false;
    bool failed_ = false;
    PcapngSession s_{};
    uint32_t radar_isn_ = 0x5E1EC7u, client_isn_ = 0xC0FFEEu;
    uint32_t radar_seq_ = 0, client_seq_ = 0;
    uint16_t ip_id_radar_ = 0, ip_id_client_ = 0;
    uint64_t frames_ = 0;
    uint64_t radar_bytes_ = 0;
    uint32_t unacked_segments_ = 0;
};

} // namespace sl::replay
