/// @file daemon_capture.h
/// @brief Capture files for the daemon's `--input`: a C interface to the host capture
///        reader (host_tools/common/capture.h): raw `.colossus` streams and pcap/pcapng
///        files, whose radar -> client TCP stream is reassembled (retransmissions,
///        reordering, gaps and reconnections handled and reported there).
///
/// Implemented in C++ (apps/shadowleand/daemon_capture_shim.cpp), linked into shadowleand
/// only. The whole stream is held in memory (malloc'd; sld_capture_free releases it).
#ifndef SHADOWLEAN_DAEMON_CAPTURE_H
#define SHADOWLEAN_DAEMON_CAPTURE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// A loaded capture.
typedef struct sld_capture {
    uint8_t *bytes;        ///< the radar -> client byte stream
    size_t size;
    uint64_t *breaks;      ///< offsets in `bytes` where the stream is discontinuous (a gap or
                           ///< a new TCP session: the decoder must be finished there), ascending
    size_t n_breaks;
    char format[16];       ///< "raw", "pcap", "pcapng"
    char report[512];      ///< one-line summary of the pcap reassembly ("" for raw)
} sld_capture_t;

/// Load `path` (format sniffed from its first bytes). @return 0, or -1 with `err` set.
int sld_capture_load(const char *path, sld_capture_t *cap, char *err, size_t err_size);

/// Free what sld_capture_load allocated. Idempotent.
void sld_capture_free(sld_capture_t *cap);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_DAEMON_CAPTURE_H
