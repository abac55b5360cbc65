// SPDX-License-Identifier: MIT
// replay_files.h: the command-line walk of the replay builds (fuzz_proto.c, fuzz_tilt.c,
// fuzz_rfit.c): a file argument is run as it is, a directory's entries (hidden ones skipped)
// one by one; the generating builds' common options (--random N, --write DIR) and the
// reading and writing of one input file.
// Included by the replay build only (not the libFuzzer one, which has its own driver).
#ifndef SL_FUZZ_REPLAY_FILES_H
#define SL_FUZZ_REPLAY_FILES_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

// One input: `path`; `name` the directory entry's name (NULL for a file argument); `index`
// the number of inputs the walk ran before it. Returns non-zero for a bad input.
typedef int (*replay_run_fn)(const char *path, const char *name, unsigned long index);

// Runs `arg` (a file, or every entry of a directory) through `run`, counting in `*files`.
// Returns the OR of run's results, or -1 when `arg` does not exist; a directory that
// cannot be opened aborts.
static int replay_path(const char *arg, unsigned long *files, replay_run_fn run)
{
    struct stat st;
    if (stat(arg, &st) != 0) {
        return -1;
    }
    if (!S_ISDIR(st.st_mode)) {
        const int bad = run(arg, NULL, *files);
        (*files)++;
        return bad;
    }
    DIR *dir = opendir(arg);
    if (dir == NULL) {
        fprintf(stderr, "replay: cannot open directory %s\n", arg);
        abort();
    }
    int bad = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        if (e->d_name[0] == '.') {
            continue;
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", arg, e->d_name);
        bad |= run(path, e->d_name, *files);
        (*files)++;
    }
    closedir(dir);
    return bad;
}

// Reads the input file `path` (its first `cap` bytes) into `buf`, its length into `*n`.
// Returns non-zero (and says so) when it cannot be opened.
static inline int replay_read(const char *prog, const char *path, uint8_t *buf, size_t cap,
                              size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "%s: cannot open %s\n", prog, path);
        return 1;
    }
    *n = fread(buf, 1, cap, f);
    fclose(f);
    return 0;
}

// The generating builds' pseudo-random bytes (xorshift64*): deterministic from `*state`.
static inline uint8_t replay_rnd(uint64_t *state)
{
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    return (uint8_t)((*state * 2685821657736338717ULL) >> 56);
}

// Keeps a generated input as DIR/random_NNNN.bin (a libFuzzer run's seed); aborts when it
// cannot be written.
static inline void replay_write(const char *dir, unsigned long k, const uint8_t *buf,
                                size_t len)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/random_%04lu.bin", dir, k);
    FILE *f = fopen(path, "wb");
    if (f == NULL || fwrite(buf, 1, len, f) != len) {
        fprintf(stderr, "replay: cannot write %s\n", path);
        abort();
    }
    fclose(f);
}

// The command line of a generating replay build: [--random N [--write DIR]] [file|dir]...
typedef struct replay_args {
    unsigned long random_n;  // --random N: pseudo-random inputs to run after the files
    const char *write_dir;   // --write DIR: keep them as files
    unsigned long files;     // input files run
    int bad;                 // OR of the files' results
} replay_args_t;

// Parses the options and runs every file argument through `run`. Returns non-zero (usage
// or a missing path, said on stderr) when the program should exit with 1.
static inline int replay_args(int argc, char **argv, const char *prog, replay_run_fn run,
                              replay_args_t *a)
{
    memset(a, 0, sizeof(*a));
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--random") == 0 && i + 1 < argc) {
            a->random_n = strtoul(argv[++i], NULL, 10);
            continue;
        }
        if (strcmp(argv[i], "--write") == 0 && i + 1 < argc) {
            a->write_dir = argv[++i];
            continue;
        }
        const int r = replay_path(argv[i], &a->files, run);
        if (r < 0) {
            fprintf(stderr, "%s: no such path %s\n", prog, argv[i]);
            return 1;
        }
        a->bad |= r;
    }
    if (a->files == 0 && a->random_n == 0) {
        fprintf(stderr, "usage: %s [--random N [--write DIR]] [file|dir]...\n", prog);
        return 1;
    }
    return 0;
}

#endif // SL_FUZZ_REPLAY_FILES_H
