#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "kernel/memory_map.hpp"
#include "sim/core/held_stores.hpp"
#include "sim/core/memory.hpp"

using namespace tpsim::core;
using trax::map::kGlobalBase;

namespace {

Program no_program() {
    Program p;
    p.name = "none";
    p.entry = trax::map::kCodeBase;
    p.segments.push_back(
        {trax::map::kCodeBase, 4, std::vector<uint8_t>(4, 0x13), true, false, true});
    return p;
}

uint32_t word_at(const Memory& m, uint32_t addr) {
    return m.load<uint32_t>(addr, nullptr);
}

}  // namespace

TEST_CASE("held stores are written in position order, up to the position asked", "[sim][held]") {
    Memory m(no_program(), {.global_bytes = 64, .local_store_bytes = 256, .threads = 1});
    HeldStores held(3);
    // Three producers store to one word; producer 1 twice at one position (kept in order).
    held.hold(2, {.position = 2, .address = kGlobalBase, .value = 20, .bytes = 4});
    held.hold(0, {.position = 3, .address = kGlobalBase, .value = 30, .bytes = 4});
    held.hold(1, {.position = 1, .address = kGlobalBase, .value = 10, .bytes = 4});
    held.hold(1, {.position = 4, .address = kGlobalBase, .value = 41, .bytes = 4});
    held.hold(1, {.position = 4, .address = kGlobalBase, .value = 42, .bytes = 4});
    held.hold(0, {.position = 6, .address = kGlobalBase + 5, .value = 0xABCD, .bytes = 1});
    CHECK(held.size() == 6);
    held.write_through(0, m);
    CHECK(word_at(m, kGlobalBase) == 0);
    held.write_through(2, m);
    CHECK(word_at(m, kGlobalBase) == 20);
    CHECK(held.size() == 4);
    held.write_through(4, m);
    CHECK(word_at(m, kGlobalBase) == 42);
    CHECK(word_at(m, kGlobalBase + 4) == 0);
    held.write_through(UINT64_MAX, m);
    CHECK(word_at(m, kGlobalBase + 4) == 0xCD00);  // one byte, the value's lowest
    CHECK(held.size() == 0);
}

TEST_CASE("a producer's held stores must not go back in the order", "[sim][held]") {
    HeldStores held(1);
    held.hold(0, {.position = 7, .address = kGlobalBase, .value = 1, .bytes = 4});
    CHECK_THROWS_AS(held.hold(0, {.position = 6, .address = kGlobalBase, .value = 2, .bytes = 4}),
                    std::logic_error);
}

TEST_CASE("held stores: producers on their own threads and a writer behind them give the "
          "sequential memory",
          "[sim][held][parallel]") {
    // Producer p holds the stores at positions i * kProducers + p, each to one of 16 words, its
    // value the position; the writer writes through the last position every producer has
    // passed, checking after each call that every word holds the last store before that bound.
    // Every 1,000 stores a producer waits for another write, so the two interleave.
    constexpr uint32_t kProducers = 4, kStores = 20'000, kWords = 16;
    constexpr uint64_t kTotal = uint64_t(kStores) * kProducers;
    Memory m(no_program(), {.global_bytes = kWords * 4, .local_store_bytes = 256, .threads = 1});
    HeldStores held(kProducers);
    std::vector<std::atomic<uint64_t>> passed(kProducers);  // its positions before this are held
    std::atomic<uint64_t> writes{0};
    const auto word_of = [](uint64_t position) { return uint32_t(position / kProducers % kWords); };
    std::vector<std::thread> producers;
    for (uint32_t p = 0; p < kProducers; ++p)
        producers.emplace_back([&, p] {
            for (uint64_t i = 0; i < kStores; ++i) {
                while (i % 1000 == 0 && writes.load() < i / 1000)
                    std::this_thread::yield();
                const uint64_t position = i * kProducers + p;
                held.hold(p, {.position = position,
                              .address = kGlobalBase + 4 * word_of(position),
                              .value = uint32_t(position),
                              .bytes = 4});
                passed[p].store(position + 1, std::memory_order_release);
            }
            passed[p].store(kTotal, std::memory_order_release);
        });
    uint64_t mismatches = 0;
    for (uint64_t bound = 0; bound < kTotal;) {
        uint64_t all = kTotal;  // every position before it is held
        for (const auto& at : passed)
            all = std::min(all, at.load(std::memory_order_acquire));
        if (all <= bound) continue;
        bound = all;
        held.write_through(bound - 1, m);
        writes.fetch_add(1);
        for (uint32_t w = 0; w < kWords; ++w) {
            uint64_t last = bound;  // the last position before `bound` that stores to word w
            while (last > 0 && word_of(last - 1) != w)
                --last;
            if (last > 0 && word_at(m, kGlobalBase + 4 * w) != uint32_t(last - 1)) ++mismatches;
        }
    }
    for (std::thread& t : producers)
        t.join();
    CHECK(mismatches == 0);
    CHECK(writes.load() >= kStores / 1000);
    CHECK(held.size() == 0);
}
