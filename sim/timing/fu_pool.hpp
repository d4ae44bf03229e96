// A pool of identical functional units shared by the TPs of one TM, with round-robin
// arbitration by a rotating priority: deterministic, and no requester waits more than
// (requesters - 1) grants behind the others.
#pragma once
#include "isa/isa.hpp"
#include "sim/stats/registry.hpp"
#include "sim/timing/bits.hpp"
#include "sim/timing/config.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <string_view>
#include <vector>

namespace tpsim::timing {

/// The pools of FuPoolsConfig; several isa::FuClass values share one pool.
enum class Pool : uint8_t {
    IntAlu,
    IntMulDiv,
    FpAdd,
    FpMul,
    FpDivSqrt,
    FpMisc,
    Branch,
    LoadStore,
    Atomic,
    Count
};

Pool pool_of(isa::FuClass fu);  // throws for FuClass::Count
std::string_view to_string(Pool pool);
const FuConfig& pool_config(const FuPoolsConfig& pools, Pool pool);

class FuPool {
public:
    struct Counters {
        uint64_t issued = 0;            ///< operations started
        uint64_t denied = 0;            ///< requests refused because every unit was taken
        uint64_t unit_busy_cycles = 0;  ///< unit-cycles occupied (issue slots if pipelined)
    };

    FuPool(const FuConfig& config, uint32_t num_requesters);

    /// What one cycle's arbitration did.
    struct Grants {
        uint32_t granted = 0;
        uint32_t denied = 0;
    };

    /// Requesters 64 * word + b, for each set bit b of `ids`, want a unit this cycle. Call
    /// before arbitrate(), at most once per requester.
    void request(uint32_t word, uint64_t ids) {
        requested_[word] |= ids;
        requests_ += count_bits(ids);
    }

    /// Grants free units to this cycle's requests in rotating-priority order: the winners'
    /// bits are OR-ed into `winners` (a word per 64 requesters, as in request()); their results
    /// can be read at now + latency. The others are denied and should request again next
    /// cycle.
    Grants arbitrate(uint64_t now, uint64_t* winners) {
        if (requests_ == 0) return {};
        // No unit frees up within a cycle, so the winners are the first `granted` requesters
        // in rotating-priority order.
        const uint32_t granted = std::min(requests_, free_units(now));
        const uint32_t denied = requests_ - granted;
        uint32_t last = 0;  // the last winner in priority order
        uint32_t left = granted;
        // Rotated walk (bits.hpp): for up to 64 requesters one part, the request word rotated
        // by the priority pointer, so the winners are its lowest `granted` bits.
        const auto take = [&](const RotatedPart& part) __attribute__((always_inline)) {
            uint64_t won = part.of(requested_[part.w]);
            requested_[part.w] &= ~part.mask;  // taken: this part's requests are decided
            if (denied != 0) {                 // else every request wins
                uint64_t first = 0;
                for (uint64_t order = won; order != 0 && left != 0; order &= order - 1, --left)
                    first |= order & -order;
                won = first;
            }
            if (won == 0) return;
            last = part.index(static_cast<uint32_t>(63 - std::countl_zero(won)));
            winners[part.w] |= part.back(won);
        };
        for_each_rotated_part(static_cast<uint32_t>(requested_.size()), next_priority_, take);
        if (!config_.pipelined) {
            // Winners take the first free units, each busy until its result is out.
            uint32_t unstarted = granted;
            for (uint64_t& free_at : unit_free_at_)
                if (unstarted != 0 && free_at <= now) free_at = now + config_.latency, --unstarted;
        }
        requests_ = 0;
        counters_.issued += granted;
        counters_.unit_busy_cycles += uint64_t{granted} * (config_.pipelined ? 1 : config_.latency);
        counters_.denied += denied;
        started_ += granted;
        if (granted != 0) next_priority_ = last + 1 == num_requesters_ ? 0 : last + 1;
        return {granted, denied};
    }

    const Counters& counters() const { return counters_; }
    const FuConfig& config() const { return config_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    /// Units that can start an operation in cycle `now`.
    uint32_t free_units(uint64_t now) {
        if (config_.pipelined) {
            // Every pipelined unit is free again one cycle after it started, so which unit
            // takes an operation is unobservable: counting this cycle's starts is enough.
            started_ = started_cycle_ == now ? started_ : 0;
            started_cycle_ = now;
            return config_.count - started_;
        }
        uint32_t free = 0;
        for (uint64_t free_at : unit_free_at_)
            free += free_at <= now;
        return free;
    }

    FuConfig config_;
    uint32_t num_requesters_;
    uint32_t next_priority_ = 0;           // requester that wins first next time
    std::vector<uint64_t> requested_;      // bit per requester, this cycle
    uint32_t requests_ = 0;                // bits set in requested_
    std::vector<uint64_t> unit_free_at_;   // per unit, if not pipelined: first cycle it can start
    uint64_t started_cycle_ = UINT64_MAX;  // if pipelined: operations started in started_cycle_
    uint32_t started_ = 0;
    Counters counters_;
};

}  // namespace tpsim::timing
