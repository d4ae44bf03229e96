// How many host threads tpsim may use (tpsim render --threads): the cycle-level chip's TMs,
// the functional machine's threads, and library code built on oneTBB. Only host scheduling
// follows it; no result depends on it.
#pragma once
#include <cstdint>

namespace tpsim::core {

/// The host threads tpsim may use: as set, or, until set, every core of the host.
uint32_t host_threads();
/// Whether set_host_threads() fixed them. Unset, a cycle-level run chooses between one host
/// thread and host_threads() as it goes (HostThreadChoice), and the functional machine runs on
/// one (docs/performance.md, "Host threads": not faster on two).
bool host_threads_set();
/// Sets them (at least 1); also limits oneTBB's parallelism for the whole process.
void set_host_threads(uint32_t threads);

/// A run made of chunks (the cycle-level chip's, between timeline rows and progress reports)
/// runs on one host thread or on `most`, whichever simulated more instructions per second when
/// last tried: more threads pay on idle cores and lose on busy ones, where a thread waits for
/// another that has no core. It starts on one for kTrySeconds (a short run never waits for a
/// second thread), tries the other count for as long, keeps the faster for 4 times that, tries
/// again, and waits twice as long before each next try while the other keeps losing.
class HostThreadChoice {
public:
    static constexpr double kTrySeconds = 0.05;

    explicit HostThreadChoice(uint32_t most) : most_(most) {}
    /// The host threads for the next chunk.
    uint32_t next() const { return on_; }
    /// The chunk just run (on next()) did `work` in `seconds`.
    void ran(uint64_t work, double seconds);

private:
    double& rate_of(uint32_t threads) { return threads == 1 ? rate_one_ : rate_most_; }

    uint32_t most_, on_ = 1, best_ = 1;
    double rate_one_ = 0, rate_most_ = 0;  // work per second, last measured on each
    bool trying_ = false;                  // on_ is not best_, for kTrySeconds
    uint64_t work_ = 0;                    // in this phase so far
    double seconds_ = 0, phase_seconds_ = kTrySeconds;
    uint32_t tries_apart_ = 4;  // phases on best_ last this many kTrySeconds
};

}  // namespace tpsim::core
