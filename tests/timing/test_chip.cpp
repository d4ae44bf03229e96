#include "sim/timing/chip.hpp"

#include <catch2/catch.hpp>

#include "tests/timing/documented_stats.hpp"
#include "tests/timing/small_chips.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <regex>
#include <sstream>
#include <stdexcept>

using namespace tpsim::timing;
using tpsim::isa::Decoded;
using tpsim::isa::Op;
namespace isa = tpsim::isa;
namespace stats = tpsim::stats;

namespace {

constexpr uint8_t x(uint8_t i) {
    return i;
}
constexpr uint8_t f(uint8_t i) {
    return isa::kFpBase + i;
}

// Fake functional core: a fixed instruction trace per thread.
class Script : public InstructionSource {
public:
    explicit Script(uint32_t threads) : trace_(threads), next_(threads, 0) {}

    Script& add(uint32_t thread, Op op, uint8_t rd, uint8_t rs1 = isa::kNoReg,
                uint8_t rs2 = isa::kNoReg, uint32_t mem_address = 0, bool taken = false) {
        const auto fu = isa::info(op).fu;
        decoded_.push_back({.op = op, .rd = rd, .rs1 = rs1, .rs2 = rs2, .fu = fu});
        StepInfo s;
        s.pc = 0x10000 + 4 * uint32_t(trace_[thread].size());
        s.insn = &decoded_.back();
        if (fu == isa::FuClass::Load || fu == isa::FuClass::Store) {
            s.mem_address = mem_address;
            s.mem_bytes = 4;
            s.mem_store = fu == isa::FuClass::Store;
        }
        s.taken = taken;
        trace_[thread].push_back(s);
        return *this;
    }
    // Ends every thread with an exiting instruction.
    Script& finish() {
        for (uint32_t t = 0; t < trace_.size(); ++t) {
            add(t, Op::ecall, isa::kNoReg);
            trace_[t].back().exited = true;
        }
        return *this;
    }
    uint32_t next_pc(uint32_t thread) const override { return trace_[thread][next_[thread]].pc; }
    void step(uint32_t thread, StepInfo& out) override { out = trace_[thread].at(next_[thread]++); }
    /// Instructions thread `thread` has executed.
    size_t steps(uint32_t thread) const { return next_[thread]; }

private:
    std::deque<Decoded> decoded_;  // stable addresses
    std::vector<std::vector<StepInfo>> trace_;
    std::vector<size_t> next_;
};

uint64_t stat(const stats::Registry& r, std::string_view name) {
    return r.at(name).integer();
}

}  // namespace

TEST_CASE("independent ALU instructions issue one per cycle", "[chip]") {
    Script s(1);
    for (int i = 0; i < 10; ++i)
        s.add(0, Op::add, x(5 + i % 3), x(1), x(2));
    s.finish();
    Chip chip(one_tp(), s);
    CHECK(chip.run() == 11);  // 10 adds + the exiting ecall, one per cycle
}

TEST_CASE("a dependent chain waits for the producing unit's latency", "[chip]") {
    ChipConfig c = one_tp();
    c.fu.fp_mul.latency = 3;
    Script s(1);
    const int n = 5;
    for (int i = 0; i < n; ++i)
        s.add(0, Op::fmul_s, f(1), f(1), f(2));  // f1 = f1 * f2
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    // Issues at 0, 3, 6, 9, 12; the ecall (no operands) at 13.
    CHECK(chip.run() == 3 * (n - 1) + 2);
    CHECK(stat(r, "tm0/stalls/operand_from/fp_mul") == uint64_t(2 * (n - 1)));
    CHECK(stat(r, "tm0/class/fp_mul") == uint64_t(n));
}

TEST_CASE("latencies and penalties longer than the sleep wheel are exact", "[chip]") {
    // A TP waiting for a known cycle sleeps in a wheel of at most 1024 slots; longer waits go
    // round it. Two TPs, so one sleeps while the other runs.
    ChipConfig c = one_tp();
    c.chip.tps_per_tm = 2;
    c.icache.threads_per_icache = 2;
    c.fu.fp_mul.latency = 5000;
    c.tp.branch_taken_penalty = 1000;
    Script s(2);
    for (int i = 0; i < 3; ++i)
        s.add(0, Op::fmul_s, f(1), f(1), f(2));  // f1 = f1 * f2
    s.add(1, Op::beq, isa::kNoReg, x(1), x(2), 0, true);
    s.add(1, Op::add, x(3), x(1), x(2));
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    // TP 0: fmuls at 0, 5000, 10000, its ecall at 10001. TP 1: beq at 0, add at 1001, ecall.
    CHECK(chip.run() == 2 * 5000 + 2);
    CHECK(stat(r, "tm0/stalls/operand_from/fp_mul") == 2 * 4999);
    CHECK(stat(r, "tm0/stalls/branch") == 1000);
    CHECK(stat(r, "tm0/instructions") == 3 + 1 + 2 + 1);
}

TEST_CASE("taken branches cost the configured penalty", "[chip]") {
    ChipConfig c = one_tp();
    c.tp.branch_taken_penalty = 3;
    c.tp.branch_not_taken_penalty = 1;
    Script s(1);
    s.add(0, Op::beq, isa::kNoReg, x(1), x(2), 0, true);
    s.add(0, Op::beq, isa::kNoReg, x(1), x(2), 0, false);
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    CHECK(chip.run() == 1 + 3 + 1 + 1 + 1);
    CHECK(stat(r, "tm0/stalls/branch") == 4);
}

TEST_CASE("TPs sharing one unit take turns; refusals are FU-busy stalls", "[chip]") {
    ChipConfig c = one_tp();
    c.chip.tps_per_tm = 4;
    c.fu.fp_add = {1, 1, true};
    Script s(4);
    const int n = 8;
    for (uint32_t t = 0; t < 4; ++t)
        for (int i = 0; i < n; ++i)
            s.add(t, Op::fadd_s, f(3 + i % 4), f(1), f(2));
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    const uint64_t cycles = chip.run();
    CHECK(cycles >= 4 * n);      // one fadd per cycle for the whole TM
    CHECK(cycles <= 4 * n + 4);  // plus the exits
    CHECK(stat(r, "tm0/fu/fp_add/issued") == 4 * n);
    CHECK(stat(r, "tm0/stalls/fu_busy") ==
          stat(r, "tm0/fu/fp_add/denied") + stat(r, "tm0/fu/int_alu/denied"));
}

TEST_CASE("a load miss costs L1, L2 and DRAM latencies; the next access to the line hits",
          "[chip]") {
    const ChipConfig c = one_tp();
    Script s(1);
    const uint32_t addr = 0x1000'0040;
    s.add(0, Op::lw, x(5), x(10), isa::kNoReg, addr);
    s.add(0, Op::add, x(6), x(5), x(5));  // needs the loaded value
    s.add(0, Op::lw, x(7), x(10), isa::kNoReg, addr + 4);
    s.add(0, Op::add, x(8), x(7), x(7));
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    chip.run();
    // lw issues at 0, reaches L1 after the LSU latency; the line comes back through L2 (lookup,
    // then fill-to-use) from a closed DRAM bank; the add issues the cycle the data arrives.
    const uint64_t miss = c.fu.load_store.latency + 2 * c.l1.hit_latency + 2 * c.l2.hit_latency +
                          c.dram.tRCD + c.dram.tCL + c.dram.tBURST;
    const uint64_t hit = c.fu.load_store.latency + c.l1.hit_latency;
    CHECK(chip.cycles() == miss + 1 + hit + 1 + 1);
    CHECK(stat(r, "tm0/l1/misses") == 1);
    CHECK(stat(r, "tm0/l1/hits") == 1);
    CHECK(stat(r, "l2/0/misses") == 1);
    CHECK(stat(r, "dram/row_misses") == 1);
}

TEST_CASE("the local store has its own latency and a high-water mark", "[chip]") {
    ChipConfig c = one_tp();
    c.tp.local_store_latency = 3;
    Script s(1);
    s.add(0, Op::sw, isa::kNoReg, x(2), x(5), 0x7FFF'FF00);
    s.add(0, Op::lw, x(6), x(2), isa::kNoReg, 0x7FFF'FFF0);
    s.add(0, Op::add, x(7), x(6), x(6));
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    // sw at 0, lw at 1, add at 1 + LSU latency + local-store latency, ecall after.
    CHECK(chip.run() == 1 + c.fu.load_store.latency + 3 + 2);
    CHECK(stat(r, "chip/local_store_high_water") == 0x100);
    CHECK(stat(r, "tm0/l1/reads") == 0);
}

TEST_CASE("atomics go through the global-register unit", "[chip]") {
    const ChipConfig c = one_tp();
    Script s(1);
    s.add(0, Op::tp_atominc, x(5));
    s.add(0, Op::add, x(6), x(5), x(5));
    s.finish();
    Chip chip(c, s);
    const auto& g = c.global_registers;
    CHECK(chip.run() == g.link_latency + g.latency + g.link_latency + 2);
}

namespace {

// Several TMs sharing one L2 and DRAM, every TP mixing loads, FP and branches.
std::string run_mixed() {
    ChipConfig c;
    c.chip.num_tms = 2;
    c.chip.tps_per_tm = 8;
    c.chip.tms_per_l2 = 2;
    Script s(16);
    for (uint32_t t = 0; t < 16; ++t)
        for (uint32_t i = 0; i < 40; ++i) {
            s.add(t, Op::flw, f(1), x(10), isa::kNoReg, 0x1000'0000 + 64 * ((t * 7 + i * 3) % 97));
            s.add(t, Op::fmul_s, f(2), f(1), f(1));
            s.add(t, Op::fdiv_s, f(3), f(2), f(1));
            s.add(t, Op::sw, isa::kNoReg, x(2), x(5), 0x1100'0000 + 4 * (t * 40 + i));
            s.add(t, Op::bne, isa::kNoReg, x(1), x(2), 0, i % 3 == 0);
        }
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    chip.run();
    CHECK(stat(r, "chip/instructions") == 16 * (40 * 5 + 1));
    // Every TP-cycle before exit either issued or stalled for exactly one cause.
    uint64_t stalls = 0;
    for (const char* cause : {"fetch_conflict", "branch", "fu_busy", "memory_port", "operand"})
        stalls += stat(r, std::string("chip/stalls/") + cause);
    CHECK(stat(r, "chip/active_tp_cycles") == stat(r, "chip/instructions") + stalls);
    CHECK(stat(r, "chip/l1/reads") == 16 * 40);
    CHECK(stat(r, "chip/l1/writes") == 16 * 40);
    CHECK(stat(r, "dram/writes") == 16 * 40);
    CHECK(stat(r, "dram/reads") <= 97);  // each line read from DRAM at most once
    std::ostringstream json;
    json << stats::values_json(stats::Snapshot(r)).dump(1);
    return json.str();
}

}  // namespace

TEST_CASE("identical inputs give identical statistics", "[chip][determinism]") {
    const std::string first = run_mixed();
    CHECK(first == run_mixed());
}

TEST_CASE("every registered key is documented in docs/statistics.md", "[chip][docs]") {
    const std::vector<std::regex> documented = documented_stat_patterns();
    REQUIRE(documented.size() > 20);
    ChipConfig c;
    c.chip.num_tms = 2;
    c.chip.tps_per_tm = 2;
    c.chip.tms_per_l2 = 1;
    Script s(4);
    s.finish();
    Chip chip(c, s);
    stats::Registry r;
    chip.register_stats(r);
    for (const stats::Entry& e : r.entries()) {
        const bool found =
            std::any_of(documented.begin(), documented.end(),
                        [&](const std::regex& re) { return std::regex_match(e.name, re); });
        INFO(e.name);
        CHECK(found);
    }
}

TEST_CASE("a fault in a private step is raised in its turn of the order (cycle, TM)",
          "[chip][parallel]") {
    // TM 1's thread steps privately and faults at its fifth instruction; TM 0's steps are not
    // private. The cycle loop may run TM 1's private steps ahead of TM 0's cycles, but its
    // fault is raised in its turn: both TMs fetch one instruction a cycle, so TM 0 has made
    // exactly five steps by then (its fifth in the same cycle, before TM 1), on any host
    // threads.
    struct FaultingScript : Script {
        using Script::Script;
        bool next_is_private(uint32_t thread) const override { return thread == 1; }
        void step(uint32_t thread, StepInfo& out) override {
            if (thread == 1 && steps(1) == 4) throw std::runtime_error("fault in thread 1");
            Script::step(thread, out);
        }
    };
    for (uint32_t host_threads : {1u, 2u}) {
        INFO("host threads " << host_threads);
        ChipConfig c = one_tp();
        c.chip.num_tms = 2;
        FaultingScript s(2);
        for (int i = 0; i < 1000; ++i)
            for (uint32_t t = 0; t < 2; ++t)
                s.add(t, Op::add, x(5 + i % 3), x(1), x(2));
        s.finish();
        Chip chip(c, s);
        chip.use_host_threads(host_threads);
        CHECK_THROWS_WITH(chip.run(), "fault in thread 1");
        CHECK(s.steps(0) == 5);
        CHECK(s.steps(1) == 4);
    }
}

TEST_CASE("TMs moved between host threads to balance their work give the same results",
          "[chip][parallel]") {
    // The steps of TMs 4-7 cost the host ~2 us each, those of TMs 0-3 nothing: the host thread
    // ticking TMs 4-7 is far busier, so the chip hands TMs to the other as it runs
    // (Chip::lane_moves). No step is private, so every step happens in its turn of the order
    // (cycle, TM): the order of the steps and every statistic are those of one host thread.
    struct SlowScript : Script {
        SlowScript(uint32_t threads, uint32_t slow_from) : Script(threads), slow_from(slow_from) {}
        void step(uint32_t thread, StepInfo& out) override {
            order.push_back(thread);
            if (thread >= slow_from) {
                const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(2);
                while (std::chrono::steady_clock::now() < until) {
                }
            }
            Script::step(thread, out);
        }
        uint32_t slow_from;
        std::vector<uint32_t> order;
    };
    const auto run = [](uint32_t host_threads, uint64_t& moves) {
        ChipConfig c = one_tp();
        c.chip.num_tms = 8;
        c.chip.tms_per_l2 = 4;
        SlowScript s(8, 4);
        for (uint32_t t = 0; t < 8; ++t)
            for (uint32_t i = 0; i < 8000; ++i)
                if (i % 8 == 0)  // loads from lines of their own: traffic to the L2s and DRAM
                    s.add(t, Op::lw, x(5 + i % 3), x(1), isa::kNoReg, 0x100000 * (t + 1) + 4 * i);
                else
                    s.add(t, Op::add, x(5 + i % 3), x(1), x(2));
        s.finish();
        Chip chip(c, s);
        stats::Registry r;
        chip.register_stats(r);
        chip.use_host_threads(host_threads);
        chip.run();
        moves = chip.lane_moves();
        std::ostringstream out;
        out << stats::values_json(stats::Snapshot(r)).dump(1) << '\n';
        for (uint32_t thread : s.order)
            out << thread << ' ';
        return out.str();
    };
    uint64_t moves = 0;
    const std::string one = run(1, moves);
    CHECK(moves == 0);
    CHECK(run(2, moves) == one);
    CHECK(moves > 0);
}
