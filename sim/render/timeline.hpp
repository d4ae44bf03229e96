// The timeline of a cycle-level run: issue rate, cache hit rates, DRAM bandwidth and active
// threads per interval of cycles, sampled from the chip's counters while it runs.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/stats/registry.hpp"

namespace tpsim::render {

class Timeline {
public:
    /// Rows kept when the interval adapts to the run: between kTargetRows and 2 * kTargetRows.
    static constexpr uint64_t kTargetRows = 200;

    /// Samples the chip counters registered in `chip_stats` (timing::Chip::register_stats) for
    /// a chip of `threads` threads, and the threads still running (`running`). `interval` cycles
    /// between samples, or 0: adapt to the run's length — start at 1024 cycles and, whenever 2 *
    /// kTargetRows samples are kept, drop every other one and double the interval (the counters are
    /// cumulative, so merging two intervals loses nothing but resolution).
    Timeline(const stats::Registry& chip_stats, uint32_t threads, std::function<uint64_t()> running,
             uint64_t interval = 0);

    /// The cycle at which the next sample is due.
    uint64_t next_sample() const { return next_; }
    /// Reads the counters at `cycle` (>= the previous sample; the run's last cycle may come
    /// before next_sample()).
    void sample(uint64_t cycle);

    /// {"interval_cycles", "columns", "rows"} of the statistics file (docs/statistics.md).
    nlohmann::ordered_json json() const;

private:
    // The cumulative counters one row is computed from, in this order.
    static constexpr size_t kCounters = 8;              // the last: threads running at the sample
    using Point = std::array<uint64_t, kCounters + 1>;  // [0]: the cycle

    std::vector<stats::Entry> counters_;
    std::function<uint64_t()> running_;
    uint32_t threads_;
    bool adaptive_;
    uint64_t interval_;
    uint64_t next_;
    std::vector<Point> points_;  // points_[0]: cycle 0, all zero
};

}  // namespace tpsim::render
