// Instruction fetch: the I-cache banks every fetch goes through, and the optional finite
// I-cache (icache.size_bytes > 0) whose misses go to the L2 (docs/hardware-model.md, "Thread
// multiprocessor"). By default the I-cache never misses, as in TRaX.
#pragma once
#include "sim/stats/registry.hpp"
#include "sim/timing/bits.hpp"
#include "sim/timing/cache.hpp"
#include "sim/timing/config.hpp"
#include "sim/timing/memory.hpp"

#include <bit>
#include <cstdint>
#include <deque>
#include <string_view>
#include <utility>
#include <vector>

namespace tpsim::timing {

/// Instruction fetch banks, modelled whether or not the I-cache can miss. Threads sharing one
/// I-cache fetch from banks interleaved by instruction word; each bank serves one address per
/// cycle, and threads fetching the same address share it (broadcast).
class ICacheBanks {
public:
    struct Counters {
        uint64_t fetches = 0;    ///< granted fetches
        uint64_t conflicts = 0;  ///< refused fetches (bank busy with another address)
    };

    ICacheBanks(const ICacheConfig& config, uint32_t num_threads);

    /// Threads tp_of(b), for each set bit b of `wanting`, fetch pc_of(thread) in cycle `now`,
    /// lowest bit first: within a cycle earlier fetches win, so the caller decides the
    /// (rotating) order. Returns the granted bits; the others conflict and try again next cycle.
    template <class TpOf, class PcOf>
    [[gnu::always_inline]] uint64_t fetch(uint64_t now, uint64_t wanting, TpOf&& tp_of,
                                          PcOf&& pc_of) {
        // Once per simulated instruction: no division (the thread's first bank is precomputed,
        // a power-of-two bank count is a mask), and no branch on whether a fetch conflicts,
        // which is unpredictable for the host.
        const uint32_t* first_bank = first_bank_.data();
        Bank* banks = banks_.data();
        uint64_t granted = 0;
        for (uint64_t bits = wanting; bits != 0; bits &= bits - 1) {
            const uint32_t bit = static_cast<uint32_t>(std::countr_zero(bits));
            const uint32_t tp = tp_of(bit);
            const uint32_t pc = pc_of(tp);
            Bank& bank = banks[first_bank[tp] + bank_mod_.of(pc / 4)];
            const bool ok = (bank.cycle != now) | (bank.pc == pc);
            bank.cycle = now;
            bank.pc ^= (bank.pc ^ pc) & -uint32_t{ok};
            granted |= uint64_t{ok} << bit;
        }
        counters_.fetches += count_bits(granted);
        counters_.conflicts += count_bits(wanting & ~granted);
        return granted;
    }

    const Counters& counters() const { return counters_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    struct Bank {
        uint64_t cycle = UINT64_MAX;  // cycle of the current reservation
        uint32_t pc = 0;
    };
    Modulus bank_mod_;                  // banks per I-cache
    std::vector<uint32_t> first_bank_;  // per thread: index of its I-cache's bank 0
    std::vector<Bank> banks_;           // all I-caches of the TM, banks_per_icache_ each
    Counters counters_;
};

/// The contents of a TM's finite I-caches: one Cache (tags, LRU, MSHRs) per threads_per_icache
/// TPs. A fetch whose bank ICacheBanks granted looks its line up: a hit goes on in the same cycle
/// (as a fetch from an I-cache that never misses); a miss sends a line request towards the L2,
/// and the TP waits until the line arrives. The arriving line is forwarded to the TPs waiting
/// for it: their next fetch from it goes on even if another fill has evicted it meanwhile, so
/// threads thrashing one set still progress.
class ICacheLines {
public:
    struct Counters {
        uint64_t misses = 0;         ///< fetches that sent a line request to the L2
        uint64_t merged_misses = 0;  ///< fetches that joined an outstanding miss
        uint64_t mshr_full = 0;      ///< fetches refused for lack of an MSHR (retried)
        uint64_t evictions = 0;      ///< valid lines replaced by fills
    };

    /// `region`: the chip's region index of instruction fetches, which the line requests carry.
    ICacheLines(const ICacheConfig& config, uint32_t num_threads, uint8_t region);

    /// TP `tp`, holding work item `item`, fetches `pc` in cycle `now` (its bank granted): Hit,
    /// Miss or MergedMiss (the TP waits for pop_reply), or MshrFull (it retries).
    CacheOutcome fetch(uint64_t now, uint32_t tp, uint32_t pc, uint32_t item) {
        Cache& cache = caches_[tp / threads_per_icache_];
        if (std::exchange(forwarded_[tp], kNoLine) == cache.line_of(pc)) return CacheOutcome::Hit;
        const MemRequest request{pc, tp, tp / threads_per_icache_, false, region_, 4, pc, item};
        const CacheOutcome outcome = cache.fetch(now, request, way_hints_[tp]);
        counters_.misses += outcome == CacheOutcome::Miss;
        counters_.merged_misses += outcome == CacheOutcome::MergedMiss;
        counters_.mshr_full += outcome == CacheOutcome::MshrFull;
        return outcome;
    }
    /// Moves the line requests made so far to `to` (the TM's queue to the L2), in order. Each
    /// carries the instruction-fetch region and, as its tag, the I-cache's index in the TM.
    void send(std::deque<OutboundRequest>& to);
    /// The line at `line_addr` for I-cache `cache` (the request's tag) arrives in cycle `now`.
    void fill(uint64_t now, uint32_t cache, uint32_t line_addr);
    /// Pops a TP whose line is there by `now` (request.source: the TP, request.pc: its pc).
    bool pop_reply(uint64_t now, MemReply& reply);
    uint32_t outstanding_misses() const;

    const Counters& counters() const { return counters_; }
    void register_stats(stats::Registry& registry, std::string_view prefix) const;

private:
    static constexpr uint32_t kNoLine = 1;  // never a line address (lines are aligned)
    uint32_t threads_per_icache_;
    uint8_t region_;
    std::vector<Cache> caches_;
    std::vector<uint32_t> forwarded_;  // per TP: the line its last reply brought, or kNoLine
    std::vector<uint32_t> way_hints_;  // per TP: Cache::fetch's way_hint
    Counters counters_;
};

}  // namespace tpsim::timing
