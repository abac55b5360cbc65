// SPDX-License-Identifier: MIT
/* sl_cli.h: the command-line conventions shared by every shadowlean executable
 * (docs/TOOLS.md, "Conventions"). Header-only, C11 and C++17.
 *
 *   --help (and -h)  the usage on stdout, exit 0
 *   --version        "<program> <version>" on stdout, exit 0 (SL_VERSION_STRING)
 *   unknown option   "<program>: unknown option '--foo'" then the usage, on stderr, exit 2
 *   bad/missing value of an option: the option is named on stderr, then the usage, exit 2
 *   exit statuses    0 ok, 1 error, 2 usage
 *
 * Each tool has one usage function taking a FILE * so the same text goes to stdout for
 * --help and to stderr on a usage error. */
#ifndef SL_CLI_H
#define SL_CLI_H

#include <stdio.h>
#include <string.h>

#include "shadowlean/sl_version.h"

#define SL_EXIT_OK 0
#define SL_EXIT_ERROR 1
#define SL_EXIT_USAGE 2

/* Returned by sl_cli_info when argv holds neither --help/-h nor --version. */
#define SL_CLI_CONTINUE (-1)

typedef void (*sl_cli_usage_fn)(FILE *out);

/* Looks for --help, -h (unless allow_h is 0) and --version in argv[1..argc-1], stopping at
 * "--". Prints the usage on stdout or "<prog> <version>" and returns SL_EXIT_OK (or
 * SL_EXIT_ERROR when stdout cannot be written); returns SL_CLI_CONTINUE when none is there.
 * Subcommand tools pass argc 2 at top level (only argv[1]) and the subcommand's own
 * argc/argv and usage after dispatching. */
static inline int sl_cli_info_h(int argc, char *const argv[], const char *prog,
                                sl_cli_usage_fn usage, int allow_h)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--") == 0) {
            break;
        }
        if (strcmp(a, "--help") == 0 || (allow_h && strcmp(a, "-h") == 0)) {
            usage(stdout);
            return fflush(stdout) == 0 ? SL_EXIT_OK : SL_EXIT_ERROR;
        }
        if (strcmp(a, "--version") == 0) {
            printf("%s %s\n", prog, SL_VERSION_STRING);
            return fflush(stdout) == 0 ? SL_EXIT_OK : SL_EXIT_ERROR;
        }
    }
    return SL_CLI_CONTINUE;
}

static inline int sl_cli_info(int argc, char *const argv[], const char *prog, sl_cli_usage_fn usage)
{
    return sl_cli_info_h(argc, argv, prog, usage, 1);
}

/* An unknown option (or stray argument): named on stderr, then the usage; SL_EXIT_USAGE. */
static inline int sl_cli_unknown(const char *prog, const char *arg, sl_cli_usage_fn usage)
{
    if (arg[0] == '-') {
        fprintf(stderr, "%s: unknown option '%s'\n", prog, arg);
    } else {
        fprintf(stderr, "%s: unexpected argument '%s'\n", prog, arg);
    }
    usage(stderr);
    return SL_EXIT_USAGE;
}

/* A missing or bad value: "<prog>: <opt>: <why>" on stderr, then the usage; SL_EXIT_USAGE. */
static inline int sl_cli_bad_value(const char *prog, const char *opt, const char *why,
                                   sl_cli_usage_fn usage)
{
    fprintf(stderr, "%s: %s: %s\n", prog, opt, why);
    usage(stderr);
    return SL_EXIT_USAGE;
}

/* A usage error that is not about one option (missing operand...): the message, then the
 * usage, on stderr; SL_EXIT_USAGE. */
static inline int sl_cli_usage_error(const char *prog, const char *why, sl_cli_usage_fn usage)
{
    fprintf(stderr, "%s: %s\n", prog, why);
    usage(stderr);
    return SL_EXIT_USAGE;
}

#endif /* SL_CLI_H */
