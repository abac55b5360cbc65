// SPDX-License-Identifier: MIT
// daemon_opts.c: defaults, INI config file (inih) and command line of shadowleand.
#include "daemon_opts.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "daemon_log.h"
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_profile.h"
#include "shadowlean/sl_can.h"
#include "shadowlean/sl_version.h"

void sld_opts_defaults(sld_opts_t *o)
{
    memset(o, 0, sizeof *o);
    o->radar_port = 6317;
    o->connect_timeout_ms = 2000;
    o->silence_timeout_ms = 3000;
    o->silent_ms = 1000;
    o->verbosity = SLD_LOG_INFO;
    o->status_period_ms = SL_CAN_IDLE_CYCLE_MS_STATUS; // the DBC's SlIdleCycleTime
    o->gs_usb_max_age_ms = 200; // as slp_gsusb_sink_default_cfg(): a late warning is worse than none
    o->log_time = SLD_LOG_TIME_AUTO;
}

// ---------------------------------------------------------------------------------------
// Value parsers

static int set_str(char *dst, size_t cap, const char *val)
{
    const size_t n = strlen(val);
    if (n >= cap) {
        return -1;
    }
    memcpy(dst, val, n + 1);
    return 0;
}

static int parse_bool(const char *v, bool *out)
{
    static const char *const t[] = {"1", "true", "yes", "on"};
    static const char *const f[] = {"0", "false", "no", "off"};
    for (size_t i = 0; i < 4; i++) {
        if (strcasecmp(v, t[i]) == 0) {
            *out = true;
            return 0;
        }
        if (strcasecmp(v, f[i]) == 0) {
            *out = false;
            return 0;
        }
    }
    return -1;
}

static int parse_u32(const char *v, uint32_t *out)
{
    char *end = NULL;
    errno = 0;
    if (v[0] == '-' || v[0] == '\0') {
        return -1;
    }
    const unsigned long long x = strtoull(v, &end, 0);
    if (errno != 0 || end == v || *end != '\0' || x > UINT32_MAX) {
        return -1;
    }
    *out = (uint32_t)x;
    return 0;
}

/// Seconds (decimal allowed) -> milliseconds, 0 .. 49 days.
static int parse_seconds_ms(const char *v, uint32_t *out_ms)
{
    char *end = NULL;
    errno = 0;
    const double s = strtod(v, &end);
    if (errno != 0 || end == v || *end != '\0' || !(s >= 0.0) || s > 4.0e6) {
        return -1;
    }
    *out_ms = (uint32_t)llround(s * 1000.0);
    return 0;
}

int sld_parse_host_port(const char *s, char *host, size_t host_size, uint16_t *port)
{
    const char *h = s;
    size_t hl;
    const char *p = NULL;
    if (s[0] == '[') {
        const char *close = strchr(s, ']');
        if (close == NULL) {
            return -1;
        }
        h = s + 1;
        hl = (size_t)(close - h);
        if (close[1] == ':') {
            p = close + 2;
        } else if (close[1] != '\0') {
            return -1;
        }
    } else {
        const char *colon = strrchr(s, ':');
        if (colon != NULL && strchr(s, ':') != colon) {
            colon = NULL; // a bare IPv6 address without brackets: no port
        }
        hl = colon != NULL ? (size_t)(colon - s) : strlen(s);
        p = colon != NULL ? colon + 1 : NULL;
    }
    if (hl == 0 || hl >= host_size) {
        return -1;
    }
    memcpy(host, h, hl);
    host[hl] = '\0';
    *port = 6317;
    if (p != NULL) {
        uint32_t v = 0;
        if (parse_u32(p, &v) != 0 || v == 0 || v > 65535) {
            return -1;
        }
        *port = (uint16_t)v;
    }
    return 0;
}

// ---------------------------------------------------------------------------------------
// One setting by its config key (section.key); the command line maps to the same keys.

static int apply(sld_opts_t *o, const char *section, const char *key, const char *val,
                 char *why, size_t why_size)
{
#define IS(s, k) (strcmp(section, s) == 0 && strcmp(key, k) == 0)
#define BAD(msg) do { snprintf(why, why_size, "%s.%s = '%s': %s", section, key, val, msg); return -1; } while (0)
    if (IS("daemon", "board")) {
        if (set_str(o->board, sizeof o->board, val) != 0) BAD("too long");
    } else if (IS("daemon", "calibration")) {
        if (set_str(o->calibration, sizeof o->calibration, val) != 0) BAD("too long");
    } else if (IS("daemon", "user")) {
        if (set_str(o->user, sizeof o->user, val) != 0) BAD("too long");
    } else if (IS("daemon", "syslog")) {
        if (parse_bool(val, &o->use_syslog) != 0) BAD("expected true/false");
    } else if (IS("daemon", "verbosity")) {
        const int l = sld_log_parse_level(val);
        if (l < 0) BAD("expected error, warning, info, debug or 0..3");
        o->verbosity = l;
    } else if (IS("daemon", "tail_slope")) {
        // sl_profile_cfg_t.prior_slope_q8: 0 (none) or 0.5 .. 24 values per bin
        char *end = NULL;
        errno = 0;
        const double v = strtod(val, &end);
        if (errno != 0 || end == val || *end != '\0' || !(v <= 0.0 ? v >= 0.0 : (v >= 0.5 && v <= 24.0))) {
            BAD("expected 0 (none) or 0.5 .. 24 values per bin");
        }
        o->tail_slope_q8 = (uint16_t)lround(v * 256.0);
    } else if (IS("daemon", "front_bins")) {
        // sl_profile_cfg_t.prior_front_bins: 0 (none) or 2 .. SL_PROFILE_LEAD_HIST - 1 bins
        uint32_t v = 0;
        if (parse_u32(val, &v) != 0 || v == 1U || v >= SL_PROFILE_LEAD_HIST) {
            BAD("expected 0 (none) or 2 .. 7 bins");
        }
        o->front_bins = (uint8_t)v;
    } else if (IS("daemon", "extract")) {
        // sl_pipeline_cfg_t.fit (the fit needs SL_CFG_FIT: the host configuration)
        if (strcmp(val, "fit") == 0 && SL_CFG_FIT) {
            o->extract = 2U;
        } else if (strcmp(val, "walk") == 0) {
            o->extract = 1U;
        } else {
            BAD(SL_CFG_FIT ? "expected walk or fit" : "expected walk (this build has no fit)");
        }
    } else if (IS("daemon", "r2_offset_mm")) {
        // sl_profile_cfg_t.prior_r2_offset_um: -100 .. +100 mm (0 = none)
        char *end = NULL;
        errno = 0;
        const double v = strtod(val, &end);
        if (errno != 0 || end == val || *end != '\0' || !(v >= -100.0 && v <= 100.0)) {
            BAD("expected -100 .. +100 mm (0 = none)");
        }
        o->r2_offset_um = (int32_t)lround(v * 1000.0);
    } else if (IS("daemon", "stats_every")) {
        if (parse_seconds_ms(val, &o->stats_every_ms) != 0) BAD("expected seconds >= 0");
    } else if (IS("daemon", "status_period_ms")) {
        if (parse_u32(val, &o->status_period_ms) != 0 || o->status_period_ms == 0) BAD("expected ms > 0");
    } else if (IS("daemon", "duration")) {
        if (parse_seconds_ms(val, &o->duration_ms) != 0) BAD("expected seconds >= 0");
    } else if (IS("daemon", "exit_idle")) {
        if (parse_seconds_ms(val, &o->exit_idle_ms) != 0) BAD("expected seconds >= 0");
    } else if (IS("input", "radar")) {
        if (sld_parse_host_port(val, o->radar_host, sizeof o->radar_host, &o->radar_port) != 0)
            BAD("expected HOST:PORT");
    } else if (IS("input", "capture")) {
        if (set_str(o->capture, sizeof o->capture, val) != 0) BAD("too long");
    } else if (IS("input", "realtime")) {
        if (parse_bool(val, &o->realtime) != 0) BAD("expected true/false");
    } else if (IS("input", "non_contour")) {
        if (parse_bool(val, &o->non_contour) != 0) BAD("expected true/false");
    } else if (IS("input", "connect_timeout_ms")) {
        if (parse_u32(val, &o->connect_timeout_ms) != 0 || o->connect_timeout_ms == 0) BAD("expected ms > 0");
    } else if (IS("input", "silence_timeout_ms")) {
        if (parse_u32(val, &o->silence_timeout_ms) != 0) BAD("expected ms");
    } else if (IS("input", "data_timeout_ms")) {
        if (parse_u32(val, &o->data_timeout_ms) != 0) BAD("expected ms");
    } else if (IS("input", "silent_ms")) {
        if (parse_u32(val, &o->silent_ms) != 0 || o->silent_ms == 0) BAD("expected ms > 0");
    } else if (IS("input", "motion")) {
        if (strcmp(val, "none") == 0 || strcmp(val, "off") == 0) {
            o->fixed_motion = false;
        } else {
            char *end = NULL;
            errno = 0;
            const double v = strtod(val, &end);
            double w = 0.0;
            if (errno == 0 && end != val && *end == ',') {
                const char *y = end + 1;
                w = strtod(y, &end);
                if (end == y) {
                    BAD("expected SPEED_M_S[,YAW_DEG_S]");
                }
            }
            if (errno != 0 || end == val || *end != '\0' || !(v >= -300.0 && v <= 300.0) ||
                !(w >= -300.0 && w <= 300.0)) {
                BAD("expected SPEED_M_S[,YAW_DEG_S] within +-300");
            }
            o->fixed_motion = true;
            o->fixed_speed_mm_s = (int32_t)lround(v * 1000.0);
            o->fixed_yaw_cdeg_s = (int32_t)lround(w * 100.0);
        }
    } else if (IS("can", "interface")) {
        if (val[0] == '\0' || set_str(o->can_iface, sizeof o->can_iface, val) != 0) BAD("bad interface name");
    } else if (IS("can", "log")) {
        if (set_str(o->can_log, sizeof o->can_log, val) != 0) BAD("too long");
    } else if (IS("can", "log_iface")) {
        if (val[0] == '\0' || strchr(val, ' ') != NULL ||
            set_str(o->can_log_iface, sizeof o->can_log_iface, val) != 0) BAD("bad interface name");
    } else if (IS("can", "log_time")) {
        if (strcmp(val, "auto") == 0) {
            o->log_time = SLD_LOG_TIME_AUTO;
        } else if (strcmp(val, "wall") == 0) {
            o->log_time = SLD_LOG_TIME_WALL;
        } else if (strcmp(val, "data") == 0) {
            o->log_time = SLD_LOG_TIME_DATA;
        } else {
            BAD("expected auto, wall or data");
        }
    } else if (IS("can", "gs_usb")) {
        bool b = false;
        if (parse_bool(val, &b) == 0) {
            o->gs_usb = b;
            o->gs_usb_sel[0] = '\0';
        } else if (strcmp(val, "any") == 0) {
            o->gs_usb = true;
            o->gs_usb_sel[0] = '\0';
        } else {
            if (set_str(o->gs_usb_sel, sizeof o->gs_usb_sel, val) != 0) BAD("too long");
            o->gs_usb = true;
        }
    } else if (IS("can", "bitrate")) {
        if (parse_u32(val, &o->bitrate) != 0 || o->bitrate > 1000000U) BAD("expected bit/s <= 1000000");
    } else if (IS("can", "gs_usb_max_age_ms")) {
        if (parse_u32(val, &o->gs_usb_max_age_ms) != 0 || o->gs_usb_max_age_ms > 60000U)
            BAD("expected ms <= 60000 (0 = frames never expire)");
    } else if (IS("can", "motion_interface")) {
        if (strcmp(val, "none") == 0 || strcmp(val, "off") == 0) {
            o->motion_off = true;
            o->motion_iface[0] = '\0';
        } else {
            if (val[0] == '\0' || set_str(o->motion_iface, sizeof o->motion_iface, val) != 0)
                BAD("bad interface name");
            o->motion_off = false;
        }
    } else if (IS("output", "targets")) {
        if (set_str(o->targets_out, sizeof o->targets_out, val) != 0) BAD("too long");
    } else {
        snprintf(why, why_size, "unknown setting [%s] %s", section, key);
        return -1;
    }
    return 0;
#undef BAD
#undef IS
}

// ---------------------------------------------------------------------------------------
// Config file

#define INI_MAX_KEYS 128
typedef struct ini_ctx {
    sld_opts_t *o;
    char *err;
    size_t err_size;
    bool failed;
    bool has_radar, has_capture;
    unsigned n_keys;
    char keys[INI_MAX_KEYS][96]; ///< "section.name" seen so far (duplicates are errors)
} ini_ctx_t;

static int on_ini(void *user, const char *section, const char *name, const char *value)
{
    ini_ctx_t *c = user;
    if (c->failed) {
        return 0;
    }
    char key[96];
    snprintf(key, sizeof key, "%s.%s", section, name);
    for (unsigned i = 0; i < c->n_keys; i++) {
        if (strcmp(c->keys[i], key) == 0) {
            snprintf(c->err, c->err_size, "%s: duplicate key (set once; the command line overrides)",
                     key);
            c->failed = true;
            return 0;
        }
    }
    if (c->n_keys < INI_MAX_KEYS) {
        memcpy(c->keys[c->n_keys++], key, sizeof key);
    }
    if (apply(c->o, section, name, value, c->err, c->err_size) != 0) {
        c->failed = true;
        return 0; // inih reports the first failing line
    }
    if (strcmp(section, "input") == 0 && strcmp(name, "radar") == 0) {
        c->has_radar = true;
    }
    if (strcmp(section, "input") == 0 && strcmp(name, "capture") == 0) {
        c->has_capture = true;
    }
    return 1;
}

int sld_opts_load_file(sld_opts_t *o, const char *path, char *err, size_t err_size)
{
    char why[512] = "";
    struct stat sb;
    if (stat(path, &sb) != 0) {
        snprintf(err, err_size, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    if (!S_ISREG(sb.st_mode)) {
        snprintf(err, err_size, "%s: not a regular file (%s)", path,
                 S_ISDIR(sb.st_mode) ? "a directory" : "a device, pipe or socket");
        return -1;
    }
    static ini_ctx_t c;
    memset(&c, 0, sizeof c);
    c.o = o;
    c.err = why;
    c.err_size = sizeof why;
    const int rc = ini_parse(path, on_ini, &c);
    if (rc == -1) {
        snprintf(err, err_size, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    if (rc == -2) {
        snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    if (rc > 0) {
        snprintf(err, err_size, "%s:%d: %s", path, rc, why[0] != '\0' ? why : "syntax error");
        return -1;
    }
    if (c.has_radar && c.has_capture) {
        snprintf(err, err_size, "%s: both [input] radar and capture are set", path);
        return -1;
    }
    return 0;
}

// ---------------------------------------------------------------------------------------
// Command line

typedef struct cli_opt {
    const char *name;    ///< long option
    const char *section; ///< config key it sets (NULL: handled specially)
    const char *key;
    int arg;             ///< 0 none, 1 required, 2 optional (next word unless it starts with '-')
    const char *fixed;   ///< value for options without argument
} cli_opt_t;

static const cli_opt_t k_cli[] = {
    {"--board", "daemon", "board", 1, NULL},
    {"--calibration", "daemon", "calibration", 1, NULL},
    {"--user", "daemon", "user", 1, NULL},
    {"--syslog", "daemon", "syslog", 0, "true"},
    {"--stderr", "daemon", "syslog", 0, "false"},
    {"--verbosity", "daemon", "verbosity", 1, NULL},
    {"--stats-every", "daemon", "stats_every", 1, NULL},
    {"--tail-slope", "daemon", "tail_slope", 1, NULL},
    {"--front-bins", "daemon", "front_bins", 1, NULL},
    {"--r2-offset", "daemon", "r2_offset_mm", 1, NULL},
    {"--extract", "daemon", "extract", 1, NULL},
    {"--status-period-ms", "daemon", "status_period_ms", 1, NULL},
    {"--duration", "daemon", "duration", 1, NULL},
    {"--exit-idle", "daemon", "exit_idle", 1, NULL},
    {"--radar", "input", "radar", 1, NULL},
    {"--input", "input", "capture", 1, NULL},
    {"--realtime", "input", "realtime", 0, "true"},
    {"--fast", "input", "realtime", 0, "false"},
    {"--non-contour", "input", "non_contour", 0, "true"},
    {"--connect-timeout-ms", "input", "connect_timeout_ms", 1, NULL},
    {"--silence-timeout-ms", "input", "silence_timeout_ms", 1, NULL},
    {"--data-timeout-ms", "input", "data_timeout_ms", 1, NULL},
    {"--silent-ms", "input", "silent_ms", 1, NULL},
    {"--motion", "input", "motion", 1, NULL},
    {"--can", "can", "interface", 1, NULL},
    {"--can-log", "can", "log", 1, NULL},
    {"--can-log-iface", "can", "log_iface", 1, NULL},
    {"--log-time", "can", "log_time", 1, NULL},
    {"--gs-usb", "can", "gs_usb", 2, "any"},
    {"--bitrate", "can", "bitrate", 1, NULL},
    {"--gs-usb-max-age-ms", "can", "gs_usb_max_age_ms", 1, NULL},
    {"--motion-can", "can", "motion_interface", 1, NULL},
    {"--targets-out", "output", "targets", 1, NULL},
    {"--config", NULL, "config", 1, NULL},
    {"--print-config", NULL, "print", 0, NULL},
};

void sld_opts_usage(void *fpv)
{
    FILE *fp = fpv;
    fputs(
        "usage: shadowleand --board NAME (--radar HOST:PORT | --input CAPTURE) [options]\n"
        "Reads a Navtech radar stream (TCP) or a capture file, detects leaning poles in the\n"
        "vehicle's radar shadow and sends PoleLean / LeanWarning / Status frames on CAN.\n"
        "\n"
        "  option                   config key                meaning\n"
        "  --config FILE                                      INI file; the command line overrides it\n"
        "  --board NAME             [daemon] board            board (see --list-boards)\n"
        "  --calibration FILE       [daemon] calibration      this vehicle's calibration (INI from sl-calib, or a\n"
        "                                                     blob from sl-tables --blob); default: the board's tables\n"
        "  --radar HOST[:PORT]      [input] radar             radar TCP stream (port 6317 default)\n"
        "  --input CAPTURE          [input] capture           raw .colossus capture or pcap/pcapng\n"
        "  --realtime | --fast      [input] realtime          capture: pace by FFT timestamps | as fast as possible (default)\n"
        "  --non-contour            [input] non_contour       radar: Start Non-Contour FFT (140)\n"
        "  --connect-timeout-ms N   [input] connect_timeout_ms  radar connect timeout (2000)\n"
        "  --silence-timeout-ms N   [input] silence_timeout_ms  reconnect after N ms without a byte (3000)\n"
        "  --data-timeout-ms N      [input] data_timeout_ms   no usable FFT row for N ms: Start FFT again,\n"
        "                                                     then reconnect after N more (0: = silence timeout)\n"
        "  --silent-ms N            [input] silent_ms         Status LinkState SILENT after N ms without FFT data (1000)\n"
        "  --motion V[,W]           [input] motion            constant vehicle motion instead of VehicleMotion frames:\n"
        "                                                     V m/s (> 0 forward), W deg/s (> 0 counter-clockwise); none = off\n"
        "  --can IFACE              [can] interface           SocketCAN raw output (can0, vcan0)\n"
        "  --can-log FILE           [can] log                 candump -L log output ('-' = stdout)\n"
        "  --can-log-iface NAME     [can] log_iface           interface name in log lines (default: --can or can0)\n"
        "  --log-time auto|wall|data [can] log_time           log timestamps: wall clock or radar data time\n"
        "                                                     (auto: data for --input, wall for --radar)\n"
        "  --gs-usb [VID:PID|BUS-PORT] [can] gs_usb           gs_usb/candleLight adapter via libusb (any = first)\n"
        "  --bitrate B              [can] bitrate             gs_usb bit rate (default: the board's)\n"
        "  --gs-usb-max-age-ms N    [can] gs_usb_max_age_ms   drop a gs_usb frame queued longer (200; 0 = never)\n"
        "  --motion-can IFACE|none  [can] motion_interface    read VehicleMotion here (default: the --can interface)\n"
        "  --targets-out FILE       [output] targets          JSON lines, one per rotation: targets and tracks\n",
        fp);
    fputs(
        "  --user NAME              [daemon] user             drop root privileges after opening everything\n"
        "  --syslog | --stderr      [daemon] syslog           log destination (default stderr)\n"
        "  -v | -q | --verbosity L  [daemon] verbosity        error, warning, info (default), debug\n"
        "  --stats-every S          [daemon] stats_every      log counters every S seconds (0 = at exit only)\n"
        "  --tail-slope V           [daemon] tail_slope       the radar's smear tail, values per bin, as an earlier\n"
        "                                                     run logged it (\"tail slope\" in the stats): used until\n"
        "                                                     the stream's own fit replaces it (0 = none, default)\n"
        "  --front-bins N           [daemon] front_bins       the radar's smear front part, bins, as an earlier run\n"
        "                                                     logged it (\"smear front part\"): used until the stream\n"
        "                                                     has learned its own (0 = none, default; 2..7)\n"
        "  --r2-offset MM           [daemon] r2_offset_mm     the walk-end offset of r2 an earlier run learned on\n"
        "                                                     upright poles (\"walk-end offset\"): used until the\n"
        "                                                     stream has learned its own (0 = none, default)\n"
        "  --extract walk|fit       [daemon] extract          a target's bounds from its range profile: the\n"
        "                                                     profile's walk (default), or the fit of the sensor\n"
        "                                                     model (range response, noise floor) to it\n"
        "  --status-period-ms N     [daemon] status_period_ms Status frame period without data (1000)\n"
        "  --duration S             [daemon] duration         stop after S seconds (0 = never)\n"
        "  --exit-idle S            [daemon] exit_idle        radar: stop after S s without FFT data (once data came)\n"
        "  --list-boards                                      print the boards linked in\n"
        "  --print-config                                     print the effective settings as a config file, exit\n"
        "  -h | --help, --version\n"
        "Signals: SIGINT/SIGTERM stop cleanly (Stop FFT, last rotation flushed, sinks drained).\n",
        fp);
}

static const cli_opt_t *find_cli(const char *name, size_t len)
{
    for (size_t i = 0; i < sizeof k_cli / sizeof k_cli[0]; i++) {
        if (strlen(k_cli[i].name) == len && strncmp(k_cli[i].name, name, len) == 0) {
            return &k_cli[i];
        }
    }
    return NULL;
}

int sld_opts_parse(sld_opts_t *o, int argc, char **argv, char *err, size_t err_size)
{
    // Pass 1: --config (and --help / --version / --list-boards, which win over errors).
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            sld_opts_usage(stdout);
            return 1;
        }
        if (strcmp(a, "--version") == 0) {
            printf("shadowleand %s\n", SL_VERSION_STRING);
            return 1;
        }
        if (strcmp(a, "--list-boards") == 0) {
            for (size_t b = 0; b < sl_board_count(); b++) {
                printf("%s\n", sl_board_at(b)->name);
            }
            return 1;
        }
        if (strcmp(a, "--config") == 0 && i + 1 < argc) {
            if (set_str(o->config, sizeof o->config, argv[i + 1]) != 0) {
                snprintf(err, err_size, "--config: path too long");
                return -1;
            }
        } else if (strncmp(a, "--config=", 9) == 0) {
            if (set_str(o->config, sizeof o->config, a + 9) != 0) {
                snprintf(err, err_size, "--config: path too long");
                return -1;
            }
        }
    }
    if (o->config[0] != '\0' && sld_opts_load_file(o, o->config, err, err_size) != 0) {
        return -1;
    }
    // Pass 2: everything, in order (a later option wins over an earlier one).
    bool cli_input = false;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "-v") == 0 || strcmp(a, "-vv") == 0 || strcmp(a, "-vvv") == 0) {
            o->verbosity += (int)strlen(a) - 1;
            if (o->verbosity > SLD_LOG_DEBUG) {
                o->verbosity = SLD_LOG_DEBUG;
            }
            continue;
        }
        if (strcmp(a, "-q") == 0) {
            o->verbosity = o->verbosity > 0 ? o->verbosity - 1 : 0;
            continue;
        }
        const char *eq = strchr(a, '=');
        const size_t nlen = eq != NULL ? (size_t)(eq - a) : strlen(a);
        const cli_opt_t *c = strncmp(a, "--", 2) == 0 ? find_cli(a, nlen) : NULL;
        if (c == NULL) {
            snprintf(err, err_size, a[0] == '-' ? "unknown option '%s'" : "unexpected argument '%s'", a);
            return -1;
        }
        const char *val = c->fixed;
        if (eq != NULL) {
            if (c->arg == 0) {
                snprintf(err, err_size, "%.*s takes no value", (int)nlen, a);
                return -1;
            }
            val = eq + 1;
        } else if (c->arg == 1) {
            if (i + 1 >= argc) {
                snprintf(err, err_size, "%s needs a value", a);
                return -1;
            }
            val = argv[++i];
        } else if (c->arg == 2 && i + 1 < argc && argv[i + 1][0] != '-') {
            val = argv[++i];
        }
        if (c->section == NULL) {
            if (strcmp(c->key, "print") == 0) {
                o->print_config = true;
            }
            continue; // --config: pass 1
        }
        if (strcmp(c->key, "radar") == 0 || strcmp(c->key, "capture") == 0) {
            if (!cli_input) {
                // The command line's input replaces the config file's, whatever its kind.
                o->radar_host[0] = '\0';
                o->capture[0] = '\0';
            }
            cli_input = true;
        }
        char why[512];
        if (apply(o, c->section, c->key, val, why, sizeof why) != 0) {
            snprintf(err, err_size, "%.*s: %s", (int)nlen, a, why);
            return -1;
        }
    }
    return 0;
}

int sld_opts_validate(const sld_opts_t *o, char *err, size_t err_size)
{
    if (o->board[0] == '\0') {
        snprintf(err, err_size, "no board: --board NAME (see --list-boards)");
        return -1;
    }
    if (sl_board_find(o->board) == NULL) {
        snprintf(err, err_size, "unknown board '%s' (see --list-boards)", o->board);
        return -1;
    }
    const bool radar = o->radar_host[0] != '\0';
    const bool cap = o->capture[0] != '\0';
    if (radar == cap) {
        snprintf(err, err_size, radar ? "--radar and --input are exclusive"
                                       : "no input: --radar HOST:PORT or --input CAPTURE");
        return -1;
    }
    if (o->realtime && radar) {
        snprintf(err, err_size, "--realtime applies to --input only");
        return -1;
    }
    if (o->fixed_motion && o->motion_iface[0] != '\0' && !o->motion_off) {
        snprintf(err, err_size, "--motion and --motion-can are exclusive (one motion input)");
        return -1;
    }
    if (strcmp(o->can_log, "-") == 0 && strcmp(o->targets_out, "-") == 0) {
        snprintf(err, err_size, "--can-log and --targets-out cannot both be stdout");
        return -1;
    }
    return 0;
}

const char *sld_opts_motion_iface(const sld_opts_t *o)
{
    if (o->motion_off || o->fixed_motion) {
        return "";
    }
    if (o->motion_iface[0] != '\0') {
        return o->motion_iface;
    }
    return o->can_iface;
}

void sld_opts_print(const sld_opts_t *o, void *fpv)
{
    FILE *fp = fpv;
    static const char *const lvl[] = {"error", "warning", "info", "debug"};
    static const char *const lt[] = {"auto", "wall", "data"};
    fprintf(fp, "; shadowleand effective settings%s%s%s\n", o->config[0] != '\0' ? " (config file " : "",
            o->config, o->config[0] != '\0' ? " + command line)" : "");
    fprintf(fp, "[daemon]\nboard = %s\n", o->board);
    if (o->calibration[0] != '\0') {
        fprintf(fp, "calibration = %s\n", o->calibration);
    }
    if (o->user[0] != '\0') {
        fprintf(fp, "user = %s\n", o->user);
    }
    fprintf(fp, "syslog = %s\nverbosity = %s\nstats_every = %.3f\nstatus_period_ms = %u\n",
            o->use_syslog ? "true" : "false", lvl[o->verbosity < 0 ? 0 : o->verbosity > 3 ? 3 : o->verbosity],
            (double)o->stats_every_ms / 1000.0, (unsigned)o->status_period_ms);
    fprintf(fp, "duration = %.3f\nexit_idle = %.3f\n", (double)o->duration_ms / 1000.0,
            (double)o->exit_idle_ms / 1000.0);
    if (o->tail_slope_q8 != 0U) {
        fprintf(fp, "tail_slope = %.4f\n", (double)o->tail_slope_q8 / 256.0);
    }
    if (o->front_bins != 0U) {
        fprintf(fp, "front_bins = %u\n", (unsigned)o->front_bins);
    }
    if (o->r2_offset_um != 0) {
        fprintf(fp, "r2_offset_mm = %.3f\n", (double)o->r2_offset_um / 1000.0);
    }
    if (o->extract != 0U) {
        fprintf(fp, "extract = %s\n", o->extract == 2U ? "fit" : "walk");
    }
    fprintf(fp, "\n[input]\n");
    if (o->radar_host[0] != '\0') {
        const bool v6 = strchr(o->radar_host, ':') != NULL;
        fprintf(fp, "radar = %s%s%s:%u\n", v6 ? "[" : "", o->radar_host, v6 ? "]" : "", (unsigned)o->radar_port);
    }
    if (o->capture[0] != '\0') {
        fprintf(fp, "capture = %s\n", o->capture);
    }
    if (o->fixed_motion) {
        fprintf(fp, "motion = %.3f,%.2f\n", (double)o->fixed_speed_mm_s / 1000.0, (double)o->fixed_yaw_cdeg_s / 100.0);
    }
    fprintf(fp, "data_timeout_ms = %u\n", (unsigned)o->data_timeout_ms);
    fprintf(fp, "realtime = %s\nnon_contour = %s\nconnect_timeout_ms = %u\nsilence_timeout_ms = %u\nsilent_ms = %u\n",
            o->realtime ? "true" : "false", o->non_contour ? "true" : "false", (unsigned)o->connect_timeout_ms,
            (unsigned)o->silence_timeout_ms, (unsigned)o->silent_ms);
    fprintf(fp, "\n[can]\n");
    if (o->can_iface[0] != '\0') {
        fprintf(fp, "interface = %s\n", o->can_iface);
    }
    if (o->can_log[0] != '\0') {
        fprintf(fp, "log = %s\n", o->can_log);
    }
    if (o->can_log_iface[0] != '\0') {
        fprintf(fp, "log_iface = %s\n", o->can_log_iface);
    }
    fprintf(fp, "log_time = %s\n", lt[o->log_time]);
    fprintf(fp, "gs_usb = %s\n", !o->gs_usb ? "false" : o->gs_usb_sel[0] != '\0' ? o->gs_usb_sel : "any");
    fprintf(fp, "bitrate = %u\n", (unsigned)o->bitrate);
    fprintf(fp, "gs_usb_max_age_ms = %u\n", (unsigned)o->gs_usb_max_age_ms);
    if (o->motion_off) {
        fprintf(fp, "motion_interface = none\n");
    } else if (o->motion_iface[0] != '\0') {
        fprintf(fp, "motion_interface = %s\n", o->motion_iface);
    }
    if (o->targets_out[0] != '\0') {
        fprintf(fp, "\n[output]\ntargets = %s\n", o->targets_out);
    }
}
