// The chip-wide global-register unit that serves atomic increments (how kernels hand out
// work). TMs send requests stamped with their send cycle and a per-TM sequence number; the unit
// serves them in (arrival cycle, TM, sequence) order, never in host call order, so the result
// does not depend on which TM the host simulated first. Only timing lives here: the value each
// thread receives is computed by the functional core.
#pragma once
#include "sim/stats/registry.hpp"
#include "sim/timing/config.hpp"

#include <cstdint>
#include <functional>
#include <queue>
#include <string_view>
#include <vector>

namespace tpsim::timing {

/// What a request asks of the unit. The synchronisation requests carry what the functional
/// core decided when it executed the instruction (core::StepRecord::value), so that
/// the unit replies in timing order with the same outcome: a TP waiting at the barrier or for
/// a semaphore gets its reply only once every request that lets it go on has been served.
enum class GlobalRequest : uint8_t {
    Increment,   ///< tp.atominc; reply with the value
    Barrier,     ///< an arrival; value: threads its arrival lets go on (0: not the last)
    Exit,        ///< a thread exited, letting `value` barrier waiters go on
    SemAcquire,  ///< value 1: got it at once; 0: waits to be handed it by a release
    SemRelease,  ///< value: 1 + the thread it hands the semaphore to, or 0
};

struct AtomicRequest {
    uint64_t sent = 0;  ///< cycle the TM sent it
    uint32_t tm = 0;
    uint32_t sequence = 0;  ///< per-TM counter, breaks ties within a cycle
    uint32_t tp = 0;        ///< returned in the reply
    uint32_t tag = 0;       ///< returned in the reply (e.g. destination register)
    GlobalRequest kind = GlobalRequest::Increment;
    uint32_t value = 0;   ///< see GlobalRequest
    uint32_t thread = 0;  ///< the sending thread (tm * tps_per_tm + tp)
};

struct AtomicReply {
    uint64_t ready = 0;  ///< cycle the result is usable back at the TP
    AtomicRequest request;
};

class GlobalRegisterUnit {
public:
    struct Counters {
        uint64_t requests = 0;       ///< atomic increments served
        uint64_t queued_cycles = 0;  ///< total cycles requests waited for a service slot
    };

    explicit GlobalRegisterUnit(const GlobalRegisterConfig& config) : config_(config) {}

    void submit(const AtomicRequest& request);
    /// Serves up to per_cycle requests that have arrived by `now`. Call once per cycle, in order.
    void tick(uint64_t now);
    /// Pops the next reply ready by `now`, in service order.
    bool pop_reply(uint64_t now, AtomicReply& reply);
    /// Nothing queued or in flight (TPs waiting at the barrier or for a semaphore aside).
    bool idle() const { return waiting_.empty() && replies_.empty(); }

    const Counters& counters() const { return counters_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    struct Arrival {
        uint64_t cycle;
        AtomicRequest request;
        bool operator>(const Arrival& o) const {
            if (cycle != o.cycle) return cycle > o.cycle;
            if (request.tm != o.request.tm) return request.tm > o.request.tm;
            return request.sequence > o.request.sequence;
        }
    };
    void reply(uint64_t now, const AtomicRequest& request) {
        replies_.push({now + config_.latency + config_.link_latency, request});
    }
    /// A synchronisation request served at `now` (see GlobalRequest).
    void serve_sync(uint64_t now, const AtomicRequest& request);

    GlobalRegisterConfig config_;
    std::priority_queue<Arrival, std::vector<Arrival>, std::greater<>> waiting_;
    // The barrier: arrivals served and waiting for their reply, and how many arrivals the
    // functional core let go on together (0: the releasing request is not served yet).
    std::vector<AtomicRequest> at_barrier_;
    uint32_t barrier_releases_ = 0;
    // Semaphore hand-overs: acquires served before the release that hands them the semaphore,
    // and threads handed one before their acquire was served.
    std::vector<AtomicRequest> acquiring_;
    std::vector<uint32_t> handed_over_;
    std::queue<AtomicReply> replies_;  // non-decreasing ready: served in order, fixed latency
    Counters counters_;
};

}  // namespace tpsim::timing
