// The status line a long run shows on a terminal.
#pragma once
#include <chrono>
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <unistd.h>

#include "sim/render/render.hpp"

namespace tpsim::cli {

/// One self-overwriting status line on stderr while the chip model runs, redrawn at most ten
/// times a second; nothing at all when stderr is not a terminal (logs, pipes, CI).
class ProgressLine {
public:
    ProgressLine() : enabled_(isatty(STDERR_FILENO) == 1) {}
    ~ProgressLine() { clear(); }
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    /// Starts a new run whose line begins with `prefix` (e.g. which scene of several).
    void start(std::string prefix) {
        clear();
        prefix_ = std::move(prefix);
        started_ = false;
        if (enabled_ && !prefix_.empty()) {
            fmt::print(stderr, "\r{}\033[K", prefix_);
            shown_ = true;
        }
    }

    void update(const render::Progress& p) {
        if (!enabled_ || p.pixels == 0) return;
        const auto now = Clock::now();
        const double share = double(p.pixels_done) / double(p.pixels);
        if (!started_) {  // the first report starts the clock: scene loading is over by then
            started_ = true;
            start_ = last_ = now;
            start_share_ = share;
            return;
        }
        if (now - last_ < std::chrono::milliseconds(100)) return;
        last_ = now;
        const double elapsed = std::chrono::duration<double>(now - start_).count();
        const std::string left =
            share > start_share_
                ? fmt::format("~{:.0f} s left", elapsed * (1 - share) / (share - start_share_))
                : "estimating time left";
        fmt::print(stderr, "\r{}{:5.1f}% of pixels, {} cycles, {}\033[K", prefix_, 100 * share,
                   p.cycles, left);
        shown_ = true;
    }

    void clear() {
        if (shown_) fmt::print(stderr, "\r\033[K");
        shown_ = false;
    }

private:
    using Clock = std::chrono::steady_clock;
    bool enabled_;
    std::string prefix_;
    bool started_ = false;
    bool shown_ = false;
    double start_share_ = 0;
    Clock::time_point start_, last_;
};

}  // namespace tpsim::cli
