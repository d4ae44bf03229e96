// Validation of the chip model on real programs (programs/*.S, cross-compiled at build time)
// executed by the functional machine: measured latencies and throughputs must equal the ones
// the configuration implies. Latencies come from two builds of one program that differ only
// by 64 extra dependent steps, so the cycle difference is 64 x the per-step latency.
#include "sim/core/elf_loader.hpp"
#include "sim/timing/machine_source.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <cstring>
#include <memory>
#include <string>

using namespace tpsim;
using namespace tpsim::timing;

namespace {

constexpr uint32_t kGlobalBase = 0x1000'0000;
constexpr uint32_t kGlobalBytes = 1 << 20;

/// One program run to completion on the chip, with its statistics registered.
struct ProgramRun {
    std::unique_ptr<core::Machine> machine;
    std::unique_ptr<MachineSource> source;
    std::unique_ptr<Chip> chip;
    stats::Registry stats;

    uint64_t stat(std::string_view name) const { return stats.at(name).integer(); }
    uint64_t cycles() const { return chip->cycles(); }
};

/// Runs programs/<name>.elf; `fill_global` may set up global memory first.
std::unique_ptr<ProgramRun> run_program(const std::string& name, const ChipConfig& config,
                                        void (*fill_global)(uint8_t* global) = nullptr) {
    core::MachineConfig machine_config = machine_config_for(config);
    machine_config.global_bytes = kGlobalBytes;
    auto run = std::make_unique<ProgramRun>();
    run->machine = std::make_unique<core::Machine>(
        core::load_elf(std::string(TPSIM_TIMING_PROGRAMS) + "/" + name + ".elf"), machine_config);
    if (fill_global) fill_global(run->machine->memory().global().data());
    run->source = std::make_unique<MachineSource>(*run->machine);
    run->chip = std::make_unique<Chip>(config, *run->source);
    run->chip->register_stats(run->stats);
    run->chip->run(10'000'000);
    return run;
}

void put_word(uint8_t* global, uint32_t addr, uint32_t value) {
    std::memcpy(global + (addr - kGlobalBase), &value, 4);
}

ChipConfig tiny(uint32_t tps = 1) {
    ChipConfig c = load_config(TPSIM_CONFIG_DIR "/tiny.toml");
    c.chip.tps_per_tm = tps;
    c.icache.threads_per_icache = tps;
    return c;
}

/// Cycles of the 128-step build minus the 64-step build of `program`.
uint64_t extra_cycles_for_64_steps(const std::string& program, const ChipConfig& c,
                                   void (*fill_global)(uint8_t*) = nullptr) {
    const uint64_t short_run = run_program(program + "_64", c, fill_global)->cycles();
    const uint64_t long_run = run_program(program + "_128", c, fill_global)->cycles();
    REQUIRE(long_run > short_run);
    return long_run - short_run;
}

// Chains for chase.S. Word 0 holds the first address.
constexpr uint32_t kChainBase = kGlobalBase + 0x1'0000;

void self_loop(uint8_t* g) {  // one word pointing at itself: every load after the first hits L1
    put_word(g, kGlobalBase, kChainBase);
    put_word(g, kChainBase, kChainBase);
}

// A ring of 32 consecutive lines: 2 KiB, twice tiny's L1 (1 KiB, 2 ways x 8 sets, cycled in
// LRU order: always a miss) and half its L2 (4 KiB, 4 ways x 16 sets: two lines per set, so
// after the first lap always a hit).
void l2_ring(uint8_t* g) {
    put_word(g, kGlobalBase, kChainBase);
    for (uint32_t i = 0; i < 32; ++i)
        put_word(g, kChainBase + 64 * i, kChainBase + 64 * ((i + 1) % 32));
}

// 130 lines one DRAM row-interleave period apart (row_bytes x channels x banks = 1 KiB on
// tiny): every load is a new line (L1 and L2 miss) in the same bank but another row (conflict).
void dram_conflicts(uint8_t* g) {
    const ChipConfig c = tiny();
    const uint32_t stride = c.dram.row_bytes * c.dram.channels * c.dram.banks;
    put_word(g, kGlobalBase, kChainBase);
    for (uint32_t i = 0; i < 130; ++i)
        put_word(g, kChainBase + stride * i, kChainBase + stride * (i + 1));
}

}  // namespace

TEST_CASE("pointer chase: L1-hit load-to-use latency is the LSU plus L1 hit latency",
          "[validation]") {
    for (auto [lsu, hit] : {std::pair{1u, 1u}, std::pair{2u, 3u}}) {
        ChipConfig c = tiny();
        c.fu.load_store.latency = lsu;
        c.l1.hit_latency = hit;
        CHECK(extra_cycles_for_64_steps("chase", c, self_loop) == 64 * (lsu + hit));
    }
}

TEST_CASE("pointer chase: L2-hit latency adds the L2 hit latency and the L1 fill", "[validation]") {
    for (uint32_t l2_hit : {4u, 9u}) {
        ChipConfig c = tiny();
        c.l2.hit_latency = l2_hit;
        CHECK(extra_cycles_for_64_steps("chase", c, l2_ring) ==
              64 * (c.fu.load_store.latency + 2 * c.l1.hit_latency + l2_hit));
    }
    const auto run = run_program("chase_128", tiny(), l2_ring);
    CHECK(run->stat("tm0/l1/hits") == 0);
    CHECK(run->stat("l2/0/misses") == 32 + 1);  // the first lap and word 0
}

TEST_CASE("pointer chase: DRAM row conflicts cost precharge, activate, CAS and burst",
          "[validation]") {
    const ChipConfig c = tiny();
    const DramConfig& d = c.dram;
    const uint64_t per_step = c.fu.load_store.latency + 2 * c.l1.hit_latency +
                              2 * c.l2.hit_latency + d.tRP + d.tRCD + d.tCL + d.tBURST;
    // The bank must be free to precharge when the next request arrives, or tRAS would add.
    REQUIRE(per_step >= d.tRP + d.tRAS);
    CHECK(extra_cycles_for_64_steps("chase", c, dram_conflicts) == 64 * per_step);
    const auto short_run = run_program("chase_64", c, dram_conflicts);
    const auto long_run = run_program("chase_128", c, dram_conflicts);
    CHECK(long_run->stat("dram/row_conflicts") - short_run->stat("dram/row_conflicts") == 64);
    CHECK(long_run->stat("dram/row_hits") == short_run->stat("dram/row_hits"));
}

TEST_CASE("dependency chains take each unit's configured latency per step", "[validation]") {
    ChipConfig c = tiny();
    c.fu.int_alu.latency = 1;
    c.fu.int_muldiv.latency = 4;
    c.fu.fp_add.latency = 3;
    c.fu.fp_mul.latency = 5;
    c.fu.fp_divsqrt.latency = 11;
    c.fu.fp_misc.latency = 2;
    const std::pair<const char*, uint32_t> chains[] = {
        {"chain_add", 1},   {"chain_mul", 4},    {"chain_fadd", 3}, {"chain_fmul", 5},
        {"chain_fdiv", 11}, {"chain_fsqrt", 11}, {"chain_fmin", 2}};
    for (auto [program, latency] : chains) {
        INFO(program);
        CHECK(extra_cycles_for_64_steps(program, c) == 64 * latency);
    }
}

TEST_CASE("N threads contending for K units get K operations per cycle", "[validation]") {
    SECTION("pipelined: 8 threads, 2 FP multipliers") {
        ChipConfig c = tiny(8);
        c.icache.banks = 64;  // no fetch conflicts: the pool alone limits the rate
        c.fu.fp_mul = {2, 2, true};
        CHECK(extra_cycles_for_64_steps("independent_fmul", c) == 64 * 8 / 2);
        CHECK(run_program("independent_fmul_64", c)->stat("tm0/fu/fp_mul/denied") > 0);
    }
    SECTION("not pipelined: 4 threads, 1 divider busy 16 cycles per operation") {
        ChipConfig c = tiny(4);
        c.icache.banks = 64;
        c.fu.fp_divsqrt = {1, 16, false};
        CHECK(extra_cycles_for_64_steps("independent_fdiv", c) == 64 * 4 * 16);
    }
    SECTION("not pipelined: 4 threads, 2 dividers") {
        ChipConfig c = tiny(4);
        c.icache.banks = 64;
        c.fu.fp_divsqrt = {2, 16, false};
        CHECK(extra_cycles_for_64_steps("independent_fdiv", c) == 64 * 4 * 16 / 2);
    }
}

TEST_CASE("loads of one line merge in an MSHR; loads of one bank conflict", "[validation]") {
    const ChipConfig c = tiny(4);  // 2 L1 banks, 2 load/store units
    const auto merged = run_program("same_line", c);
    CHECK(merged->stat("tm0/l1/reads") == 4);
    CHECK(merged->stat("tm0/l1/misses") == 1);
    CHECK(merged->stat("tm0/l1/merged_misses") == 3);
    CHECK(merged->stat("dram/reads") == 1);

    CHECK(run_program("same_bank", c)->stat("tm0/l1/bank_conflicts") > 0);
    CHECK(run_program("next_lines", c)->stat("tm0/l1/bank_conflicts") == 0);
}

TEST_CASE("a streaming kernel saturates the DRAM bandwidth and no more", "[validation]") {
    for (uint32_t channels : {1u, 2u}) {
        ChipConfig c = tiny(8);
        c.dram.channels = channels;
        c.dram.row_bytes = 4096;
        c.dram.queue_depth = 64;
        c.l1.mshrs = 64;
        c.l2.mshrs = 64;
        c.l2.banks = 8;
        const auto run = run_program("stream", c);
        const double peak =
            double(channels) * c.l2.line_bytes / std::max(c.dram.tBURST, c.dram.tCCD);  // B/cycle
        const double achieved = run->stats.value("chip/dram/bandwidth_bytes_per_cycle");
        INFO("channels " << channels << ": " << achieved << " of " << peak << " B/cycle");
        CHECK(run->stat("dram/bytes_read") == 2048 * 64);
        CHECK(run->stat("dram/bus_busy_cycles") <= run->cycles() * channels);
        CHECK(achieved <= peak);
        CHECK(achieved >= 0.8 * peak);
    }
}

TEST_CASE("rdcycle reads the chip's cycle in timing mode and instret without a timing model",
          "[validation]") {
    constexpr uint64_t kSteps = 64;  // fdiv.s in the guest's timed chain (-DSTEPS)
    ChipConfig c = tiny();
    c.fu.fp_divsqrt.latency = 11;
    // A dependent chain of N steps of latency L takes N x L cycles; the reads themselves, the
    // first fdiv's issue and the fmv that waits for the result add a couple of cycles.
    auto timed = run_program("rdcycle_fdiv", c);
    const auto guest_cycles = uint64_t(timed->machine->thread(0).exit_code);
    CHECK(guest_cycles >= kSteps * 11);
    CHECK(guest_cycles <= kSteps * 11 + 4);

    // Functionally every instruction is one cycle: the second read sees the first read, the
    // chain and the fmv retired.
    core::MachineConfig functional = machine_config_for(c);
    functional.global_bytes = kGlobalBytes;
    core::Machine machine(core::load_elf(std::string(TPSIM_TIMING_PROGRAMS) + "/rdcycle_fdiv.elf"),
                          functional);
    machine.run();
    CHECK(uint64_t(machine.thread(0).exit_code) == kSteps + 2);
}

namespace {

/// tiny with `tps` threads and a finite I-cache of 1 KiB (2 ways x 8 sets of 64-byte lines) per
/// `per_icache` threads; the I-cache's line is the L1's.
ChipConfig finite_icache(uint32_t tps, uint32_t per_icache) {
    ChipConfig c = tiny(tps);
    c.icache.threads_per_icache = per_icache;
    c.icache.size_bytes = 1024;
    c.icache.ways = 2;
    c.icache.line_bytes = c.l1.line_bytes;
    validate(c);
    return c;
}

}  // namespace

TEST_CASE("a loop larger than the I-cache misses on every line of every lap", "[validation]") {
    // icache_thrash_<laps>: line 0, then 32 loop lines per lap, then the epilogue's line. Each
    // of the 8 sets holds 2 of the loop's 4 lines mapping to it, fetched in cyclic order: LRU
    // always evicts the next one needed. Each of the 4 threads has its own I-cache.
    for (uint32_t laps : {2u, 3u}) {
        INFO(laps << " laps");
        const auto run = run_program(fmt::format("icache_thrash_{}", laps), finite_icache(4, 1));
        const uint64_t per_thread = 1 + 32 * laps + 1;
        CHECK(run->stat("tm0/icache/misses") == 4 * per_thread);
        CHECK(run->stat("tm0/icache/merged_misses") == 0);
        CHECK(run->stat("chip/icache/misses") == 4 * per_thread);
        // Every miss is one line request to the L2; the 34 lines come from DRAM once (the L2
        // holds them all).
        CHECK(run->stat("region/instruction_fetch/l2/reads") == 4 * per_thread);
        CHECK(run->stat("region/instruction_fetch/dram/reads") == 34);
        CHECK(run->stat("chip/stalls/fetch_miss") > 0);
        // Every TP-cycle is an issue or one stall, the waits for lines included.
        uint64_t stalls = 0;
        for (const char* cause : {"fetch_conflict", "branch", "fu_busy", "memory_port", "operand",
                                  "sync", "fetch_miss"})
            stalls += run->stat(fmt::format("chip/stalls/{}", cause));
        CHECK(run->stat("chip/active_tp_cycles") == run->stat("chip/instructions") + stalls);
    }
}

TEST_CASE("a loop that fits the I-cache misses once per line, however many threads share it",
          "[validation]") {
    // icache_fits_<laps>: line 0, 8 loop lines (one per set; line 0 and the epilogue's line
    // share a set with one of them, 2 ways), the epilogue's line: 10 cold misses in all.
    for (uint32_t laps : {2u, 3u}) {
        INFO(laps << " laps");
        const auto shared = run_program(fmt::format("icache_fits_{}", laps), finite_icache(4, 4));
        CHECK(shared->stat("tm0/icache/misses") == 10);
        CHECK(shared->stat("tm0/icache/evictions") == 0);
        // The other three threads wait for the line the first one missed, or find it there.
        CHECK(shared->stat("tm0/icache/merged_misses") <= 3 * 10);
        CHECK(shared->stat("region/instruction_fetch/dram/reads") == 10);
        const auto own = run_program(fmt::format("icache_fits_{}", laps), finite_icache(4, 1));
        CHECK(own->stat("tm0/icache/misses") == 4 * 10);
    }
}

TEST_CASE("an I-cache miss that hits the L2 stalls the thread 2 + l2.hit_latency cycles",
          "[validation]") {
    // One thread: it fetches in cycle t and misses; its line request leaves the I-cache's
    // lookup at t + 1, the L2 hit returns it at t + 1 + l2.hit_latency, and it is forwarded to
    // the thread a cycle later. The third lap's 32 misses all hit the L2.
    const ChipConfig c = finite_icache(1, 1);
    const auto two = run_program("icache_thrash_2", c);
    const auto three = run_program("icache_thrash_3", c);
    const uint64_t per_miss = 2 + c.l2.hit_latency;
    CHECK(three->stat("chip/stalls/fetch_miss") - two->stat("chip/stalls/fetch_miss") ==
          32 * per_miss);
    // Without the I-cache's misses, the lap costs exactly that much less.
    ChipConfig never_misses = c;
    never_misses.icache.size_bytes = 0;
    const uint64_t lap = three->cycles() - two->cycles();
    const uint64_t lap_never_missing = run_program("icache_thrash_3", never_misses)->cycles() -
                                       run_program("icache_thrash_2", never_misses)->cycles();
    CHECK(lap == lap_never_missing + 32 * per_miss);
}
