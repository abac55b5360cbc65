// SPDX-License-Identifier: MIT
// view_frames.h: a capture (raw .colossus, pcap/pcapng) or an Oxford PNG folder decoded into
// whole rotations, for the host tools that look at images (sl-view, sl-calib). Host only.
//
// Every byte goes through the core: capture.h's MessageReader streams the file through the
// core decoder (1 MiB reassembly buffer) and sl_scan assembles rotations (double
// buffering, nearest-azimuth index, the first `roi_bins` bins of each azimuth). An Oxford
// folder is first converted with oxford.h (the same converter as `sl-replay from-oxford`)
// into an in-memory Colossus stream, so it is decoded exactly as its converted capture.
//
// Frames are copied out as cv::Mat (CV_8U, azimuths x roi_bins, row = azimuth index, column =
// range bin). When no row of the stream holds `roi_bins` bins (a capture with short rows),
// every frame is cropped to the longest row received (FrameSet::roi_bins says how many), so
// sl_scan's zero fill never looks like data. Frames with fewer than `min_valid_fraction` of their azimuths stored are dropped
// and counted (an Oxford sequence ends with a one-row frame: its last row, encoder tick 5599,
// is azimuth index 0 and opens a frame that never fills).
//
// A capture file, pipe, FIFO or "-" is streamed (capture.h read_capture: the port's reader),
// never loaded, and reading stops once `max_frames` frames are kept.
// Memory: for_each_frame hands each frame over and keeps none (sl-view, sl-calib shadow and
// elongation); decode_frames (an in-memory stream, tests) keeps one Mat per frame (400 x
// 512 B = 200 KB each; bound it with max_frames); both hold the reader's window, and an
// Oxford folder's converted stream while it is decoded.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "shadowlean/sl_proto.h"
#include "shadowlean/sl_scan.h"

namespace sl {

struct RadarFrame {
    uint32_t rotation = 0;          ///< sl_scan frame number (0 = first in the stream)
    uint64_t t_first_us = 0, t_last_us = 0;
    int valid_azimuths = 0;         ///< rows stored
    cv::Mat power;                  ///< CV_8U, azimuths x roi_bins (FrameSet::roi_bins)
    int widest_row = 0;             ///< most bins any stored row of this frame held
    std::vector<uint8_t> flags;     ///< SL_SCAN_AZ_* per azimuth
};

struct FrameOptions {
    int roi_bins = SL_CFG_ROI_BINS;     ///< bins kept per azimuth (1 .. SL_CFG_ROI_BINS)
    int azimuths = 0, encoder_size = 0; ///< geometry for streams without a Configuration
    double bin_size_m = 0;          ///< > 0: overrides the stream's bin size; Oxford folders:
                                    ///< the bin size written into the converted stream
    double min_valid_fraction = 0.5;///< drop frames with fewer valid azimuths than this
    int max_frames = 0;             ///< > 0: stop after this many kept frames
    bool ignore_sweep = false;      ///< sl_scan cfg.ignore_sweep
};

struct FrameSet {
    std::string source;             ///< path given
    std::string kind;               ///< "raw", "pcap", "pcapng", "oxford-png"
    int azimuths = 0, encoder_size = 0;
    int roi_bins = 0;               ///< columns of every frame (<= FrameOptions::roi_bins)
    double bin_size_m = 0;          ///< from the Configuration (or the override / board)
    bool bin_from_config = false;   ///< true: the stream's Configuration gave the bin size
    std::vector<RadarFrame> frames;
    int dropped_partial = 0;        ///< frames dropped by min_valid_fraction
    int delivered = 0;              ///< frames kept (decode_frames) or handed over (for_each_frame)
    sl_proto_stats_t proto{};
    sl_scan_stats_t scan{};
};

/// One decoded rotation as it arrives; `meta` is the FrameSet so far (geometry, bin size once
/// known; `frames` stays empty). Return false to stop reading.
using FrameFn = std::function<bool(RadarFrame &frame, const FrameSet &meta)>;

/// Decodes `path` (a capture file, pipe, FIFO or "-", or a folder of Oxford PNGs:
/// DIR/radar/*.png or DIR/*.png) without keeping the frames: each surviving rotation goes to
/// `fn` in stream order (memory: one frame plus the reader's window, whatever the capture's
/// length). The frames are not cropped: they have FrameOptions::roi_bins columns; at the end
/// `meta.roi_bins` is the crop to the widest row received and `meta.delivered` the number of
/// frames handed over. false + err on I/O or format errors, or when no frame survives.
bool for_each_frame(const std::string &path, const FrameOptions &opt, FrameSet &meta,
                    const FrameFn &fn, std::string &err);

/// Decodes an in-memory Colossus byte stream and keeps its frames in `out.frames`, each
/// cropped to `out.roi_bins` (same rules and errors as for_each_frame).
bool decode_frames(const std::vector<uint8_t> &bytes, const FrameOptions &opt, FrameSet &out,
                   std::string &err);

} // namespace sl
