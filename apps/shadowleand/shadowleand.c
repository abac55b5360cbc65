// SPDX-License-Identifier: MIT
// shadowleand.c: the shadowlean daemon. Radar TCP stream or capture file in, pole-lean
// CAN frames out (SocketCAN, candump log, gs_usb), one sl_pipeline_t in between.
//
// One thread, one poll() loop. Every turn: signals (signalfd), VehicleMotion frames, the
// input (radar client I/O and timers, or the next due part of the capture), the sinks'
// deferred work, the idle Status frame, the periodic stats line, the exit conditions.
// Options: daemon_opts.h (also `shadowleand --help`).
//
// Clocks. The sinks, timers and the radar input use CLOCK_MONOTONIC. With a capture file
// the pipeline is driven by the radar's own FFT timestamps (the "data clock"), so the
// output does not depend on how fast the machine replays (--fast and --realtime give the
// same frames; track timeouts behave as they did on the road). The candump log writes the
// data clock for captures and the wall clock (CLOCK_REALTIME) for a live radar, unless
// --log-time says otherwise.
#include <errno.h>
#include <grp.h>
#include <inttypes.h>
#include <poll.h>
#include <pwd.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#include "can_sink.h"
#include "socketcan.h"
#include "capture_reader.h"
#include "calib_file.h"
#include "candump.h"
#include "daemon_log.h"
#include "daemon_motion.h"
#include "daemon_opts.h"
#include "daemon_targets.h"
#include "gsusb/gsusb_usb.h"
#include "gsusb/gsusb_sink.h"
#include "radar_client.h"
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_calblob.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_pipeline.h"
#include "shadowlean/sl_proto.h"
#include "port_clock.h"

#define FAST_MSGS_PER_TURN 512U   // capture messages fed per loop turn in --fast mode
#define MAX_PLAY_GAP_US 5000000U  // --realtime: longer timestamp gaps are shortened to this
#define DRAIN_STALL_MS 1000U      // at exit: give up when no queued frame moved for this long

#define HOLD_SLICE 4096U           // --realtime: stream bytes decoded at a time
#define HOLD_MSGS 8192U            // --realtime: messages held (copied) at most
#define HOLD_LEAD_BYTES (1U << 20) // payload bytes held at most before the data clock starts

/// --realtime: one message decoded ahead and held (payload copied) until it is due, or a
/// discontinuity (the pipeline's stream is finished there).
typedef struct held_msg {
    sl_proto_msg_t m;  ///< payload.data re-pointed into the hold buffer when delivered
    size_t off;        ///< payload offset in the hold buffer
    uint64_t t_us;     ///< FFT timestamp, 0 = not FFT data
    bool brk;
} held_msg_t;

typedef struct daemon {
    sld_opts_t o;
    const sl_board_t *board;     // the nominal board, or cal_board (--calibration)
    sl_board_t cal_board;        // calibrated view (sl_calblob.h) into cal_blob / g_cal_ws
    uint8_t *cal_blob;           // the calibration blob, kept for the daemon's lifetime
    sl_pipeline_cfg_t pcfg;
    uint32_t status_id; // bare id of the Status frames
    uint8_t status_eff; // SL_CAN_FLAG_EFF or 0

    // sinks
    slp_socketcan_t sc;
    bool sc_on;
    slp_candump_t log;
    bool log_on;
    bool log_error_logged;
    slp_gsusb_sink_t gs;
    bool gs_on;
    slp_can_sink_t sinks[3];
    size_t n_sinks;
    uint32_t sink_drops_seen;   // sum of the sinks' dropped counters already in the pipeline's
                                // can_dropped (wraps like the counters: differences only)
    sld_log_time_t log_time;

    // motion input
    sld_motion_t motion;
    bool motion_on;

    // input: radar
    bool is_radar;
    slp_radar_client_t radar;
    uint8_t *radar_reasm;
    bool fed_since_finish;
    uint64_t stream_start_mono; // Configuration received (start of streaming)
    uint64_t last_fft_mono;
    bool had_fft;               // any FFT data since start
    slp_radar_state_t last_radar_state;

    // input: capture, streamed (bounded memory): each byte is decoded once, by `pacer`,
    // whose messages go to sl_pipeline_on_msg: at once with --fast; with --realtime they
    // are held (copied, a few KiB ahead) until due. Messages before the first FFT timestamp
    // are held too: the data clock starts there.
    slp_capture_t *cr;
    sl_proto_t pacer;
    uint8_t *pacer_reasm;
    bool decode_once;           // --fast: the pacer hands messages over at once
    held_msg_t *held;
    size_t n_held, next_held;
    uint8_t *hold;
    size_t hold_len, hold_cap;
    slp_capture_piece_t piece; // DATA piece being decoded (--realtime)
    size_t piece_pos;
    bool have_piece;
    bool clock_known;           // data_us started (first FFT seen, or given up waiting)
    bool cap_end;               // the reader returned END or ERROR
    bool cap_error;
    uint64_t fed;               // stream bytes decoded
    uint64_t n_msgs, n_fft, n_breaks;
    bool cap_done;
    uint64_t play_wall0, play_us, play_prev_t;
    bool play_started;

    // clocks
    uint64_t mono_us;
    uint64_t data_us;           // latest FFT timestamp fed (capture input)

    // status / stats
    uint8_t link_state;
    uint64_t last_status_mono;
    bool idle_status;           // send Status frames when no rotation does
    uint64_t cap_next_due;      // capture: mono time the next message is due (0 = now)
    uint32_t status_frames, idle_status_frames, frames_out, rotations_seen;
    uint32_t exit_undrained;    // frames the sinks still held when the exit drain gave up
    uint64_t next_stats_mono;
    uint64_t start_mono;

    // --targets-out
    FILE *targets;
    bool targets_own;
    bool targets_failed;

    int sfd;
    bool stop;
    const char *stop_why;
} daemon_t;

// The pipeline is ~250 KB with the default capacities, the radar client ~70 KB: static.
static sl_pipeline_t g_pipe;
static daemon_t g_d;

static uint64_t pipe_now(const daemon_t *d)
{
    return d->is_radar ? d->mono_us : d->data_us;
}

static uint64_t realtime_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (uint64_t)ts.tv_sec * 1000000U + (uint64_t)ts.tv_nsec / 1000U;
}

// ---------------------------------------------------------------------------------------
// Output: the pipeline's port

static sl_err_t send_frame(daemon_t *d, const sl_can_frame_t *f)
{
    if (d->log_on) {
        const bool data = d->log_time == SLD_LOG_TIME_DATA;
        d->log.stamp_us = data ? d->data_us : realtime_us();
    }
    if (f->id == d->status_id && (f->flags & SL_CAN_FLAG_EFF) == d->status_eff) {
        d->status_frames++;
        d->last_status_mono = d->mono_us;
    }
    d->frames_out++;
    if (d->n_sinks == 0) {
        return SL_OK;
    }
    const uint32_t drops_before = slp_can_sinks_dropped(d->sinks, d->n_sinks);
    const sl_err_t e = slp_can_sinks_send(d->sinks, d->n_sinks, f, d->mono_us);
    if (e != SL_OK && slp_can_sinks_dropped(d->sinks, d->n_sinks) != drops_before) {
        // The pipeline counts this refused frame itself (can_tx's return value): one of the
        // sinks' new drops is reported that way, the rest by report_sink_drops().
        d->sink_drops_seen++;
    }
    if (d->log_on && d->log.broken_pipe && !d->stop) {
        d->stop = true;
        d->stop_why = "the reader of the CAN log (stdout) went away";
    }
    return e;
}

static sl_err_t port_can_tx(void *ctx, const sl_can_frame_t *f)
{
    return send_frame(ctx, f);
}

static void port_on_rotation(void *ctx, const sl_pipeline_rotation_t *r)
{
    daemon_t *d = ctx;
    d->rotations_seen++;
    if (d->targets != NULL && !d->targets_failed && sld_targets_write_rotation(d->targets, r) != 0) {
        d->targets_failed = true;
        sld_log(SLD_LOG_ERR, "--targets-out: write failed: %s", strerror(errno));
    }
    unsigned live = 0;
    for (uint16_t i = 0; i < r->n_track_slots; i++) {
        live += r->tracks[i].live ? 1U : 0U;
    }
    sld_log(SLD_LOG_DEBUG, "rotation %" PRIu32 ": %u/%u azimuths, %u targets, %u tracks, level %u, n_eff %u",
            r->rotation, (unsigned)r->valid, (unsigned)r->azimuths, (unsigned)r->n_targets, live,
            (unsigned)r->level, (unsigned)r->frames_eff);
}

/// Status frame outside the rotations (no data): the pipeline sends it through the port
/// (its own sender: the Status E2E counter sequence stays intact; a refusal is counted).
static void send_idle_status(daemon_t *d)
{
    if (sl_pipeline_send_status(&g_pipe, pipe_now(d)) == SL_OK) {
        d->idle_status_frames++;
    }
}

/// Drops the sinks counted after accepting a frame (SocketCAN stale / bus-off drops of
/// queued frames, gs_usb frames never confirmed): the increase of the summed sink drop
/// counters not yet reported goes into the pipeline's count (Status.CanDropped).
static void report_sink_drops(daemon_t *d)
{
    const uint32_t now = slp_can_sinks_dropped(d->sinks, d->n_sinks);
    const uint32_t fresh = now - d->sink_drops_seen; // modulo 2^32, like the counters
    d->sink_drops_seen = now;
    if (fresh != 0) {
        sl_pipeline_add_can_dropped(&g_pipe, fresh);
    }
}

// ---------------------------------------------------------------------------------------
// Input: radar

/// --motion: the constant motion, refreshed before every feed so it never goes stale.
static void fixed_motion(const daemon_t *d, uint64_t now_us)
{
    if (d->o.fixed_motion) {
        sl_pipeline_set_motion(&g_pipe, d->o.fixed_speed_mm_s, true, d->o.fixed_yaw_cdeg_s, true, now_us);
    }
}

static void radar_on_bytes(void *ctx, const uint8_t *data, size_t len, uint64_t now_us)
{
    (void)data;
    (void)len;
    daemon_t *d = ctx;
    d->fed_since_finish = true;
    fixed_motion(d, now_us);
}

/// Decode once: the radar client's decoder hands every message to the pipeline.
static void radar_on_msg(void *ctx, const sl_proto_msg_t *msg, uint64_t now_us)
{
    daemon_t *d = ctx;
    sl_pipeline_on_msg(&g_pipe, msg, now_us);
    if (msg->id == SL_PROTO_ID_FFT_DATA || msg->id == SL_PROTO_ID_FFT_DATA_16) {
        // Liveness is usable data, not the message id: a malformed or empty FFT message
        // does not keep the link STREAMING.
        sl_proto_fft_t f;
        if (sl_proto_parse_fft(msg, &f) == SL_OK && f.bins > 0U) {
            d->last_fft_mono = now_us;
            d->had_fft = true;
        }
    } else if (msg->id == SL_PROTO_ID_CONFIGURATION) {
        sl_proto_config_t c;
        if (sl_proto_parse_config(msg, &c) == SL_OK) {
            sld_log(SLD_LOG_INFO, "radar configuration: %u azimuths, %u bins of %" PRIu32 " um, %u.%03u Hz",
                    (unsigned)c.azimuths, (unsigned)c.range_bins, sl_proto_config_bin_size_um(&c),
                    (unsigned)(c.rotation_mhz / 1000U), (unsigned)(c.rotation_mhz % 1000U));
            if (c.azimuths != d->board->azimuths || c.encoder_size != d->board->encoder_size) {
                sld_log(SLD_LOG_ERR, "radar geometry (%u azimuths, %u ticks) differs from board %s (%u, %u):"
                        " every row is refused (Health CONFIG_MISMATCH)",
                        (unsigned)c.azimuths, (unsigned)c.encoder_size, d->board->name,
                        (unsigned)d->board->azimuths, (unsigned)d->board->encoder_size);
            }
            const uint32_t um = sl_proto_config_bin_size_um(&c);
            const uint32_t bu = d->board->bin_size_um;
            if ((uint64_t)(um > bu ? um - bu : bu - um) * 100U > bu) {
                sld_log(SLD_LOG_ERR, "radar bin size %" PRIu32 " um differs from board %s (%" PRIu32
                        " um) by more than 1 %%: ranges and leans are scaled wrong (Health "
                        "RANGE_RESOLUTION_MISMATCH)", um, d->board->name, bu);
            }
        }
    }
}

static void radar_finish(daemon_t *d, uint64_t now_us)
{
    if (d->fed_since_finish) {
        d->fed_since_finish = false;
        sl_pipeline_finish(&g_pipe, now_us);
    }
}

static void radar_on_event(void *ctx, slp_radar_event_t ev, slp_radar_reason_t reason, uint64_t now_us)
{
    daemon_t *d = ctx;
    const slp_radar_client_t *c = &d->radar;
    switch (ev) {
    case SLP_RADAR_EV_CONNECTED:
        sld_log(SLD_LOG_INFO, "radar %s:%u connected", d->o.radar_host, (unsigned)d->o.radar_port);
        if (c->stats.connects > 1U) {
            sl_pipeline_add_reconnect(&g_pipe, now_us); // Health.Reconnects, LINK_FLAPPING
        }
        break;
    case SLP_RADAR_EV_CONFIG:
        d->stream_start_mono = now_us;
        break;
    case SLP_RADAR_EV_DISCONNECTED:
        sld_log(SLD_LOG_WARN, "radar disconnected (%s%s%s); reconnecting in %" PRIu32 " ms",
                slp_radar_reason_str(reason), c->stats.last_errno != 0 ? ": " : "",
                c->stats.last_errno != 0 ? strerror(c->stats.last_errno) : "", c->stats.backoff_ms);
        radar_finish(d, now_us);
        break;
    case SLP_RADAR_EV_CONNECT_FAILED:
        // Logged once per failure streak at warning level, then at debug level.
        sld_log(c->stats.connect_failures + c->stats.connect_timeouts <= 1 ? SLD_LOG_WARN : SLD_LOG_DEBUG,
                "radar %s:%u: connect failed (%s%s%s); retrying", d->o.radar_host,
                (unsigned)d->o.radar_port, slp_radar_reason_str(reason),
                c->stats.last_errno != 0 ? ": " : "",
                c->stats.last_errno != 0 ? strerror(c->stats.last_errno) : "");
        radar_finish(d, now_us);
        break;
    case SLP_RADAR_EV_STOPPED:
        radar_finish(d, now_us);
        break;
    }
}

static uint8_t radar_link_state(daemon_t *d)
{
    switch (d->radar.state) {
    case SLP_RADAR_IDLE:
    case SLP_RADAR_BACKOFF:
        return SL_CAN_LINK_DISCONNECTED;
    case SLP_RADAR_CONNECTING:
        return SL_CAN_LINK_CONNECTING;
    case SLP_RADAR_WAIT_CONFIG:
        return SL_CAN_LINK_WAIT_CONFIG;
    case SLP_RADAR_STREAMING: {
        uint64_t ref = d->stream_start_mono;
        if (d->had_fft && d->last_fft_mono > ref) {
            ref = d->last_fft_mono;
        }
        return d->mono_us >= ref + (uint64_t)d->o.silent_ms * 1000U ? SL_CAN_LINK_SILENT
                                                                     : SL_CAN_LINK_STREAMING;
    }
    }
    return SL_CAN_LINK_DISCONNECTED;
}

static int radar_setup(daemon_t *d)
{
    size_t reasm = d->board->max_message_bytes;
    if (reasm < 65536U) {
        reasm = 65536U;
    }
    d->radar_reasm = malloc(reasm);
    if (d->radar_reasm == NULL) {
        sld_log(SLD_LOG_ERR, "out of memory");
        return -1;
    }
    slp_radar_client_cfg_t cfg;
    slp_radar_client_cfg_defaults(&cfg);
    cfg.host = d->o.radar_host;
    cfg.port = d->o.radar_port;
    cfg.connect_timeout_ms = d->o.connect_timeout_ms;
    cfg.silence_timeout_ms = d->o.silence_timeout_ms;
    // Data watchdog: no usable FFT row for the silence timeout -> Start FFT again, then
    // reconnect (keep-alives or a byte trickle no longer keep a blind link open).
    cfg.data_timeout_ms = d->o.data_timeout_ms != 0 ? d->o.data_timeout_ms : d->o.silence_timeout_ms;
    cfg.non_contour = d->o.non_contour;
    cfg.reasm_buf = d->radar_reasm;
    cfg.reasm_size = reasm;
    cfg.max_payload_bytes = d->board->max_message_bytes; // the pipeline decoder's limit
    cfg.on_msg = radar_on_msg;
    cfg.on_bytes = radar_on_bytes;
    cfg.on_event = radar_on_event;
    cfg.ctx = d;
    const sl_err_t e = slp_radar_client_init(&d->radar, &cfg);
    sl_pipeline_set_decoder_stats(&g_pipe, &d->radar.proto.stats); // Status.DecoderResyncs
    if (e != SL_OK) {
        sld_log(SLD_LOG_ERR, "radar %s:%u: %s", d->o.radar_host, (unsigned)d->o.radar_port,
                e == SL_ERR_PORT ? "cannot resolve the name" : sl_err_str(e));
        return -1;
    }
    return 0;
}

// ---------------------------------------------------------------------------------------
// Input: capture file

static void pacer_on_msg(void *ctx, const sl_proto_msg_t *msg)
{
    daemon_t *d = ctx;
    uint64_t t = 0;
    sl_proto_fft_t fft;
    if ((msg->id == SL_PROTO_ID_FFT_DATA || msg->id == SL_PROTO_ID_FFT_DATA_16) &&
        sl_proto_parse_fft(msg, &fft) == SL_OK) {
        t = sl_proto_fft_time_us(&fft);
        if (!d->clock_known && d->n_fft == 0) {
            d->data_us = t; // the data clock starts at the first FFT message
        }
        d->n_fft++;
    }
    d->n_msgs++;
    if (d->decode_once) {
        // --fast: straight to the pipeline at its data clock.
        if (t > d->data_us) {
            d->data_us = t;
        }
        fixed_motion(d, pipe_now(d));
        sl_pipeline_on_msg(&g_pipe, msg, pipe_now(d));
        return;
    }
    // --realtime: hold a copy until it is due (bounded: see capture_step).
    if (d->n_held >= HOLD_MSGS || d->hold_len + msg->payload.size > d->hold_cap) {
        sld_log(SLD_LOG_ERR, "internal: capture hold buffer full, message dropped"); // not reached
        return;
    }
    held_msg_t *h = &d->held[d->n_held++];
    h->m = *msg;
    h->off = d->hold_len;
    h->t_us = t;
    h->brk = false;
    if (msg->payload.size > 0) {
        memcpy(d->hold + d->hold_len, msg->payload.data, msg->payload.size);
        d->hold_len += msg->payload.size;
    }
}

/// Open the capture (path or "-"): nothing is read beyond the format sniff.
static int capture_setup(daemon_t *d)
{
    char err[512];
    d->cr = slp_capture_open(d->o.capture, NULL, err, sizeof err);
    if (d->cr == NULL) {
        sld_log(SLD_LOG_ERR, "--input: %s", err);
        return -1;
    }
    d->decode_once = !d->o.realtime;
    size_t reasm = d->board->max_message_bytes;
    if (reasm < 65536U) {
        reasm = 65536U;
    }
    d->pacer_reasm = malloc(reasm);
    d->hold_cap = HOLD_LEAD_BYTES + HOLD_SLICE + reasm;
    if (!d->decode_once) {
        d->hold = malloc(d->hold_cap);
        d->held = malloc(HOLD_MSGS * sizeof *d->held);
    }
    if (d->pacer_reasm == NULL || (!d->decode_once && (d->hold == NULL || d->held == NULL))) {
        sld_log(SLD_LOG_ERR, "out of memory");
        return -1;
    }
    // The pipeline decoder's limit: both accept and reject the same headers.
    const sl_proto_cfg_t pc = {.reasm_buf = d->pacer_reasm, .reasm_size = reasm,
                              .max_payload_bytes = d->board->max_message_bytes, .truncate_long = false,
                              .on_msg = pacer_on_msg, .ctx = d};
    sl_proto_init(&d->pacer, &pc);
    sl_pipeline_set_decoder_stats(&g_pipe, &d->pacer.stats); // Status.DecoderResyncs
    sld_log(SLD_LOG_INFO, "input %s (%s)", d->o.capture,
            slp_capture_format_name(slp_capture_report(d->cr)->format));
    return 0;
}

/// End of input (END or ERROR piece).
static void capture_end(daemon_t *d, const slp_capture_piece_t *pc)
{
    sl_proto_finish(&d->pacer);
    d->cap_end = true;
    if (!d->clock_known) {
        d->clock_known = true;
        if (d->n_fft == 0) {
            d->data_us = realtime_us();
        }
    }
    if (pc->kind == SLP_CAPTURE_ERROR) {
        d->cap_error = true;
        sld_log(SLD_LOG_ERR, "--input %s: %s", d->o.capture, slp_capture_error(d->cr));
    }
}

/// --fast, decode once: the reader's pieces go through the pacer straight into the pipeline.
static void capture_step_fast(daemon_t *d)
{
    for (unsigned turn = 0; turn < 16U && !d->cap_done && !d->stop; turn++) {
        slp_capture_piece_t pc;
        slp_capture_next(d->cr, &pc);
        if (pc.kind == SLP_CAPTURE_DATA) {
            sl_proto_feed(&d->pacer, pc.data, pc.size, 0);
            d->fed += pc.size;
        } else if (pc.kind == SLP_CAPTURE_BREAK) {
            sl_proto_finish(&d->pacer);
            sl_pipeline_finish(&g_pipe, pipe_now(d));
            d->n_breaks++;
        } else {
            capture_end(d, &pc);
            sl_pipeline_finish(&g_pipe, pipe_now(d));
            d->cap_done = true;
        }
    }
}

/// --realtime: decode the next slice (or take the next piece) into the hold queue.
static void capture_decode_more(daemon_t *d)
{
    if (!d->have_piece) {
        slp_capture_next(d->cr, &d->piece);
        if (d->piece.kind == SLP_CAPTURE_DATA) {
            d->have_piece = true;
            d->piece_pos = 0;
        } else if (d->piece.kind == SLP_CAPTURE_BREAK) {
            sl_proto_finish(&d->pacer);
            d->held[d->n_held++] = (held_msg_t){.brk = true};
            d->n_breaks++;
            return;
        } else {
            capture_end(d, &d->piece);
            return;
        }
    }
    size_t k = d->piece.size - d->piece_pos;
    k = k < HOLD_SLICE ? k : HOLD_SLICE;
    sl_proto_feed(&d->pacer, d->piece.data + d->piece_pos, k, 0);
    d->piece_pos += k;
    d->fed += k;
    if (d->piece_pos == d->piece.size) {
        d->have_piece = false;
    }
}

/// Feed what is due. @return the monotonic time of the next due message (0 = now / done).
static uint64_t capture_step(daemon_t *d)
{
    if (d->decode_once) {
        capture_step_fast(d);
        return 0;
    }
    unsigned budget = FAST_MSGS_PER_TURN;
    while (!d->cap_done && !d->stop && budget-- > 0) {
        if (!d->clock_known) {
            // Hold until the first FFT timestamp (or give up after HOLD_LEAD_BYTES /
            // about HOLD_MSGS messages: the wall clock then).
            if (d->n_fft > 0) {
                d->clock_known = true;
            } else if (d->hold_len > HOLD_LEAD_BYTES || d->n_held + 2U * HOLD_SLICE / SL_PROTO_HEADER_BYTES > HOLD_MSGS) {
                d->clock_known = true;
                d->data_us = realtime_us();
            } else if (!d->cap_end) {
                capture_decode_more(d);
            }
            continue;
        }
        if (d->next_held >= d->n_held) {
            d->n_held = d->next_held = 0;
            d->hold_len = 0;
            if (d->cap_end) {
                sl_pipeline_finish(&g_pipe, pipe_now(d));
                d->cap_done = true;
                break;
            }
            capture_decode_more(d);
            continue;
        }
        held_msg_t *h = &d->held[d->next_held];
        if (h->brk) {
            sl_pipeline_finish(&g_pipe, pipe_now(d));
            d->next_held++;
            continue;
        }
        if (h->t_us != 0) {
            if (!d->play_started) {
                d->play_started = true;
                d->play_wall0 = d->mono_us;
                d->play_prev_t = h->t_us;
                // The idle-Status clock starts with the data, not with the set-up
                // (opening a gs_usb device in a slow VM took > 1 s: an idle Status
                // before the first rotation).
                d->last_status_mono = d->mono_us;
            } else {
                uint64_t dt = h->t_us > d->play_prev_t ? h->t_us - d->play_prev_t : 0;
                if (dt > MAX_PLAY_GAP_US) {
                    dt = MAX_PLAY_GAP_US;
                }
                const uint64_t due = d->play_wall0 + d->play_us + dt;
                if (due > d->mono_us) {
                    return due; // not yet (play_us/prev_t unchanged until it is fed)
                }
                d->play_us += dt;
                d->play_prev_t = h->t_us;
            }
            if (h->t_us > d->data_us) {
                d->data_us = h->t_us;
            }
        }
        sl_proto_msg_t m = h->m;
        m.payload.data = m.payload.size > 0 ? d->hold + h->off : NULL;
        fixed_motion(d, pipe_now(d));
        sl_pipeline_on_msg(&g_pipe, &m, pipe_now(d));
        d->next_held++;
    }
    return 0;
}

/// End of capture: what was read, decoded and skipped. @return false when the input ended
/// with a read error, or held bytes but not one Colossus message (junk: every byte skipped).
static bool capture_report(daemon_t *d)
{
    const slp_capture_report_t *r = slp_capture_report(d->cr);
    char line[512];
    slp_capture_report_line(d->cr, line, sizeof line);
    sld_log(SLD_LOG_INFO, "input %s (%s): %" PRIu64 " bytes read, %" PRIu64 " stream bytes, %" PRIu64
            " messages, %" PRIu64 " FFT, %" PRIu64 " discontinuities, %" PRIu64 " bytes skipped%s%s",
            d->o.capture, slp_capture_format_name(r->format), r->bytes_in, r->stream_bytes, d->n_msgs,
            d->n_fft, d->n_breaks, d->pacer.stats.bytes_skipped, line[0] != '\0' ? "; " : "", line);
    if (d->pacer.stats.resyncs != 0 || d->pacer.stats.truncated != 0) {
        sld_log(SLD_LOG_WARN, "input: %" PRIu32 " decoder resyncs, %" PRIu32 " truncated messages, %" PRIu64
                " bytes skipped", d->pacer.stats.resyncs, d->pacer.stats.truncated, d->pacer.stats.bytes_skipped);
    }
    if (d->n_msgs == 0 && r->bytes_in > 0 && !d->stop) {
        sld_log(SLD_LOG_ERR, "--input %s: no Colossus message in %" PRIu64 " bytes (%" PRIu64 " skipped)",
                d->o.capture, r->stream_bytes, d->pacer.stats.bytes_skipped);
        return false;
    }
    return !d->cap_error;
}

// ---------------------------------------------------------------------------------------
// Motion input

static void on_motion_frame(void *ctx, const sl_can_frame_t *f)
{
    daemon_t *d = ctx;
    const sl_err_t e = sl_pipeline_on_can_rx(&g_pipe, f, pipe_now(d));
    if (e != SL_OK) {
        sld_log(SLD_LOG_DEBUG, "VehicleMotion frame rejected: %s", sl_err_str(e));
    }
}

// ---------------------------------------------------------------------------------------
// Set-up, privileges, stats

static int open_sinks(daemon_t *d)
{
    const uint64_t now = d->mono_us;
    if (d->o.can_iface[0] != '\0') {
        const sl_err_t e = slp_socketcan_open(&d->sc, d->o.can_iface, NULL);
        if (e == SL_ERR_ARG) {
            sld_log(SLD_LOG_ERR, "--can %s: bad interface name", d->o.can_iface);
            return -1;
        }
        if (e != SL_OK) {
            // Usable anyway: frames are dropped and counted, the socket is reopened later.
            sld_log(SLD_LOG_WARN, "--can %s: %s (frames are dropped until it appears)", d->o.can_iface,
                    strerror(d->sc.last_errno));
        }
        d->sc_on = true;
        d->sinks[d->n_sinks++] = slp_socketcan_sink(&d->sc);
    }
    if (d->o.can_log[0] != '\0') {
        const char *iface = d->o.can_log_iface[0] != '\0' ? d->o.can_log_iface
                            : d->o.can_iface[0] != '\0' ? d->o.can_iface
                                                        : "can0";
        const sl_err_t e = slp_candump_open(&d->log, d->o.can_log, iface);
        if (e != SL_OK) {
            sld_log(SLD_LOG_ERR, "--can-log %s: %s", d->o.can_log,
                    e == SL_ERR_ARG ? "bad interface name" : strerror(d->log.last_errno));
            return -1;
        }
        d->log_on = true;
        d->sinks[d->n_sinks++] = slp_candump_sink(&d->log);
    }
    if (d->o.gs_usb) {
        slp_gsusb_sink_cfg_t cfg = slp_gsusb_sink_default_cfg();
        cfg.selector = d->o.gs_usb_sel[0] != '\0' ? d->o.gs_usb_sel : NULL;
        cfg.can.bitrate = d->o.bitrate != 0 ? d->o.bitrate : d->board->can_bitrate;
        cfg.max_age_us = (uint64_t)d->o.gs_usb_max_age_ms * 1000U;
        const sl_err_t e = slp_gsusb_sink_open(&d->gs, &cfg, now);
        if (e == SL_ERR_ARG) {
            sld_log(SLD_LOG_ERR, "--gs-usb %s: %s", d->o.gs_usb_sel, slp_gsusb_sink_last_error(&d->gs));
            return -1;
        }
        if (e != SL_OK) {
            sld_log(SLD_LOG_WARN, "--gs-usb %s: %s (frames are dropped; retrying every second)",
                    d->o.gs_usb_sel[0] != '\0' ? d->o.gs_usb_sel : "(any)", slp_gsusb_sink_last_error(&d->gs));
        } else {
            sld_log(SLD_LOG_INFO, "gs_usb adapter up at %" PRIu32 " bit/s", cfg.can.bitrate);
        }
        d->gs_on = true;
        d->sinks[d->n_sinks++] = slp_gsusb_sink_as_sink(&d->gs);
    }
    if (d->n_sinks == 0) {
        sld_log(SLD_LOG_WARN, "no CAN output (--can, --can-log, --gs-usb): frames are only counted");
    }
    return 0;
}

static int drop_privileges(const char *user)
{
    errno = 0;
    const struct passwd *pw = getpwnam(user);
    if (pw == NULL) {
        sld_log(SLD_LOG_ERR, "--user %s: no such user%s%s", user, errno != 0 ? ": " : "",
                errno != 0 ? strerror(errno) : "");
        return -1;
    }
    if (geteuid() != 0) {
        if (pw->pw_uid == geteuid()) {
            return 0; // already that user
        }
        sld_log(SLD_LOG_ERR, "--user %s: only root can change user (running as uid %u)", user,
                (unsigned)geteuid());
        return -1;
    }
    if (initgroups(pw->pw_name, pw->pw_gid) != 0 || setgid(pw->pw_gid) != 0 || setuid(pw->pw_uid) != 0) {
        sld_log(SLD_LOG_ERR, "--user %s: cannot drop privileges: %s", user, strerror(errno));
        return -1;
    }
    if (pw->pw_uid != 0 && (setuid(0) == 0 || seteuid(0) == 0)) {
        sld_log(SLD_LOG_ERR, "--user %s: root privileges could be regained", user);
        return -1;
    }
    sld_log(SLD_LOG_INFO, "running as %s (uid %u, gid %u)", user, (unsigned)pw->pw_uid, (unsigned)pw->pw_gid);
    return 0;
}

static void log_stats(daemon_t *d, int level, const char *what)
{
    const sl_pipeline_stats_t *s = &g_pipe.stats;
    sld_log(level,
            "%s: %" PRIu32 " rotations, %" PRIu32 " azimuths (%" PRIu32 " missing), %" PRIu32
            " targets, level %u, decoder: %" PRIu32 " messages %" PRIu32 " resyncs; CAN: %" PRIu32
            " frames (%" PRIu32 " Status, %" PRIu32 " idle Status), %" PRIu32 " dropped; motion: %" PRIu32
            " accepted %" PRIu32 " rejected; candidates dropped (no target slot) %" PRIu32,
            what, s->rotations, s->azimuths, s->azimuths_missing, s->targets,
            (unsigned)sl_track_max_level(&g_pipe.tracker), g_pipe.proto.stats.messages,
            g_pipe.proto.stats.resyncs, d->frames_out, d->status_frames, d->idle_status_frames,
            s->can_dropped, s->motion_accepted, s->motion_rejected,
            g_pipe.detect.stats.target_overflow);
    const sl_profile_stats_t *ps = &g_pipe.prof.stats;
    sld_log(SLD_LOG_INFO, "%s: range profiles: %" PRIu32 " targets refined (%" PRIu32
            " from one rotation's neighbouring azimuths, moving, %" PRIu32
            " neighbours left out as ending elsewhere; %" PRIu32
            " with a ramp in their sigma); mask bounds kept: %" PRIu32
            " no slot, %" PRIu32 " too few rows, %" PRIu32 " no tail (%" PRIu32
            " cut off), %" PRIu32
            " other; tilt observations %" PRIu32 " (%" PRIu32 " unverified left out, %" PRIu32
            " outliers dropped from inconsistent fits, %" PRIu32 " from fitted ones)",
            what, ps->extracted, ps->spatial, ps->misaligned, ps->ramps,
            ps->fallback[SL_PROFILE_NO_SLOT],
            ps->fallback[SL_PROFILE_FEW_FRAMES], ps->fallback[SL_PROFILE_NO_TAIL], ps->cut_ends,
            ps->fallback[SL_PROFILE_LEAD_CUT] + ps->fallback[SL_PROFILE_NO_RUN] +
                ps->fallback[SL_PROFILE_TAIL_CUT],
            g_pipe.tilt.stats.observations, g_pipe.tilt.stats.unverified,
            g_pipe.tilt.stats.outliers, g_pipe.tilt.stats.gross);
#if SL_CFG_FIT
    if (g_pipe.cfg.fit) {
        sld_log(SLD_LOG_INFO, "%s: sensor model's fit: %" PRIu32 " fits run, %" PRIu32
                " targets given their slot's last fit, %" PRIu32 " refits without an answer "
                "(the last fit kept), %" PRIu32 " answers from the flat density; OK %" PRIu32 ", out of model %" PRIu32 ", no signal %" PRIu32
                ", not converged %" PRIu32,
                what, ps->fits, ps->fits_reused, ps->fits_kept, ps->fits_flat,
                ps->fit_quality[SL_RFIT_OK],
                ps->fit_quality[SL_RFIT_OUT_OF_MODEL], ps->fit_quality[SL_RFIT_NO_SIGNAL],
                ps->fit_quality[SL_RFIT_NOT_CONVERGED]);
    }
#endif
    if (g_pipe.prof.slope_q8 != 0U) { // what --tail-slope takes on the next start
        sld_log(SLD_LOG_INFO, "%s: tail slope %.4f values/bin (%s; %" PRIu32 " fits taken, %" PRIu32
                " refused)", what, g_pipe.prof.slope_q8 / 256.0,
                g_pipe.prof.cal_n != 0U ? "self-fitted" : "--tail-slope, no fit yet",
                g_pipe.prof.stats.cal_accepted, g_pipe.prof.stats.cal_rejected);
    }
    const uint8_t *ln = g_pipe.prof.lead_n;
    if (g_pipe.prof.front_bins != 0U || g_pipe.prof.stats.front_skipped != 0U ||
        ln[0] + ln[1] + ln[2] + ln[3] + ln[4] + ln[5] + ln[6] + ln[7] != 0) {
        // what --front-bins takes on the next start
        sld_log(SLD_LOG_INFO, "%s: smear front part %u bins; rises of leaning-away returns "
                "(bins 0..7+, recent): %u %u %u %u %u %u %u %u; r1 moved past it on %" PRIu32
                " targets", what, (unsigned)g_pipe.prof.front_bins, ln[0], ln[1], ln[2], ln[3],
                ln[4], ln[5], ln[6], ln[7], g_pipe.prof.stats.front_skipped);
    }
    if (g_pipe.prof.r2_offset_um != 0 || g_pipe.prof.stats.resid_samples != 0U) {
        // what --r2-offset takes on the next start
        sld_log(SLD_LOG_INFO, "%s: walk-end offset of r2 %+.3f mm (%s; %" PRIu32
                " upright residuals counted)", what, g_pipe.prof.r2_offset_um / 1000.0,
                g_pipe.prof.stats.resid_samples >= SL_PROFILE_RESID_MIN ? "learned on upright poles"
                                                                       : "--r2-offset, not enough of its own yet",
                g_pipe.prof.stats.resid_samples);
    }
    // The sensor model: the response in use and the noise floor the occupied thresholds read.
    const sl_response_t *rs = &g_pipe.resp;
    char fl[8 * 24] = "";
    size_t fo = 0;
    for (uint32_t b = 0; b * SL_RESP_FLOOR_BAND < g_pipe.mask_bins && fo + 24 < sizeof fl; b++) {
        const int32_t f = sl_response_floor_lp(rs, b * SL_RESP_FLOOR_BAND);
        fo += (size_t)(f == INT32_MIN
                           ? snprintf(fl + fo, sizeof fl - fo, " -/%u", (unsigned)g_pipe.thr_band[b])
                           : snprintf(fl + fo, sizeof fl - fo, " %.1f/%u", f * 3.0103 / 256.0,
                                      (unsigned)g_pipe.thr_band[b]));
    }
    sld_log(SLD_LOG_INFO, "%s: sensor model: range response %s (half power %.2f bins; %" PRIu32
            " isolated peaks learned from %" PRIu32 " rows, %" PRIu32 " with a rival, %" PRIu32
            " implausible); noise floor dB / occupied threshold per %u bins:%s", what,
            rs->source == SL_RESPONSE_LEARNED      ? "learned from the stream"
            : rs->source == SL_RESPONSE_CALIBRATED ? "from the calibration"
                                                   : "the board's prior",
            sl_response_hpw_q8(rs) / 256.0, rs->learn_n, rs->stats.rows, rs->stats.rivals,
            rs->stats.implausible, (unsigned)SL_RESP_FLOOR_BAND, fl);
    const sl_drift_t *dw = &g_pipe.drift;
    sld_log(SLD_LOG_INFO, "%s: theta drift watch: %s %+.2f deg%s; samples %" PRIu32 ", no ground %" PRIu32
            ", occupied %" PRIu32 ", outliers %" PRIu32, what, dw->valid ? "estimate" : "no estimate",
            dw->drift_cdeg / 100.0, dw->fault ? " THETA_DRIFT" : "", dw->stats.samples, dw->stats.no_ground,
            dw->stats.occupied, dw->stats.outliers);
    if (s->can_rx != 0) {
        const sl_can_e2e_rx_t *e2e = &g_pipe.motion_rx.e2e;
        const uint32_t *n = e2e->stats.status;
        sld_log(level, "%s: VehicleMotion E2E (Profile 11, max delta counter %u): OK %" PRIu32
                ", OK_SOME_LOST %" PRIu32 " (%" PRIu32 " frames lost), INITIAL %" PRIu32
                " (first after a start or a gap: value unused), REPEATED %" PRIu32
                ", WRONG_SEQUENCE %" PRIu32 ", ERROR %" PRIu32 " (CRC %" PRIu32 ", DLC %" PRIu32
                ", counter 15 %" PRIu32 ", Data ID nibble %" PRIu32 "), NO_NEW_DATA %" PRIu32
                " (reception gaps); %" PRIu32 " other ids",
                what, (unsigned)e2e->max_delta_counter, n[SL_CAN_E2E_OK], n[SL_CAN_E2E_OK_SOME_LOST],
                e2e->stats.lost_frames, n[SL_CAN_E2E_INITIAL], n[SL_CAN_E2E_REPEATED],
                n[SL_CAN_E2E_WRONG_SEQUENCE], n[SL_CAN_E2E_ERROR], e2e->stats.crc_errors,
                e2e->stats.bad_dlc, e2e->stats.bad_counter, e2e->stats.bad_nibble,
                n[SL_CAN_E2E_NO_NEW_DATA], g_pipe.motion_rx.stats.other_ids);
    }
    if (d->exit_undrained != 0) {
        sld_log(SLD_LOG_WARN, "%s: CAN: %" PRIu32 " frames undrained at exit (dropped)", what, d->exit_undrained);
    }
    if (s->motion_set_calls != 0) {
        sld_log(SLD_LOG_DEBUG, "%s: motion setter (--motion): %" PRIu32 " calls", what, s->motion_set_calls);
    }
    const sl_detect_stats_t *ds = &g_pipe.detect.stats;
    sld_log(SLD_LOG_DEBUG,
            "%s: detection: %" PRIu32 " runs, %" PRIu32 " groups, %" PRIu32 " targets; rejected near %" PRIu32
            " shadow %" PRIu32 " wide %" PRIu32 " broken %" PRIu32 " short %" PRIu32 " rho %" PRIu32 " weak %" PRIu32
            "; overflows cand %" PRIu32 " target %" PRIu32
            "; tracks: %" PRIu32 " created %" PRIu32 " dropped %" PRIu32 " confirmed %" PRIu32
            " inconsistent; mask bins %u",
            what, ds->runs, ds->groups, ds->targets, ds->rejected[SL_DETECT_REJ_NEAR],
            ds->rejected[SL_DETECT_REJ_SHADOW], ds->rejected[SL_DETECT_REJ_WIDE],
            ds->rejected[SL_DETECT_REJ_BROKEN], ds->rejected[SL_DETECT_REJ_SHORT],
            ds->rejected[SL_DETECT_REJ_RHO], ds->rejected[SL_DETECT_REJ_WEAK], ds->cand_overflow, ds->target_overflow,
            g_pipe.tracker.stats.created, g_pipe.tracker.stats.dropped,
            g_pipe.tracker.stats.confirmations, g_pipe.tracker.stats.inconsistent,
            (unsigned)g_pipe.mask_bins);
    for (size_t i = 0; i < d->n_sinks; i++) {
        slp_can_sink_stats_t st = {0, 0, 0, 0};
        d->sinks[i].get_stats(d->sinks[i].ctx, &st);
        sld_log(level, "%s: sink %s: %" PRIu32 " sent, %" PRIu32 " dropped, %" PRIu32 " queued, %" PRIu32 " errors",
                what, d->sinks[i].name, st.sent, st.dropped, st.queued, st.errors);
    }
    if (d->sc_on) {
        const slp_socketcan_stats_t *c = &d->sc.stats;
        sld_log(level + (c->retries + c->bus_off + c->link_down == 0 ? 1 : 0),
                "%s: socketcan %s: %" PRIu32 " retries (%" PRIu32 " ENOBUFS), bus-off %" PRIu32
                ", link down %" PRIu32 ", dropped full/stale/down/bus-off/error %" PRIu32 "/%" PRIu32
                "/%" PRIu32 "/%" PRIu32 "/%" PRIu32,
                what, d->sc.ifname, c->retries, c->enobufs, c->bus_off, c->link_down, c->dropped_full,
                c->dropped_stale, c->dropped_down, c->dropped_bus_off, c->dropped_error);
    }
    if (d->gs_on) {
        const slp_gsusb_sink_stats_t *g = &d->gs.stats;
        const bool lost = g->unconfirmed + g->dropped_in_flight + g->dropped_down + g->dropped_full +
                              g->dropped_stale + g->dropped_error + g->dropped_invalid != 0U;
        sld_log(level + (lost || g->down_events != 0U ? 0 : 1),
                "%s: gs_usb: %" PRIu32 " submitted, %" PRIu32 " confirmed, %" PRIu32
                " unconfirmed; dropped in-flight/down/full/stale/error/invalid %" PRIu32 "/%" PRIu32
                "/%" PRIu32 "/%" PRIu32 "/%" PRIu32 "/%" PRIu32 "; %" PRIu32 " down events, %" PRIu32
                " reopens",
                what, g->submitted, g->confirmed, g->unconfirmed, g->dropped_in_flight, g->dropped_down,
                g->dropped_full, g->dropped_stale, g->dropped_error, g->dropped_invalid, g->down_events,
                g->reopens);
    }
    if (d->is_radar) {
        const slp_radar_client_stats_t *r = &d->radar.stats;
        sld_log(level,
                "%s: radar %s: %" PRIu32 " connects (%" PRIu32 " reconnects), %" PRIu32 " failures, %" PRIu32
                " silence timeouts, %" PRIu32 " FFT messages, %" PRIu64 " bytes",
                what, slp_radar_state_str(d->radar.state), r->connects, r->reconnects,
                r->connect_failures + r->connect_timeouts, r->silence_timeouts, r->fft_messages, r->bytes_rx);
    }
}

// --calibration FILE: the vehicle's calibration (INI or blob) validated against the nominal
// board; the pipeline then runs on the calibrated view. Any error: a clear message, exit 1.
static sl_calblob_ws_t g_cal_ws;

static int load_calibration(daemon_t *d)
{
    char err[512];
    size_t len = 0;
    if (slp_calib_file_load(d->o.calibration, d->board, &d->cal_blob, &len, err, sizeof err) != 0) {
        sld_log(SLD_LOG_ERR, "calibration %s", err);
        return -1;
    }
    sl_calblob_info_t info;
    const sl_err_t e = sl_calblob_open(d->cal_blob, len, d->board, &g_cal_ws, &d->cal_board, &info);
    if (e != SL_OK) {
        sld_log(SLD_LOG_ERR, "calibration %s: rejected for board %s: %s (%s, entry %u); not used",
                d->o.calibration, d->board->name, sl_err_str(e), info.what != NULL ? info.what : "?",
                (unsigned)info.index);
        free(d->cal_blob);
        d->cal_blob = NULL;
        return -1;
    }
    int tmin = INT32_MAX, tmax = INT32_MIN;
    unsigned changed = 0;
    for (size_t i = 0; i < d->cal_board.azimuths; i++) {
        const int t = d->cal_board.theta_cdeg[i];
        tmin = t < tmin ? t : tmin;
        tmax = t > tmax ? t : tmax;
        changed += t != d->board->theta_cdeg[i] ? 1U : 0U;
    }
    sld_log(SLD_LOG_INFO, "calibration %s: board %s, theta %.2f .. %.2f deg (%u of %u azimuths differ from "
            "the board's), radar height %.3f m, crc %08" PRIx32 "%s", d->o.calibration, d->board->name,
            tmin / 100.0, tmax / 100.0, changed, (unsigned)d->cal_board.azimuths,
            d->cal_board.radar_height_um / 1e6, info.crc, info.zero_copy ? "" : " (decoded)");
    d->board = &d->cal_board;
    return 0;
}

static int setup_signals(daemon_t *d)
{
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGHUP);
    if (sigprocmask(SIG_BLOCK, &set, NULL) != 0) {
        return -1;
    }
    d->sfd = signalfd(-1, &set, SFD_NONBLOCK | SFD_CLOEXEC);
    signal(SIGPIPE, SIG_IGN); // a closed stdout is an EPIPE write error, counted
    return d->sfd < 0 ? -1 : 0;
}

static void read_signals(daemon_t *d)
{
    struct signalfd_siginfo si;
    while (read(d->sfd, &si, sizeof si) == (ssize_t)sizeof si) {
        if (si.ssi_signo == SIGHUP) {
            sld_log(SLD_LOG_INFO, "SIGHUP ignored (no reload; restart to apply a new config)");
            continue;
        }
        if (!d->stop) {
            d->stop = true;
            d->stop_why = si.ssi_signo == SIGINT ? "SIGINT" : "SIGTERM";
        }
    }
}

// ---------------------------------------------------------------------------------------

// The exit drain's clock and pause (slp_can_sinks_drain injects them for tests).
static uint64_t drain_now_us(void *ctx)
{
    (void)ctx;
    return slp_now_us();
}

static void drain_wait(void *ctx)
{
    (void)ctx;
    struct timespec ts = {0, 2000000};
    nanosleep(&ts, NULL);
}

static void shutdown_all(daemon_t *d)
{
    d->mono_us = slp_now_us();
    if (d->is_radar) {
        const uint32_t stops = d->radar.stats.stops_sent;
        slp_radar_client_stop(&d->radar, 200); // Stop FFT when streaming; STOPPED -> finish
        if (d->radar.stats.stops_sent != stops) {
            sld_log(SLD_LOG_INFO, "Stop FFT sent to the radar");
        }
        radar_finish(d, d->mono_us);
    } else if (!d->cap_done) {
        sl_pipeline_finish(&g_pipe, pipe_now(d)); // interrupted: flush the partial rotation
    }
    // Drain what the sinks still hold (SocketCAN retry queue, gs_usb echo window): until
    // every queue is empty, or no frame has left any queue for DRAIN_STALL_MS (progress,
    // not elapsed time: a slow adapter that keeps confirming is waited for).
    const slp_can_drain_result_t dr = slp_can_sinks_drain(d->sinks, d->n_sinks, (uint64_t)DRAIN_STALL_MS * 1000U,
                                                          drain_now_us, drain_wait, NULL);
    d->mono_us = slp_now_us();
    d->exit_undrained = dr.left;
    if (dr.left != 0) {
        sld_log(SLD_LOG_WARN,
                "exit: %" PRIu32 " frames still queued, dropped (no sink progress for %u ms; %" PRIu32
                " frames left the queues during the drain)",
                dr.left, DRAIN_STALL_MS, dr.moved);
    }
    log_stats(d, SLD_LOG_INFO, "exit");
    if (d->is_radar) {
        slp_radar_client_deinit(&d->radar);
    }
    if (d->sc_on) {
        slp_socketcan_close(&d->sc);
    }
    if (d->log_on) {
        slp_candump_close(&d->log);
    }
    if (d->gs_on) {
        slp_gsusb_sink_close(&d->gs);
    }
    if (d->motion_on) {
        sld_motion_close(&d->motion);
    }
    if (d->targets != NULL) {
        if ((fflush(d->targets) != 0 || (d->targets_own && fclose(d->targets) != 0)) && !d->targets_failed) {
            sld_log(SLD_LOG_ERR, "--targets-out: write failed: %s", strerror(errno));
        }
        d->targets = NULL;
    }
}

int main(int argc, char **argv)
{
    daemon_t *d = &g_d;
    sld_opts_defaults(&d->o);
    char err[1024];
    const int pr = sld_opts_parse(&d->o, argc, argv, err, sizeof err);
    if (pr > 0) {
        return 0;
    }
    if (pr < 0) {
        // The tools' convention: the offending option named, then the usage, on stderr.
        fprintf(stderr, "shadowleand: %s\n", err);
        sld_opts_usage(stderr);
        return 2;
    }
    if (sld_opts_validate(&d->o, err, sizeof err) != 0) {
        fprintf(stderr, "shadowleand: %s\n", err);
        return 2;
    }
    if (d->o.print_config) {
        sld_opts_print(&d->o, stdout);
        return 0;
    }
    sld_log_setup(d->o.verbosity, d->o.use_syslog);
    d->board = sl_board_find(d->o.board);
    if (d->o.calibration[0] != '\0' && load_calibration(d) != 0) {
        return 1;
    }
    d->is_radar = d->o.radar_host[0] != '\0';
    d->log_time = d->o.log_time != SLD_LOG_TIME_AUTO ? d->o.log_time
                  : d->is_radar                     ? SLD_LOG_TIME_WALL
                                                    : SLD_LOG_TIME_DATA;
    d->idle_status = d->is_radar || d->o.realtime;
    d->sfd = -1;
    d->mono_us = slp_now_us();
    d->start_mono = d->mono_us;
    sl_can_ids_t ids;
    sl_can_ids_from_board(&ids, d->board);
    d->status_id = ids.id[SL_CAN_MSG_STATUS] & SL_CAN_EFF_MASK;
    d->status_eff = (uint8_t)((ids.id[SL_CAN_MSG_STATUS] & SL_CAN_DBC_EFF_BIT) != 0 ? SL_CAN_FLAG_EFF : 0U);

    if (setup_signals(d) != 0) {
        sld_log(SLD_LOG_ERR, "signals: %s", strerror(errno));
        return 1;
    }
    // Pipeline.
    sl_pipeline_cfg_default(&d->pcfg, d->board);
    d->pcfg.port.can_tx = port_can_tx;
    d->pcfg.port.on_rotation = port_on_rotation;
    d->pcfg.port.ctx = d;
    d->pcfg.profile_cfg.prior_slope_q8 = d->o.tail_slope_q8; // --tail-slope (0: none)
    d->pcfg.profile_cfg.prior_front_bins = d->o.front_bins;  // --front-bins (0: none)
    d->pcfg.profile_cfg.prior_r2_offset_um = d->o.r2_offset_um; // --r2-offset (0: none)
    if (d->o.extract != 0U) {
        d->pcfg.fit = d->o.extract == 2U; // --extract walk|fit (else the pipeline's default)
    }
    if (sl_pipeline_init(&g_pipe, d->board, &d->pcfg) != SL_OK) {
        sld_log(SLD_LOG_ERR, "pipeline for board %s: %s", d->board->name,
                g_pipe.last_err_msg != NULL ? g_pipe.last_err_msg : "init failed");
        return 1;
    }
    // Input, outputs, motion: everything that may need privileges is opened here.
    if ((d->is_radar ? radar_setup(d) : capture_setup(d)) != 0 || open_sinks(d) != 0) {
        shutdown_all(d);
        return 1;
    }
    if (d->o.targets_out[0] != '\0') {
        const bool out = strcmp(d->o.targets_out, "-") == 0;
        d->targets = out ? stdout : fopen(d->o.targets_out, "w");
        d->targets_own = !out;
        if (d->targets == NULL || sld_targets_write_header(d->targets, d->board, &d->pcfg) != 0) {
            sld_log(SLD_LOG_ERR, "--targets-out %s: %s", d->o.targets_out, strerror(errno));
            shutdown_all(d);
            return 1;
        }
    }
    const char *miface = sld_opts_motion_iface(&d->o);
    if (miface[0] != '\0') {
        d->motion_on = true;
        if (sld_motion_open(&d->motion, miface, d->board->can_id_vehicle_motion, d->mono_us) != SL_OK) {
            sld_log(SLD_LOG_WARN, "--motion-can %s: %s (retrying every second)", miface,
                    strerror(d->motion.last_errno));
        }
    }
    if (d->o.user[0] != '\0' && drop_privileges(d->o.user) != 0) {
        shutdown_all(d);
        return 1;
    }
    char port_txt[8] = "";
    if (d->is_radar) {
        snprintf(port_txt, sizeof port_txt, ":%u", (unsigned)d->o.radar_port);
    }
    if (d->o.fixed_motion) {
        sld_log(SLD_LOG_INFO, "constant motion: %.3f m/s, %.2f deg/s (--motion)",
                (double)d->o.fixed_speed_mm_s / 1000.0, (double)d->o.fixed_yaw_cdeg_s / 100.0);
    }
    sld_log(SLD_LOG_INFO, "board %s, input %s%s%s%s, %zu CAN output(s)%s%s", d->board->name,
            d->is_radar ? "radar " : "capture ", d->is_radar ? d->o.radar_host : d->o.capture, port_txt,
            d->is_radar ? "" : (d->o.realtime ? " (real time)" : " (as fast as possible)"), d->n_sinks,
            d->motion_on ? ", VehicleMotion from " : "", d->motion_on ? miface : "");

    if (d->is_radar) {
        slp_radar_client_start(&d->radar);
    }
    d->link_state = d->is_radar ? SL_CAN_LINK_CONNECTING : SL_CAN_LINK_STREAMING;
    sl_pipeline_set_link_state(&g_pipe, d->link_state);
    // A live radar gets a Status frame at once (CONNECTING); a capture replayed in real time
    // only when a rotation is late, so --realtime and --fast write the same frames. The
    // clock is read again here: opening the outputs (a gs_usb adapter) may take a while.
    d->mono_us = slp_now_us();
    d->last_status_mono = d->is_radar ? d->mono_us - (uint64_t)d->o.status_period_ms * 1000U : d->mono_us;
    d->next_stats_mono = d->o.stats_every_ms != 0 ? d->mono_us + (uint64_t)d->o.stats_every_ms * 1000U : UINT64_MAX;
    const uint64_t end_mono = d->o.duration_ms != 0 ? d->mono_us + (uint64_t)d->o.duration_ms * 1000U : UINT64_MAX;

    struct pollfd fds[4 + 8];
    while (!d->stop) {
        // --- wait
        d->mono_us = slp_now_us();
        uint64_t wake = end_mono;
        if (d->idle_status) {
            const uint64_t due = d->last_status_mono + (uint64_t)d->o.status_period_ms * 1000U;
            wake = due < wake ? due : wake;
        }
        wake = d->next_stats_mono < wake ? d->next_stats_mono : wake;
        nfds_t n = 0;
        fds[n++] = (struct pollfd){d->sfd, POLLIN, 0};
        if (d->motion_on) {
            fds[n++] = (struct pollfd){sld_motion_fd(&d->motion), POLLIN, 0}; // fd -1 is ignored
            if (sld_motion_fd(&d->motion) < 0) {
                const uint64_t due = d->motion.next_open_us;
                wake = due < wake ? due : wake;
            }
        }
        const nfds_t i_radar = n;
        if (d->is_radar) {
            fds[n++] = (struct pollfd){slp_radar_client_fd(&d->radar), slp_radar_client_events(&d->radar), 0};
            const int t = slp_radar_client_timeout_ms(&d->radar, d->mono_us);
            if (t >= 0) {
                const uint64_t due = d->mono_us + (uint64_t)t * 1000U;
                wake = due < wake ? due : wake;
            }
            if (d->o.exit_idle_ms != 0 && d->had_fft) {
                const uint64_t due = d->last_fft_mono + (uint64_t)d->o.exit_idle_ms * 1000U;
                wake = due < wake ? due : wake;
            }
            // Recompute SILENT on time.
            if (d->radar.state == SLP_RADAR_STREAMING) {
                uint64_t ref = d->stream_start_mono > d->last_fft_mono ? d->stream_start_mono : d->last_fft_mono;
                const uint64_t due = ref + (uint64_t)d->o.silent_ms * 1000U;
                if (due > d->mono_us && due < wake) {
                    wake = due;
                }
            }
        } else if (!d->cap_done) {
            const uint64_t cap_due = capture_step(d);
            d->cap_next_due = cap_due;
            if (cap_due == 0) {
                wake = d->mono_us; // more to feed now: just look at the fds
            } else {
                wake = cap_due < wake ? cap_due : wake;
            }
        }
        if (d->gs_on && slp_gsusb_sink_is_up(&d->gs)) {
            n += (nfds_t)slp_gsusb_usb_pollfds(&d->gs.usb, &fds[n], 8);
            const uint64_t due = d->mono_us + 50000U; // echo timeouts, reopen
            wake = due < wake ? due : wake;
        } else if (d->gs_on || d->sc_on) {
            const uint64_t due = d->mono_us + 200000U; // retries, reopen
            wake = due < wake ? due : wake;
        }
        int timeout_ms = -1;
        if (wake != UINT64_MAX) {
            const uint64_t ms = wake <= d->mono_us ? 0 : (wake - d->mono_us + 999U) / 1000U;
            timeout_ms = ms > 60000U ? 60000 : (int)ms;
        }
        if (d->cap_done && !d->is_radar) {
            break; // capture fed completely (finish already called)
        }
        const int rc = poll(fds, n, timeout_ms);
        if (rc < 0 && errno != EINTR) {
            sld_log(SLD_LOG_ERR, "poll: %s", strerror(errno));
            break;
        }
        d->mono_us = slp_now_us();
        // --- work
        if (rc > 0 && (fds[0].revents & POLLIN) != 0) {
            read_signals(d);
        }
        if (d->motion_on) {
            sld_motion_read(&d->motion, d->mono_us, on_motion_frame, d);
        }
        if (d->is_radar && d->o.exit_idle_ms != 0 && d->had_fft &&
            d->mono_us >= d->last_fft_mono + (uint64_t)d->o.exit_idle_ms * 1000U) {
            // Before the client's timers: a late wake-up stops with the link still open
            // (Stop FFT is sent) rather than after a watchdog drop.
            d->stop = true;
            d->stop_why = "--exit-idle";
        }
        if (d->is_radar && !d->stop) {
            const short rev = rc > 0 ? fds[i_radar].revents : 0;
            slp_radar_client_handle(&d->radar, rev, d->mono_us);
            if (d->radar.state != d->last_radar_state) {
                sld_log(SLD_LOG_DEBUG, "radar state %s", slp_radar_state_str(d->radar.state));
                d->last_radar_state = d->radar.state;
            }
            const uint8_t ls = radar_link_state(d);
            if (ls != d->link_state) {
                if (ls == SL_CAN_LINK_SILENT) {
                    sld_log(SLD_LOG_WARN, "radar link SILENT: no FFT data for %" PRIu32 " ms", d->o.silent_ms);
                } else if (d->link_state == SL_CAN_LINK_SILENT && ls == SL_CAN_LINK_STREAMING) {
                    sld_log(SLD_LOG_INFO, "radar link streaming again");
                }
                d->link_state = ls;
                sl_pipeline_set_link_state(&g_pipe, ls);
            }
        }
        slp_can_sinks_poll(d->sinks, d->n_sinks, d->mono_us);
        report_sink_drops(d);
        if (d->log_on && d->log.stats.errors != 0U && !d->log_error_logged) {
            d->log_error_logged = true;
            sld_log(SLD_LOG_ERR, "--can-log %s: write failed: %s (frames are lost; Health "
                    "CAN_OUTPUT_ERRORS)", d->o.can_log, strerror(d->log.last_errno));
        }
        // A capture replayed in real time is idle only when its next message is due later
        // (a gap in the capture). When its data is due already, the daemon is behind
        // schedule (descheduled under load): the data is fed next time round and the
        // rotation's own Status follows; an idle Status here would be a timing artefact
        // (the flaky "Status frame outside a rotation group" of daemon_gs_usb_output_in_vm).
        const bool behind = !d->is_radar && (d->cap_next_due == 0 || d->cap_next_due <= d->mono_us);
        if (d->idle_status && !behind &&
            d->mono_us >= d->last_status_mono + (uint64_t)d->o.status_period_ms * 1000U) {
            send_idle_status(d);
        }
        if (d->mono_us >= d->next_stats_mono) {
            log_stats(d, SLD_LOG_INFO, "stats");
            d->next_stats_mono = d->mono_us + (uint64_t)d->o.stats_every_ms * 1000U;
        }
        if (d->targets != NULL && d->targets_own) {
            fflush(d->targets);
        }
        if (d->mono_us >= end_mono && !d->stop) {
            d->stop = true;
            d->stop_why = "--duration";
        }
    }
    if (d->stop) {
        sld_log(SLD_LOG_INFO, "stopping (%s)", d->stop_why != NULL ? d->stop_why : "?");
    } else if (!d->is_radar) {
        sld_log(SLD_LOG_INFO, "end of capture");
    }
    if (!d->is_radar && (g_pipe.stats.rotations == 0U || sl_pipeline_faults(&g_pipe) != 0U)) {
        // A capture that ends blind or faulty says so on CAN: one last Status + Health
        // (a clean capture ends with its last rotation's frames, as before).
        send_idle_status(d);
    }
    const bool input_ok = d->is_radar || capture_report(d);
    shutdown_all(d);
    // Exit status (docs/DAEMON.md, "Exit statuses"): 1 unreadable input, 4 an output could not be
    // written (CAN log, targets), 3 capture mode without a usable rotation or with a
    // configuration fault raised, 0 otherwise (2: bad options, before this point).
    const bool log_failed = d->log_on && d->log.stats.errors != 0U;
    if (log_failed) {
        sld_log(SLD_LOG_ERR, "--can-log %s: %" PRIu32 " write errors (%s), %" PRIu32 " frames lost",
                d->o.can_log, d->log.stats.errors, strerror(d->log.last_errno), d->log.stats.dropped);
    }
    const uint16_t cfg_faults = (uint16_t)(g_pipe.faults_seen | sl_pipeline_faults(&g_pipe)) &
                                (uint16_t)(SL_CAN_FAULT_CONFIG_MISMATCH | SL_CAN_FAULT_RANGE_RESOLUTION_MISMATCH);
    int exit_rc = 0;
    if (!input_ok) {
        exit_rc = 1;
    } else if (log_failed || d->targets_failed) {
        exit_rc = 4;
    } else if (!d->is_radar && (g_pipe.stats.rotations == 0U || cfg_faults != 0U)) {
        if ((cfg_faults & SL_CAN_FAULT_CONFIG_MISMATCH) != 0U) {
            sld_log(SLD_LOG_ERR, "input %s: the radar's geometry (azimuths / encoder size) differs from "
                    "board %s: %" PRIu32 " rows refused", d->o.capture, d->board->name, g_pipe.stats.rows_dropped);
        }
        if ((cfg_faults & SL_CAN_FAULT_RANGE_RESOLUTION_MISMATCH) != 0U) {
            sld_log(SLD_LOG_ERR, "input %s: radar bin size %" PRIu32 " um differs from board %s (%" PRIu32
                    " um) by more than 1 %%", d->o.capture, g_pipe.radar_bin_um, d->board->name,
                    d->board->bin_size_um);
        }
        if (g_pipe.stats.rotations == 0U) {
            sld_log(SLD_LOG_ERR, "input %s: no usable rotation", d->o.capture);
        }
        exit_rc = 3;
    }
    slp_capture_close(d->cr);
    free(d->held);
    free(d->cal_blob);
    free(d->hold);
    free(d->pacer_reasm);
    free(d->radar_reasm);
    sld_log_close();
    return exit_rc;
}
