// SPDX-License-Identifier: MIT
// replay_files.h: the command-line walk of the replay builds (fuzz_proto.c, fuzz_tilt.c):
// a file argument is run as it is, a directory's entries (hidden ones skipped) one by one.
// Included by the replay build only (not the libFuzzer one, which has its own driver).
#ifndef SL_FUZZ_REPLAY_FILES_H
#define SL_FUZZ_REPLAY_FILES_H

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
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

#endif // SL_FUZZ_REPLAY_FILES_H
