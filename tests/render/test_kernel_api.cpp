// The course API's printing, barrier and semaphores, on the functional engine, the cycle-level
// chip and the native twin, on chips of several shapes.
#include <cstdio>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/render/profile.hpp"
#include "sim/render/render.hpp"
#include "sim/render/report.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/stats/registry.hpp"

using namespace tpsim;

namespace {

constexpr render::Engine kEngines[] = {render::Engine::functional, render::Engine::timing,
                                       render::Engine::native};

const char* name_of(render::Engine engine) {
    return engine == render::Engine::functional ? "functional"
           : engine == render::Engine::timing   ? "cycle-level"
                                                : "native twin";
}

struct Shape {
    uint32_t tms, tps;
};
// One thread, one TM, several TMs, odd TP counts.
constexpr Shape kShapes[] = {{1, 1}, {1, 8}, {4, 3}, {2, 5}};

render::RenderResult run(const char* kernel, render::Engine engine, Shape shape,
                         bool profile = false) {
    render::RenderOptions o;
    o.scene = std::filesystem::path(TPSIM_SOURCE_DIR) / "scenes" / "cornell.toml";
    o.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / (std::string(kernel) + ".elf");
    o.engine = engine;
    o.image_width = o.image_height = 16;
    o.chip.chip.num_tms = shape.tms;
    o.chip.chip.tps_per_tm = shape.tps;
    o.profile = profile;
    return render::render(o);
}

/// Framebuffer word `i` as an integer.
int framebuffer_word(const render::RenderResult& r, uint32_t i) {
    return int(r.image.words.at(r.image.header.framebuffer.addr + i));
}

std::string host_format(const char* format, double a, double b, double c, double d, double e,
                        double f, double g, double h) {
    char text[256];
    std::snprintf(text, sizeof text, format, a, b, c, d, e, f, g, h);
    return text;
}

/// What print_order.cpp prints in thread `id`, formatted by the host's C library.
std::string expected_print_order(uint32_t id) {
    char line1[128], line3[128];
    std::snprintf(line1, sizeof line1, "x = %d, %i%%, %u, %x/%X, [%c] %s\n", int(id), -int(id),
                  4000000000u, 255 + id, 0xbeef, char('a' + id % 26), "ok");
    const std::string line2 = host_format(
        "f = %f %.3f %.0f %8.2f|%-7.1f|%+.2f %f %f\n", double(float(id) * 0.1f), double(-2.0005f),
        2.5, double(3.14159f), 1.25, 7.0, double(1e30f), double(1e-7f));
    std::snprintf(line3, sizeof line3, "pad [%5d] [%-5d] [%05d] [%.3d] [%6s] [%-6s] [%.2s]\n",
                  int(id), int(id), -int(id), int(id), "ab", "cd", "efgh");
    const std::string lines[] = {line1,
                                 line2,
                                 line3,
                                 "bad %!d(float) %!f(int) %!s(int)\n",
                                 std::to_string(id) + "\n",
                                 "0.500000\n",
                                 "simtrax printf " + std::to_string(id) + "\n",
                                 "no newline at the end\n"};
    std::string text;
    for (const std::string& line : lines)
        text += "[thread " + std::to_string(id) + "] " + line;
    return text;
}

}  // namespace

TEST_CASE("kernel api: printing is tagged, in thread order, the same on every engine",
          "[kernel_api]") {
    for (const Shape shape : kShapes) {
        const uint32_t threads = shape.tms * shape.tps;
        std::string expected;
        for (uint32_t id = 0; id < threads; ++id)
            expected += expected_print_order(id);
        for (const render::Engine engine : kEngines) {
            INFO(name_of(engine) << " on " << shape.tms << " x " << shape.tps);
            const render::RenderResult r = run("print_order", engine, shape);
            CHECK(r.output.tagged() == expected);
            CHECK(r.output.dropped() == 0);
            CHECK(r.output.truncation_note().empty());
        }
    }
}

TEST_CASE("kernel api: the barrier orders every thread's writes before the reads after it",
          "[kernel_api]") {
    constexpr int kRounds = 3;  // as barrier_neighbour.cpp
    for (const Shape shape : kShapes) {
        const int n = int(shape.tms * shape.tps);
        // Thread n - 1 writes only in round 0, then exits.
        const auto value = [n](int thread, int round) {
            return thread == n - 1 && n > 1 ? thread * 10 : thread * 10 + round;
        };
        for (const render::Engine engine : kEngines) {
            INFO(name_of(engine) << " on " << shape.tms << " x " << shape.tps);
            const bool timing = engine == render::Engine::timing;
            const render::RenderResult r = run("barrier_neighbour", engine, shape, timing);
            for (int id = 0; id < n; ++id) {
                const int rounds = id == n - 1 && n > 1 ? 1 : kRounds;
                int sum = 0;
                for (int round = 0; round < rounds; ++round)
                    sum += value((id + 1) % n, round);
                INFO("thread " << id);
                CHECK(framebuffer_word(r, uint32_t(n + id)) == sum);
            }
            if (engine == render::Engine::timing) {
                // Waiting TPs stall with cause "sync"; every barrier issues as a sync instruction.
                stats::Registry registry;
                r.timing->chip->register_stats(registry);
                const stats::Snapshot s(registry);
                CHECK(s.value("chip/class/sync") ==
                      double(r.instructions.per_fu[size_t(isa::FuClass::Sync)]));
                CHECK(r.instructions.per_fu[size_t(isa::FuClass::Sync)] ==
                      uint64_t(n > 1 ? 2 * kRounds * (n - 1) + 1 : 2 * kRounds));
                if (n > 1) CHECK(s.value("chip/stalls/sync") > 0);
                // Every TP-cycle is an issue or one stall, the waits included ...
                double stalls = 0;
                for (const std::string_view cause : render::kStallNames)
                    if (cause != "fetch_miss")  // only with a finite I-cache
                        stalls += s.value(fmt::format("chip/stalls/{}", cause));
                CHECK(s.value("chip/active_tp_cycles") == s.value("chip/instructions") + stalls);
                // ... and the profile charges each wait to its instruction.
                uint64_t profiled = 0;
                for (const timing::PcCounters& pc : r.timing->chip->profile().words)
                    profiled += pc.stalls[size_t(timing::Stall::Sync)];
                CHECK(double(profiled) == s.value("chip/stalls/sync"));
            }
        }
    }
}

TEST_CASE("kernel api: a semaphore makes a shared counter exact", "[kernel_api]") {
    constexpr int kTimes = 5;  // as semaphore_counter.hpp
    for (const Shape shape : kShapes) {
        const int n = int(shape.tms * shape.tps);
        for (const render::Engine engine : kEngines) {
            INFO(name_of(engine) << " on " << shape.tms << " x " << shape.tps);
            CHECK(framebuffer_word(run("semaphore_counter", engine, shape), 0) == n * kTimes);
        }
    }
    // The control: on the chip, threads interleave between the load and the store.
    const Shape wide{4, 8};
    CHECK(framebuffer_word(run("unlocked_counter", render::Engine::timing, wide), 0) <
          int(wide.tms * wide.tps) * kTimes);
}

TEST_CASE("kernel api: a deadlock is a fault naming the waiting threads", "[kernel_api]") {
    for (const render::Engine engine : kEngines) {
        INFO(name_of(engine));
        try {
            run("deadlock", engine, {1, 4});
            FAIL("no fault");
        } catch (const Error& e) {
            const std::string what = e.what();
            INFO(what);
            CHECK(what.find("deadlock") != std::string::npos);
            // Which thread blocks last depends on the engine; the message names the others.
            CHECK((what.find("thread 0 at the barrier") != std::string::npos ||
                   what.find("waits at the barrier") != std::string::npos));
            CHECK(what.find("semaphore 3 (held by thread 0)") != std::string::npos);
        }
    }
}

TEST_CASE("kernel api: the output is capped, keeping the same bytes on every engine",
          "[kernel_api]") {
    const Shape shape{2, 4};
    const render::RenderResult reference = run("print_flood", render::Engine::functional, shape);
    const trax::KernelOutput& out = reference.output;
    CHECK(out.kept() == trax::KernelOutput::kDefaultLimitBytes);
    CHECK(out.dropped() > 0);
    CHECK(out.truncation_note().find("dropped " + std::to_string(out.dropped())) !=
          std::string::npos);
    // The first threads' output whole, the last's not at all.
    CHECK(out.of(0).size() > 100'000);
    CHECK(out.of(shape.tms * shape.tps - 1).empty());
    for (const render::Engine engine : {render::Engine::timing, render::Engine::native}) {
        INFO(name_of(engine));
        const render::RenderResult r = run("print_flood", engine, shape);
        CHECK(r.output.tagged() == out.tagged());
        CHECK(r.output.dropped() == out.dropped());
    }
}

TEST_CASE("kernel output: what is kept does not depend on the order threads printed in",
          "[kernel_api]") {
    const std::vector<std::pair<uint32_t, std::string>> prints = {
        {2, "cc\n"}, {0, "aaaa"}, {1, "bbb\n"}, {0, "a\n"}, {2, "c"}, {1, "b"}};
    trax::KernelOutput forward(3, 10), backward(3, 10);
    for (const auto& [thread, text] : prints)
        forward.append(thread, text);
    for (auto it = prints.rbegin(); it != prints.rend(); ++it)
        backward.append(it->first, it->second);
    // 15 bytes in thread order: "aaaaa\n" "bbb\nb" "cc\nc"; the first 10 are kept.
    CHECK(forward.of(0) == "aaaaa\n");
    CHECK(forward.of(1) == "bbb\n");
    CHECK(forward.of(2).empty());
    CHECK(forward.dropped() == 5);
    CHECK(forward.tagged() == "[thread 0] aaaaa\n[thread 1] bbb\n");
    // Backwards each thread's own pieces come reversed, so only thread order is compared.
    CHECK(backward.kept() == 10);
    CHECK(backward.dropped() == 5);
    CHECK(backward.of(2).empty());
}
