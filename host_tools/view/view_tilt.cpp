// SPDX-License-Identifier: MIT
// view_tilt.cpp: the core pipeline with a constant motion input over a capture, collecting
// the fitted poles per rotation (view_tilt.h).
#include "view_tilt.h"

#include <cmath>
#include <memory>

#include "capture.h"
#include "shadowlean/sl_pipeline.h"

namespace slv {
namespace {

struct Ctx {
    sl_pipeline_t *p = nullptr;
    std::vector<std::vector<TiltMark>> *out = nullptr;
};

void on_rotation(void *ctx, const sl_pipeline_rotation_t *r)
{
    auto *c = static_cast<Ctx *>(ctx);
    std::vector<TiltMark> marks;
    const sl_tiltobs_t *t = &c->p->tilt;
    for (const sl_tiltobs_ring_t &ring : t->ring) {
        sl_tiltobs_vehicle_t v;
        if (ring.track_id == 0U || !sl_tiltobs_vehicle(t, &ring, &v) ||
            (v.quality != SL_TILT_FITTED && v.quality != SL_TILT_AMBIGUOUS)) {
            continue;
        }
        TiltMark m;
        m.id = ring.track_id;
        m.quality = v.quality;
        m.base_x_m = v.base_x_um * 1e-6;
        m.base_y_m = v.base_y_um * 1e-6;
        m.psi_deg = v.psi_cdeg / 100.0;
        m.phi_deg = v.phi_cdeg / 100.0;
        marks.push_back(m);
    }
    if (c->out->size() <= r->rotation) {
        c->out->resize(r->rotation + 1U);
    }
    (*c->out)[r->rotation] = std::move(marks);
}

} // namespace

bool tilt_marks(const std::string &path, const sl_board_t *b, double speed_mps, double yaw_dps,
                std::vector<std::vector<TiltMark>> &out, std::string &err)
{
    auto p = std::make_unique<sl_pipeline_t>();
    Ctx ctx{p.get(), &out};
    sl_pipeline_cfg_t cfg;
    sl_pipeline_cfg_default(&cfg, b);
    cfg.port.ctx = &ctx;
    cfg.port.on_rotation = on_rotation;
    if (sl_pipeline_init(p.get(), b, &cfg) != SL_OK) {
        err = "sl_pipeline_init rejected board " + std::string(b->name);
        return false;
    }
    const int32_t v = static_cast<int32_t>(std::lround(speed_mps * 1000.0));
    const int32_t w = static_cast<int32_t>(std::lround(yaw_dps * 100.0));
    // Motion refreshed before every chunk (the vehicle bus would send it at 50 Hz); the
    // rotation period comes from the radar's timestamps. The capture is streamed and cut
    // into 64 KiB chunks of the reassembled stream (memory: one chunk, not the capture).
    const size_t chunk = 65536;
    uint64_t now = 1000000U;
    std::vector<uint8_t> buf;
    buf.reserve(chunk);
    auto feed = [&] {
        sl_pipeline_set_motion(p.get(), v, true, w, true, now);
        (void)sl_pipeline_feed(p.get(), buf.data(), buf.size(), now);
        buf.clear();
        now += 1000U;
    };
    sl::Capture info;
    uint64_t bytes = 0;
    const bool ok = sl::read_capture(
        path,
        [&](const uint8_t *d, size_t n) {
            while (n > 0) {
                const size_t k = std::min(n, chunk - buf.size());
                buf.insert(buf.end(), d, d + k);
                d += k;
                n -= k;
                if (buf.size() == chunk) {
                    feed();
                }
            }
            return true;
        },
        sl::CaptureBreakFn{}, info, bytes, err);
    if (!ok) {
        return false;
    }
    if (!buf.empty()) {
        feed();
    }
    (void)sl_pipeline_finish(p.get(), now);
    return true;
}

} // namespace slv
