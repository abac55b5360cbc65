// SPDX-License-Identifier: MIT
// daemon_log.c: stderr / syslog logging of shadowleand (see daemon_log.h).
#include "daemon_log.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <syslog.h>

static int g_level = SLD_LOG_INFO;
static bool g_syslog = false;

void sld_log_setup(int verbosity, bool use_syslog)
{
    g_level = verbosity < SLD_LOG_ERR ? SLD_LOG_ERR : verbosity > SLD_LOG_DEBUG ? SLD_LOG_DEBUG : verbosity;
    if (use_syslog && !g_syslog) {
        openlog("shadowleand", LOG_PID | LOG_NDELAY, LOG_DAEMON);
    } else if (!use_syslog && g_syslog) {
        closelog();
    }
    g_syslog = use_syslog;
}

int sld_log_level(void)
{
    return g_level;
}

void sld_log(int level, const char *fmt, ...)
{
    if (level > g_level) {
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    if (g_syslog) {
        static const int prio[] = {LOG_ERR, LOG_WARNING, LOG_INFO, LOG_DEBUG};
        vsyslog(prio[level < 0 ? 0 : level > 3 ? 3 : level], fmt, ap);
    } else {
        static const char *const name[] = {"error", "warning", "info", "debug"};
        fprintf(stderr, "shadowleand: %s: ", name[level < 0 ? 0 : level > 3 ? 3 : level]);
        vfprintf(stderr, fmt, ap);
        fputc('\n', stderr);
    }
    va_end(ap);
}

void sld_log_close(void)
{
    if (g_syslog) {
        closelog();
        g_syslog = false;
    }
}

int sld_log_parse_level(const char *s)
{
    static const char *const names[] = {"error", "warning", "info", "debug"};
    if (s == NULL) {
        return -1;
    }
    if (s[0] >= '0' && s[0] <= '3' && s[1] == '\0') {
        return s[0] - '0';
    }
    for (int i = 0; i < 4; i++) {
        if (strcmp(s, names[i]) == 0) {
            return i;
        }
    }
    if (strcmp(s, "warn") == 0) {
        return SLD_LOG_WARN;
    }
    return -1;
}
