#include "sim/render/timeline.hpp"

#include <algorithm>
#include <limits>

namespace tpsim::render {

namespace {

// The chip counters a row is computed from (cumulative since cycle 0).
constexpr const char* kCounterNames[] = {
    "chip/instructions", "chip/l1/hits",    "chip/l1/reads",      "chip/l2/hits",
    "chip/l2/reads",     "dram/bytes_read", "dram/bytes_written",
};
enum Counter { Instructions, L1Hits, L1Reads, L2Hits, L2Reads, DramRead, DramWritten, Running };
constexpr uint64_t kFirstInterval = 1024;

double ratio(uint64_t numerator, uint64_t denominator) {
    return denominator == 0 ? 0.0 : double(numerator) / double(denominator);
}

/// A hit rate is undefined for an interval without reads: NaN, written as null.
double hit_rate(uint64_t hits, uint64_t reads) {
    return reads == 0 ? std::numeric_limits<double>::quiet_NaN() : double(hits) / double(reads);
}

}  // namespace

Timeline::Timeline(const stats::Registry& chip_stats, uint32_t threads,
                   std::function<uint64_t()> running, uint64_t interval)
    : running_(std::move(running)), threads_(threads), adaptive_(interval == 0),
      interval_(interval == 0 ? kFirstInterval : interval), next_(interval_) {
    static_assert(std::size(kCounterNames) + 1 == kCounters);
    for (const char* name : kCounterNames)
        counters_.push_back(chip_stats.at(name));
    points_.push_back({});
}

void Timeline::sample(uint64_t cycle) {
    Point p{cycle};
    for (size_t i = 0; i < counters_.size(); ++i)
        p[i + 1] = counters_[i].integer();
    p[Running + 1] = running_();
    points_.push_back(p);
    next_ = cycle + interval_;
    if (adaptive_ && points_.size() > 2 * kTargetRows) {
        // Keep cycle 0 and every second sample: the intervals of the kept ones double.
        std::vector<Point> kept;
        for (size_t i = 0; i < points_.size(); i += 2)
            kept.push_back(points_[i]);
        if (kept.back()[0] != points_.back()[0]) kept.push_back(points_.back());
        points_ = std::move(kept);
        interval_ *= 2;
        next_ = points_.back()[0] + interval_;
    }
}

nlohmann::ordered_json Timeline::json() const {
    nlohmann::ordered_json doc;
    doc["interval_cycles"] = interval_;
    doc["columns"] = {"cycle",       "issue_rate",           "l1_hit_rate",
                      "l2_hit_rate", "dram_bytes_per_cycle", "active_threads"};
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (size_t i = 1; i < points_.size(); ++i) {
        const Point& a = points_[i - 1];
        const Point& b = points_[i];
        const uint64_t cycles = b[0] - a[0];
        if (cycles == 0) continue;
        const auto delta = [&](Counter c) { return b[c + 1] - a[c + 1]; };
        rows.push_back({b[0], ratio(delta(Instructions), cycles * threads_),
                        hit_rate(delta(L1Hits), delta(L1Reads)),
                        hit_rate(delta(L2Hits), delta(L2Reads)),
                        ratio(delta(DramRead) + delta(DramWritten), cycles), b[Running + 1]});
    }
    doc["rows"] = std::move(rows);
    return doc;
}

}  // namespace tpsim::render
