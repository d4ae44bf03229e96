#include <algorithm>
#include <chrono>
#include <cstring>
#include <ctime>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "isa/isa.hpp"
#include "kernel/memory_map.hpp"
#include "sim/core/error.hpp"
#include "sim/core/machine.hpp"
#include "tests/sim/test_support.hpp"

using namespace tpsim;
using namespace tpsim::core;
using tpsim::test::guest_program;

namespace {

Machine machine_for(const std::string& name, MachineConfig config = {}) {
    return Machine(load_elf(guest_program(name)), config);
}

uint32_t global_word(const Machine& m, uint32_t index) {
    uint32_t word;
    std::memcpy(&word, m.memory().global().data() + 4 * index, 4);
    return word;
}

uint32_t symbol_address(const Program& p, const std::string& name) {
    for (const Symbol& s : p.functions)
        if (s.name == name) return s.address;
    FAIL("no symbol " << name);
    return 0;
}

/// Runs the program and returns the fault message ("" if it exited normally).
std::string fault_message(Machine& m) {
    try {
        m.run();
    } catch (const Fault& f) {
        return f.what();
    }
    return "";
}

}  // namespace

TEST_CASE("instruction-class programs compute the expected results", "[sim][machine]") {
    // Each program exits with 0 when all of its checks pass, else with the failed check's number.
    for (const char* name :
         {"alu", "muldiv", "branch", "loadstore", "float", "calls", "csr", "trap", "spec_traps"}) {
        INFO("program " << name);
        Machine m = machine_for(name);
        m.run();
        CHECK(m.thread(0).state == ThreadState::Exited);
        CHECK(m.thread(0).exit_code == 0);
    }
}

TEST_CASE("the exit ecall ends the thread with a0", "[sim][machine]") {
    Machine m = machine_for("exit_code");
    m.run();
    CHECK(m.thread(0).exit_code == 42);
    CHECK(m.thread(0).exit_pc == m.program().entry + 8);
    // li a0; li a7; ecall
    CHECK(m.counters().instructions == 3);
    CHECK(m.counters().per_op[size_t(isa::Op::ecall)] == 1);
    CHECK(m.counters().per_op[size_t(isa::Op::addi)] == 2);
}

TEST_CASE("1024 threads each see their own ids and write them to global memory", "[sim][machine]") {
    constexpr uint32_t kThreads = 1024;
    Machine m = machine_for("hartid", {.threads = kThreads, .global_bytes = 8 * kThreads});
    m.run();
    for (uint32_t i = 0; i < kThreads; ++i) {
        INFO("thread " << i);
        REQUIRE(global_word(m, i) == i);
        REQUIRE(global_word(m, kThreads + i) == ((i / 32) << 16 | (i % 32)));
        REQUIRE(m.thread(i).exit_code == int32_t(i & 0xff));
    }
}

TEST_CASE("tp.atominc hands out unique tickets across 1024 threads", "[sim][machine]") {
    constexpr uint32_t kThreads = 1024, kTicketsEach = 4;
    // A quantum of 3 interleaves the threads' loops mid-iteration.
    Machine m = machine_for(
        "atominc",
        {.threads = kThreads, .global_bytes = 4 * kThreads * kTicketsEach, .quantum = 3});
    m.run();
    CHECK(m.global_register(7) == kThreads * kTicketsEach);
    CHECK(m.global_register(6) == 0);
    std::vector<uint32_t> claimed(kThreads + 1, 0);
    for (uint32_t ticket = 0; ticket < kThreads * kTicketsEach; ++ticket) {
        const uint32_t owner = global_word(m, ticket);  // mhartid + 1; 0 = never handed out
        REQUIRE(owner >= 1);
        REQUIRE(owner <= kThreads);
        ++claimed[owner];
    }
    CHECK(std::all_of(claimed.begin() + 1, claimed.end(),
                      [](uint32_t n) { return n == kTicketsEach; }));
}

TEST_CASE("faults name kind, thread, pc, function, instruction and a fix", "[sim][machine]") {
    struct Case {
        const char* program;
        uint32_t victim_offset;  // of the faulting instruction in victim()
        const char* kind;
        const char* detail;
    };
    const Case cases[] = {
        {"fault_null_load", 4, "null pointer access", "lw a0, 8(zero) reads 4 bytes at 0x00000008"},
        {"fault_unmapped_load", 8, "unmapped access", "reads 4 bytes at 0x40000000"},
        {"fault_misaligned_load", 12, "misaligned access", "not 4-byte aligned"},
        {"fault_write_code", 12, "write to read-only memory", "sw zero, 0(t0) writes 4 bytes"},
        {"fault_illegal", 4, "illegal instruction", "): word 0x00000000 is not"},
        {"fault_ebreak", 4, "breakpoint", "ebreak"},
        {"fault_bad_ecall", 8, "unsupported ecall", "a7=64"},
    };
    for (const Case& c : cases) {
        INFO("program " << c.program);
        Machine m = machine_for(c.program);
        const uint32_t pc = symbol_address(m.program(), "victim") + c.victim_offset;
        const std::string message = fault_message(m);
        CHECK_THAT(message, Catch::StartsWith(std::string(c.kind) + " in thread 0 at pc " +
                                              fmt::format("{:#010x}", pc) + " (victim+" +
                                              fmt::format("{:#x}", c.victim_offset)));
        CHECK_THAT(message, Catch::Contains(c.detail));
        CHECK_THAT(message, Catch::Contains("fault.S:"));
        CHECK(message.find('\n') == std::string::npos);
        CHECK(m.thread(0).state == ThreadState::Faulted);
    }
}

TEST_CASE("a jump to a misaligned target is reported at the jump", "[sim][machine]") {
    for (const char* program : {"misaligned_jalr", "misaligned_branch"}) {
        INFO("program " << program);
        Machine m = machine_for(program);
        const uint32_t jump = symbol_address(m.program(), "victim") + 12;  // after la (2) + addi
        const std::string message = fault_message(m);
        CHECK_THAT(message, Catch::StartsWith(fmt::format(
                                "misaligned jump in thread 0 at pc {:#010x} (victim+0xc", jump)));
        CHECK_THAT(message,
                   Catch::Contains(fmt::format("jumps to {:#010x}, which is not 4-byte aligned",
                                               std::string(program) == "misaligned_jalr"
                                                   ? symbol_address(m.program(), "_start") + 2
                                                   : jump + 6)));
        CHECK(m.thread(0).hart.pc == jump);
    }
}

TEST_CASE("only executable segments run, and a gap between them costs nothing", "[sim][machine]") {
    Machine far = machine_for("segments_far_code");
    REQUIRE(far.code().size() == 2);
    CHECK(far.code()[1].base == 0x0ffff000);
    // The decoded code is the two segments' words, not the 256 MiB between them.
    CHECK(far.code()[0].words + far.code()[1].words < 64);
    far.run();
    CHECK(far.thread(0).exit_code == 0);

    Machine data = machine_for("segments_data_code");
    const std::string message = fault_message(data);
    CHECK_THAT(message, Catch::StartsWith("jump outside the code in thread 0 at pc 0x00020000"));
    CHECK_THAT(message, Catch::Contains("outside the code [0x00010000, 0x000100") &&
                            Catch::Contains(") [0x0ffff000, 0x0ffff008)"));
}

TEST_CASE("a runaway work item stops at the item limit", "[sim][machine]") {
    Machine m = machine_for("fault_endless", {.max_item_instructions = 500, .quantum = 64});
    const std::string message = fault_message(m);
    CHECK_THAT(message, Catch::StartsWith("instruction limit reached in thread 0 at pc 0x"));
    CHECK_THAT(message, Catch::Contains("ran 500 instructions on one work item") &&
                            Catch::Contains("--max-item-instructions"));
    CHECK(m.thread(0).hart.instret == 500);
}

TEST_CASE("a jump to address 0 is reported as leaving the code", "[sim][machine]") {
    Machine m = machine_for("fault_jump_null");
    CHECK_THAT(fault_message(m),
               Catch::StartsWith("jump outside the code in thread 0 at pc 0x00000000: fetch from "
                                 "0x00000000"));
}

TEST_CASE("unbounded recursion is a stack overflow in the recursive function", "[sim][machine]") {
    Machine m = machine_for("stack_overflow", {.local_store_bytes = 1024});
    const std::string message = fault_message(m);
    CHECK_THAT(message, Catch::StartsWith("stack overflow in thread 0 at pc 0x"));
    CHECK_THAT(message, Catch::Contains("(recurse+0x"));
    const uint32_t line = tpsim::test::line_of("stack_overflow.c", "RECURSE_LINE");
    CHECK_THAT(message, Catch::Contains(fmt::format("stack_overflow.c:{})", line)));
    CHECK_THAT(message,
               Catch::Contains("below the 1024-byte local store [0x7ffffc00, 0x80000000)"));
    CHECK_THAT(message,
               Catch::EndsWith("reduce recursion/locals or enlarge the local store "
                               "(exec --local-store N, render --set tp.local_store_bytes=N)"));
}

TEST_CASE("a runaway thread stops at the instruction limit", "[sim][machine]") {
    Machine m = machine_for("fault_endless", {.max_instructions = 1000, .quantum = 64});
    const std::string message = fault_message(m);
    CHECK_THAT(message, Catch::StartsWith("instruction limit reached in thread 0 at pc 0x"));
    CHECK_THAT(message, Catch::Contains("(victim"));
    CHECK_THAT(message, Catch::Contains("): the thread ran 1000 instructions (the limit)") &&
                            Catch::Contains("--max-instructions"));
    CHECK(m.thread(0).executed == 1000);
}

TEST_CASE("a fault in one of 1024 threads names that thread", "[sim][machine]") {
    Machine m = machine_for("fault_thread17_ebreak", {.threads = 1024});
    CHECK_THAT(fault_message(m), Catch::StartsWith("breakpoint in thread 17 at pc"));
    CHECK(m.thread(16).state == ThreadState::Exited);  // thread order by id within a round
    CHECK(m.thread(17).state == ThreadState::Faulted);
}

TEST_CASE("step() reports each instruction's pc, memory access and control flow",
          "[sim][machine]") {
    Machine m = machine_for("loadstore");
    const uint32_t entry = m.program().entry;
    std::vector<StepRecord> trace;
    while (m.thread(0).state == ThreadState::Running)
        trace.push_back(m.step(0));
    CHECK(m.thread(0).exit_code == 0);
    REQUIRE(trace.size() > 10);
    CHECK(trace.front().pc == entry);
    CHECK(trace.back().exited);
    CHECK_FALSE(trace.back().taken);
    const auto taken =
        std::count_if(trace.begin(), trace.end(), [](const StepRecord& r) { return r.taken; });
    CHECK(taken == 0);  // loadstore.S is straight-line code: CHECK's bne never branches
    CHECK(trace.back().insn->op == isa::Op::ecall);
    // The first load of the program is `lw t1, 0(t0)` of the .data word.
    const auto first_load = std::find_if(
        trace.begin(), trace.end(), [](const StepRecord& r) { return r.insn->op == isa::Op::lw; });
    REQUIRE(first_load != trace.end());
    CHECK(first_load->mem_bytes == 4);
    CHECK_FALSE(first_load->mem_store);
    CHECK(first_load->mem_address == m.program().segments.back().vaddr);
    const auto first_sb = std::find_if(
        trace.begin(), trace.end(), [](const StepRecord& r) { return r.insn->op == isa::Op::sb; });
    REQUIRE(first_sb != trace.end());
    CHECK(first_sb->mem_bytes == 1);
    CHECK(first_sb->mem_store);
    for (const StepRecord& r : trace)
        if (r.insn->op == isa::Op::addi) CHECK(r.mem_bytes == 0);
    CHECK_THROWS_AS(m.step(0), Error);  // the thread has exited
}

TEST_CASE("step() marks taken branches and jumps", "[sim][machine]") {
    Machine m = machine_for("branch");
    std::vector<StepRecord> trace;
    while (m.thread(0).state == ThreadState::Running)
        trace.push_back(m.step(0));
    REQUIRE(m.thread(0).exit_code == 0);
    // branch.S: the six checks "branch to fail if wrong" fall through; the next six branch.
    std::vector<const StepRecord*> branches;
    for (const StepRecord& r : trace)
        if (isa::info(r.insn->op).fu == isa::FuClass::Branch) branches.push_back(&r);
    REQUIRE(branches.size() > 12);
    for (size_t i = 0; i < 6; ++i)
        CHECK_FALSE(branches[i]->taken);
    for (size_t i = 6; i < 12; ++i)
        CHECK(branches[i]->taken);
    for (const StepRecord* r : branches)
        if (r->insn->op == isa::Op::jal || r->insn->op == isa::Op::jalr) CHECK(r->taken);
}

TEST_CASE("step() and run() agree, and runs are reproducible", "[sim][machine]") {
    constexpr uint32_t kThreads = 64;
    const MachineConfig config{.threads = kThreads, .global_bytes = 4 * (kThreads + 1)};
    auto make = [&] {
        Machine m = machine_for("bench", config);
        const uint32_t iterations = 50;
        std::memcpy(m.memory().global().data(), &iterations, 4);
        return m;
    };
    Machine fast = make();
    fast.run();
    Machine again = make();
    again.run();
    Machine stepped = make();
    // Timing-model style: one instruction per running thread per round, in reverse order.
    for (bool any = true; any;) {
        any = false;
        for (uint32_t t = kThreads; t-- > 0;)
            if (stepped.thread(t).state == ThreadState::Running) stepped.step(t), any = true;
    }
    for (uint32_t i = 1; i <= kThreads; ++i) {
        INFO("thread " << i - 1);
        REQUIRE(global_word(fast, i) == global_word(again, i));
        REQUIRE(global_word(fast, i) == global_word(stepped, i));
    }
    CHECK(fast.counters().instructions == stepped.counters().instructions);
    CHECK(fast.counters().per_op == stepped.counters().per_op);
}

TEST_CASE("machine configuration is validated", "[sim][machine]") {
    CHECK_THROWS_WITH(machine_for("alu", {.local_store_bytes = 1000}),
                      Catch::Contains("--local-store"));
    CHECK_THROWS_AS(machine_for("alu", {.threads = 0}), Error);
    CHECK_THROWS_AS(machine_for("alu", {.max_instructions = 0}), Error);
    CHECK_THROWS_AS(machine_for("alu", {.quantum = 0}), Error);
}

// Throughput of the functional loop; run by hand: test_sim "[.bench]" (Release build).
TEST_CASE("functional throughput on a compute-heavy kernel", "[.bench]") {
    constexpr uint32_t kThreads = 1024, kIterations = 12000;
    Machine m = machine_for("bench", {.threads = kThreads, .global_bytes = 4 * (kThreads + 1)});
    std::memcpy(m.memory().global().data(), &kIterations, 4);
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    m.run();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // CPU time too: the wall clock suffers when the host is busy with other work.
    const double cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const double instructions = double(m.counters().instructions);
    WARN(fmt::format("{:.0f} M instructions in {:.3f} s wall ({:.1f} M/s), {:.3f} s CPU "
                     "({:.1f} M/s)",
                     instructions / 1e6, seconds, instructions / seconds / 1e6, cpu_seconds,
                     instructions / cpu_seconds / 1e6));
    CHECK(instructions > 1e8);
}
