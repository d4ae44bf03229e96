#include "sim/timing/icache.hpp"

#include <fmt/format.h>

namespace tpsim::timing {

ICacheBanks::ICacheBanks(const ICacheConfig& config, uint32_t num_threads)
    : bank_mod_(config.banks),
      banks_(size_t{(num_threads + config.threads_per_icache - 1) / config.threads_per_icache} *
             config.banks) {
    for (uint32_t tp = 0; tp < num_threads; ++tp)
        first_bank_.push_back(tp / config.threads_per_icache * config.banks);
}

void ICacheBanks::register_stats(stats::Registry& r, std::string_view prefix) const {
    r.add_counter(
        fmt::format("{}/fetches", prefix), counters_.fetches,
        "fetches granted (an instruction each, and a finite I-cache's lookups that missed)");
    r.add_counter(fmt::format("{}/conflicts", prefix), counters_.conflicts,
                  "fetches refused by an I-cache bank conflict (one cycle lost each)");
}

ICacheLines::ICacheLines(const ICacheConfig& config, uint32_t num_threads, uint8_t region)
    : threads_per_icache_(config.threads_per_icache), region_(region),
      forwarded_(num_threads, kNoLine), way_hints_(num_threads, 0) {
    const uint32_t caches =
        (num_threads + config.threads_per_icache - 1) / config.threads_per_icache;
    for (uint32_t c = 0; c < caches; ++c)
        caches_.emplace_back(icache_lines_config(config));
}

void ICacheLines::send(std::deque<OutboundRequest>& to) {
    for (Cache& cache : caches_) {
        to.insert(to.end(), cache.outbound().begin(), cache.outbound().end());
        cache.outbound().clear();
    }
}

void ICacheLines::fill(uint64_t now, uint32_t cache, uint32_t line_addr) {
    Cache& c = caches_[cache];
    const uint64_t evictions = c.counters().evictions;
    c.fill(now, line_addr);
    counters_.evictions += c.counters().evictions - evictions;
}

bool ICacheLines::pop_reply(uint64_t now, MemReply& reply) {
    for (Cache& cache : caches_)
        if (cache.pop_reply(now, reply)) {
            forwarded_[reply.request.source] = cache.line_of(reply.request.pc);
            return true;
        }
    return false;
}

uint32_t ICacheLines::outstanding_misses() const {
    uint32_t n = 0;
    for (const Cache& cache : caches_)
        n += cache.outstanding_misses();
    return n;
}

void ICacheLines::register_stats(stats::Registry& r, std::string_view prefix) const {
    auto name = [&](std::string_view leaf) { return fmt::format("{}/{}", prefix, leaf); };
    r.add_counter(name("misses"), counters_.misses, "fetches that requested a line from the L2",
                  "fetches");
    r.add_counter(name("merged_misses"), counters_.merged_misses,
                  "fetches merged into an outstanding I-cache miss", "fetches");
    r.add_counter(name("mshr_full"), counters_.mshr_full,
                  "fetches refused for lack of an I-cache MSHR (retried)", "fetches");
    r.add_counter(name("evictions"), counters_.evictions, "valid I-cache lines replaced", "lines");
}

}  // namespace tpsim::timing
