// Parallel simulation: the cycle-level chip and the functional machine on 1, 2, 3 and 8 host
// threads give the same statistics, images, profiles, per-pixel costs, kernel output and
// faults, on chips of one TM, several, an odd count, and fewer TMs than host threads.
#include <algorithm>
#include <atomic>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "sim/core/error.hpp"
#include "sim/core/fault.hpp"
#include "sim/core/host_threads.hpp"
#include "sim/core/lane_balance.hpp"
#include "sim/core/ordered_turns.hpp"
#include "sim/core/spin_wait.hpp"
#include "sim/render/render.hpp"
#include "sim/render/report.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/stats/registry.hpp"

using namespace tpsim;

namespace {

constexpr uint32_t kHostThreads[] = {1, 2, 3, 8};

struct Shape {
    uint32_t tms, tps;
};

/// Everything a run reports that must not depend on the host threads, as text.
std::string everything(const render::RenderResult& r) {
    std::ostringstream out;
    stats::Registry all;
    render::register_stats(r, all);
    for (const stats::Entry& e : all.entries())
        if (!e.name.starts_with("host/")) out << e.name << '=' << e.value() << '\n';
    out << "output " << r.output.tagged() << " dropped " << r.output.dropped() << '\n';
    out << "image";
    for (uint32_t word : r.image.words)
        out << ' ' << word;
    out << '\n';
    if (r.timing) {
        const timing::WorkItemCosts& items = r.timing->chip->work_items();
        for (const timing::WorkItemCounters& c : items.items)
            out << c.cycles << ',' << c.instructions << ',' << c.dram_bytes << ' ';
        out << "unassigned " << items.unassigned.cycles << ',' << items.unassigned.instructions
            << ',' << items.unassigned.dram_bytes << '\n';
        for (const timing::PcCounters& c : r.timing->chip->profile().words) {
            out << c.executions << ',' << c.l1_misses << ',' << c.dram_bytes;
            for (uint64_t stall : c.stalls)
                out << ',' << stall;
            out << ' ';
        }
    }
    return out.str();
}

render::RenderOptions options(const char* kernel, render::Engine engine, Shape shape,
                              uint32_t pixels) {
    render::RenderOptions o;
    o.scene = std::filesystem::path(TPSIM_SOURCE_DIR) / "scenes" / "cornell.toml";
    o.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / (std::string(kernel) + ".elf");
    o.engine = engine;
    o.image_width = o.image_height = pixels;
    o.chip.chip.num_tms = shape.tms;
    o.chip.chip.tps_per_tm = shape.tps;
    o.chip.chip.tms_per_l2 = std::min(shape.tms, 2u);
    return o;
}

/// Runs `o` on each host-thread count; every run must report what the first did.
void check_same_for_any_host_threads(const render::RenderOptions& o) {
    std::string first;
    for (uint32_t threads : kHostThreads) {
        INFO("host threads " << threads);
        core::set_host_threads(threads);
        const std::string now = everything(render::render(o));
        if (first.empty())
            first = now;
        else
            CHECK(now == first);  // (not printed: megabytes)
    }
}

/// The fault `o` ends with: its message and the output before it.
std::string fault_of(const render::RenderOptions& o) {
    try {
        render::render(o);
    } catch (const core::Fault& f) {
        return std::string(f.what()) + "\n" + f.output().tagged();
    }
    return "no fault";
}

}  // namespace

TEST_CASE("ordered turns: actions at increasing positions run in position order on any lanes",
          "[parallel]") {
    // Each lane owns the positions p with p % lanes == lane; at a random subset of its
    // positions it appends p to a plain vector in its turn. The vector must come out sorted,
    // whatever the host does.
    for (uint32_t lanes : {2u, 3u, 8u}) {
        INFO(lanes << " lanes");
        core::OrderedTurns turns(lanes);
        constexpr uint64_t kPositions = 200'000;
        std::vector<uint64_t> log;
        std::vector<std::thread> threads;
        for (uint32_t lane = 0; lane < lanes; ++lane)
            threads.emplace_back([&, lane] {
                std::mt19937 random(lane);
                for (uint64_t p = lane; p < kPositions; p += lanes) {
                    turns.reach(lane, p);
                    if (random() % 4 == 0) {
                        turns.wait_turn(lane, p);
                        log.push_back(p);
                    }
                }
                turns.reach(lane, core::OrderedTurns::kDone);
            });
        for (std::thread& t : threads)
            t.join();
        CHECK(log.size() > kPositions / 5);
        CHECK(std::is_sorted(log.begin(), log.end()));
    }
}

TEST_CASE("lane balance: the lanes' blocks of TMs follow their measured time per TM",
          "[parallel]") {
    using core::LaneLoad;
    const std::vector<uint32_t> halves = {0, 8, 16};
    const std::vector<bool> all(16, true);
    // Equal lanes stay as they are; so does a difference within the least gain asked for.
    CHECK(core::balance_lanes(halves, std::vector<LaneLoad>{{8, 8, 0}, {8, 8, 0}}, all, 0.02) ==
          halves);
    CHECK(core::balance_lanes(halves, std::vector<LaneLoad>{{8.1, 8, 0}, {8, 8, 0}}, all, 0.02) ==
          halves);
    // A lane twice as slow per TM gets a third of them: 5 TMs at 2 against 11 at 1 (the busiest
    // lane 11 instead of 16).
    CHECK(core::balance_lanes(halves, std::vector<LaneLoad>{{8, 8, 0}, {16, 8, 0}}, all, 0.02) ==
          std::vector<uint32_t>{0, 11, 16});
    // Serial work on lane 0 (the shared parts, 2 TMs' worth) leaves it fewer TMs.
    CHECK(core::balance_lanes(halves, std::vector<LaneLoad>{{8, 8, 2}, {8, 8, 0}}, all, 0.02) ==
          std::vector<uint32_t>{0, 7, 16});
    // Idle TMs cost nothing and stay with the block before them: TMs 0-3 and 12 running,
    // lane 0 has four at 1 s each, lane 1 one: three and two (TM 3 and idle 4-11 go to lane 1).
    std::vector<bool> running(16, false);
    for (uint32_t t : {0, 1, 2, 3, 12})
        running[t] = true;
    CHECK(core::balance_lanes(halves, std::vector<LaneLoad>{{4, 4, 0}, {1, 1, 0}}, running, 0.02) ==
          std::vector<uint32_t>{0, 3, 16});
    // A lane with no running TM is taken to be as fast as the others.
    running[12] = false;
    CHECK(core::balance_lanes(halves, std::vector<LaneLoad>{{4, 4, 0}, {0, 0, 0}}, running, 0.02) ==
          std::vector<uint32_t>{0, 2, 16});
    // Three lanes, the middle one three times as slow: the busiest lane's time is 6 (e.g. 5, 2
    // and 5 TMs) instead of 12.
    const std::vector<uint32_t> thirds = core::balance_lanes(
        std::vector<uint32_t>{0, 4, 8, 12}, std::vector<LaneLoad>{{4, 4, 0}, {12, 4, 0}, {4, 4, 0}},
        std::vector<bool>(12, true), 0.02);
    REQUIRE(thirds.size() == 4);
    CHECK(thirds.front() == 0);
    CHECK(thirds.back() == 12);
    CHECK(std::max({thirds[1] - thirds[0], 3 * (thirds[2] - thirds[1]), thirds[3] - thirds[2]}) ==
          6);
    // Nothing measured: no change.
    CHECK(core::balance_lanes(halves, std::vector<LaneLoad>(2), all, 0.02) == halves);
}

TEST_CASE("spin barrier: each completion sees every thread's phase, and only then do they go on",
          "[parallel]") {
    // Every thread writes its own plain slot before arriving; the completion checks that all
    // slots hold the phase and records it; after the barrier each thread checks the record. A
    // thread that drops out halfway leaves the others going with one fewer.
    for (uint32_t count : {2u, 3u, 8u}) {
        INFO(count << " threads");
        constexpr uint32_t kPhases = 20'000, kDropAt = kPhases / 2;
        std::vector<uint32_t> slots(count, 0);
        uint32_t completed = 0, bad = 0, arrivals = count;
        const auto completion = [&]() noexcept {
            for (uint32_t t = 0; t < arrivals; ++t)
                bad += slots[t] != completed + 1;
            ++completed;
            if (completed == kDropAt) arrivals = count - 1;  // the last thread dropped in this one
        };
        core::SpinBarrier barrier(count, completion);
        std::atomic<uint32_t> late{0};
        std::vector<std::thread> threads;
        for (uint32_t t = 0; t < count; ++t)
            threads.emplace_back([&, t] {
                for (uint32_t phase = 1; phase <= kPhases; ++phase) {
                    slots[t] = phase;
                    if (t == count - 1 && phase == kDropAt) {
                        barrier.arrive_and_drop();
                        return;
                    }
                    barrier.arrive_and_wait();
                    late += completed < phase;
                }
            });
        for (std::thread& t : threads)
            t.join();
        CHECK(completed == kPhases);
        CHECK(bad == 0);
        CHECK(late == 0);
    }
}

TEST_CASE("host thread choice: keeps the faster count, tries the other again ever less often",
          "[parallel]") {
    // Chunks of 10 ms: a phase of kTrySeconds is 5 chunks. Returns the counts chunk by chunk
    // when `most` threads do `speedup` times the work per second of one.
    const auto counts = [](double speedup, uint32_t chunks) {
        core::HostThreadChoice choice(4);
        std::string seen;
        for (uint32_t c = 0; c < chunks; ++c) {
            const uint32_t threads = choice.next();
            seen += char('0' + threads);
            choice.ran(threads == 1 ? 1000 : uint64_t(1000 * speedup), 0.01);
        }
        return seen;
    };
    // Faster: one phase on 1, then on 4, trying 1 again after 4 phases, then 8, ...
    const std::string faster = counts(2.0, 100);
    CHECK(faster.substr(0, 10) == "1111144444");
    CHECK(faster.substr(10, 20) == std::string(20, '4'));
    CHECK(faster.substr(30, 5) == "11111");
    CHECK(faster.substr(35, 20) == std::string(20, '4'));
    CHECK(faster.substr(55, 5) == "11111");
    CHECK(faster.substr(60, 40) == std::string(40, '4'));
    // Slower: back to 1 after each try, tried after 4, 8, 16 phases.
    const std::string slower = counts(0.5, 200);
    CHECK(slower.substr(0, 10) == "1111144444");
    CHECK(slower.substr(10, 20) == std::string(20, '1'));
    CHECK(slower.substr(30, 5) == "44444");
    CHECK(slower.substr(35, 40) == std::string(40, '1'));
    CHECK(slower.substr(75, 5) == "44444");
    CHECK(std::count(slower.begin(), slower.end(), '4') == 20);
    // One host thread: nothing to choose.
    core::HostThreadChoice one(1);
    one.ran(1000, 1.0);
    CHECK(one.next() == 1);
}

TEST_CASE("parallel: a finite I-cache's misses to the L2 are the same on any host threads",
          "[parallel]") {
    // A 1 KiB I-cache per 4 TPs thrashes on the tracer: instruction lines travel with the data
    // lines from every TM to the L2s, in the same order for any host threads.
    for (const Shape shape : {Shape{4, 8}, Shape{3, 5}}) {
        INFO(shape.tms << " TMs x " << shape.tps << " TPs");
        render::RenderOptions o = options("tracer", render::Engine::timing, shape, 16);
        o.chip.icache.size_bytes = 1024;
        o.chip.icache.threads_per_icache = 4;
        o.profile = true;
        check_same_for_any_host_threads(o);
    }
}

TEST_CASE("parallel: the tracer on the cycle-level chip is the same on any host threads",
          "[parallel]") {
    // One TM; four; an odd count (3 TMs of 5 TPs); and 2 TMs, fewer than 3 or 8 host threads.
    for (const Shape shape : {Shape{1, 8}, Shape{4, 8}, Shape{3, 5}, Shape{2, 16}}) {
        INFO(shape.tms << " TMs x " << shape.tps << " TPs");
        render::RenderOptions o = options("tracer", render::Engine::timing, shape, 16);
        o.profile = shape.tms == 4;
        check_same_for_any_host_threads(o);
    }
}

TEST_CASE("parallel: the pipeline of any lookahead gives the same results on any host threads",
          "[parallel]") {
    // The lookahead min(l2.hit_latency, global-register latency + link) sets the stretches:
    // 1 cycle each after the shared parts' last (lookahead 1), 1 cycle with the shared parts
    // a stretch behind (3), 3 cycles (7, one cycle left over).
    for (const auto& [l2, registers] : {std::pair{1u, 4u}, {3u, 4u}, {9u, 5u}}) {
        INFO("l2 hit latency " << l2 << ", global-register latency " << registers);
        render::RenderOptions o = options("tracer", render::Engine::timing, Shape{4, 8}, 16);
        o.chip.l2.hit_latency = l2;
        o.chip.global_registers.latency = registers;
        check_same_for_any_host_threads(o);
    }
}

TEST_CASE("parallel: atomics, racing shared loads and stores, barriers, semaphores and prints "
          "are the same on any host threads",
          "[parallel]") {
    for (const char* kernel :
         {"unlocked_counter", "semaphore_counter", "barrier_neighbour", "print_order"})
        for (const render::Engine engine : {render::Engine::timing, render::Engine::functional})
            for (const Shape shape : {Shape{1, 4}, Shape{4, 3}, Shape{3, 5}}) {
                INFO(kernel << (engine == render::Engine::timing ? " cycle-level " : " functional ")
                            << shape.tms << " TMs x " << shape.tps << " TPs");
                check_same_for_any_host_threads(options(kernel, engine, shape, 8));
            }
}

TEST_CASE("parallel: a fault reports the same thread and output on any host threads",
          "[parallel]") {
    // An illegal instruction, and a store into the stack's overflow guard (a private step).
    for (const auto& [param, message] :
         {std::pair{"private_fault=0", "is not an RV32IMF instruction"},
          std::pair{"private_fault=1", "stack overflow"}})
        for (const render::Engine engine : {render::Engine::timing, render::Engine::functional})
            for (const Shape shape : {Shape{4, 8}, Shape{3, 5}}) {
                INFO(param << ", "
                           << (engine == render::Engine::timing ? "cycle-level " : "functional ")
                           << shape.tms << " TMs x " << shape.tps << " TPs");
                render::RenderOptions o = options("fault_race", engine, shape, 8);
                o.params = {param};
                std::string first;
                for (uint32_t threads : kHostThreads) {
                    INFO("host threads " << threads);
                    core::set_host_threads(threads);
                    const std::string fault = fault_of(o);
                    CHECK(fault.find(message) != std::string::npos);
                    if (first.empty())
                        first = fault;
                    else
                        CHECK(fault == first);
                }
            }
}

TEST_CASE("parallel: sampled simulation is the same on any host threads", "[parallel]") {
    render::RenderOptions o = options("tracer", render::Engine::timing, Shape{4, 8}, 32);
    o.sampling = render::SamplingOptions{};
    o.sampling->rate = 0.2;
    o.sampling->unit_cycles = 500;
    o.sampling->warmup_cycles = 200;
    check_same_for_any_host_threads(o);
}
