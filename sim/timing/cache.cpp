#include "sim/timing/cache.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>

#include <stdexcept>

namespace tpsim::timing {

Cache::Cache(const CacheConfig& config, uint32_t write_combining_lines)
    : config_(config), num_sets_(config.size_bytes / (config.ways * config.line_bytes)),
      line_shift_(static_cast<uint32_t>(std::countr_zero(config.line_bytes))),
      bank_mod_(config.banks), set_mod_(std::max(num_sets_, 1u)),
      ways_(size_t{num_sets_} * config.ways), mshrs_(config.mshrs),
      bank_used_at_(config.banks, UINT64_MAX), combining_capacity_(write_combining_lines) {
    if (num_sets_ == 0 || (config.line_bytes & (config.line_bytes - 1)) != 0)
        throw std::invalid_argument(
            "Cache: invalid geometry; validate the ChipConfig before building caches");
}

const Cache::Way* Cache::find(uint32_t line) const {
    return const_cast<Cache*>(this)->find(line);
}

bool Cache::contains(uint32_t addr) const {
    return find(line_of(addr)) != nullptr;
}

uint32_t Cache::outstanding_misses() const {
    uint32_t n = 0;
    for (const Mshr& m : mshrs_)
        n += m.busy;
    return n;
}

CacheOutcome Cache::access(uint64_t now, const MemRequest& request) {
    uint64_t& bank_used = bank_used_at_[bank_of(request.addr)];
    if (bank_used == now) {
        ++counters_.bank_conflicts;
        return CacheOutcome::BankConflict;
    }
    if (request.write) {
        bank_used = now;
        ++counters_.writes;
        if (Way* way = find(line_of(request.addr))) way->last_use = ++use_clock_;
        const uint64_t after_lookup = now + config_.hit_latency;
        if (combining_capacity_ != 0) return combine(after_lookup, request);
        outbound_.push_back({after_lookup, request});
        return CacheOutcome::WriteForward;
    }
    const CacheOutcome outcome = read<true>(now, request);
    if (outcome != CacheOutcome::MshrFull) bank_used = now;
    return outcome;
}

CacheOutcome Cache::fetch_miss(uint64_t now, const MemRequest& request) {
    return read<false>(now, request);
}

template <bool kReplyOnHit>
[[gnu::always_inline]] inline CacheOutcome Cache::read(uint64_t now, const MemRequest& request) {
    const uint32_t line = line_of(request.addr);
    const uint64_t after_lookup = now + config_.hit_latency;
    if (Way* way = find(line)) {
        ++counters_.reads;
        ++counters_.hits;
        way->last_use = ++use_clock_;
        if constexpr (kReplyOnHit) replies_.push_back({after_lookup, request});
        return CacheOutcome::Hit;
    }
    Mshr* free_mshr = nullptr;
    for (Mshr& m : mshrs_) {
        if (m.busy && m.line == line) {
            ++counters_.reads;
            ++counters_.merged_misses;
            m.waiters.push_back(request);
            return CacheOutcome::MergedMiss;
        }
        if (!m.busy && !free_mshr) free_mshr = &m;
    }
    if (!free_mshr) {
        ++counters_.mshr_full;
        return CacheOutcome::MshrFull;
    }
    ++counters_.reads;
    ++counters_.misses;
    // The line's buffered stores reach the next level before the line is read from it.
    for (size_t i = 0; i < combining_.size(); ++i)
        if (combining_[i].first.addr == line) {
            write_line(i, after_lookup);
            break;
        }
    free_mshr->busy = true;
    free_mshr->line = line;
    free_mshr->waiters.assign(1, request);
    MemRequest line_request = request;
    line_request.addr = line;
    outbound_.push_back({after_lookup, line_request});
    return CacheOutcome::Miss;
}

CacheOutcome Cache::combine(uint64_t at, const MemRequest& request) {
    const uint32_t line = line_of(request.addr);
    size_t index = 0;
    while (index < combining_.size() && combining_[index].first.addr != line)
        ++index;
    if (index == combining_.size()) {
        if (combining_.size() == combining_capacity_) {
            write_line(0, at);  // the oldest line makes room
            --index;
        }
        CombiningLine opened{request, std::vector<uint64_t>((config_.line_bytes + 63) / 64), 0};
        opened.first.addr = line;
        combining_.push_back(std::move(opened));
    }
    CombiningLine& entry = combining_[index];
    for (uint32_t b = request.addr - line; b < request.addr - line + request.bytes; ++b) {
        uint64_t& word = entry.written[b / 64];
        entry.bytes += (word >> (b % 64) & 1) ^ 1;
        word |= uint64_t{1} << (b % 64);
    }
    if (entry.bytes == config_.line_bytes) write_line(index, at);
    return CacheOutcome::WriteCombined;
}

void Cache::write_line(size_t index, uint64_t at) {
    MemRequest write = combining_[index].first;
    write.bytes = static_cast<uint16_t>(combining_[index].bytes);
    outbound_.push_back({at, write});
    combining_.erase(combining_.begin() + static_cast<std::ptrdiff_t>(index));
}

bool Cache::drain_write_buffer(uint64_t now) {
    const bool any = !combining_.empty();
    while (!combining_.empty())
        write_line(0, now);
    return any;
}

bool Cache::install(uint32_t line) {
    Way* set = &ways_[size_t{set_of(line)} * config_.ways];
    Way* victim = &set[0];
    for (uint32_t w = 0; w < config_.ways; ++w) {
        if (!set[w].valid) {
            victim = &set[w];
            break;
        }
        if (set[w].last_use < victim->last_use) victim = &set[w];
    }
    const bool evicted = victim->valid;
    *victim = {line, true, ++use_clock_};
    return evicted;
}

bool Cache::warm(uint32_t addr, bool write) {
    const uint32_t line = line_of(addr);
    if (Way* way = find(line)) {
        way->last_use = ++use_clock_;
        return true;
    }
    if (!write) install(line);
    return false;
}

void Cache::fill(uint64_t now, uint32_t line_addr) {
    const uint32_t line = line_of(line_addr);
    if (!find(line)) counters_.evictions += install(line);
    for (Mshr& m : mshrs_) {
        if (!m.busy || m.line != line) continue;
        for (const MemRequest& waiter : m.waiters)
            replies_.push_back({now + config_.hit_latency, waiter});
        m.waiters.clear();
        m.busy = false;
    }
}

void Cache::register_stats(stats::Registry& r, std::string_view prefix) const {
    auto name = [&](std::string_view leaf) { return fmt::format("{}/{}", prefix, leaf); };
    r.add_counter(name("reads"), counters_.reads, "loads accepted", "accesses");
    r.add_counter(name("writes"), counters_.writes, "stores accepted (write-around)", "accesses");
    r.add_counter(name("hits"), counters_.hits, "loads that hit", "accesses");
    r.add_counter(name("misses"), counters_.misses, "loads that requested a line below",
                  "accesses");
    r.add_counter(name("merged_misses"), counters_.merged_misses,
                  "loads merged into an outstanding miss (MSHR hit)", "accesses");
    r.add_counter(name("bank_conflicts"), counters_.bank_conflicts,
                  "accesses refused because their bank was busy", "accesses");
    r.add_counter(name("mshr_full"), counters_.mshr_full, "loads refused for lack of an MSHR",
                  "accesses");
    r.add_counter(name("evictions"), counters_.evictions, "valid lines replaced", "lines");
    r.add_ratio(name("hit_rate"), name("hits"), name("reads"), "hits / reads", "ratio");
}

}  // namespace tpsim::timing
