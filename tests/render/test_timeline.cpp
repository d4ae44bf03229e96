// The timeline samples cumulative chip counters and reports per-interval rates.
#include "sim/render/timeline.hpp"

#include <catch2/catch.hpp>

#include <functional>

using namespace tpsim;

namespace {

/// The counters a Timeline reads, as a fake chip that issues `issue_per_cycle` instructions on
/// each of its threads and reads one L1 line per cycle (hitting every other cycle).
struct FakeChip {
    uint64_t instructions = 0, l1_hits = 0, l1_reads = 0, l2_hits = 0, l2_reads = 0;
    uint64_t dram_read = 0, dram_written = 0;
    uint32_t running;
    stats::Registry registry;
    explicit FakeChip(uint32_t threads) : running(threads) {
        registry.add_counter("chip/instructions", instructions, "");
        registry.add_counter("chip/l1/hits", l1_hits, "");
        registry.add_counter("chip/l1/reads", l1_reads, "");
        registry.add_counter("chip/l2/hits", l2_hits, "");
        registry.add_counter("chip/l2/reads", l2_reads, "");
        registry.add_counter("dram/bytes_read", dram_read, "");
        registry.add_counter("dram/bytes_written", dram_written, "");
    }
    std::function<uint64_t()> running_threads() {
        return [this] { return running; };
    }
    void tick(uint64_t cycle, uint32_t threads) {
        instructions += threads / 2;
        ++l1_reads;
        l1_hits += cycle % 2;
        dram_read += 64;
        running = threads;
    }
};

}  // namespace

TEST_CASE("a fixed-interval timeline reports the rates of each interval", "[render][timeline]") {
    FakeChip chip(4);
    render::Timeline timeline(chip.registry, 4, chip.running_threads(), 100);
    uint64_t cycle = 0;
    for (; cycle < 1050; ++cycle) {
        if (cycle == timeline.next_sample()) timeline.sample(cycle);
        chip.tick(cycle, 4);
    }
    chip.running = 1;        // three threads have exited by the end
    timeline.sample(cycle);  // the run's end, mid-interval
    const auto doc = timeline.json();
    CHECK(doc["interval_cycles"] == 100);
    const auto& rows = doc["rows"];
    REQUIRE(rows.size() == 11);
    CHECK(rows[0][0] == 100);
    CHECK(rows[10][0] == 1050);
    for (const auto& row : rows) {
        CHECK(row[1].get<double>() == Approx(0.5));   // 2 of 4 threads issue each cycle
        CHECK(row[2].get<double>() == Approx(0.5));   // every other read hits
        CHECK(row[3].dump() == "null");               // no L2 reads: no hit rate
        CHECK(row[4].get<double>() == Approx(64.0));  // B/cycle
    }
    CHECK(rows[9][5] == 4);  // threads running at each sample
    CHECK(rows[10][5] == 1);
}

TEST_CASE("an adaptive timeline keeps about 200 rows however long the run", "[render][timeline]") {
    for (uint64_t length : {5'000ull, 300'000ull, 3'000'000ull}) {
        FakeChip chip(2);
        render::Timeline timeline(chip.registry, 2, chip.running_threads());
        uint64_t cycle = 0;
        for (; cycle < length; ++cycle) {
            if (cycle == timeline.next_sample()) timeline.sample(cycle);
            chip.tick(cycle, 2);
        }
        timeline.sample(cycle);
        const auto doc = timeline.json();
        const auto& rows = doc["rows"];
        INFO(length);
        if (length / 1024 < render::Timeline::kTargetRows)
            CHECK(rows.size() == (length + 1023) / 1024);  // short runs: the first interval
        else
            CHECK((rows.size() >= render::Timeline::kTargetRows &&
                   rows.size() <= 2 * render::Timeline::kTargetRows + 1));
        CHECK(rows.back()[0] == length);
        uint64_t previous = 0;
        for (const auto& row : rows) {  // strictly increasing cycles, rates unchanged by merging
            CHECK(row[0].get<uint64_t>() > previous);
            previous = row[0].get<uint64_t>();
            CHECK(row[4].get<double>() == Approx(64.0));
        }
    }
}
