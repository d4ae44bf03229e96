#include "sim/timing/dram.hpp"
#include "sim/timing/global_registers.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

using namespace tpsim::timing;

namespace {

constexpr uint32_t kLine = 64;

DramConfig one_channel() {
    DramConfig c;  // trax timings: tRCD 12, tCL 12, tRP 12, tRAS 28, tBURST 2, tRTP 4
    c.channels = 1;
    c.banks = 2;
    c.row_bytes = 512;
    return c;
}

// Sends one read at `at` (after ticking up to it) and returns its reply cycle.
uint64_t read_latency(Dram& dram, uint64_t& now, uint64_t at, uint32_t addr) {
    for (; now < at; ++now)
        dram.tick(now);
    REQUIRE(dram.enqueue(now, {addr, 0, 0, false}));
    MemReply reply;
    for (;; ++now) {
        dram.tick(now);
        if (dram.pop_reply(now, reply)) return now - at;
        REQUIRE(now < at + 1000);
    }
}

}  // namespace

TEST_CASE("address mapping is row:bank:channel:column", "[dram]") {
    DramConfig c;
    c.channels = 4;
    c.banks = 8;
    c.row_bytes = 1024;
    Dram dram(c, kLine);
    const uint32_t addr = (5u * 8 * 4 + 3u * 4 + 2u) * 1024 + 200;  // row 5, bank 3, channel 2
    const DramLocation at = dram.locate(addr);
    CHECK(at.channel == 2);
    CHECK(at.bank == 3);
    CHECK(at.row == 5);
    CHECK(at.column == 200);
}

TEST_CASE("row miss, row hit and row conflict latencies follow the timing table", "[dram]") {
    const DramConfig c = one_channel();
    Dram dram(c, kLine);
    uint64_t now = 0;
    // Bank 0 closed: ACT, tRCD, RD, tCL, burst.
    CHECK(read_latency(dram, now, 0, 0x000) == c.tRCD + c.tCL + c.tBURST);
    // Same row, long after: RD only.
    CHECK(read_latency(dram, now, 100, 0x040) == c.tCL + c.tBURST);
    // Row 1 of bank 0 (chunk 2): PRE, tRP, ACT, tRCD, RD.
    CHECK(read_latency(dram, now, 200, 2 * c.row_bytes) == c.tRP + c.tRCD + c.tCL + c.tBURST);
    // A conflict right after the activate waits for tRAS before the precharge.
    const uint64_t activated = 200 + c.tRP;
    const uint64_t latency = read_latency(dram, now, activated + 1, 0);
    CHECK(activated + 1 + latency == activated + c.tRAS + c.tRP + c.tRCD + c.tCL + c.tBURST);
    const auto& k = dram.counters();
    CHECK(k.row_misses == 1);
    CHECK(k.row_hits == 1);
    CHECK(k.row_conflicts == 2);
    CHECK(k.activates == 3);
    CHECK(k.bytes_read == 4 * kLine);
}

TEST_CASE("FR-FCFS serves a younger row hit before an older row conflict", "[dram]") {
    const DramConfig c = one_channel();
    Dram dram(c, kLine);
    uint64_t now = 0;
    read_latency(dram, now, 0, 0x000);                           // opens row 0 of bank 0
    REQUIRE(dram.enqueue(now, {2 * c.row_bytes, 0, 1, false}));  // older, conflicts
    REQUIRE(dram.enqueue(now, {0x080, 0, 2, false}));            // younger, hits
    std::vector<uint32_t> order;
    MemReply reply;
    for (uint64_t end = now + 200; now < end; ++now) {
        dram.tick(now);
        while (dram.pop_reply(now, reply))
            order.push_back(reply.request.tag);
    }
    CHECK(order == std::vector<uint32_t>{2, 1});
}

TEST_CASE("a streaming pattern reaches the configured bandwidth and no more", "[dram]") {
    DramConfig c;  // trax: 2048 B rows, 16 banks, tBURST = tCCD = 2
    c.channels = 2;
    Dram dram(c, kLine);
    const double peak = double(c.channels) * kLine / std::max(c.tBURST, c.tCCD);  // B/cycle
    uint32_t next_addr = 0;
    MemReply reply;
    uint64_t bytes = 0;
    const uint64_t cycles = 20000;
    for (uint64_t now = 0; now < cycles; ++now) {
        while (dram.can_accept(next_addr)) {
            REQUIRE(dram.enqueue(now, {next_addr, 0, 0, false}));
            next_addr += kLine;
        }
        dram.tick(now);
        while (dram.pop_reply(now, reply))
            bytes += kLine;
    }
    const double achieved = double(bytes) / cycles;
    CHECK(achieved <= peak);
    CHECK(achieved >= 0.9 * peak);
    CHECK(dram.counters().bus_busy_cycles <= cycles * c.channels);
    CHECK(dram.counters().row_hits > 20 * dram.counters().activates);
}

TEST_CASE("writes use the bus, need no reply, and full queues refuse requests", "[dram]") {
    DramConfig c = one_channel();
    c.queue_depth = 2;
    Dram dram(c, kLine);
    CHECK(dram.enqueue(0, {0x000, 0, 0, true}));
    CHECK(dram.enqueue(0, {0x040, 0, 0, true}));
    CHECK_FALSE(dram.enqueue(0, {0x080, 0, 0, true}));
    for (uint64_t now = 0; now < 100; ++now)
        dram.tick(now);
    MemReply reply;
    CHECK_FALSE(dram.pop_reply(100, reply));
    CHECK(dram.idle());
    CHECK(dram.counters().writes == 2);
    CHECK(dram.counters().bytes_written == 2 * kLine);
    CHECK(dram.counters().queue_full == 1);
}

TEST_CASE("DRAM is deterministic for a fixed request pattern", "[dram][determinism]") {
    auto run = [] {
        DramConfig c = one_channel();
        c.channels = 2;
        c.banks = 4;
        Dram dram(c, kLine);
        std::vector<std::pair<uint64_t, uint32_t>> replies;
        uint32_t lcg = 12345;
        MemReply reply;
        for (uint64_t now = 0; now < 5000; ++now) {
            lcg = lcg * 1664525u + 1013904223u;
            const uint32_t addr = (lcg >> 8) % (1u << 16) & ~(kLine - 1);
            if (now % 3 == 0) dram.enqueue(now, {addr, 0, uint32_t(now), (lcg & 1) != 0});
            dram.tick(now);
            while (dram.pop_reply(now, reply))
                replies.emplace_back(reply.ready, reply.request.tag);
        }
        return replies;
    };
    const auto first = run();
    CHECK(first.size() > 100);
    CHECK(first == run());
}

TEST_CASE("global registers serve in (arrival, TM, sequence) order with fixed latency",
          "[atomic]") {
    GlobalRegisterConfig c;  // latency 4, one per cycle, link 2
    GlobalRegisterUnit unit(c);
    // Submitted in host order TM 3 first; TM 1 must still be served first.
    unit.submit({10, 3, 0, 7, 0});
    unit.submit({10, 1, 1, 5, 0});
    unit.submit({10, 1, 0, 4, 0});
    std::vector<std::pair<uint64_t, uint32_t>> got;
    AtomicReply reply;
    for (uint64_t now = 0; now < 40; ++now) {
        unit.tick(now);
        while (unit.pop_reply(now, reply))
            got.emplace_back(reply.ready, reply.request.tp);
    }
    const uint64_t first = 10 + c.link_latency + c.latency + c.link_latency;
    CHECK(got ==
          std::vector<std::pair<uint64_t, uint32_t>>{{first, 4}, {first + 1, 5}, {first + 2, 7}});
    CHECK(unit.counters().queued_cycles == 0 + 1 + 2);
    CHECK(unit.idle());
}
