// A pool of identical functional units shared by the TPs of one TM, with round-robin
// arbitration by a rotating priority: deterministic, and no requester waits more than
// (requesters - 1) grants behind the others.
#pragma once
#include "isa/isa.hpp"
#include "stats/registry.hpp"
#include "timing/bits.hpp"
#include "timing/config.hpp"

#include <algorithm>
#include <bit>
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

    /// Requesters 64 * word + b, for each set bit b of `ids`, want a unit this cycle. Call
    /// before arbitrate(), at most once per requester.
    void request(uint32_t word, uint64_t ids) {
        requested_[word] |= ids;
        requests_ += count_bits(ids);
    }

    /// Grants free units to this cycle's requests in rotating-priority order, calling
    /// on_grant(id, ready_cycle) for each winner (ready_cycle = when its result can be read);
    /// the others are counted as denied and should request again next cycle. Returns how many
    /// were denied.
    template <class OnGrant>
    uint32_t arbitrate(uint64_t now, OnGrant&& on_grant) {
        if (requests_ == 0) return 0;
        // Requests are a bit set, walked from the priority pointer with wrap-around: the
        // rotating-priority order without sorting.
        const uint32_t words = static_cast<uint32_t>(requested_.size());
        const uint32_t first_word = next_priority_ >> 6;
        const uint64_t below_start = (uint64_t{1} << (next_priority_ & 63)) - 1;
        uint32_t last_granted = kNone;
        for (uint32_t k = 0, w = first_word; k <= words; ++k, w = w + 1 == words ? 0 : w + 1) {
            // The first word is visited twice: its bits from the pointer up, last the ones below.
            uint64_t bits = requested_[w];
            if (k == 0) bits &= ~below_start;
            else if (k == words) bits &= below_start;
            else if (w == first_word) continue;
            if (k != 0) requested_[w] = 0;  // its last visit (cleared here: no memset call)
            for (; bits != 0; bits &= bits - 1) {
                if (!try_start(now)) break;  // no unit frees up within a cycle: the rest lose too
                const uint32_t id = (w << 6) + static_cast<uint32_t>(std::countr_zero(bits));
                on_grant(id, now + config_.latency);
                last_granted = id;
                --requests_;
            }
        }
        const uint32_t denied = requests_;
        counters_.denied += denied;
        if (last_granted != kNone)
            next_priority_ = last_granted + 1 == num_requesters_ ? 0 : last_granted + 1;
        requests_ = 0;
        return denied;
    }

    const Counters& counters() const { return counters_; }
    const FuConfig& config() const { return config_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    static constexpr uint32_t kNone = UINT32_MAX;
    bool try_start(uint64_t now);  // inline below: called once per simulated instruction

    FuConfig config_;
    uint32_t num_requesters_;
    uint32_t next_priority_ = 0;          // requester that wins first next time
    std::vector<uint64_t> requested_;     // bit per requester, this cycle
    uint32_t requests_ = 0;               // bits set in requested_
    std::vector<uint64_t> unit_free_at_;  // per unit, if not pipelined: first cycle it can start
    uint64_t starts_cycle_ = UINT64_MAX;  // if pipelined: operations started in cycle starts_cycle_
    uint32_t starts_ = 0;
    Counters counters_;
};

inline bool FuPool::try_start(uint64_t now) {
    if (config_.pipelined) {
        // Every pipelined unit is free again one cycle after it started, so which unit takes an
        // operation is unobservable: counting this cycle's starts is enough.
        if (starts_cycle_ != now) starts_cycle_ = now, starts_ = 0;
        if (starts_ == config_.count) return false;
        ++starts_;
        ++counters_.issued;
        ++counters_.unit_busy_cycles;
        return true;
    }
    for (uint64_t& free_at : unit_free_at_) {
        if (free_at > now) continue;
        free_at = now + config_.latency;  // not pipelined: busy until the result is out
        ++counters_.issued;
        counters_.unit_busy_cycles += config_.latency;
        return true;
    }
    return false;
}

}  // namespace tpsim::timing
