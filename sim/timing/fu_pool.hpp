// A pool of identical functional units shared by the TPs of one TM, with round-robin
// arbitration by a rotating priority: deterministic, and no requester waits more than
// (requesters - 1) grants behind the others.
#pragma once
#include "isa/isa.hpp"
#include "stats/registry.hpp"
#include "timing/config.hpp"

#include <cstdint>
#include <string_view>
#include <vector>

namespace tpsim::timing {

/// The pools of FuPoolsConfig; several isa::FuClass values share one pool.
enum class Pool : uint8_t { IntAlu, IntMulDiv, FpAdd, FpMul, FpDivSqrt, FpMisc, Branch, LoadStore,
                            Atomic, Count };

Pool pool_of(isa::FuClass fu);  // throws for FuClass::Count
std::string_view to_string(Pool pool);
const FuConfig& pool_config(const FuPoolsConfig& pools, Pool pool);

class FuPool {
public:
    struct Counters {
        uint64_t issued = 0;             ///< operations started
        uint64_t denied = 0;             ///< requests refused because every unit was taken
        uint64_t unit_busy_cycles = 0;   ///< unit-cycles occupied (issue slots if pipelined)
    };

    FuPool(const FuConfig& config, uint32_t num_requesters);

    /// Requester `id` wants a unit this cycle. Call before arbitrate(), at most once per id.
    void request(uint32_t id) { pending_.push_back(id); }

    /// Grants free units to this cycle's requests in rotating-priority order, calling
    /// on_grant(id, ready_cycle) for each winner (ready_cycle = when its result can be read);
    /// the others are counted as denied and should request again next cycle.
    template <class OnGrant>
    void arbitrate(uint64_t now, OnGrant&& on_grant) {
        if (pending_.empty()) return;
        if (pending_.size() > 1) order_by_priority();
        uint32_t last_granted = kNone;
        for (uint32_t id : pending_) {
            if (!try_start(now)) {
                ++counters_.denied;
                continue;
            }
            on_grant(id, now + config_.latency);
            last_granted = id;
        }
        if (last_granted != kNone) next_priority_ = (last_granted + 1) % num_requesters_;
        pending_.clear();
    }

    const Counters& counters() const { return counters_; }
    const FuConfig& config() const { return config_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    static constexpr uint32_t kNone = UINT32_MAX;
    void order_by_priority();
    bool try_start(uint64_t now);

    FuConfig config_;
    uint32_t num_requesters_;
    uint32_t next_priority_ = 0;          // requester that wins first next time
    std::vector<uint32_t> pending_;
    std::vector<uint64_t> unit_free_at_;  // per unit, if not pipelined: first cycle it can start
    uint64_t starts_cycle_ = UINT64_MAX;  // if pipelined: operations started in cycle starts_cycle_
    uint32_t starts_ = 0;
    Counters counters_;
};

}  // namespace tpsim::timing
