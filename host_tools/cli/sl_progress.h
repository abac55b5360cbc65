// SPDX-License-Identifier: MIT
/* sl_progress.h: progress of long runs on stderr, shared by sl-view, sl-eval, sl-calib and
 * sl-sim (docs/TOOLS.md, "Conventions"). Header-only C++17.
 *
 *   - printed only when stderr is a terminal (isatty(2)): a pipe, a file or a CI log gets
 *     nothing, so outputs stay diff-able;
 *   - -q / --quiet silences it (the tool passes quiet to the constructor);
 *   - one line rewritten in place ("\r"): "<prog>: <what> <done>/<total> (<pct>%) <el> s,
 *     eta <s> s", redrawn when the integer percentage changes (not on a timer: nothing
 *     here depends on the machine's speed); finish() ends the line.
 *
 * Thread-safe: update() may be called from worker threads. */
#ifndef SL_PROGRESS_H
#define SL_PROGRESS_H

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace sl {

/// True when progress should be printed: not quiet and stderr is a terminal.
inline bool progress_wanted(bool quiet)
{
    return !quiet && isatty(STDERR_FILENO) == 1;
}

class Progress {
public:
    Progress(const char *prog, bool quiet) : prog_(prog), on_(progress_wanted(quiet)) {}
    ~Progress() { finish(); }
    Progress(const Progress &) = delete;
    Progress &operator=(const Progress &) = delete;

    bool enabled() const { return on_; }

    /// done of total steps of `what` (total 0: unknown, the count alone is shown).
    void update(long long done, long long total, const std::string &what)
    {
        if (!on_) {
            return;
        }
        std::lock_guard<std::mutex> lock(mu_);
        const int pct = total > 0 ? static_cast<int>(100 * done / total) : -1;
        if (what == what_ && pct == pct_ && (total > 0 || (done & 63) != 0)) {
            return;
        }
        what_ = what;
        pct_ = pct;
        const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        if (total > 0) {
            const double eta = done > 0 ? el / static_cast<double>(done) * static_cast<double>(total - done) : 0.0;
            std::fprintf(stderr, "\r%s: %s %lld/%lld (%d%%) %.0f s, eta %.0f s   ", prog_, what.c_str(), done,
                         total, pct, el, eta);
        } else {
            std::fprintf(stderr, "\r%s: %s %lld, %.0f s   ", prog_, what.c_str(), done, el);
        }
        std::fflush(stderr);
        drawn_ = true;
    }

    /// Ends the progress line (if one was drawn).
    void finish()
    {
        std::lock_guard<std::mutex> lock(mu_);
        if (drawn_) {
            std::fputc('\n', stderr);
            drawn_ = false;
        }
        what_.clear();
        pct_ = -2;
    }

private:
    const char *prog_;
    bool on_;
    bool drawn_ = false;
    int pct_ = -2;
    std::string what_;
    std::mutex mu_;
    std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

} // namespace sl

#endif // SL_PROGRESS_H
