// SPDX-License-Identifier: MIT
// sl-gsusb-send: open a gs_usb (candleLight) adapter through libusb and send CAN frames,
// generated or from a candump log, printing each confirmation (the adapter's echo).
// Uses the same sink as the daemon (firmware/port/linux/gsusb/gsusb_sink.h).
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "candump.h"
#include "sl_cli.h"
#include "gsusb/gsusb_sink.h"
#include "port_clock.h"

#define MAX_FRAMES 100000U

static volatile sig_atomic_t stop_flag;

static void on_signal(int sig)
{
    (void)sig;
    stop_flag = 1;
}

typedef struct app {
    slp_gsusb_sink_t sink;
    FILE *tx_log;
    FILE *rx_log;
    bool quiet;
    uint32_t confirmed_after_reopen;
    uint32_t rx_replies;
} app_t;

static app_t app;

static void usage(FILE *to)
{
    fprintf(to,
            "usage: sl-gsusb-send [VID:PID|BUS-PORT] [--bitrate B] [--count N] [--log FILE] [options]\n"
            "Open a gs_usb / candleLight USB-CAN adapter with libusb (the kernel gs_usb driver is\n"
            "detached while it runs and re-attached at the end) and send CAN frames; every frame\n"
            "is confirmed by the adapter's echo (it went out on the bus).\n"
            "  VID:PID | BUS-PORT    the adapter: 1d50:606f, or bus-port as in sysfs (1-1, 3-2.4);\n"
            "                        default: the first adapter with a known gs_usb id\n"
            "  --bitrate B           bit/s (default 500000); bit timing from the adapter's clock\n"
            "  --sample-point P      permille (default 875 up to 500k, as Linux)\n"
            "  --count N             generated frames (default 10), or at most N from --log\n"
            "  --log FILE            send the frames of a candump log (candump -L / -l format)\n"
            "  --interval-ms T       pause between frames (default 0: as fast as the echo window allows)\n"
            "  --max-in-flight N     echo window (default 10)\n"
            "  --echo-timeout-ms T   no echo this long: frame unconfirmed (default 1000)\n"
            "  --linger-ms T         after the last frame, wait this long for echoes (default echo timeout + 500)\n"
            "  --drain-ms T          then keep receiving bus frames this long (default 100)\n"
            "  --expect-rx N         ... or until N frames were received from the bus\n"
            "  --reopen-ms T         retry period while the adapter is gone (default 1000)\n"
            "  --tx-log FILE         write every confirmed frame as a candump -L line\n"
            "  --rx-log FILE         write every frame received from the bus as a candump -L line\n"
            "  --summary FILE        write the counters as key=value lines\n"
            "  --loopback / --listen-only   adapter modes (if it offers them)\n"
            "  --list                list the gs_usb adapters and exit\n"
            "  --quiet               no per-frame lines\n"
            "exit status: 0 every frame confirmed, 1 some frames not confirmed, 2 the adapter could\n"
            "not be opened/started (the message says which request failed and why) or usage error\n");
}

static void on_tx_done(void *ctx, const sl_can_frame_t *f, uint32_t tag, slp_gsusb_tx_result_t r,
                       uint64_t latency_us)
{
    app_t *a = ctx;
    char txt[48];
    slp_candump_format_frame(f, txt, sizeof txt);
    if (r == SLP_GSUSB_TX_CONFIRMED) {
        if (a->sink.stats.reopens > 0U) {
            a->confirmed_after_reopen++;
        }
        if (a->tx_log != NULL) {
            char line[96];
            fprintf(a->tx_log, "%s\n", slp_candump_format_line(f, slp_now_us(), "gsusb0", line, sizeof line));
        }
        if (!a->quiet) {
            printf("confirmed #%u %s (echo after %lu us)\n", (unsigned)tag, txt, (unsigned long)latency_us);
        }
    } else if (!a->quiet) {
        printf("%s #%u %s\n", r == SLP_GSUSB_TX_TIMEOUT ? "UNCONFIRMED (no echo)" : "DROPPED in flight",
               (unsigned)tag, txt);
    }
}

static void on_rx(void *ctx, const sl_can_frame_t *f, const slp_gsusb_rx_info_t *info)
{
    app_t *a = ctx;
    char txt[48];
    slp_candump_format_frame(f, txt, sizeof txt);
    if ((f->flags & SL_CAN_FLAG_ERR) == 0U) {
        a->rx_replies++;
    }
    if (a->rx_log != NULL) {
        char line[96];
        fprintf(a->rx_log, "%s\n", slp_candump_format_line(f, info->now_us, "gsusb0", line, sizeof line));
    }
    if (!a->quiet) {
        printf("rx %s%s%s\n", txt, (f->flags & SL_CAN_FLAG_ERR) != 0U ? " (error frame)" : "",
               info->overflow ? " (adapter RX overflow)" : "");
    }
}

// Generated frame k: alternating 11-bit and 29-bit ids, dlc k % 9, a data pattern.
static sl_can_frame_t gen_frame(uint32_t k)
{
    sl_can_frame_t f;
    memset(&f, 0, sizeof f);
    if (k % 3U == 2U) {
        f.flags = SL_CAN_FLAG_EFF;
        f.id = (0x1ABC0000U + k * 0x101U) & SL_CAN_EFF_MASK;
    } else {
        f.id = (0x100U + k) & SL_CAN_SFF_MASK;
    }
    f.dlc = (uint8_t)(k % 9U);
    for (uint8_t i = 0; i < f.dlc; i++) {
        f.data[i] = (uint8_t)(k * 7U + i * 0x11U);
    }
    return f;
}

static bool parse_u32(const char *s, uint32_t *out)
{
    char *end = NULL;
    errno = 0;
    unsigned long v = strtoul(s, &end, 0);
    if (errno != 0 || end == s || *end != '\0' || v > 0xFFFFFFFFUL) {
        return false;
    }
    *out = (uint32_t)v;
    return true;
}

static size_t load_log(const char *path, sl_can_frame_t *frames, size_t max, uint32_t limit)
{
    FILE *fp = fopen(path, "r");
    if (fp == NULL) {
        fprintf(stderr, "sl-gsusb-send: cannot open %s: %s\n", path, strerror(errno));
        exit(2);
    }
    char line[512];
    size_t n = 0;
    unsigned lineno = 0;
    while (fgets(line, sizeof line, fp) != NULL && n < max && n < limit) {
        lineno++;
        const char *why = NULL;
        sl_err_t rc = slp_candump_parse_line(line, &frames[n], &why);
        if (rc == SL_ERR_NEED_MORE) {
            continue;
        }
        if (rc != SL_OK) {
            fprintf(stderr, "sl-gsusb-send: %s:%u: %s\n", path, lineno, why != NULL ? why : "bad line");
            exit(2);
        }
        if ((frames[n].flags & SL_CAN_FLAG_ERR) != 0U) {
            fprintf(stderr, "sl-gsusb-send: %s:%u: error frame skipped (cannot be sent)\n", path, lineno);
            continue;
        }
        n++;
    }
    fclose(fp);
    return n;
}

static void write_summary(FILE *to, const app_t *a, size_t frames)
{
    const slp_gsusb_sink_stats_t *s = &a->sink.stats;
    const slp_gsusb_stats_t *d = &a->sink.drv.stats;
    const slp_gsusb_usb_stats_t *u = &a->sink.usb.stats;
    const slp_gsusb_bt_result_t *t = &a->sink.drv.timing;
    fprintf(to,
            "frames=%zu\noffered=%u\nsubmitted=%u\nconfirmed=%u\nunconfirmed=%u\n"
            "dropped_in_flight=%u\ndropped_down=%u\ndropped_full=%u\ndropped_stale=%u\n"
            "dropped_error=%u\ndropped_invalid=%u\nrx_frames=%u\nrx_error_frames=%u\n"
            "down_events=%u\nreopen_attempts=%u\nreopens=%u\nopen_failures=%u\n"
            "confirmed_after_reopen=%u\nwindow_full=%u\nmax_in_flight=%u\nstalls_out=%u\n"
            "stalls_in=%u\nclear_halts=%u\nclear_halt_failures=%u\ntx_retries=%u\n"
            "out_resubmits=%u\nusb_out_stalls=%u\nusb_in_stalls=%u\nvanished=%u\nbus_off=%u\n"
            "err_passive=%u\nerr_warning=%u\nkernel_detaches=%u\nkernel_reattaches=%u\n"
            "echo_mismatch=%u\necho_unknown=%u\ntx_timeouts=%u\nusb_out_timeouts=%u\n"
            "eps_from_descriptor=%d\nep_in=0x%02x\nep_out=0x%02x\nfclk=%u\nbitrate=%u\nbrp=%u\n"
            "prop_seg=%u\nphase_seg1=%u\nphase_seg2=%u\nsjw=%u\nsample_point=%u\n",
            frames, s->offered, s->submitted, s->confirmed, s->unconfirmed, s->dropped_in_flight,
            s->dropped_down, s->dropped_full, s->dropped_stale, s->dropped_error, s->dropped_invalid,
            s->rx_frames, s->rx_error_frames, s->down_events, s->reopen_attempts, s->reopens,
            s->open_failures, a->confirmed_after_reopen, d->tx_window_full,
            (unsigned)a->sink.drv.echo.stats.max_in_flight, d->stalls_out, d->stalls_in,
            d->clear_halts, d->clear_halt_failures, d->tx_retries, u->out_resubmits, u->out_stalls,
            u->in_stalls, d->vanished, d->bus_off, d->err_passive, d->err_warning, u->kernel_detaches,
            u->kernel_reattaches, d->echo_mismatch, d->echo_unknown, d->tx_timeouts, u->out_timeouts,
            a->sink.usb.eps_from_descriptor ? 1 : 0, (unsigned)a->sink.usb.ep_in,
            (unsigned)a->sink.usb.ep_out, (unsigned)a->sink.drv.bt_const.fclk_hz, t->bitrate,
            t->bt.brp, t->bt.prop_seg, t->bt.phase_seg1, t->bt.phase_seg2, t->bt.sjw,
            (unsigned)t->sample_point_permille);
}

int main(int argc, char **argv)
{
    slp_gsusb_sink_cfg_t cfg = slp_gsusb_sink_default_cfg();
    uint32_t count = 10;
    bool count_given = false;
    uint32_t interval_ms = 0;
    uint32_t linger_ms = 0;
    bool linger_given = false;
    uint32_t drain_ms = 100;
    uint32_t expect_rx = UINT32_MAX;
    uint32_t v = 0;
    const char *log_path = NULL;
    const char *tx_path = NULL;
    const char *rx_path = NULL;
    const char *summary_path = NULL;
    bool list = false;
    enum {
        O_BITRATE = 256, O_COUNT, O_LOG, O_INTERVAL, O_WINDOW, O_ECHO, O_LINGER, O_REOPEN, O_TX,
        O_RX, O_SUMMARY, O_LOOP, O_LISTEN, O_LIST, O_QUIET, O_SP, O_DRAIN, O_EXPECT_RX, O_HELP
    };
    static const struct option opts[] = {
        {"bitrate", required_argument, NULL, O_BITRATE},
        {"count", required_argument, NULL, O_COUNT},
        {"log", required_argument, NULL, O_LOG},
        {"interval-ms", required_argument, NULL, O_INTERVAL},
        {"max-in-flight", required_argument, NULL, O_WINDOW},
        {"echo-timeout-ms", required_argument, NULL, O_ECHO},
        {"linger-ms", required_argument, NULL, O_LINGER},
        {"reopen-ms", required_argument, NULL, O_REOPEN},
        {"tx-log", required_argument, NULL, O_TX},
        {"rx-log", required_argument, NULL, O_RX},
        {"summary", required_argument, NULL, O_SUMMARY},
        {"loopback", no_argument, NULL, O_LOOP},
        {"listen-only", no_argument, NULL, O_LISTEN},
        {"list", no_argument, NULL, O_LIST},
        {"quiet", no_argument, NULL, O_QUIET},
        {"sample-point", required_argument, NULL, O_SP},
        {"drain-ms", required_argument, NULL, O_DRAIN},
        {"expect-rx", required_argument, NULL, O_EXPECT_RX},
        {"help", no_argument, NULL, O_HELP},
        {NULL, 0, NULL, 0},
    };
    const int info = sl_cli_info(argc, argv, "sl-gsusb-send", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    int c;
    opterr = 0; // unknown options and missing values are reported below, naming the option
    while ((c = getopt_long(argc, argv, ":h", opts, NULL)) != -1) {
        bool ok = true;
        switch (c) {
        case O_BITRATE: ok = parse_u32(optarg, &cfg.can.bitrate) && cfg.can.bitrate > 0U; break;
        case O_COUNT: ok = parse_u32(optarg, &count) && count <= MAX_FRAMES; count_given = true; break;
        case O_LOG: log_path = optarg; break;
        case O_INTERVAL: ok = parse_u32(optarg, &interval_ms); break;
        case O_WINDOW:
            ok = parse_u32(optarg, &v) && v >= 1U && v <= SLP_GSUSB_MAX_IN_FLIGHT;
            cfg.can.max_in_flight = (uint8_t)v;
            break;
        case O_ECHO: ok = parse_u32(optarg, &cfg.can.echo_timeout_ms) && cfg.can.echo_timeout_ms > 0U; break;
        case O_LINGER: ok = parse_u32(optarg, &linger_ms); linger_given = true; break;
        case O_REOPEN:
            ok = parse_u32(optarg, &v) && v > 0U;
            cfg.reopen_interval_us = (uint64_t)v * 1000U;
            break;
        case O_TX: tx_path = optarg; break;
        case O_RX: rx_path = optarg; break;
        case O_SUMMARY: summary_path = optarg; break;
        case O_LOOP: cfg.can.mode_flags |= SLP_GSUSB_FEAT_LOOP_BACK; break;
        case O_LISTEN: cfg.can.mode_flags |= SLP_GSUSB_FEAT_LISTEN_ONLY; break;
        case O_LIST: list = true; break;
        case O_QUIET: app.quiet = true; break;
        case O_SP:
            ok = parse_u32(optarg, &v) && v > 0U && v < 1000U;
            cfg.can.sample_point_permille = (uint16_t)v;
            break;
        case O_DRAIN: ok = parse_u32(optarg, &drain_ms); break;
        case O_EXPECT_RX: ok = parse_u32(optarg, &expect_rx); break;
        case 'h':
        case O_HELP: usage(stdout); return 0;
        case ':': return sl_cli_bad_value("sl-gsusb-send", argv[optind - 1], "needs a value", usage);
        default: return sl_cli_unknown("sl-gsusb-send", argv[optind - 1], usage);
        }
        if (!ok) {
            fprintf(stderr, "sl-gsusb-send: bad value for --%s: '%s'\n", opts[c - O_BITRATE].name, optarg);
            return 2;
        }
    }
    if (optind + 1 < argc) {
        return sl_cli_unknown("sl-gsusb-send", argv[optind + 1], usage);
    }
    cfg.selector = optind < argc ? argv[optind] : NULL;
    if (!linger_given) {
        linger_ms = cfg.can.echo_timeout_ms + 500U;
    }

    if (list) {
        slp_gsusb_usb_t u;
        char buf[2048];
        if (slp_gsusb_usb_init(&u) != SL_OK) {
            fprintf(stderr, "sl-gsusb-send: %s\n", u.err);
            return 2;
        }
        int n = slp_gsusb_usb_list(&u, buf, sizeof buf);
        fputs(buf, stdout);
        printf("%d gs_usb adapter(s)\n", n < 0 ? 0 : n);
        slp_gsusb_usb_deinit(&u);
        return n > 0 ? 0 : 1;
    }

    static sl_can_frame_t frames[MAX_FRAMES];
    size_t n_frames;
    if (log_path != NULL) {
        n_frames = load_log(log_path, frames, MAX_FRAMES, count_given ? count : MAX_FRAMES);
    } else {
        n_frames = count;
        for (uint32_t k = 0; k < count; k++) {
            frames[k] = gen_frame(k);
        }
    }
    if (tx_path != NULL && (app.tx_log = fopen(tx_path, "w")) == NULL) {
        fprintf(stderr, "sl-gsusb-send: cannot write %s: %s\n", tx_path, strerror(errno));
        return 2;
    }
    if (rx_path != NULL && (app.rx_log = fopen(rx_path, "w")) == NULL) {
        fprintf(stderr, "sl-gsusb-send: cannot write %s: %s\n", rx_path, strerror(errno));
        return 2;
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    setvbuf(stdout, NULL, _IOLBF, 0);

    cfg.on_tx_done = on_tx_done;
    cfg.on_rx = on_rx;
    cfg.user = &app;
    sl_err_t rc = slp_gsusb_sink_open(&app.sink, &cfg, slp_now_us());
    if (rc != SL_OK) {
        fprintf(stderr, "sl-gsusb-send: cannot start the adapter: %s (%s)\n",
                slp_gsusb_sink_last_error(&app.sink), sl_err_str(rc));
        slp_gsusb_sink_close(&app.sink);
        return 2;
    }
    const slp_gsusb_t *d = &app.sink.drv;
    printf("adapter %04x:%04x at %s: %u channel(s), sw %u hw %u, clock %u Hz, features 0x%x, "
           "endpoints 0x%02x/0x%02x%s%s\n",
           (unsigned)app.sink.usb.vid, (unsigned)app.sink.usb.pid, app.sink.usb.where,
           (unsigned)d->dev_cfg.icount + 1U, (unsigned)d->dev_cfg.sw_version,
           (unsigned)d->dev_cfg.hw_version, (unsigned)d->bt_const.fclk_hz,
           (unsigned)d->bt_const.feature, (unsigned)app.sink.usb.ep_in, (unsigned)app.sink.usb.ep_out,
           app.sink.usb.eps_from_descriptor ? "" : " (fallback)",
           app.sink.usb.detached ? ", kernel driver detached" : "");
    printf("bit timing: %u bit/s, brp %u, prop %u, ph1 %u, ph2 %u, sjw %u, sample point %u.%u %%\n",
           d->timing.bitrate, d->timing.bt.brp, d->timing.bt.prop_seg, d->timing.bt.phase_seg1,
           d->timing.bt.phase_seg2, d->timing.bt.sjw, d->timing.sample_point_permille / 10U,
           d->timing.sample_point_permille % 10U);

    uint8_t window = d->cfg.max_in_flight;
    for (size_t i = 0; i < n_frames && stop_flag == 0; i++) {
        // Keep the echo window full but do not pile frames into the sink's queue (where
        // they could go stale): wait for a free echo id first.
        while (stop_flag == 0 && slp_gsusb_sink_is_up(&app.sink) &&
               slp_gsusb_sink_pending(&app.sink) >= window) {
            slp_gsusb_sink_wait(&app.sink, 10);
        }
        sl_err_t s = slp_gsusb_sink_send(&app.sink, &frames[i], slp_now_us());
        if (s != SL_OK && !app.quiet) {
            char txt[48];
            printf("not sent #%zu %s: %s%s\n", i, slp_candump_format_frame(&frames[i], txt, sizeof txt),
                   sl_err_str(s), slp_gsusb_sink_is_up(&app.sink) ? "" : " (adapter down)");
        }
        uint64_t until = slp_now_us() + (uint64_t)interval_ms * 1000U;
        do {
            slp_gsusb_sink_wait(&app.sink, interval_ms > 0U ? 5U : 0U);
        } while (stop_flag == 0 && slp_now_us() < until);
    }
    uint64_t until = slp_now_us() + (uint64_t)linger_ms * 1000U;
    while (stop_flag == 0 && slp_now_us() < until &&
           (slp_gsusb_sink_pending(&app.sink) > 0U || !slp_gsusb_sink_is_up(&app.sink))) {
        slp_gsusb_sink_wait(&app.sink, 10);
        if (!slp_gsusb_sink_is_up(&app.sink) && app.sink.stats.reopens == 0U &&
            app.sink.stats.down_events == 0U) {
            break;
        }
    }
    // Bus frames can trail the last echo (a reply to the last frame, say).
    until = slp_now_us() + (uint64_t)drain_ms * 1000U;
    while (stop_flag == 0 && slp_gsusb_sink_is_up(&app.sink) && app.rx_replies < expect_rx &&
           slp_now_us() < until) {
        slp_gsusb_sink_wait(&app.sink, 10);
    }
    bool was_up = slp_gsusb_sink_is_up(&app.sink);
    slp_gsusb_sink_close(&app.sink);
    if (app.tx_log != NULL) {
        fclose(app.tx_log);
    }
    if (app.rx_log != NULL) {
        fclose(app.rx_log);
    }
    const slp_gsusb_sink_stats_t *st = &app.sink.stats;
    printf("summary: frames %zu, confirmed %u, unconfirmed %u, dropped %u (down %u, in flight %u, "
           "full %u, stale %u, error %u), rx %u, error frames %u, down events %u, reopens %u%s\n",
           n_frames, st->confirmed, st->unconfirmed,
           st->dropped_down + st->dropped_in_flight + st->dropped_full + st->dropped_stale +
               st->dropped_error + st->dropped_invalid,
           st->dropped_down, st->dropped_in_flight, st->dropped_full, st->dropped_stale,
           st->dropped_error, st->rx_frames, st->rx_error_frames, st->down_events, st->reopens,
           was_up ? "" : " (adapter down at exit)");
    if (summary_path != NULL) {
        FILE *fp = fopen(summary_path, "w");
        if (fp == NULL) {
            fprintf(stderr, "sl-gsusb-send: cannot write %s: %s\n", summary_path, strerror(errno));
            return 2;
        }
        write_summary(fp, &app, n_frames);
        fclose(fp);
    }
    if (stop_flag != 0) {
        return 1;
    }
    return st->confirmed == n_frames ? 0 : 1;
}
