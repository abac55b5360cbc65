// SPDX-License-Identifier: MIT
// The detection pipeline (sl_pipeline.h): decoder -> frame-less scan -> threshold -> mask
// (window shortened with speed) -> streaming detection -> tracker -> CAN frames.
//
// Detection is fed while the rotation arrives, one row per azimuth in increasing order:
// the stable row straight out of sl_mask_update(). Azimuths the stream skipped get their
// held stable row from the mask (as sl_detect_rotation_from_mask() would); a late
// (out-of-order) row still updates the mask but detection has already passed it, so this
// rotation uses that azimuth's held row. At the rotation's end only sl_detect_end(), the
// tracker and the CAN encoding remain, which keeps the latency short.
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shadowlean/sl_pipeline.h"

#include "compiler.h"

#define ROTATION_US_MIN 50000U   // plausible radar rotation periods for the measured T
#define ROTATION_US_MAX 2000000U
#define LEARN_PEAK_BINS 256U     // bins beyond the shadow's edge the shape is learned from
#define MODEL_UPDATE_ROTATIONS 16U // rotations between adoptions of the learned shape
#define LEARN_FAST_ROTATIONS 64U   // cfg.learn_fast: every row read in at most these rotations

static void set_err(sl_pipeline_t *p, sl_err_t e, uint8_t reason, const char *msg)
{
    p->reason = reason;
    if (p->last_err == SL_OK) {
        p->last_err = e;
        p->last_err_msg = msg;
    }
}

void sl_pipeline_cfg_default(sl_pipeline_cfg_t *cfg, const sl_board_t *board)
{
    SL_ASSERT(cfg != NULL);
    memset(cfg, 0, sizeof *cfg);
    sl_detect_cfg_default(&cfg->detect);
    sl_track_cfg_default(&cfg->track);
    cfg->threshold = board != NULL ? board->threshold : 40U;
    cfg->mask_frames = board != NULL ? board->mask_frames : 16U;
    if (cfg->mask_frames == 0U || cfg->mask_frames > SL_CFG_MASK_FRAMES_MAX) {
        cfg->mask_frames = SL_CFG_MASK_FRAMES_MAX < 16 ? SL_CFG_MASK_FRAMES_MAX : 16U;
    }
    cfg->max_missed = SL_MASK_MAX_MISSED_DEFAULT;
    cfg->pow16_shift = 8U;
    cfg->confirm_hits = 3U;
    cfg->motion_adapt = true;
    cfg->min_frames = 1U;
    cfg->motion_budget_um = board != NULL ? board->bin_size_um : 43800U;
    cfg->motion_timeout_us = 500000U;
    cfg->rotation_us = 250000U;
    cfg->row_timeout_us = 1000000U;
    const sl_vscale_t cts = SL_VSCALE_CTS350X;
    cfg->value_scale = cts;
    if (board != NULL && !(board->value_scale.kind == (uint8_t)SL_VSCALE_LOG2 &&
                           board->value_scale.cpo_q8 == 0U)) {
        cfg->value_scale = board->value_scale;
    }
    cfg->learn = true;
    cfg->learn_fast = SL_CFG_FIT != 0;
    cfg->floor_margin_lp = 851U; // 10 dB = 10 / 3.0103 octaves x 256
    cfg->profile = true;
    cfg->fit = false;
    sl_profile_cfg_default(&cfg->profile_cfg);
#if SL_CFG_GROUND
    cfg->ground = true;
    sl_ground_cfg_default(&cfg->ground_cfg, board);
    cfg->ground_cfg.threshold = 0U; // the pipeline's threshold
#endif
}

uint8_t sl_pipeline_window(uint8_t n, uint8_t min_frames, int32_t speed_mm_s,
                           int32_t yaw_rate_cdeg_s, uint32_t rotation_us, uint32_t budget_um,
                           uint32_t r_max_um)
{
    if (n == 0U) {
        return 0U;
    }
    const uint8_t lo = min_frames == 0U ? 1U : (min_frames > n ? n : min_frames);
    const uint64_t v = (uint64_t)(speed_mm_s < 0 ? -(int64_t)speed_mm_s : (int64_t)speed_mm_s);
    const uint64_t w = (uint64_t)(yaw_rate_cdeg_s < 0 ? -(int64_t)yaw_rate_cdeg_s
                                                      : (int64_t)yaw_rate_cdeg_s);
    // Translation per rotation: v [mm/s] x T [us] / 1000 = um (rounded up).
    uint64_t disp = (v * rotation_us + 999U) / 1000U;
    // Rotation per rotation: w [cdeg/s] x T [us] -> urad = w T pi / (18000 x 1e6) x 1e6,
    // pi ~ 355/113; the farthest point of interest moves r_max x angle.
    uint64_t urad = (w * rotation_us * 355U + 113U * 18000U - 1U) / (113U * 18000U);
    if (urad > 7000000U) {
        urad = 7000000U; // more than a turn per rotation: anything moves anywhere
    }
    disp += ((uint64_t)r_max_um * urad + 999999U) / 1000000U;
    if (disp == 0U) {
        return n;
    }
    // (n_eff - 1) x disp <= D.
    const uint64_t ne = (uint64_t)budget_um / disp + 1U;
    if (ne >= n) {
        return n;
    }
    return (uint8_t)(ne < lo ? lo : ne);
}

// ------------------------------------------------------------------------------- motion

// The newest fresh motion (setter or CAN). False: none, or older than the timeout.
static bool motion_now(const sl_pipeline_t *p, uint64_t now_us, sl_can_vehicle_motion_t *out)
{
    sl_can_vehicle_motion_t can;
    const bool have_can = sl_can_motion_rx_get(&p->motion_rx, now_us, &can);
    const bool have_set = p->motion_set && now_us >= p->motion_t_us &&
                          now_us - p->motion_t_us <= p->cfg.motion_timeout_us;
    if (have_set && (!have_can || p->motion_t_us >= p->motion_rx.last_t_us)) {
        *out = p->motion;
        return true;
    }
    if (have_can) {
        *out = can;
        return true;
    }
    return false;
}

// ------------------------------------------------------------------------------- output

// Hard output ceiling (sl_can.h): two token buckets on the port's clock, one for
// PoleLean/LeanWarning, one for Status/Health: refilled at SL_CAN_MAX_*_FRAMES_PER_100MS per
// 100 ms, holding at most SL_CAN_BURST_WINDOWS times that (a backlog after a stall). A frame
// without a token is withheld, counted and flagged (CAN_RATE_LIMITED). Tokens in 1/1000.
static bool can_budget(sl_pipeline_t *p, bool status, uint32_t frames)
{
    uint32_t *tokens = status ? &p->can_tokens_status : &p->can_tokens_data;
    if (!p->can_clock_set) {
        p->can_clock_set = true;
        p->can_tokens_data = SL_CAN_MAX_DATA_FRAMES_PER_100MS * SL_CAN_BURST_WINDOWS * 1000U;
        p->can_tokens_status = SL_CAN_MAX_STATUS_FRAMES_PER_100MS * SL_CAN_BURST_WINDOWS * 1000U;
        p->can_clock_us = p->now_us;
    }
    if (p->now_us > p->can_clock_us) {
        const uint64_t dt = p->now_us - p->can_clock_us;
        // rate frames per 100,000 us = rate / 100 milli-frames per us; both buckets.
        const uint64_t add_d = dt * SL_CAN_MAX_DATA_FRAMES_PER_100MS / 100U;
        const uint64_t add_s = dt * SL_CAN_MAX_STATUS_FRAMES_PER_100MS / 100U;
        const uint64_t cap_d = (uint64_t)SL_CAN_MAX_DATA_FRAMES_PER_100MS * SL_CAN_BURST_WINDOWS * 1000U;
        const uint64_t cap_s = (uint64_t)SL_CAN_MAX_STATUS_FRAMES_PER_100MS * SL_CAN_BURST_WINDOWS * 1000U;
        const uint64_t td = p->can_tokens_data + add_d;
        const uint64_t ts = p->can_tokens_status + add_s;
        p->can_tokens_data = (uint32_t)(td > cap_d ? cap_d : td);
        p->can_tokens_status = (uint32_t)(ts > cap_s ? cap_s : ts);
    }
    p->can_clock_us = p->now_us; // a clock going backwards refills nothing
    if (*tokens < frames * 1000U) {
        p->stats.can_rate_limited += frames;
        p->fault_latched |= (uint16_t)SL_CAN_FAULT_CAN_RATE_LIMITED;
        return false;
    }
    *tokens -= frames * 1000U;
    return true;
}

// One frame to the port (budget already taken).
static void can_out(sl_pipeline_t *p, const sl_can_frame_t *f)
{
    if (p->cfg.port.can_tx(p->cfg.port.ctx, f) == SL_OK) {
        p->stats.can_frames++;
    } else {
        p->stats.can_dropped++; // SL_ERR_BUSY or a port error: never retried, never blocks
    }
}

static void can_send(sl_pipeline_t *p, const sl_can_frame_t *f)
{
    if (p->cfg.port.can_tx != NULL && can_budget(p, false, 1U)) {
        can_out(p, f);
    }
}

static int32_t vehicle_az_cdeg(const sl_pipeline_t *p, uint16_t az)
{
    const int64_t a = (int64_t)az * 36000 / (int64_t)p->board->azimuths;
    return (int32_t)(a + p->board->radar_yaw_cdeg);
}

static uint8_t quality_of(const sl_track_t *t)
{
    if (t->valid_hits > 0U) {
        return (uint8_t)SL_CAN_QUALITY_FILTERED;
    }
    switch (t->last_flag) {
    case SL_INCLINE_AMBIGUOUS: return (uint8_t)SL_CAN_QUALITY_AMBIGUOUS;
    case SL_INCLINE_OUT_OF_DOMAIN: return (uint8_t)SL_CAN_QUALITY_OUT_OF_MODEL;
    default: return (uint8_t)SL_CAN_QUALITY_INVALID;
    }
}

// A usable row arrived within cfg.row_timeout_us of now.
static bool rows_fresh(const sl_pipeline_t *p)
{
    return p->have_row && p->now_us >= p->last_row_us &&
           p->now_us - p->last_row_us <= (uint64_t)p->cfg.row_timeout_us;
}

// Reconnects within the flapping window at `now`.
static bool flapping(const sl_pipeline_t *p)
{
    if (p->stats.reconnects < SL_CAN_FLAP_RECONNECTS) {
        return false;
    }
    // The oldest of the last SL_CAN_FLAP_RECONNECTS reconnect times.
    const uint64_t oldest = p->reconnect_t_us[p->reconnect_next % SL_CAN_FLAP_RECONNECTS];
    return p->now_us >= oldest && p->now_us - oldest <= (uint64_t)SL_CAN_FLAP_WINDOW_MS * 1000U;
}

uint16_t sl_pipeline_faults(const sl_pipeline_t *p)
{
    if (p == NULL) {
        return 0U;
    }
    uint16_t f = p->fault_latched;
    if (p->geometry_bad) {
        f |= (uint16_t)SL_CAN_FAULT_CONFIG_MISMATCH;
    }
    if (p->bin_size_bad) {
        f |= (uint16_t)SL_CAN_FAULT_RANGE_RESOLUTION_MISMATCH;
    }
    const bool connected = p->link_state == (uint8_t)SL_CAN_LINK_STREAMING ||
                           p->link_state == (uint8_t)SL_CAN_LINK_SILENT ||
                           p->link_state == (uint8_t)SL_CAN_LINK_WAIT_CONFIG;
    const bool fft_seen = p->scan.stats.fft != p->snap.fft;
    if (!rows_fresh(p) && (connected || fft_seen)) {
        f |= (uint16_t)SL_CAN_FAULT_NO_USABLE_ROWS;
    }
    if (p->decoder_stats->resyncs != p->snap.resyncs || p->scan.stats.malformed != p->snap.malformed ||
        p->scan.stats.bad_azimuth != p->snap.bad_azimuth ||
        p->scan.stats.empty_rows != p->snap.empty_rows) {
        f |= (uint16_t)SL_CAN_FAULT_MALFORMED_DATA;
    }
    if (p->stats.can_dropped != p->snap.can_dropped) {
        f |= (uint16_t)SL_CAN_FAULT_CAN_OUTPUT_ERRORS;
    }
    if (p->scan.stats.disorder != p->snap.disorder) {
        f |= (uint16_t)SL_CAN_FAULT_AZIMUTH_DISORDER;
    }
    if (p->detect.stats.target_overflow != p->snap.target_overflow) {
        f |= (uint16_t)SL_CAN_FAULT_TARGET_SLOTS_OVERFLOW;
    }
    if (flapping(p)) {
        f |= (uint16_t)SL_CAN_FAULT_LINK_FLAPPING;
    }
    if (p->drift.fault) {
        f |= (uint16_t)SL_CAN_FAULT_THETA_DRIFT;
    }
    if (p->stats.motion_rejected != p->snap.motion_rejected) {
        f |= (uint16_t)SL_CAN_FAULT_MOTION_E2E;
    }
    return f;
}

// One Status frame with the current counters and link state (rotation or idle), then one
// Health frame. The link state sent is STREAMING only while usable rows arrive: a port
// that says STREAMING without a usable row since the previous Status is reported SILENT.
static void emit_status(sl_pipeline_t *p)
{
    uint8_t link = p->link_state;
    if (link == (uint8_t)SL_CAN_LINK_STREAMING && p->rows_since_status == 0U && !rows_fresh(p)) {
        link = (uint8_t)SL_CAN_LINK_SILENT;
    }
    p->rows_since_status = 0U;
    const sl_can_status_t st = {
        .link_state = link,
        .rotations = p->stats.rotations,
        .azimuths_missing = p->stats.azimuths_missing,
        .decoder_resyncs = p->decoder_stats->resyncs,
        .can_dropped = p->stats.can_dropped,
    };
    // Status and its Health pass the ceiling together (a Health never goes missing alone).
    const bool send = p->cfg.port.can_tx != NULL && can_budget(p, true, 2U);
    sl_can_frame_t f;
    if (sl_can_encode_status(&p->can, &st, &f) == SL_OK && send) {
        can_out(p, &f);
    }
    const uint16_t faults = sl_pipeline_faults(p);
    const sl_can_health_t h = {
        .fault = faults,
        .reconnects = p->stats.reconnects,
        .candidates_dropped = p->detect.stats.target_overflow,
        .theta_drift_cdeg = sl_drift_cdeg(&p->drift),
        .response_source = p->resp.source,
    };
    p->faults_seen |= faults;
    sl_can_frame_t hf;
    const bool hok = sl_can_encode_health(&p->can, &h, &hf) == SL_OK; // counter advances
    if (!send) {
        return; // withheld by the ceiling: the next Health that goes out reports all of it
    }
    p->last_faults = faults;
    // The next Health reports what happens from now on, including the fate of this Health
    // frame itself (a refusal counts as a CAN output error next time); persistent faults
    // are re-derived each time.
    p->fault_latched = 0U;
    p->rows_since_health = 0U;
    p->snap.fft = p->scan.stats.fft;
    p->snap.resyncs = p->decoder_stats->resyncs;
    p->snap.malformed = p->scan.stats.malformed;
    p->snap.bad_azimuth = p->scan.stats.bad_azimuth;
    p->snap.empty_rows = p->scan.stats.empty_rows;
    p->snap.can_dropped = p->stats.can_dropped;
    p->snap.disorder = p->scan.stats.disorder;
    p->snap.target_overflow = p->detect.stats.target_overflow;
    p->snap.motion_rejected = p->stats.motion_rejected;
    if (hok) {
        can_out(p, &hf);
    }
}

// What LeanWarning says about a track (sl_pipeline.h, "LeanWarning and the fitted tilt"):
// the tracker's level, filtered in-plane alpha and sigma, or, when the track's drive-by fit
// is FITTED, the tilt towards the vehicle's path, its sigma and the level of that lean; when
// it is AMBIGUOUS, the same of the more dangerous of its two readings that are usable
// (ambiguous_usable), else the tracker's.
typedef struct warn_view {
    uint8_t level;
    bool valid;        // a lean number
    bool fitted;       // from the 3D fit
    int32_t lean_cdeg;
    uint16_t sigma_cdeg;
} warn_view_t;

static uint8_t lean_level(const sl_pipeline_t *p, int32_t a)
{
    const sl_board_t *b = p->board;
    if (b->danger_lean_cdeg > 0 && a >= b->danger_lean_cdeg) {
        return (uint8_t)SL_WARN_DANGER;
    }
    const int32_t m = p->cfg.track.caution_abs ? sl_fx_abs32(a) : a;
    if (b->caution_lean_cdeg > 0 && m >= b->caution_lean_cdeg) {
        return (uint8_t)SL_WARN_CAUTION;
    }
    return (uint8_t)SL_WARN_NONE;
}

// An AMBIGUOUS fit's reading speaks for the warning only when it is a pole's (its tilt
// within the largest lean the detector keeps a pole for) and its lean over the path is known
// within the tracker's sigma limit (cfg.track.max_sigma_cdeg, as a tracker's level rises).
static bool ambiguous_usable(const sl_pipeline_t *p, const sl_tiltobs_vehicle_t *tv)
{
    const uint16_t mt = p->tilt.max_tan_q16;
    const int32_t max_psi = (mt == 0U) ? 9000
        : sl_incline_bam32_to_cdeg(sl_incline_atan2_bam32((int32_t)mt, (int32_t)65536));
    return tv->psi_cdeg <= max_psi && tv->lean_path_sigma_cdeg <= p->cfg.track.max_sigma_cdeg;
}

static SL_NOINLINE void warn_view(const sl_pipeline_t *p, const sl_track_t *t, warn_view_t *v)
{
    v->level = t->level;
    v->valid = t->valid_hits > 0U;
    v->fitted = false;
    v->lean_cdeg = t->alpha_cdeg;
    v->sigma_cdeg = t->sigma_cdeg;
    if (!p->tilt.moving) {
        return;
    }
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&p->tilt, t->id);
    sl_tiltobs_vehicle_t tv;
    if (!sl_tiltobs_vehicle(&p->tilt, r, &tv) ||
        (tv.quality != (uint8_t)SL_TILT_FITTED && tv.quality != (uint8_t)SL_TILT_AMBIGUOUS)) {
        return;
    }
    const bool amb = tv.quality == (uint8_t)SL_TILT_AMBIGUOUS;
    for (uint32_t k = 0U; k < 2U; k++) { // the best reading, then an AMBIGUOUS fit's other one
        if (k == 1U && !sl_tiltobs_vehicle_mirror(&p->tilt, r, &tv)) {
            break;
        }
        if (amb && !ambiguous_usable(p, &tv)) {
            continue;
        }
        const uint8_t lv = lean_level(p, tv.lean_path_cdeg);
        if (!v->fitted || lv > v->level || (lv == v->level && tv.lean_path_cdeg > v->lean_cdeg)) {
            v->valid = true;
            v->fitted = true;
            v->lean_cdeg = tv.lean_path_cdeg;
            v->sigma_cdeg = tv.lean_path_sigma_cdeg;
            v->level = lv;
        }
    }
}

// PoleTilt of track `t` when it has an observation history with a fit; an AMBIGUOUS fit's
// frame is followed by its other reading's (Quality MIRROR, sl_can.h): the two pass the
// output ceiling together or not at all.
static SL_NOINLINE void emit_tilt(sl_pipeline_t *p, const sl_track_t *t)
{
    const sl_tiltobs_ring_t *r = sl_tiltobs_find(&p->tilt, t->id);
    bool send = false;
    for (uint32_t k = 0U; k < 2U && p->tilt.moving; k++) {
        sl_tiltobs_vehicle_t tv;
        if (!(k == 0U ? sl_tiltobs_vehicle(&p->tilt, r, &tv)
                      : sl_tiltobs_vehicle_mirror(&p->tilt, r, &tv))) {
            return;
        }
        if (k == 0U) {
            uint32_t frames = 1U; // an AMBIGUOUS frame goes with its MIRROR frame
            if (tv.quality == (uint8_t)SL_TILT_AMBIGUOUS) {
                frames = 2U;
            }
            send = p->cfg.port.can_tx != NULL && can_budget(p, false, frames);
        }
        const sl_can_pole_tilt_t pt = {
            .target_id = (uint8_t)(t->id & 15U),
            .quality = k == 0U ? tv.quality : (uint8_t)SL_CAN_TILT_MIRROR,
            .tilt_cdeg = tv.psi_cdeg,
            .direction_cdeg = tv.phi_cdeg,
            .tilt_sigma_cdeg = tv.psi_sigma_cdeg,
            .direction_sigma_cdeg = tv.phi_sigma_cdeg,
            .base_x_um = tv.base_x_um,
            .base_y_um = tv.base_y_um,
        };
        sl_can_frame_t f;
        if (sl_can_encode_pole_tilt(&p->can, &pt, &f) == SL_OK && send) {
            can_out(p, &f);
        }
    }
}

#if SL_CFG_GROUND
// With the ground on: GroundPlane (NONE without a plane), then one GroundHazard per sector
// with a confirmed hazard, in sector order (sl_can.h). Each frame passes the output ceiling
// on its own, as PoleLean does; a withheld frame still advances its E2E counter.
static SL_NOINLINE void emit_ground(sl_pipeline_t *p)
{
    const sl_ground_t *g = &p->ground;
    const sl_ground_plane_t *pl = &g->plane;
    const sl_can_ground_plane_t gp = {
        .quality = pl->quality,
        .height_mm = pl->height_mm,
        .pitch_cdeg = pl->pitch_cdeg,
        .roll_cdeg = pl->roll_cdeg,
        .height_sigma_mm = pl->height_sigma_mm,
        .pitch_sigma_cdeg = pl->pitch_sigma_cdeg,
        .roll_sigma_cdeg = pl->roll_sigma_cdeg,
    };
    sl_can_frame_t f;
    if (sl_can_encode_ground_plane(&p->can, &gp, &f) == SL_OK) {
        can_send(p, &f);
    }
    for (uint32_t k = 0; k < (uint32_t)SL_CFG_GROUND_SECTORS; k++) {
        const sl_ground_sector_t *s = &g->sec[k];
        if (s->kind == (uint8_t)SL_GROUND_FLAT) {
            continue;
        }
        const sl_can_ground_hazard_t h = {
            .kind = s->kind,
            .sector = (uint8_t)k,
            .azimuth_cdeg = sl_ground_sector_cdeg(g, k),
            .height_diff_mm = -s->resid_mm, // the ground above the plane (resid: below it)
            .distance_um = s->dist_um > 0 ? (uint32_t)s->dist_um : 0U,
            .sigma_mm = s->sigma_mm,
        };
        if (sl_can_encode_ground_hazard(&p->can, &h, &f) == SL_OK) {
            can_send(p, &f);
        }
    }
}
#endif

static void emit_can(sl_pipeline_t *p)
{
    const sl_tracker_t *tr = &p->tracker;
    const uint16_t confirm = p->cfg.confirm_hits == 0U ? 1U : p->cfg.confirm_hits;
    sl_can_frame_t f;
    const sl_track_t *worst = NULL;
    warn_view_t wv = {0U, false, false, 0, 0U};
    for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
        const sl_track_t *t = &tr->tracks[i];
        if (t->live == 0U || t->hits < confirm || t->confirmed == 0U) {
            continue;
        }
        // The most severe confirmed track: level, then |lean| (valid ones first).
        warn_view_t v;
        warn_view(p, t, &v);
        if (worst == NULL || v.level > wv.level ||
            (v.level == wv.level &&
             ((v.valid && !wv.valid) ||
              (v.valid && sl_fx_abs32(v.lean_cdeg) > sl_fx_abs32(wv.lean_cdeg))))) {
            worst = t;
            wv = v;
        }
        if (t->updated == 0U) {
            continue; // PoleLean only for tracks seen this rotation
        }
        if (t->last_slant != 0U) {
            // ... on one azimuth's run: a pole leaning across the beam (SL_TARGET_SLANT) has
            // none (its bounds span the group's azimuths). It still updates the track, its
            // warning and the 3D tilt: its PoleTilt goes out alone.
            emit_tilt(p, t);
            continue;
        }
        const uint8_t q = quality_of(t);
        const bool has_lean = q == (uint8_t)SL_CAN_QUALITY_FILTERED;
        const sl_can_pole_lean_t pl = {
            .target_id = (uint8_t)(t->id & 15U),
            .quality = q,
            .azimuth_cdeg = vehicle_az_cdeg(p, t->az),
            .range_inner_um = t->r1_um, // rounded once, by the encoder
            .range_outer_um = t->r2_um,
            .lean_cdeg = has_lean ? t->alpha_cdeg : 0,
            .lean_sigma_cdeg = has_lean ? t->sigma_cdeg : 0U,
        };
        if (sl_can_encode_pole_lean(&p->can, &pl, &f) == SL_OK) {
            can_send(p, &f);
        }
        emit_tilt(p, t);
    }
    sl_can_lean_warning_t lw;
    memset(&lw, 0, sizeof lw);
    if (worst != NULL) {
        const uint8_t q = wv.fitted ? (uint8_t)SL_CAN_QUALITY_FILTERED : quality_of(worst);
        const bool has_lean = q == (uint8_t)SL_CAN_QUALITY_FILTERED;
        lw.level = wv.level;
        lw.has_target = true;
        lw.target_id = (uint8_t)(worst->id & 15U);
        lw.quality = q;
        lw.azimuth_cdeg = vehicle_az_cdeg(p, worst->az);
        lw.range_um = worst->r1_um;
        lw.lean_cdeg = has_lean ? wv.lean_cdeg : 0;
        lw.lean_sigma_cdeg = has_lean ? wv.sigma_cdeg : 0U;
    }
    if (sl_can_encode_lean_warning(&p->can, &lw, &f) == SL_OK) {
        can_send(p, &f);
    }
#if SL_CFG_GROUND
    if (p->cfg.ground) {
        emit_ground(p);
    }
#endif
    // Status last: it reports the drops of this rotation's frames too.
    emit_status(p);
}

// ------------------------------------------------------------------------------- rotation

// Slots by evidence (sl_detect.h stage 4b): the azimuths where confirmed tracks are,
// widened by the tracker's azimuth gate, get the track bonus, so an established pole keeps
// its slot however much clutter competes for the slots.
static void detect_hints_from_tracks(sl_pipeline_t *p)
{
    sl_detect_hints_clear(&p->detect);
    const sl_tracker_t *tr = &p->tracker;
    for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
        const sl_track_t *t = &tr->tracks[i];
        if (t->live != 0U && t->confirmed != 0U) {
            sl_detect_hint(&p->detect, t->az, sl_track_gate_az(tr, t));
        }
    }
}

// ------------------------------------------------------------------------- sensor model

// The smallest 8-bit value whose power is at least lp (255 when none is).
static uint8_t value_at_least(const sl_response_t *r, int32_t lp)
{
    uint32_t v = 0U;
    while (v < 255U && r->lp_q8[v] < lp) {
        v++;
    }
    return (uint8_t)v;
}

// Occupied thresholds per floor band: the configured one, raised where the learned noise
// floor's mean plus the margin is higher (a radar whose receiver noise sits above the
// configured threshold would otherwise mark every bin occupied). Bands with no floor yet,
// or one the 8-bit scale does not resolve (sl_response_floor_resolved), keep the configured
// threshold.
static void update_thresholds(sl_pipeline_t *p)
{
    const uint32_t base = p->cfg.threshold > 255U ? 255U : p->cfg.threshold;
    const uint32_t bands = ((uint32_t)p->mask_bins + SL_RESP_FLOOR_BAND - 1U) / SL_RESP_FLOOR_BAND;
    p->thr_flat = true;
    for (uint32_t b = 0; b < SL_CFG_RESP_FLOOR_BANDS; b++) {
        uint32_t t = base;
        const int32_t fl = b < bands ? sl_response_floor_lp(&p->resp, b * SL_RESP_FLOOR_BAND)
                                     : INT32_MIN;
        if (fl != INT32_MIN && p->cfg.learn &&
            sl_response_floor_resolved(&p->resp, b * SL_RESP_FLOOR_BAND)) {
            const uint32_t v = value_at_least(&p->resp, fl + (int32_t)p->cfg.floor_margin_lp);
            t = v > t ? v : t;
        }
        p->thr_band[b] = (uint8_t)t;
        p->thr_flat = p->thr_flat && t == base;
    }
}

// The row the sensor model reads: one azimuth per rotation, moving by 247 of 400 azimuths
// (the golden section of the turn) each rotation, so successive rows spread over the turn
// and every azimuth is read in turn, or to the next azimuth after a row that gave a peak.
// The floor is read inside the shadow (beyond the near-field band): there only the
// receiver's noise and sparse targets are. The shape is read from isolated peaks beyond the
// shadow, over the message's own 8-bit bins (past the masked ones where the radar sends
// them), over LEARN_PEAK_BINS beyond the shadow's edge (the near scene, where returns are
// strongest; the cost per rotation stays bounded however long the radar's rows are): inside
// the shadow a slender target's own extent would be taken for the response.
static SL_NOINLINE void learn_row(sl_pipeline_t *p, const sl_scan_row_t *row)
{
    const uint32_t near = p->det_board.near_exclusion_bins;
    const uint32_t edge = p->det_board.shadow_bins != NULL ? p->det_board.shadow_bins[row->idx]
                                                           : 0U;
    const uint32_t in_end = edge < p->mask_bins ? edge : p->mask_bins;
    if (near < in_end) {
        (void)sl_response_learn_floor(&p->resp, row->power, p->mask_bins, near, in_end);
    }
    const sl_proto_fft_t *f = row->fft;
    if (f != NULL && f->bin_data != NULL && f->bytes_per_bin == 1U) {
        const uint32_t reach = edge + 1U + LEARN_PEAK_BINS;
        const uint32_t n = f->bins < reach ? f->bins : reach;
        if (edge + 1U < n) {
            p->learn_hit = sl_response_learn_peaks(&p->resp, f->bin_data, n, edge + 1U, n) > 0;
        }
    }
}

#if SL_CFG_FIT
// cfg.learn_fast applies: the fit reads the response (cfg.fit), the shape in use is still
// the board's prior, within the stream's first LEARN_FAST_ROTATIONS rotations (a stream
// without isolated returns would otherwise be read row by row for ever).
static bool learning_fast(const sl_pipeline_t *p)
{
    return p->cfg.fit && p->cfg.learn_fast && p->resp.source == (uint8_t)SL_RESPONSE_PRIOR &&
           p->stats.rotations < LEARN_FAST_ROTATIONS;
}
#endif

// Rotation end: the thresholds follow the floor; every MODEL_UPDATE_ROTATIONS rotations the
// learned shape replaces the one in use once enough peaks agree (sl_response.h: deriving
// the taps, cumulative and speckle correlation costs tens of thousands of instructions, and
// the running medians move by a step per peak).
static void model_end_rotation(sl_pipeline_t *p)
{
    if (!p->cfg.learn) {
        return;
    }
    bool update = p->stats.rotations % MODEL_UPDATE_ROTATIONS == MODEL_UPDATE_ROTATIONS - 1U;
#if SL_CFG_FIT
    update = update || (learning_fast(p) && p->resp.learn_n >= p->resp.cfg.min_peaks);
#endif
    if (update) {
        (void)sl_response_update(&p->resp);
    }
    update_thresholds(p);
    // A row that gave a peak is followed by its neighbour (the beam holds a point return
    // over a few azimuths); otherwise the next row is 247 of 400 azimuths on.
    const uint32_t naz = p->det_board.azimuths;
    const uint32_t step = p->learn_hit ? 1U : (naz * 618U + 500U) / 1000U;
    p->learn_az = (uint16_t)(((uint32_t)p->learn_az + step) % naz);
    p->learn_hit = false;
}

// Thresholds one row into p->bits band by band (on_row calls sl_thresh_u8 itself while every
// band has the configured threshold).
static SL_NOINLINE void threshold_bands(sl_pipeline_t *p, const uint8_t *power)
{
    for (uint32_t k = 0; k < p->mask_bins; k += SL_RESP_FLOOR_BAND) {
        const uint32_t n = p->mask_bins - k < SL_RESP_FLOOR_BAND ? p->mask_bins - k
                                                                 : SL_RESP_FLOOR_BAND;
        sl_thresh_u8(power + k, n, p->thr_band[k / SL_RESP_FLOOR_BAND], p->bits + k / 32U);
    }
}

static void begin_rotation(sl_pipeline_t *p)
{
    sl_can_vehicle_motion_t m;
    uint8_t w = p->cfg.mask_frames;
    p->motion_valid = false;
    p->speed_mm_s = 0;
    p->yaw_cdeg_s = 0;
    if (motion_now(p, p->now_us, &m)) {
        p->motion_valid = m.speed_valid || m.yaw_rate_valid;
        p->speed_mm_s = m.speed_valid ? m.speed_mm_s : 0;
        p->yaw_cdeg_s = m.yaw_rate_valid ? m.yaw_rate_cdeg_s : 0;
    }
    p->detect.union_ext = p->motion_valid; // group extents for the tilt history
    // Poles leaning across the beam (SLANT, sl_detect.h stage 4): with range profiles their
    // far end is refined on the azimuth of their lowest point (sl_profile.h).
    p->detect.slant = p->motion_valid;
    if (p->motion_valid && p->cfg.motion_adapt) {
        w = sl_pipeline_window(p->cfg.mask_frames, p->cfg.min_frames, p->speed_mm_s,
                               p->yaw_cdeg_s, p->rotation_us, p->cfg.motion_budget_um,
                               p->r_max_um);
    }
    p->frames_eff = w;
    (void)sl_mask_set_window(&p->mask, w);
    sl_detect_begin(&p->detect);
    detect_hints_from_tracks(p);
    p->next_az = 0U;
    p->in_rotation = 1U;
}

// Detection rows for azimuths [from, to) that got no row (yet) this rotation: their held
// stable rows, unless the mask will drop their history at the end of this rotation, or the
// vehicle moved too far since the row was taken. A row m + 1 rotations old (m = missed so
// far) shows the scene displaced by up to (m + 1) x disp, and (n_eff - 1) x disp <= D, so
// it is still within the cell budget D only when m + 2 <= n_eff. While moving faster than
// D / T (n_eff = 1) a lost azimuth is simply absent, never a stale ghost.
static void feed_held(sl_pipeline_t *p, uint32_t from, uint32_t to)
{
    for (uint32_t a = from; a < to; a++) {
        const uint32_t missed = sl_mask_missed(&p->mask, (uint16_t)a);
        if (!sl_mask_has_history(&p->mask, (uint16_t)a) || missed + 1U > p->mask.max_missed ||
            missed + 2U > p->frames_eff) {
            continue;
        }
        (void)sl_mask_stable_prefix(&p->mask, (uint16_t)a, p->mask_words, p->occ, NULL);
        (void)sl_detect_row(&p->detect, (uint16_t)a, p->occ, p->mask_words);
    }
}

#if SL_CFG_GROUND
// The ground's row: the raw message's 8-bit bins (the whole range), else (16-bit) the
// scan's reduced row of the masked bins.
static SL_NOINLINE void ground_row(sl_pipeline_t *p, const sl_scan_row_t *row)
{
    const sl_proto_fft_t *f = row->fft;
    // the row thresholded for the mask serves the occupied test when the thresholds agree
    const uint32_t *bits = p->ground.cfg.threshold == p->cfg.threshold ? p->bits : NULL;
    if (f != NULL && f->bin_data != NULL && f->bytes_per_bin == 1U) {
        sl_ground_row(&p->ground, row->idx, f->bin_data, f->bins, bits, p->mask_bins);
    } else {
        sl_ground_row(&p->ground, row->idx, row->power, p->mask_bins, bits, p->mask_bins);
    }
}
#endif

static void on_row(void *ctx, const sl_scan_row_t *row)
{
    sl_pipeline_t *p = ctx;
    if (p->geometry_bad) {
        p->stats.rows_dropped++; // the radar announced another geometry than the board's
        return;
    }
    if (p->in_rotation == 0U) {
        begin_rotation(p);
    }
    p->stats.azimuths++;
    p->rows_since_status++;
    p->rows_since_health++;
    p->last_row_us = p->now_us;
    p->have_row = true;
    if (p->thr_flat) {
        sl_thresh_u8(row->power, p->mask_bins, p->cfg.threshold, p->bits);
    } else {
        threshold_bands(p, row->power);
    }
    if (row->idx == p->learn_az && p->cfg.learn) {
        learn_row(p, row);
    }
#if SL_CFG_FIT
    else if (p->cfg.learn && learning_fast(p)) {
        learn_row(p, row);
    }
#endif
    if (row->idx == p->drift.watch_az) { // once per rotation: the bins past the mask
        sl_drift_tail(&p->drift, row->fft, p->mask_bins, p->cfg.pow16_shift, p->cfg.threshold);
    }
#if SL_CFG_GROUND
    if (p->cfg.ground && row->idx >= sl_ground_want(&p->ground)) {
        ground_row(p, row); // `reads` rows per sector and rotation
    }
#endif
    if (p->cfg.profile) {
        sl_profile_row(&p->prof, row->idx, row->power, p->mask_bins, p->bits,
                       p->detect.win_bins[row->idx < p->detect.azimuths ? row->idx : 0U]);
    }
    if (row->idx >= p->next_az) {
        if (row->idx > p->next_az) {
            feed_held(p, p->next_az, row->idx);
        }
        if (sl_mask_update(&p->mask, row->idx, p->bits, p->occ, NULL) == SL_OK) {
            sl_detect_set_amplitude(&p->detect, row->power, p->mask_bins,
                                    (uint8_t)(p->cfg.threshold > 255U ? 255U : p->cfg.threshold));
            (void)sl_detect_row(&p->detect, row->idx, p->occ, p->mask_words);
        }
        p->next_az = (uint16_t)(row->idx + 1U);
    } else {
        // Late row: counts for the mask; detection of this rotation used the held row.
        (void)sl_mask_update(&p->mask, row->idx, p->bits, NULL, NULL);
    }
}

static void measure_period(sl_pipeline_t *p, const sl_scan_rot_t *rot)
{
    if (rot->end == (uint8_t)SL_SCAN_END_WRAP && p->last_t_last_us != 0U &&
        rot->t_last_us > p->last_t_last_us) {
        const uint64_t d = rot->t_last_us - p->last_t_last_us;
        if (d >= ROTATION_US_MIN && d <= ROTATION_US_MAX) {
            p->rotation_us = (uint32_t)d;
        }
    }
    p->last_t_last_us = rot->stats.valid != 0U ? rot->t_last_us : 0U;
}

// Tracker gates follow the ego motion of one rotation.
static SL_NOINLINE void set_track_motion(sl_pipeline_t *p)
{
    uint32_t disp_um = 0, yaw_bam = 0;
    if (p->motion_valid) {
        const uint64_t v = (uint64_t)(p->speed_mm_s < 0 ? -(int64_t)p->speed_mm_s
                                                        : (int64_t)p->speed_mm_s);
        const uint64_t w = (uint64_t)(p->yaw_cdeg_s < 0 ? -(int64_t)p->yaw_cdeg_s
                                                        : (int64_t)p->yaw_cdeg_s);
        const uint64_t d = (v * p->rotation_us + 999U) / 1000U;
        // w [cdeg/s] x T [us] / 1e6 = cdeg per rotation; x 2^32 / 36000 (~119305) = bam32.
        const uint64_t cd_e6 = w * p->rotation_us; // cdeg x 1e6, < 2^37
        const uint64_t bam = (cd_e6 * 119305U + 999999U) / 1000000U;
        disp_um = d > UINT32_MAX ? UINT32_MAX : (uint32_t)d;
        yaw_bam = bam > UINT32_MAX ? UINT32_MAX : (uint32_t)bam;
    }
    sl_track_set_motion(&p->tracker, disp_um, yaw_bam);
}

// The port's per-rotation report.
static SL_NOINLINE void report_rotation(sl_pipeline_t *p, const sl_scan_rot_t *rot,
                                        uint32_t n_targets)
{
    const sl_pipeline_rotation_t r = {
        .rotation = p->stats.rotations - 1U,
        .now_us = p->now_us,
        .t_first_us = rot->t_first_us,
        .t_last_us = rot->t_last_us,
        .azimuths = rot->azimuths,
        .valid = rot->stats.valid,
        .missing = rot->stats.missing,
        .end = rot->end,
        .frames_eff = p->frames_eff,
        .motion_valid = p->motion_valid,
        .speed_mm_s = p->speed_mm_s,
        .yaw_rate_cdeg_s = p->yaw_cdeg_s,
        .targets = p->detect.targets,
        .n_targets = (uint16_t)n_targets,
        .tracks = p->tracker.tracks,
        .n_track_slots = SL_CFG_MAX_TARGETS,
        .level = (uint8_t)sl_track_max_level(&p->tracker),
        .model = &p->resp,
        .threshold = p->thr_band,
        .bands = (uint16_t)(((uint32_t)p->mask_bins + SL_RESP_FLOOR_BAND - 1U) / SL_RESP_FLOOR_BAND),
    };
    p->cfg.port.on_rotation(p->cfg.port.ctx, &r);
}

// SHADOW on the best r2 there is: the profile's own r2 when the target was refined (the
// board's d(S) then decides nothing: a d that overcorrects no longer lets a pole whose base
// is beyond the edge through), else the mask's r2 less d(r2) (the prior; detection already
// tested it, except for targets whose smear tail crosses the edge, SL_TARGET_TAIL_EDGE,
// sl_detect.h stage 1). Rejected targets leave the array (order kept) and are counted as
// SHADOW. @return the targets left.
static SL_NOINLINE uint32_t shadow_after_refine(sl_pipeline_t *p, uint32_t n)
{
    uint32_t k = 0U;
    for (uint32_t i = 0; i < n; i++) {
        const sl_target_t *t = &p->detect.targets[i];
        if (t->r2_um >= t->shadow_slant_um) {
            p->detect.stats.rejected[SL_DETECT_REJ_SHADOW]++;
            continue;
        }
        if (k != i) {
            p->detect.targets[k] = *t;
        }
        k++;
    }
    p->detect.n_targets = (uint8_t)k;
    return k;
}

// Moving: the profile watches, next rotation, the azimuths where each track updated now is
// expected (its static-object prediction under one rotation's displacement, +-2 azimuths:
// the representative azimuth moves by up to half a beam's return, and the refinement sums
// the neighbours of whichever it is). Confirmed tracks first (also when missed this
// rotation), then the others updated now; then, while slots are free, +-4 azimuths for the
// tracks a SLANT target updated: a pole leaning across the line of sight is represented by
// the azimuth of its lowest visible point, which moves within its 10-15 azimuths as the
// vehicle passes (sl_track.h), and at 3 m/s lands 3-4 azimuths from the prediction on one
// rotation in five (its rows then unwatched: SL_PROFILE_NO_SLOT, not a 3D-tilt observation).
// Reversing: the prediction is for forward motion, and moving back by d is moving forward by
// d along the opposite axis: the bearing turned by half a turn, predicted, turned back.
static SL_NOINLINE void reserve_profiles(sl_pipeline_t *p)
{
    const uint32_t b = p->det_board.bin_size_um;
    if (b == 0U) {
        return;
    }
    for (uint32_t pass = 0; pass < 3U; pass++) {
        for (uint32_t i = 0; i < SL_CFG_MAX_TARGETS; i++) {
            const sl_track_t *t = &p->tracker.tracks[i];
            // a confirmed track missed this rotation is still predicted (dead reckoning:
            // its az / r1 moved to the prediction); an unconfirmed one only when updated;
            // the wider watch for one a SLANT target updated, while slots are free
            bool take;
            if (pass == 0U) {
                take = t->confirmed != 0U;
            } else if (pass == 1U) {
                take = t->confirmed == 0U && t->updated != 0U;
            } else {
                take = t->updated != 0U && t->last_slant != 0U &&
                       p->prof.n_live + 4U <= SL_CFG_PROFILE_SLOTS;
            }
            if (t->live == 0U || !take) {
                continue;
            }
            const uint32_t naz = p->det_board.azimuths;
            const uint32_t turn = p->tracker.motion_reverse ? naz / 2U : 0U;
            uint16_t az = 0;
            uint32_t r = 0;
            sl_track_predict_static(&p->det_board, (uint16_t)(((uint32_t)t->az + turn) % naz),
                                    t->r1_um, p->tracker.motion_um, &az, &r);
            az = (uint16_t)(((uint32_t)az + naz - turn) % naz);
            const uint32_t bin = r / b;
            (void)sl_profile_reserve(&p->prof, az, (uint16_t)(bin > 0xFFFFU ? 0xFFFFU : bin),
                                     pass < 2U ? 2U : 4U);
        }
    }
}

static void on_rot(void *ctx, const sl_scan_rot_t *rot)
{
    sl_pipeline_t *p = ctx;
    if (p->in_rotation == 0U && p->geometry_bad) {
        // Every row of this rotation was refused (configuration mismatch): nothing was
        // seen, so it is not a processed rotation; all its azimuths are missing.
        p->stats.azimuths_missing += rot->azimuths;
        p->stats.refused_rotations++;
        return;
    }
    if (p->in_rotation == 0U) {
        begin_rotation(p); // cannot happen (a rotation has a row); keeps the state sane
    }
    feed_held(p, p->next_az, rot->azimuths < p->mask.azimuths ? rot->azimuths
                                                              : p->mask.azimuths);
    sl_mask_end_rotation(&p->mask);
    const sl_ssize_t nt = sl_detect_end(&p->detect);
    uint32_t n_targets = nt > 0 ? (uint32_t)nt : 0U;
    if (p->cfg.profile) {
        for (uint32_t i = 0; i < n_targets; i++) {
#if SL_CFG_FIT
            if (p->cfg.fit) {
                (void)sl_profile_refine_fit(&p->prof, p->board, &p->resp, p->cfg.threshold,
                                            &p->detect.targets[i]);
                continue;
            }
#endif
            (void)sl_profile_refine(&p->prof, p->board, p->cfg.threshold, &p->detect.targets[i]);
        }
        n_targets = shadow_after_refine(p, n_targets);
        sl_profile_assign(&p->prof, p->detect.targets, n_targets);
        // A profile must not mix positions: cleared every rotation while the window is short.
        sl_profile_end_rotation(&p->prof, p->frames_eff < p->cfg.mask_frames);
        // The self-calibrated tail replaces the board's d(S) at the shadow edge (sl_detect.h
        // stage 1) from the next rotation on.
        sl_detect_set_tail_slope(&p->detect, p->prof.slope_q8);
    }
    measure_period(p, rot);
    set_track_motion(p);
    sl_track_set_reverse(&p->tracker, p->motion_valid && p->speed_mm_s < 0);
    sl_track_update(&p->tracker, p->detect.targets, n_targets, p->now_us);
    if (p->cfg.profile && p->prof.moving != 0U) {
        reserve_profiles(p);
    }
    // A stream whose returns are cut off (sl_profile.h, "Cut-off returns") has no range bound
    // the 3D fit could take, and what the histories hold from before that was known is
    // suspect: cleared, as without motion.
    // So is what they hold from before the stream's front part became known (its r1s early
    // by up to the front's length; sl_profile.h, "Front part").
    const bool suspect = p->cfg.profile && (sl_profile_cut(&p->prof) || p->prof.front_news != 0U);
    p->prof.front_news = 0U;
    sl_tiltobs_advance(&p->tilt, p->motion_valid && !suspect, p->speed_mm_s, p->yaw_cdeg_s,
                       p->rotation_us);
    // Unless the stream is known not to smear (returns seen to end in cliffs, no tail
    // self-fitted), a target the profile could not check (no slot, too few rows) may carry
    // a tail in its bounds: not a 3D-tilt observation. From the start of the stream: its
    // first rotations (the first hits of every track while moving) come before any
    // evidence either way.
    p->tilt.verified_only = p->cfg.profile && (p->cfg.fit || !sl_profile_clean(&p->prof));
    sl_tiltobs_update(&p->tilt, p->tracker.tracks, p->detect.targets, n_targets);
    // Drift watch (sl_drift.h): one azimuth per rotation, read from the mask's stable row at
    // the rotation's end, joined with its raw tail when the mask's end is settled (stable-free
    // plane in p->bits); p->occ and p->bits are free once detection has ended.
    if (sl_mask_stable_prefix(&p->mask, p->drift.watch_az, p->mask_words, p->occ, p->bits)) {
        sl_drift_row(&p->drift, &p->det_board, p->drift.watch_az, p->occ, p->bits, p->mask_bins,
                     p->det_board.bin_size_um);
    }
    sl_drift_end_rotation(&p->drift);
    model_end_rotation(p);
#if SL_CFG_GROUND
    if (p->cfg.ground) {
        sl_ground_set_motion(&p->ground, p->motion_valid, p->speed_mm_s, p->rotation_us);
        sl_ground_end_rotation(&p->ground);
    }
#endif
    p->stats.rotations++;
    p->stats.azimuths_missing += rot->stats.missing;
    p->stats.targets += n_targets;
    if (p->cfg.port.on_rotation != NULL) {
        report_rotation(p, rot, n_targets);
    }
    emit_can(p);
    p->in_rotation = 0U;
}

// Ranges from the radar's own bin size: detection runs on a copy of the board whose
// bin size (and near-exclusion band, in bins) is the radar's; the shadow geometry is in
// micrometres, so detection's per-azimuth windows follow. Re-initialising detection drops
// the rotation's open candidates (a Configuration means a (re)start). When the radar's
// bins are so small that detection would need more bins than are masked, the board's
// bin size is kept (RANGE_RESOLUTION_MISMATCH stays raised) rather than cutting the shadow.
static void use_bin_size(sl_pipeline_t *p, uint32_t um)
{
    if (um == 0U || um == p->det_board.bin_size_um) {
        return;
    }
    const sl_board_t *b = p->board;
    if (b->shadow_um == NULL) {
        return; // no micrometre shadow table: cannot move to other bins
    }
    // det_board is the board but for the three fields set here (sl_pipeline_init copies
    // it): built in place and put back field by field, no board-sized copies on the stack
    // (this runs under on_msg, on the FFT path's deepest chain).
    const uint32_t keep_um = p->det_board.bin_size_um;
    const uint16_t keep_near = p->det_board.near_exclusion_bins;
    const uint16_t *const keep_shadow = p->det_board.shadow_bins;
    const uint64_t near_um = (uint64_t)b->near_exclusion_bins * b->bin_size_um;
    const uint64_t near = (near_um + um - 1U) / um;
    p->det_board = *b;
    p->det_board.bin_size_um = um;
    p->det_board.near_exclusion_bins = (uint16_t)(near > b->roi_bins ? b->roi_bins : near);
    p->det_board.shadow_bins = NULL; // in the board's bins; detection uses shadow_um
    if (sl_detect_init(&p->detect, &p->det_board, &p->cfg.detect) != SL_OK ||
        sl_detect_bins_needed(&p->detect) > p->mask_bins) {
        p->det_board.bin_size_um = keep_um;
        p->det_board.near_exclusion_bins = keep_near;
        p->det_board.shadow_bins = keep_shadow;
        (void)sl_detect_init(&p->detect, &p->det_board, &p->cfg.detect);
        p->stats.bin_size_unserved++;
    } else {
        p->stats.bin_size_changes++;
    }
    if (p->cfg.profile) {
        sl_detect_set_tail_slope(&p->detect, p->prof.slope_q8); // re-init cleared it
    }
#if SL_CFG_GROUND
    sl_ground_set_bin_size(&p->ground, p->det_board.bin_size_um);
#endif
}

// A Configuration message (its parsed form stays out of on_msg's frame, which the FFT
// path's deepest chain goes through).
static SL_NOINLINE void on_config(sl_pipeline_t *p, const sl_proto_msg_t *m)
{
    sl_proto_config_t c;
    if (sl_proto_parse_config(m, &c) == SL_OK) {
        // The board's bin size is the expected one; > 1 % off is flagged (ranges and
        // leans would be scaled wrong by that much).
        const uint32_t um = sl_proto_config_bin_size_um(&c);
        const uint64_t b = p->board->bin_size_um;
        const uint64_t diff = (um > b) ? um - b : b - um;
        p->radar_bin_um = um;
        p->bin_size_bad = um == 0U || diff * 100U > b;
        if (p->bin_size_bad) {
            p->stats.bin_size_mismatch++;
            set_err(p, SL_ERR_RANGE, (uint8_t)SL_PIPELINE_OK,
                    "radar bin size differs from the board's by more than 1 %");
        }
        use_bin_size(p, um);
    }
}

static void on_msg(void *ctx, const sl_proto_msg_t *m)
{
    sl_pipeline_t *p = ctx;
    if (m->id == (uint8_t)SL_PROTO_ID_CONFIGURATION && p->scan.stats.azimuths != 0U) {
        p->stats.restarts++; // a radar (re)start announces itself with a Configuration
    }
    const uint32_t rejected = p->scan.stats.config_rejected;
    const uint32_t accepted = p->scan.stats.configs;
    const uint32_t blind = p->scan.stats.blind_rotations;
    (void)sl_scan_on_msg(&p->scan, m);
    if (p->scan.stats.blind_rotations != blind) {
        // A rotation's worth of FFT messages gave no row: its azimuths are missing.
        const uint32_t add = (p->scan.stats.blind_rotations - blind) * (uint32_t)p->board->azimuths;
        p->stats.azimuths_missing = (add > UINT32_MAX - p->stats.azimuths_missing)
                                        ? UINT32_MAX
                                        : p->stats.azimuths_missing + add;
        p->stats.blind_rotations += p->scan.stats.blind_rotations - blind;
    }
    if (m->id == (uint8_t)SL_PROTO_ID_CONFIGURATION) {
        on_config(p, m);
    }
    if (p->scan.stats.config_rejected != rejected) {
        // Rows of this radar would be mapped with the board's geometry: drop them until a
        // matching Configuration arrives.
        p->geometry_bad = true;
        p->stats.geometry_rejected++;
        set_err(p, SL_ERR_RANGE, (uint8_t)SL_PIPELINE_OK,
                "radar configuration does not match the board (azimuths / encoder size)");
    } else if (p->scan.stats.configs != accepted) {
        p->geometry_bad = false;
    }
}

// ------------------------------------------------------------------------------- API

sl_err_t sl_pipeline_init(sl_pipeline_t *p, const sl_board_t *board,
                          const sl_pipeline_cfg_t *cfg)
{
    if (p == NULL) {
        return SL_ERR_ARG;
    }
    memset(p, 0, sizeof *p);
    if (board == NULL) {
        set_err(p, SL_ERR_ARG, (uint8_t)SL_PIPELINE_BAD_ARG, "NULL board");
        return SL_ERR_ARG;
    }
    if (cfg != NULL) {
        p->cfg = *cfg;
    } else {
        sl_pipeline_cfg_default(&p->cfg, board);
    }
    p->board = board;
    const sl_pipeline_cfg_t *c = &p->cfg;
    if (c->pow16_shift > 15U || c->max_missed == 255U || c->mask_frames == 0U ||
        (c->fit && SL_CFG_FIT == 0)) {
        set_err(p, SL_ERR_ARG, (uint8_t)SL_PIPELINE_BAD_ARG, "configuration value out of range");
        return SL_ERR_ARG;
    }
    if (c->mask_frames > SL_CFG_MASK_FRAMES_MAX) {
        set_err(p, SL_ERR_RANGE, (uint8_t)SL_PIPELINE_MASK_FRAMES,
                "mask_frames exceeds SL_CFG_MASK_FRAMES_MAX");
        return SL_ERR_RANGE;
    }
    if (board->azimuths == 0U || board->azimuths > SL_CFG_MAX_AZIMUTHS ||
        board->encoder_size == 0U) {
        set_err(p, SL_ERR_RANGE, (uint8_t)SL_PIPELINE_BOARD_AZIMUTHS,
                "board azimuths exceed SL_CFG_MAX_AZIMUTHS");
        return SL_ERR_RANGE;
    }
    if (board->roi_bins == 0U || board->roi_bins > SL_CFG_ROI_BINS) {
        set_err(p, SL_ERR_RANGE, (uint8_t)SL_PIPELINE_BOARD_ROI,
                "board roi_bins exceed SL_CFG_ROI_BINS");
        return SL_ERR_RANGE;
    }
    p->det_board = *board;
    sl_err_t e = sl_detect_init(&p->detect, &p->det_board, &c->detect);
    if (e != SL_OK) {
        set_err(p, e, (uint8_t)SL_PIPELINE_STAGE_INIT, "sl_detect_init rejected the board");
        return e;
    }
    // Threshold and mask only what detection reads, in whole words.
    const uint32_t need = sl_detect_bins_needed(&p->detect);
    uint32_t bins = (need + 31U) & ~31U;
    if (bins > board->roi_bins) {
        bins = board->roi_bins;
    }
    if (bins == 0U) {
        bins = 32U <= board->roi_bins ? 32U : board->roi_bins;
    }
    if (bins > SL_CFG_MASK_BINS) {
        set_err(p, SL_ERR_RANGE, (uint8_t)SL_PIPELINE_MASK_BINS,
                "detection needs more bins than SL_CFG_MASK_BINS");
        return SL_ERR_RANGE;
    }
    p->mask_bins = (uint16_t)bins;
    p->mask_words = (uint16_t)SL_BITS_WORDS(bins);
    p->r_max_um = (uint32_t)(((uint64_t)need * board->bin_size_um > UINT32_MAX)
                                 ? UINT32_MAX
                                 : (uint64_t)need * board->bin_size_um);
    e = sl_mask_init(&p->mask, board->azimuths, (uint16_t)bins, c->mask_frames, c->max_missed);
    if (e == SL_OK && c->profile) {
        e = sl_profile_init(&p->prof, board->azimuths, board->near_exclusion_bins,
                            &c->profile_cfg);
    }
    if (e == SL_OK && c->profile) {
        sl_detect_set_tail_slope(&p->detect, p->prof.slope_q8); // a saved prior, or 0
    }
    if (e == SL_OK) {
        e = sl_track_init(&p->tracker, board, &c->track);
    }
    if (e == SL_OK) {
        e = sl_tiltobs_init(&p->tilt, &p->det_board); // bin size as detection uses it
        p->tilt.max_tan_q16 = c->detect.max_lean_tan_q16;
    }
    sl_drift_init(&p->drift, board);
    if (e == SL_OK) {
        // The board's prior, NULL: the CTS350-X lobe (sl_board.h); a calibration's response
        // (sl_calblob.h) is the one in use from the start, as CALIBRATED.
        e = sl_response_init(&p->resp, &c->value_scale, board->response_prior_q8, NULL);
        if (e == SL_OK && board->response_calibrated != 0U && board->response_prior_q8 != NULL) {
            e = sl_response_set(&p->resp, board->response_prior_q8,
                                (uint8_t)SL_RESPONSE_CALIBRATED);
        }
        p->learn_az = 0U;
        update_thresholds(p);
    }
#if SL_CFG_GROUND
    if (e == SL_OK && c->ground) {
        p->cfg.ground_cfg.threshold = c->ground_cfg.threshold != 0U ? c->ground_cfg.threshold
                                                                    : c->threshold;
        p->cfg.ground_cfg.scale = c->value_scale; // the values' scale: the pipeline's
        e = sl_ground_init(&p->ground, board, &p->cfg.ground_cfg);
    }
#endif
    sl_can_ids_t ids;
    if (e == SL_OK) {
        sl_can_ids_from_board(&ids, board);
        e = sl_can_tx_init(&p->can, &ids);
    }
    if (e != SL_OK) {
        set_err(p, e, (uint8_t)SL_PIPELINE_STAGE_INIT, "a stage rejected the board or cfg");
        return e;
    }
    sl_can_motion_rx_init(&p->motion_rx, board->can_id_vehicle_motion,
                          &ids.e2e[SL_CAN_MSG_VEHICLE_MOTION], board->can_max_delta_counter_motion,
                          c->motion_timeout_us);
    const sl_scan_cfg_t sc = {
        .roi_bins = (uint16_t)bins,
        .pow16_shift = c->pow16_shift,
        .expect_azimuths = board->azimuths,
        .expect_encoder_size = board->encoder_size,
        .azimuths = board->azimuths,
        .encoder_size = board->encoder_size,
        .ignore_sweep = c->ignore_sweep,
        .on_row = on_row,
        .on_rot = on_rot,
        .row_buf = p->row8,
        .row_buf_size = (uint16_t)sizeof p->row8,
        .ctx = p,
    };
    e = sl_scan_init(&p->scan, &sc, NULL, NULL);
    if (e != SL_OK) {
        set_err(p, e, (uint8_t)SL_PIPELINE_STAGE_INIT, "sl_scan_init rejected the board");
        return e;
    }
    const sl_proto_cfg_t pc = {
        .reasm_buf = p->reasm,
        .reasm_size = sizeof p->reasm,
        .max_payload_bytes = board->max_message_bytes,
        .truncate_long = true,
        .on_msg = on_msg,
        .ctx = p,
    };
    e = sl_proto_init(&p->proto, &pc);
    p->decoder_stats = &p->proto.stats;
    if (e != SL_OK) {
        set_err(p, e, (uint8_t)SL_PIPELINE_STAGE_INIT, "sl_proto_init failed");
        return e;
    }
    p->rotation_us = c->rotation_us != 0U ? c->rotation_us : 250000U;
    if (p->cfg.row_timeout_us == 0U) {
        p->cfg.row_timeout_us = 1000000U;
    }
    p->frames_eff = c->mask_frames;
    p->link_state = (uint8_t)SL_CAN_LINK_DISCONNECTED;
    p->ready = true;
    return SL_OK;
}

sl_err_t sl_pipeline_feed(sl_pipeline_t *p, const uint8_t *data, size_t len, uint64_t now_us)
{
    if (p == NULL || (data == NULL && len != 0U) || !p->ready) {
        return SL_ERR_ARG;
    }
    p->now_us = now_us;
    const sl_err_t e = sl_proto_feed(&p->proto, data, len, now_us);
    sl_tiltobs_fit_pending(&p->tilt); // outside the decoder's call chain (stack)
    return e;
}

sl_err_t sl_pipeline_on_msg(sl_pipeline_t *p, const sl_proto_msg_t *msg, uint64_t now_us)
{
    if (p == NULL || msg == NULL || !p->ready) {
        return SL_ERR_ARG;
    }
    p->now_us = now_us;
    on_msg(p, msg);
    sl_tiltobs_fit_pending(&p->tilt);
    return SL_OK;
}

void sl_pipeline_set_decoder_stats(sl_pipeline_t *p, const sl_proto_stats_t *stats)
{
    if (p != NULL) {
        p->decoder_stats = stats != NULL ? stats : &p->proto.stats;
    }
}

sl_err_t sl_pipeline_finish(sl_pipeline_t *p, uint64_t now_us)
{
    if (p == NULL || !p->ready) {
        return SL_ERR_ARG;
    }
    p->now_us = now_us;
    (void)sl_proto_finish(&p->proto);
    sl_scan_flush(&p->scan);
    sl_tiltobs_fit_pending(&p->tilt);
    p->last_t_last_us = 0U; // the next stream's clock may differ
    return SL_OK;
}

sl_err_t sl_pipeline_on_can_rx(sl_pipeline_t *p, const sl_can_frame_t *f, uint64_t now_us)
{
    if (p == NULL || f == NULL || !p->ready) {
        return SL_ERR_ARG;
    }
    p->stats.can_rx++;
    const sl_err_t e = sl_can_motion_rx_feed(&p->motion_rx, f, now_us);
    if (e == SL_OK) {
        p->stats.motion_accepted++;
    } else if (e != SL_ERR_ARG) {
        p->stats.motion_rejected++;
    }
    return e;
}

void sl_pipeline_set_motion(sl_pipeline_t *p, int32_t speed_mm_s, bool speed_valid,
                            int32_t yaw_rate_cdeg_s, bool yaw_rate_valid, uint64_t now_us)
{
    SL_ASSERT(p != NULL);
    p->motion.speed_mm_s = speed_mm_s;
    p->motion.speed_valid = speed_valid;
    p->motion.yaw_rate_cdeg_s = yaw_rate_cdeg_s;
    p->motion.yaw_rate_valid = yaw_rate_valid;
    p->motion_t_us = now_us;
    p->motion_set = true;
    p->stats.motion_set_calls++;
}

void sl_pipeline_set_link_state(sl_pipeline_t *p, uint8_t link_state)
{
    SL_ASSERT(p != NULL);
    p->link_state = link_state;
}

sl_err_t sl_pipeline_send_status(sl_pipeline_t *p, uint64_t now_us)
{
    if (p == NULL || !p->ready) {
        return SL_ERR_ARG;
    }
    p->now_us = now_us;
    emit_status(p);
    return SL_OK;
}

void sl_pipeline_add_reconnect(sl_pipeline_t *p, uint64_t now_us)
{
    SL_ASSERT(p != NULL);
    if (p->stats.reconnects != UINT32_MAX) {
        p->stats.reconnects++;
    }
    p->reconnect_t_us[p->reconnect_next % SL_CAN_FLAP_RECONNECTS] = now_us;
    p->reconnect_next = (uint8_t)((p->reconnect_next + 1U) % SL_CAN_FLAP_RECONNECTS);
    p->now_us = now_us;
}

void sl_pipeline_add_can_dropped(sl_pipeline_t *p, uint32_t n)
{
    SL_ASSERT(p != NULL);
    p->stats.can_dropped = (n > UINT32_MAX - p->stats.can_dropped) ? UINT32_MAX
                                                                   : p->stats.can_dropped + n;
}
