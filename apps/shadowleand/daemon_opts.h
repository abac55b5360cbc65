// SPDX-License-Identifier: MIT
/// @file daemon_opts.h
/// @brief Settings of the shadowleand daemon: defaults, config file (inih), command line.
///
/// Precedence: built-in defaults < config file (`--config FILE`) < command line. Every
/// setting has a command-line option and a config-file key (table in `sld_opts_usage()`
/// and in docs/DAEMON.md, generated from k_cli). The config file is an INI file read with inih (`ini_parse`):
///
///     [daemon]   board, calibration, user, syslog, verbosity, stats_every, duration, exit_idle,
///                status_period_ms
///     [input]    radar (HOST:PORT) | capture (FILE), realtime, non_contour,
///                connect_timeout_ms, silence_timeout_ms, silent_ms, motion
///     [can]      interface, log, log_iface, log_time, gs_usb, bitrate, gs_usb_max_age_ms,
///                motion_interface
///     [output]   targets
///
/// Booleans accept true/false, yes/no, on/off, 1/0. Unknown sections or keys and bad
/// values are errors (with the line number), so a typo never silently changes behaviour.
/// On the command line, choosing an input (`--radar` or `--input`) replaces the config
/// file's input of either kind.
///
/// Not thread-safe; plain C strings in fixed arrays (values longer than the array are
/// rejected, never truncated). Cost: O(file size + argc).
#ifndef SHADOWLEAN_DAEMON_OPTS_H
#define SHADOWLEAN_DAEMON_OPTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SLD_PATH_CHARS 1024U ///< longest path + 1
#define SLD_NAME_CHARS 64U   ///< longest board / user name + 1
#define SLD_IFACE_CHARS 16U  ///< IFNAMSIZ

/// `log_time`: timestamps written in the candump log.
typedef enum sld_log_time {
    SLD_LOG_TIME_AUTO = 0, ///< DATA for --input, WALL for --radar
    SLD_LOG_TIME_WALL = 1, ///< CLOCK_REALTIME when the frame was sent
    SLD_LOG_TIME_DATA = 2, ///< the radar's FFT timestamp the frame was computed from
} sld_log_time_t;

/// All settings.
typedef struct sld_opts {
    char config[SLD_PATH_CHARS];       ///< --config FILE ("" = none)
    bool print_config;                 ///< --print-config: print the settings and exit
    char board[SLD_NAME_CHARS];        ///< --board NAME                      [daemon] board
    char calibration[SLD_PATH_CHARS];  ///< --calibration FILE (INI or blob; "" = the board's) [daemon] calibration
    char radar_host[256];              ///< --radar HOST[:PORT]               [input] radar
    uint16_t radar_port;               ///< default 6317
    char capture[SLD_PATH_CHARS];      ///< --input FILE                      [input] capture
    bool realtime;                     ///< --realtime / --fast               [input] realtime
    bool non_contour;                  ///< --non-contour                     [input] non_contour
    uint32_t connect_timeout_ms;       ///< --connect-timeout-ms (2000)       [input] connect_timeout_ms
    uint32_t silence_timeout_ms;       ///< --silence-timeout-ms (3000): reconnect [input] silence_timeout_ms
    uint32_t data_timeout_ms;          ///< --data-timeout-ms (0 = silence timeout): data watchdog [input] data_timeout_ms
    uint32_t silent_ms;                ///< --silent-ms (1000): no FFT data -> SILENT [input] silent_ms
    char can_iface[SLD_IFACE_CHARS];   ///< --can IFACE                       [can] interface
    char can_log[SLD_PATH_CHARS];      ///< --can-log FILE ("-" stdout)        [can] log
    char can_log_iface[SLD_IFACE_CHARS]; ///< --can-log-iface NAME             [can] log_iface
    sld_log_time_t log_time;           ///< --log-time auto|wall|data         [can] log_time
    bool gs_usb;                       ///< --gs-usb [SEL]                    [can] gs_usb
    char gs_usb_sel[48];               ///< selector, "" = first known adapter
    uint32_t bitrate;                  ///< --bitrate B (0 = board's)         [can] bitrate
    uint32_t gs_usb_max_age_ms;        ///< --gs-usb-max-age-ms (200; 0 = never) [can] gs_usb_max_age_ms
    char motion_iface[SLD_IFACE_CHARS];///< --motion-can IFACE|none           [can] motion_interface
    bool motion_off;                   ///< motion input disabled ("none")
    bool fixed_motion;                 ///< --motion SPEED[,YAW]: constant motion [input] motion
    int32_t fixed_speed_mm_s;          ///< its speed, mm/s (> 0 forward)
    int32_t fixed_yaw_cdeg_s;          ///< its yaw rate, 0.01 deg/s (> 0 counter-clockwise)
    char targets_out[SLD_PATH_CHARS];  ///< --targets-out FILE ("-" stdout)   [output] targets
    char user[SLD_NAME_CHARS];         ///< --user NAME                       [daemon] user
    bool use_syslog;                   ///< --syslog / --stderr               [daemon] syslog
    int verbosity;                     ///< -v/-q/--verbosity L (2 = info)    [daemon] verbosity
    uint32_t stats_every_ms;           ///< --stats-every S (0 = only at exit) [daemon] stats_every
    uint32_t status_period_ms;         ///< --status-period-ms (1000)         [daemon] status_period_ms
    uint32_t duration_ms;              ///< --duration S (0 = run until stopped) [daemon] duration
    uint32_t exit_idle_ms;             ///< --exit-idle S (0 = never)          [daemon] exit_idle
    uint16_t tail_slope_q8;            ///< --tail-slope V: the sensor's smear tail, values per
                                       ///< bin x 256, saved from an earlier run (0 = none)
                                       ///< [daemon] tail_slope
    uint8_t front_bins;                ///< --front-bins N: the sensor's smear front part, bins,
                                       ///< saved from an earlier run (0 = none; 2..7)
                                       ///< [daemon] front_bins
    int32_t r2_offset_um;              ///< --r2-offset MM: the walk-end offset of r2 learned
                                       ///< on upright poles by an earlier run, um (0 = none;
                                       ///< |mm| <= 100) [daemon] r2_offset_mm
    uint8_t extract;                   ///< --extract walk|fit: a target's bounds from the
                                       ///< profile's walk (1) or the sensor model's fit (2);
                                       ///< 0: the pipeline's default (sl_pipeline_cfg_t.fit)
                                       ///< [daemon] extract
} sld_opts_t;

/// Defaults: verbosity info, port 6317, timeouts as listed, everything else empty/off.
void sld_opts_defaults(sld_opts_t *o);

/// Load an INI config file into `o` (on top of what is there).
/// @return 0, or -1 with a message ("FILE:LINE: ...") in `err`.
int sld_opts_load_file(sld_opts_t *o, const char *path, char *err, size_t err_size);

/// Parse the command line: first loads `--config FILE` if present, then applies every
/// option (command line wins). @return 0 = run (or print, see `print_config`), 1 = exit 0
/// (--help/--version/--list-boards printed), -1 = error (message in `err`).
int sld_opts_parse(sld_opts_t *o, int argc, char **argv, char *err, size_t err_size);

/// Checks that need the whole picture (exactly one input, a board, ...).
/// @return 0 or -1 with a message in `err`.
int sld_opts_validate(const sld_opts_t *o, char *err, size_t err_size);

/// The interface to read VehicleMotion from: motion_iface, else can_iface, else "" (none).
const char *sld_opts_motion_iface(const sld_opts_t *o);

/// Print the usage text to `fp` (a FILE *; void * keeps stdio out of this header).
void sld_opts_usage(void *fp);

/// Print the effective settings as a config file that sld_opts_load_file() reads back to
/// the same settings (`shadowleand --print-config`). `fp` is a FILE *.
void sld_opts_print(const sld_opts_t *o, void *fp);

/// Split "HOST:PORT", "[V6ADDR]:PORT" or "HOST" (port 6317). @return 0 or -1.
int sld_parse_host_port(const char *s, char *host, size_t host_size, uint16_t *port);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_DAEMON_OPTS_H
