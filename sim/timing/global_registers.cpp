#include "sim/timing/global_registers.hpp"

#include <fmt/format.h>

#include <algorithm>

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
        if (next.request.kind == GlobalRequest::Increment) [[likely]]
            reply(now, next.request);
        else
            serve_sync(now, next.request);
    }
}

void GlobalRegisterUnit::serve_sync(uint64_t now, const AtomicRequest& request) {
    switch (request.kind) {
    case GlobalRequest::Increment:
        break;
    case GlobalRequest::Barrier:
    case GlobalRequest::Exit:
        if (request.kind == GlobalRequest::Barrier) at_barrier_.push_back(request);
        if (request.value != 0) barrier_releases_ = request.value;
        if (barrier_releases_ != 0 && at_barrier_.size() == barrier_releases_) {
            for (const AtomicRequest& waiter : at_barrier_)
                reply(now, waiter);
            at_barrier_.clear();
            barrier_releases_ = 0;
        }
        return;
    case GlobalRequest::SemAcquire: {
        const auto handed = std::find(handed_over_.begin(), handed_over_.end(), request.thread);
        if (request.value == 1 || handed != handed_over_.end()) {
            if (handed != handed_over_.end()) handed_over_.erase(handed);
            reply(now, request);
        } else {
            acquiring_.push_back(request);
        }
        return;
    }
    case GlobalRequest::SemRelease:
        reply(now, request);
        if (request.value != 0) {
            const uint32_t next = request.value - 1;
            const auto waiter =
                std::find_if(acquiring_.begin(), acquiring_.end(),
                             [next](const AtomicRequest& r) { return r.thread == next; });
            if (waiter != acquiring_.end()) {
                reply(now, *waiter);
                acquiring_.erase(waiter);
            } else {
                handed_over_.push_back(next);
            }
        }
        return;
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
                  "requests served: atomic increments, barrier arrivals and exits, semaphore "
                  "operations",
                  "requests");
    r.add_counter(fmt::format("{}/queued_cycles", prefix), counters_.queued_cycles,
                  "cycles requests waited for a service slot, summed", "cycles");
}

}  // namespace tpsim::timing
