#include "sim/timing/global_registers.hpp"

#include <fmt/format.h>

namespace tpsim::timing {

void GlobalRegisterUnit::submit(const AtomicRequest& request) {
    waiting_.push({request.sent + config_.link_latency, request});
}

void GlobalRegisterUnit::tick(uint64_t now) {
    for (uint32_t served = 0; served < config_.per_cycle && !waiting_.empty(); ++served) {
        const Arrival next = waiting_.top();
        if (next.cycle > now) break;
        waiting_.pop();
        ++counters_.requests;
        counters_.queued_cycles += now - next.cycle;
        replies_.push({now + config_.latency + config_.link_latency, next.request});
    }
}

bool GlobalRegisterUnit::pop_reply(uint64_t now, AtomicReply& reply) {
    if (replies_.empty() || replies_.front().ready > now) return false;
    reply = replies_.front();
    replies_.pop();
    return true;
}

void GlobalRegisterUnit::register_stats(stats::Registry& r, std::string_view prefix) const {
    r.add_counter(fmt::format("{}/requests", prefix), counters_.requests,
                  "atomic increments served", "requests");
    r.add_counter(fmt::format("{}/queued_cycles", prefix), counters_.queued_cycles,
                  "cycles requests waited for a service slot, summed", "cycles");
}

}  // namespace tpsim::timing
