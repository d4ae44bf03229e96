// A banked, set-associative (true LRU), non-blocking data cache with MSHRs that merge misses
// to the same line, used for the per-TM L1 and the per-group L2.
//
// Policy (docs/hardware-model.md): reads allocate; stores are write-around (as in TRaX): a store
// is forwarded to the next level, never allocates, and leaves a present line valid; stores need
// no reply. Optionally (the L2's write_combining_lines) stores merge in a small buffer of lines
// and go on as one line write each. Each bank accepts one access per cycle; bank = line number
// % banks. Fills do not occupy a bank. Data values are never stored: the functional core owns
// them.
#pragma once
#include "sim/stats/registry.hpp"
#include "sim/timing/bits.hpp"
#include "sim/timing/config.hpp"
#include "sim/timing/memory.hpp"

#include <bit>
#include <cstdint>
#include <deque>
#include <string_view>
#include <vector>

namespace tpsim::timing {

/// n % divisor without a division when the divisor is a power of two (the usual bank and set
/// counts): the caches take several per access, the I-cache banks one per fetch.
class Modulus {
public:
    explicit Modulus(uint32_t divisor)
        : divisor_(divisor), power_of_two_(std::has_single_bit(divisor)), mask_(divisor - 1) {}
    uint32_t of(uint32_t n) const { return power_of_two_ ? n & mask_ : n % divisor_; }

private:
    uint32_t divisor_;
    bool power_of_two_;
    uint32_t mask_;
};

enum class CacheOutcome : uint8_t {
    Hit,            ///< reply queued for now + hit_latency
    Miss,           ///< a line request went to the next level
    MergedMiss,     ///< joined an outstanding miss to the same line
    WriteForward,   ///< store accepted and forwarded (write-around)
    WriteCombined,  ///< store accepted into the write-combining buffer
    BankConflict,   ///< bank already used this cycle: nothing happened, retry next cycle
    MshrFull,       ///< no MSHR free: nothing happened, retry later
};

inline bool accepted(CacheOutcome o) {
    return o != CacheOutcome::BankConflict && o != CacheOutcome::MshrFull;
}

class Cache {
public:
    struct Counters {
        uint64_t reads = 0;   ///< accepted loads (= hits + misses + merged_misses)
        uint64_t writes = 0;  ///< accepted stores
        uint64_t hits = 0;
        uint64_t misses = 0;          ///< loads that sent a line request to the next level
        uint64_t merged_misses = 0;   ///< loads that joined an outstanding miss
        uint64_t bank_conflicts = 0;  ///< refused accesses (bank busy this cycle)
        uint64_t mshr_full = 0;       ///< refused loads (no MSHR free)
        uint64_t evictions = 0;       ///< valid lines replaced by fills
    };

    /// `write_combining_lines` > 0 adds a write-combining buffer of that many lines.
    explicit Cache(const CacheConfig& config, uint32_t write_combining_lines = 0);

    /// Presents one access in cycle `now`; calls must come in non-decreasing `now`.
    CacheOutcome access(uint64_t now, const MemRequest& request);
    /// An instruction fetch (a finite I-cache's tags, ICacheLines): the caller has arbitrated
    /// the banks, and a hit queues no reply (the fetch goes on in this cycle); a miss is a
    /// load's miss. `way_hint`, the requester's own, is where its last fetch hit: a fetch from
    /// the same line looks there first (the host's speed only: a thread fetches a line many
    /// times in a row, and searching the set's ways is an unpredictable branch for the host).
    CacheOutcome fetch(uint64_t now, const MemRequest& request, uint32_t& way_hint) {
        const uint32_t line = line_of(request.addr);
        Way* way = &ways_[way_hint];
        if (!way->valid || way->line != line) [[unlikely]]
            way = find(line);
        if (way) [[likely]] {
            way_hint = static_cast<uint32_t>(way - ways_.data());
            ++counters_.reads;
            ++counters_.hits;
            way->last_use = ++use_clock_;
            return CacheOutcome::Hit;
        }
        return fetch_miss(now, request);
    }
    /// The line holding `line_addr` arrives from the next level in cycle `now`: it is
    /// installed (evicting the LRU way) and every merged waiter gets a reply at now + hit_latency.
    void fill(uint64_t now, uint32_t line_addr);
    /// Functional warming (Chip::warm): the tag and LRU state `access` and `fill` would leave
    /// behind for this access, without timing, MSHRs or counters. Returns whether it hit; a
    /// load that misses installs its line at once.
    bool warm(uint32_t addr, bool write);
    /// Pops the oldest reply whose data is ready by `now` (inline: asked every TM and cycle).
    bool pop_reply(uint64_t now, MemReply& reply) {
        if (replies_.empty() || replies_.front().ready > now) return false;
        reply = replies_.front();
        replies_.pop_front();
        return true;
    }

    /// Requests for the next level in the order they were made; the owner drains it.
    std::deque<OutboundRequest>& outbound() { return outbound_; }
    const std::deque<OutboundRequest>& outbound() const { return outbound_; }
    bool contains(uint32_t addr) const;
    uint32_t line_of(uint32_t addr) const { return addr & ~(config_.line_bytes - 1); }
    uint32_t bank_of(uint32_t addr) const { return bank_mod_.of(addr >> line_shift_); }
    uint32_t outstanding_misses() const;
    /// End of the run: every line in the write-combining buffer goes on as a line write, oldest
    /// first, visible below from `now`. Returns whether there were any.
    bool drain_write_buffer(uint64_t now);
    bool holds_combined_lines() const { return !combining_.empty(); }

    const Counters& counters() const { return counters_; }
    const CacheConfig& config() const { return config_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    struct Way {
        uint32_t line = 0;
        bool valid = false;
        uint64_t last_use = 0;  // LRU stamp from use_clock_; deterministic, never host time
    };
    struct Mshr {
        uint32_t line = 0;
        bool busy = false;
        std::vector<MemRequest> waiters;
    };

    /// A line being written in the write-combining buffer: which bytes, and the request that
    /// opened it (its region, pc and work item go on with the line write).
    struct CombiningLine {
        MemRequest first;
        std::vector<uint64_t> written;  // bit per byte of the line
        uint32_t bytes = 0;             // bits set in `written`
    };

    Way* find(uint32_t line) {
        Way* set = &ways_[size_t{set_of(line)} * config_.ways];
        for (uint32_t w = 0; w < config_.ways; ++w)
            if (set[w].valid && set[w].line == line) return &set[w];
        return nullptr;
    }
    CacheOutcome fetch_miss(uint64_t now, const MemRequest& request);
    /// A load whose bank is free: a hit (with a reply if kReplyOnHit), a miss or a merge.
    template <bool kReplyOnHit> CacheOutcome read(uint64_t now, const MemRequest& request);
    /// Puts `line` (not present) into the LRU way of its set; returns whether it evicted one.
    bool install(uint32_t line);
    CacheOutcome combine(uint64_t now, const MemRequest& request);
    /// Sends buffered line `index` on as one line write, visible below from `at`.
    void write_line(size_t index, uint64_t at);
    const Way* find(uint32_t line) const;
    uint32_t set_of(uint32_t line) const { return set_mod_.of(line >> line_shift_); }

    CacheConfig config_;
    uint32_t num_sets_;
    uint32_t line_shift_;  // log2(line_bytes), validated a power of two
    Modulus bank_mod_;
    Modulus set_mod_;
    std::vector<Way> ways_;  // num_sets_ x ways
    std::vector<Mshr> mshrs_;
    std::vector<uint64_t> bank_used_at_;  // last cycle each bank accepted an access
    uint64_t use_clock_ = 0;
    std::deque<MemReply> replies_;  // non-decreasing `ready`
    std::deque<OutboundRequest> outbound_;
    uint32_t combining_capacity_;
    std::vector<CombiningLine> combining_;  // oldest first
    Counters counters_;
};

}  // namespace tpsim::timing
