#include "sim/core/lane_balance.hpp"

#include <algorithm>

namespace tpsim::core {

std::vector<uint32_t> balance_lanes(std::span<const uint32_t> bounds,
                                    std::span<const LaneLoad> loads,
                                    const std::vector<bool>& running, double least_gain) {
    const std::vector<uint32_t> same(bounds.begin(), bounds.end());
    const size_t lanes = loads.size();
    // Each lane's time per running TM; the mean where a lane has none to measure.
    std::vector<double> per_tm(lanes, 0);
    double measured = 0;
    uint32_t measured_lanes = 0;
    for (size_t l = 0; l < lanes; ++l)
        if (loads[l].running_tms != 0) {
            per_tm[l] = loads[l].tm_seconds / loads[l].running_tms;
            measured += per_tm[l];
            ++measured_lanes;
        }
    if (measured_lanes == 0 || measured <= 0) return same;
    for (size_t l = 0; l < lanes; ++l)
        if (loads[l].running_tms == 0) per_tm[l] = measured / measured_lanes;

    // Min-max by hand-outs: each running TM in turn to the lane that would then finish first.
    const auto busy = [&](size_t l, uint32_t tms) {
        return tms * per_tm[l] + loads[l].other_seconds;
    };
    const uint32_t total = uint32_t(std::count(running.begin(), running.end(), true));
    std::vector<uint32_t> share(lanes, 0);
    for (uint32_t handed = 0; handed < total; ++handed) {
        size_t best = 0;
        for (size_t l = 1; l < lanes; ++l)
            if (busy(l, share[l] + 1) < busy(best, share[best] + 1)) best = l;
        ++share[best];
    }
    double now = 0, then = 0;
    for (size_t l = 0; l < lanes; ++l) {
        now = std::max(now, busy(l, loads[l].running_tms));
        then = std::max(then, busy(l, share[l]));
    }
    if (then >= now * (1 - least_gain)) return same;

    // The blocks: each lane's share of running TMs in id order; an idle TM stays with the
    // block before it.
    const uint32_t tms = uint32_t(running.size());
    std::vector<uint32_t> out(lanes + 1, tms);
    out[0] = 0;
    size_t lane = 0;
    uint32_t taken = 0;
    for (uint32_t t = 0; t < tms; ++t) {
        if (!running[t]) continue;
        while (taken == share[lane]) {
            out[++lane] = t;
            taken = 0;
        }
        ++taken;
    }
    return out;
}

}  // namespace tpsim::core
