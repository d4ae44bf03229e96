#include "sim/timing/icache.hpp"

#include <catch2/catch.hpp>

using namespace tpsim::timing;

namespace {

// 8 sets x 2 ways x 64 B, 2 banks, 3-cycle hits, 2 MSHRs.
const CacheConfig kSmall{1024, 2, 64, 2, 3, 2};
constexpr uint32_t kSetStride = 8 * 64;  // addresses this far apart share a set

MemRequest load(uint32_t addr, uint32_t tag = 0) {
    return {addr, 0, tag, false};
}
MemRequest store(uint32_t addr) {
    return {addr, 0, 0, true};
}

// Fake next level: answers every outbound read `latency` cycles after it becomes visible.
void serve_next_level(Cache& cache, uint32_t latency) {
    while (!cache.outbound().empty()) {
        const OutboundRequest out = cache.outbound().front();
        cache.outbound().pop_front();
        if (!out.request.write) cache.fill(out.cycle + latency, out.request.addr);
    }
}

uint64_t reply_cycle(Cache& cache, uint64_t from) {
    MemReply reply;
    for (uint64_t t = from; t < from + 1000; ++t)
        if (cache.pop_reply(t, reply)) return t;
    return 0;
}

}  // namespace

TEST_CASE("a cache returns a hit after the configured latency", "[cache]") {
    Cache cache(kSmall);
    cache.fill(0, 0x100);
    REQUIRE(cache.access(10, load(0x104, 7)) == CacheOutcome::Hit);
    MemReply reply;
    CHECK_FALSE(cache.pop_reply(12, reply));
    REQUIRE(cache.pop_reply(13, reply));
    CHECK(reply.ready == 13);
    CHECK(reply.request.tag == 7);
    CHECK(cache.counters().hits == 1);
}

TEST_CASE("a miss goes to the next level and returns after its latency plus two lookups",
          "[cache]") {
    Cache cache(kSmall);
    REQUIRE(cache.access(0, load(0x1234)) == CacheOutcome::Miss);
    REQUIRE(cache.outbound().size() == 1);
    CHECK(cache.outbound().front().cycle == 3);              // after the tag lookup
    CHECK(cache.outbound().front().request.addr == 0x1200);  // whole line
    serve_next_level(cache, 20);
    CHECK(reply_cycle(cache, 0) == 3 + 20 + 3);  // lookup, next level, fill-to-use
    CHECK(cache.contains(0x1200));
    CHECK(cache.counters().misses == 1);
}

TEST_CASE("MSHRs merge misses to one line and limit distinct outstanding lines", "[cache]") {
    Cache cache(kSmall);
    CHECK(cache.access(0, load(0x000, 1)) == CacheOutcome::Miss);
    CHECK(cache.access(1, load(0x008, 2)) == CacheOutcome::MergedMiss);
    CHECK(cache.access(2, load(0x040, 3)) == CacheOutcome::Miss);  // second MSHR
    CHECK(cache.access(3, load(0x080, 4)) == CacheOutcome::MshrFull);
    CHECK(cache.access(4, load(0x030, 5)) == CacheOutcome::MergedMiss);  // merging needs none
    CHECK(cache.outbound().size() == 2);
    CHECK(cache.outstanding_misses() == 2);
    cache.fill(50, 0x000);
    MemReply reply;
    int woken = 0;
    while (cache.pop_reply(53, reply)) {
        ++woken;
        CHECK(reply.ready == 53);
    }
    CHECK(woken == 3);                                           // tags 1, 2 and 5
    CHECK(cache.access(54, load(0x080)) == CacheOutcome::Miss);  // MSHR freed
    const auto& c = cache.counters();
    CHECK(c.misses == 3);
    CHECK(c.merged_misses == 2);
    CHECK(c.mshr_full == 1);
    CHECK(c.reads == c.hits + c.misses + c.merged_misses);
}

TEST_CASE("one access per bank per cycle; conflicts are counted and change nothing", "[cache]") {
    Cache cache(kSmall);
    cache.fill(0, 0x000);  // bank 0
    cache.fill(0, 0x040);  // bank 1
    CHECK(cache.bank_of(0x000) != cache.bank_of(0x040));
    CHECK(cache.access(5, load(0x000)) == CacheOutcome::Hit);
    CHECK(cache.access(5, load(0x080)) == CacheOutcome::BankConflict);  // bank 0 again
    CHECK(cache.access(5, load(0x040)) == CacheOutcome::Hit);           // bank 1 is free
    CHECK(cache.access(6, load(0x080)) == CacheOutcome::Miss);          // next cycle
    CHECK(cache.counters().bank_conflicts == 1);
    CHECK(cache.counters().reads == 3);
}

TEST_CASE("LRU evicts the least recently used way", "[cache]") {
    Cache cache(kSmall);
    const uint32_t a = 0, b = kSetStride, c = 2 * kSetStride;
    cache.fill(0, a);
    cache.fill(1, b);
    CHECK(cache.access(2, load(a)) == CacheOutcome::Hit);  // a is now most recent
    cache.fill(3, c);
    CHECK(cache.contains(a));
    CHECK_FALSE(cache.contains(b));
    CHECK(cache.contains(c));
    CHECK(cache.counters().evictions == 1);
}

TEST_CASE("stores are write-around: forwarded, never allocated, no reply", "[cache]") {
    Cache cache(kSmall);
    CHECK(cache.access(0, store(0x200)) == CacheOutcome::WriteForward);
    CHECK_FALSE(cache.contains(0x200));
    REQUIRE(cache.outbound().size() == 1);
    CHECK(cache.outbound().front().request.write);
    CHECK(cache.outbound().front().request.addr == 0x200);
    cache.fill(1, 0x300);
    CHECK(cache.access(2, store(0x300)) == CacheOutcome::WriteForward);
    CHECK(cache.contains(0x300));
    MemReply reply;
    CHECK_FALSE(cache.pop_reply(100, reply));
    CHECK(cache.counters().writes == 2);
}

TEST_CASE("I-cache banks: one address per bank per cycle, shared addresses broadcast", "[icache]") {
    ICacheBanks icache(ICacheConfig{16, 4}, 32);
    auto fetch = [&](uint64_t now, uint32_t tp, uint32_t pc) {
        const auto tp_of = [&](uint32_t) { return tp; };
        return icache.fetch(now, 1, tp_of, [&](uint32_t) { return pc; }) == 1;
    };
    CHECK(fetch(0, 0, 0x1000));
    CHECK(fetch(0, 1, 0x1000));        // same address: broadcast
    CHECK_FALSE(fetch(0, 2, 0x1010));  // same bank (word 4 % 4), other address
    CHECK(fetch(0, 3, 0x1004));        // other bank
    CHECK(fetch(0, 16, 0x1010));       // thread 16 uses the second I-cache
    CHECK(fetch(1, 2, 0x1010));        // next cycle
    CHECK(icache.counters().conflicts == 1);
    CHECK(icache.counters().fetches == 5);
}

TEST_CASE("I-cache banks: a set of threads fetches lowest bit first", "[icache]") {
    ICacheBanks icache(ICacheConfig{16, 4}, 32);
    // Threads 4..7 all want bank 0; 4 and 6 the same address: 4 wins, 6 shares it.
    const uint32_t pcs[] = {0x1000, 0x1010, 0x1000, 0x1020};
    const uint64_t granted = icache.fetch(
        0, 0b1111, [](uint32_t bit) { return 4 + bit; },
        [&](uint32_t thread) { return pcs[thread - 4]; });
    CHECK(granted == 0b0101);
    CHECK(icache.counters().fetches == 2);
    CHECK(icache.counters().conflicts == 2);
}

TEST_CASE("write-combining merges stores to a line into one line write", "[cache]") {
    Cache cache(kSmall, 2);  // two lines of 64 B
    const auto store_of = [](uint32_t addr, uint16_t bytes) {
        MemRequest s = store(addr);
        s.bytes = bytes;
        return s;
    };
    uint64_t now = 0;
    // Line 0x000 written in 16 word stores (alternating banks keep them one per cycle): only
    // the last one sends it on, as one write of all 64 bytes.
    for (uint32_t b = 0; b < 64; b += 4) {
        CHECK(cache.outbound().empty());
        REQUIRE(cache.access(now++, store_of(b, 4)) == CacheOutcome::WriteCombined);
    }
    REQUIRE(cache.outbound().size() == 1);
    CHECK(cache.outbound().front().request.addr == 0x000);
    CHECK(cache.outbound().front().request.bytes == 64);
    CHECK(cache.outbound().front().request.write);
    cache.outbound().clear();
    // Rewriting bytes adds none; a third line evicts the oldest, partly written one.
    REQUIRE(cache.access(now++, store_of(0x100, 4)) == CacheOutcome::WriteCombined);
    REQUIRE(cache.access(now++, store_of(0x100, 4)) == CacheOutcome::WriteCombined);
    REQUIRE(cache.access(now++, store_of(0x248, 8)) == CacheOutcome::WriteCombined);
    CHECK(cache.outbound().empty());
    REQUIRE(cache.access(now++, store_of(0x3c0, 2)) == CacheOutcome::WriteCombined);
    REQUIRE(cache.outbound().size() == 1);
    CHECK(cache.outbound().front().request.addr == 0x100);
    CHECK(cache.outbound().front().request.bytes == 4);
    cache.outbound().clear();
    // A load miss to a buffered line sends the line's stores on before the line request.
    REQUIRE(cache.access(now++, load(0x240)) == CacheOutcome::Miss);
    REQUIRE(cache.outbound().size() == 2);
    CHECK(cache.outbound()[0].request.write);
    CHECK(cache.outbound()[0].request.addr == 0x240);
    CHECK(cache.outbound()[0].request.bytes == 8);
    CHECK_FALSE(cache.outbound()[1].request.write);
    cache.outbound().clear();
    // The end of the run drains what is left.
    CHECK(cache.holds_combined_lines());
    CHECK(cache.drain_write_buffer(now));
    REQUIRE(cache.outbound().size() == 1);
    CHECK(cache.outbound().front().request.addr == 0x3c0);
    CHECK(cache.outbound().front().request.bytes == 2);
    CHECK_FALSE(cache.holds_combined_lines());
    CHECK_FALSE(cache.drain_write_buffer(now));
}

TEST_CASE("warming leaves the tags and LRU order of the accesses, without counting them",
          "[cache][sampling]") {
    Cache cache(kSmall);
    CHECK_FALSE(cache.warm(0x100, false));  // a load misses and installs its line at once
    CHECK(cache.contains(0x100));
    CHECK(cache.warm(0x104, false));       // the same line now hits
    CHECK_FALSE(cache.warm(0x800, true));  // a store goes around: no line
    CHECK_FALSE(cache.contains(0x800));
    // LRU as access/fill keep it: of two lines in a set, the one touched last stays.
    cache.warm(0x100 + kSetStride, false);
    cache.warm(0x100, false);
    cache.warm(0x100 + 2 * kSetStride, false);
    CHECK(cache.contains(0x100));
    CHECK_FALSE(cache.contains(0x100 + kSetStride));
    CHECK(cache.counters().reads == 0);
    CHECK(cache.counters().evictions == 0);
    // The cycle-level model finds the warmed line.
    CHECK(cache.access(0, load(0x100)) == CacheOutcome::Hit);
}
