// SPDX-License-Identifier: MIT
/// @file daemon_log.h
/// @brief Logging of the shadowleand daemon: stderr (default) or syslog, four levels.
///
/// Levels: 0 error, 1 warning, 2 info (default), 3 debug. A message is written when its
/// level is <= the configured verbosity. On stderr every line is prefixed with
/// "shadowleand: <level>: "; with syslog the priority carries the level (LOG_ERR,
/// LOG_WARNING, LOG_INFO, LOG_DEBUG) and the ident is "shadowleand", facility LOG_DAEMON.
/// Not thread-safe (the daemon is single-threaded). Cost: one vfprintf / vsyslog.
#ifndef SHADOWLEAN_DAEMON_LOG_H
#define SHADOWLEAN_DAEMON_LOG_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { SLD_LOG_ERR = 0, SLD_LOG_WARN = 1, SLD_LOG_INFO = 2, SLD_LOG_DEBUG = 3 };

/// Set the verbosity (clamped to 0..3) and the destination. Calling it again switches
/// (openlog/closelog as needed).
void sld_log_setup(int verbosity, bool use_syslog);

/// Current verbosity.
int sld_log_level(void);

/// printf-style message at `level` (no trailing newline needed).
void sld_log(int level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/// Close syslog if it was opened.
void sld_log_close(void);

/// Level name for "verbosity = warning" style settings: "error", "warning", "info",
/// "debug" (or a digit 0..3). @return the level or -1 when unknown.
int sld_log_parse_level(const char *s);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_DAEMON_LOG_H
