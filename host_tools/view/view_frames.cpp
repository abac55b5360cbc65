// SPDX-License-Identifier: MIT
// view_frames.cpp: capture / Oxford folder -> rotations, through sl_proto and sl_scan.
#include "view_frames.h"

#include <algorithm>
#include <memory>
#include <sys/stat.h>

#include "capture.h"
#include "oxford.h"

namespace sl {
namespace {

struct DecodeCtx {
    sl_scan_t scan{};
    const FrameOptions *opt = nullptr;
    FrameSet *out = nullptr;
    const FrameFn *fn = nullptr;    // set: frames go to it, not into out->frames
    int widest = 0;                 // widest row of the frames handed to fn
    bool stop = false;
    uint32_t config_bin_um = 0;
};

void on_frame(void *vctx, const sl_scan_frame_t *f)
{
    auto *c = static_cast<DecodeCtx *>(vctx);
    if (c->stop) {
        return;
    }
    const int az = f->azimuths;
    if (az <= 0 || f->stats.valid < c->opt->min_valid_fraction * az) {
        c->out->dropped_partial++;
        return;
    }
    RadarFrame fr;
    fr.rotation = f->rotation;
    fr.t_first_us = f->t_first_us;
    fr.t_last_us = f->t_last_us;
    fr.valid_azimuths = f->stats.valid;
    fr.power = cv::Mat(az, f->roi_bins, CV_8U);
    fr.flags.assign(f->flags, f->flags + az);
    for (int i = 0; i < az; i++) {
        std::copy(f->power[i], f->power[i] + f->roi_bins, fr.power.ptr<uint8_t>(i));
        if (f->flags[i] & SL_SCAN_AZ_VALID) {
            fr.widest_row = std::max(fr.widest_row, static_cast<int>(f->bins[i]));
        }
    }
    c->out->azimuths = az;
    c->out->encoder_size = f->encoder_size;
    c->out->delivered++;
    if (c->fn) {
        c->widest = std::max(c->widest, fr.widest_row);
        c->out->roi_bins = c->opt->roi_bins;
        if (c->opt->bin_size_m > 0) {
            c->out->bin_size_m = c->opt->bin_size_m;
        } else if (c->config_bin_um > 0) {
            c->out->bin_size_m = c->config_bin_um * 1e-6;
            c->out->bin_from_config = true;
        }
        if (!(*c->fn)(fr, *c->out)) {
            c->stop = true;
        }
    } else {
        c->out->frames.push_back(std::move(fr));
    }
    if (c->opt->max_frames > 0 && c->out->delivered >= c->opt->max_frames) {
        c->stop = true;
    }
}

void on_msg(void *vctx, const sl_proto_msg_t *m)
{
    auto *c = static_cast<DecodeCtx *>(vctx);
    if (c->stop) {
        return;
    }
    if (m->id == SL_PROTO_ID_CONFIGURATION) {
        sl_proto_config_t cfg;
        if (sl_proto_parse_config(m, &cfg) == SL_OK) {
            const uint32_t um = sl_proto_config_bin_size_um(&cfg);
            if (um > 0 && c->config_bin_um == 0) {
                c->config_bin_um = um;
            }
        }
    }
    (void)sl_scan_on_msg(&c->scan, m);
}

bool is_dir(const std::string &p)
{
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

bool decode(MessageReader &rd, const FrameOptions &opt, FrameSet &out, std::string &err,
            const FrameFn *fn = nullptr)
{
    if (opt.roi_bins < 1 || opt.roi_bins > SL_CFG_ROI_BINS) {
        err = "roi_bins must be in 1.." + std::to_string(SL_CFG_ROI_BINS);
        return false;
    }
    auto ctx = std::make_unique<DecodeCtx>();
    auto fill = std::make_unique<sl_scan_frame_t>();
    auto spare = std::make_unique<sl_scan_frame_t>();
    ctx->opt = &opt;
    ctx->out = &out;
    ctx->fn = fn;
    sl_scan_cfg_t sc{};
    sc.roi_bins = static_cast<uint16_t>(opt.roi_bins);
    sc.pow16_shift = 8;
    sc.azimuths = static_cast<uint16_t>(opt.azimuths);
    sc.encoder_size = static_cast<uint16_t>(opt.encoder_size);
    sc.ignore_sweep = opt.ignore_sweep;
    sc.on_frame = on_frame;
    sc.ctx = ctx.get();
    if (sl_scan_init(&ctx->scan, &sc, fill.get(), spare.get()) != SL_OK) {
        err = "sl_scan_init rejected the geometry (azimuths " + std::to_string(opt.azimuths) +
              ", encoder " + std::to_string(opt.encoder_size) + ")";
        return false;
    }
    // The capture's messages, one at a time (capture.h MessageReader: the one way from a
    // capture's bytes to messages); reading stops once enough frames are kept.
    uint8_t id = 0;
    std::vector<uint8_t> m;
    while (!ctx->stop && rd.next(id, m)) {
        sl_proto_msg_t pm{};
        pm.id = id;
        pm.payload.data = m.data() + SL_PROTO_HEADER_BYTES;
        pm.payload.size = m.size() - SL_PROTO_HEADER_BYTES;
        pm.wire_bytes = static_cast<uint32_t>(pm.payload.size);
        on_msg(ctx.get(), &pm);
    }
    if (!rd.error().empty()) {
        err = rd.error();
        return false;
    }
    sl_scan_flush(&ctx->scan);
    out.proto = rd.stats();
    out.scan = ctx->scan.stats;
    out.roi_bins = opt.roi_bins;
    if (opt.bin_size_m > 0) {
        out.bin_size_m = opt.bin_size_m;
        out.bin_from_config = false;
    } else if (ctx->config_bin_um > 0) {
        out.bin_size_m = ctx->config_bin_um * 1e-6;
        out.bin_from_config = true;
    }
    // Rows shorter than the ROI (contoured data, captures with fewer bins) are zero-filled
    // by sl_scan: crop every frame to the longest row actually received.
    {
        int widest = ctx->widest;
        for (const auto &f : out.frames) {
            widest = std::max(widest, f.widest_row);
        }
        if (widest > 0 && widest < out.roi_bins) {
            for (auto &f : out.frames) {
                f.power = f.power(cv::Rect(0, 0, widest, f.power.rows)).clone();
            }
            out.roi_bins = widest;
        }
    }
    if (out.delivered == 0) {
        err = "no complete rotation decoded (" + std::to_string(out.proto.fft8 + out.proto.fft16) +
              " FFT messages, " + std::to_string(out.dropped_partial) + " partial frames)";
        return false;
    }
    if (out.bin_size_m <= 0) {
        err = "no bin size: the stream has no Configuration; give one (board or --bin-size-m)";
        return false;
    }
    return true;
}

} // namespace

bool decode_frames(const std::vector<uint8_t> &bytes, const FrameOptions &opt, FrameSet &out,
                   std::string &err)
{
    if (out.kind.empty()) {
        out.kind = "raw";
    }
    MessageReader rd;
    rd.open_memory(bytes.data(), bytes.size());
    return decode(rd, opt, out, err);
}

namespace {

bool read_path(const std::string &path, const FrameOptions &opt, FrameSet &out,
               const FrameFn *fn, std::string &err)
{
    out = FrameSet{};
    out.source = path;
    if (is_dir(path)) {
        OxfordOptions oo;
        if (opt.bin_size_m > 0) {
            oo.bin_size_m = opt.bin_size_m;
        }
        OxfordReport rep;
        std::vector<uint8_t> bytes;
        if (!oxford_to_colossus(path, oo, bytes, rep, err)) {
            return false;
        }
        out.kind = "oxford-png";
        MessageReader rd;
        rd.open_memory(bytes.data(), bytes.size());
        if (!decode(rd, opt, out, err, fn)) {
            err = path + ": " + err;
            return false;
        }
        return true;
    }
    // A capture file, pipe, FIFO or "-": streamed through the port's reader, never loaded.
    MessageReader rd;
    if (!rd.open(path, err)) {
        err = path + ": " + err;
        return false;
    }
    out.kind = capture_format_name(rd.format());
    const bool ok = decode(rd, opt, out, err, fn);
    out.kind = capture_format_name(rd.format());
    if (!ok) {
        if (err.compare(0, path.size(), path) != 0) {
            err = path + ": " + err;
        }
        return false;
    }
    return true;
}

} // namespace

bool for_each_frame(const std::string &path, const FrameOptions &opt, FrameSet &meta,
                    const FrameFn &fn, std::string &err)
{
    return read_path(path, opt, meta, &fn, err);
}

} // namespace sl
