// End to end on the tracer kernel: the cycle-level engine is deterministic and never changes
// the image, whatever the timing parameters (functional-first: timing decides only *when*).
#include "sim/core/elf_loader.hpp"
#include "sim/core/host_threads.hpp"
#include "sim/image/memory_image.hpp"
#include "sim/render/render.hpp"
#include "sim/render/report.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/timing/config.hpp"
#include "sim/timing/machine_source.hpp"

#include <catch2/catch.hpp>

#include "tests/scratch.hpp"
#include "tests/timing/documented_stats.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

using namespace tpsim;

namespace {

std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    if (at == std::string::npos)
        throw std::runtime_error("scenes/cornell.toml has no '" + from + "'");
    return text.replace(at, from.size(), to);
}

/// scenes/cornell.toml at 32x32 pixels, written to a scratch file.
std::filesystem::path small_cornell() {
    std::ifstream in(TPSIM_SCENE_DIR "/cornell.toml");
    std::stringstream text;
    text << in.rdbuf();
    std::string scene = replaced(text.str(), "width = 256", "width = 32");
    scene = replaced(scene, "height = 256", "height = 32");
    scene = replaced(scene, "path = \"cornell.obj\"", "path = \"" TPSIM_SCENE_DIR "/cornell.obj\"");
    const auto path = tpsim::testing::scratch_path("cornell32.toml");
    std::ofstream(path) << scene;
    return path;
}

render::RenderResult render_cornell(render::Engine engine, const timing::ChipConfig& chip) {
    static const std::filesystem::path scene = small_cornell();
    render::RenderOptions options;
    options.scene = scene;
    options.kernel = TPSIM_KERNEL_DIR "/tracer.elf";
    options.engine = engine;
    options.chip = chip;
    return render::render(options);
}

timing::ChipConfig tiny() {
    return timing::load_config(TPSIM_CONFIG_DIR "/tiny.toml");
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

/// Every statistic except host timings, as JSON text.
std::string simulated_stats(const render::RenderResult& result) {
    stats::Registry all;
    render::register_stats(result, all);
    std::ostringstream out;
    for (const stats::Entry& e : all.entries())
        if (!e.name.starts_with("host/")) out << e.name << '=' << e.value() << '\n';
    return out.str();
}

}  // namespace

TEST_CASE("two cycle-level renders give identical statistics and images", "[render][determinism]") {
    const auto first = render_cornell(render::Engine::timing, tiny());
    const auto second = render_cornell(render::Engine::timing, tiny());
    REQUIRE(first.timing);
    CHECK(first.timing->chip->cycles() > 0);
    CHECK(simulated_stats(first) == simulated_stats(second));
    CHECK(same_bits(first.rgb, second.rgb));
}

TEST_CASE("timing parameters never change the image", "[render][invariance]") {
    const auto reference = render_cornell(render::Engine::functional, tiny());
    const char* variants[][2] = {
        {"l1.size_bytes=4096", "l1.ways=4"},
        {"dram.tCL=40", "dram.tRP=30"},
        {"fu.fp_mul.count=4", "fu.fp_add.latency=7"},
        {"global_registers.latency=50", "icache.banks=1"},
        {"l2.write_combining_lines=2", "l2.size_bytes=4096"},
    };
    uint64_t previous_cycles = 0;
    for (const auto& overrides : variants) {
        timing::ChipConfig chip = tiny();
        for (const char* o : overrides)
            timing::apply_override(chip, o);
        const auto result = render_cornell(render::Engine::timing, chip);
        INFO(overrides[0] << ' ' << overrides[1]);
        CHECK(same_bits(result.rgb, reference.rgb));
        CHECK(result.timing->chip->cycles() != previous_cycles);  // the timing did change
        previous_cycles = result.timing->chip->cycles();
    }
}

TEST_CASE("BVH node orders move the traffic, never the image or the instructions",
          "[render][invariance][layout]") {
    const auto reference = render_cornell(render::Engine::timing, tiny());
    const auto stat = [](const render::RenderResult& result, const char* key) {
        stats::Registry all;
        render::register_stats(result, all);
        return all.value(key);
    };
    const double unaligned_misses = stat(reference, "region/bvh_nodes/l1/misses");
    for (scene::BvhOrder order : scene::kBvhOrders)
        for (bool align : {false, true}) {
            render::RenderOptions options;
            options.scene = small_cornell();
            options.kernel = TPSIM_KERNEL_DIR "/tracer.elf";
            options.engine = render::Engine::timing;
            options.chip = tiny();
            options.accel.bvh_order = order;
            options.accel.bvh_align_pairs = align;
            const auto result = render::render(options);
            INFO(scene::to_string(order) << (align ? ", aligned" : ""));
            CHECK(same_bits(result.rgb, reference.rgb));
            CHECK(result.instructions.total == reference.instructions.total);
            CHECK(result.traversal.nodes_visited == reference.traversal.nodes_visited);
            CHECK(result.image.header.bvh_nodes.count ==
                  reference.image.header.bvh_nodes.count + (align ? 1 : 0));
            // A 1 KiB L1: a pair that fills one line costs one miss where a straddling pair
            // costs two.
            if (align) CHECK(stat(result, "region/bvh_nodes/l1/misses") < unaligned_misses);
        }
}

namespace {

/// The small Cornell box on the tiny chip through another structure's tracer. The wide BVH's,
/// the kd-tree's and the octree's traversal stacks (64, 40 and 48 entries) and the packets' rays
/// do not fit the tiny chip's 1 KiB of local store; two TMs give each of two host threads one.
render::RenderOptions structure_run(const char* kernel) {
    render::RenderOptions options;
    options.scene = small_cornell();
    options.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / kernel;
    options.engine = render::Engine::timing;
    options.chip = tiny();
    options.chip.tp.local_store_bytes = 2048;
    options.chip.chip.num_tms = 2;
    return options;
}

/// Renders on one and on two host threads; CHECKs that both give `reference`'s image without a
/// stack overflow and the same statistics. Returns the first.
render::RenderResult render_on_one_and_two_host_threads(const render::RenderOptions& options,
                                                        const render::RenderResult& reference) {
    std::optional<render::RenderResult> first;
    for (uint32_t host_threads : {1u, 2u}) {
        core::set_host_threads(host_threads);
        auto result = render::render(options);
        CHECK(same_bits(result.rgb, reference.rgb));
        CHECK(result.traversal.stack_overflows == 0);
        if (!first)
            first = std::move(result);
        else
            CHECK(simulated_stats(result) == simulated_stats(*first));
    }
    return std::move(*first);
}

}  // namespace

TEST_CASE("The wide BVHs render the binary BVH's image in both box formats, the same on one "
          "and on two host threads",
          "[render][invariance][wide]") {
    const auto reference = render_cornell(render::Engine::timing, tiny());
    const auto stat = [](const render::RenderResult& result, const char* key) {
        stats::Registry all;
        render::register_stats(result, all);
        return all.value(key);
    };
    for (scene::AccelStructure structure :
         {scene::AccelStructure::bvh4, scene::AccelStructure::bvh8}) {
        double float_bytes = 0;
        for (scene::BvhBoxes boxes : scene::kBvhBoxes) {
            INFO(scene::to_string(structure) << " " << scene::to_string(boxes));
            render::RenderOptions options = structure_run("tracer_wide.elf");
            options.accel.structure = structure;
            options.accel.bvh_boxes = boxes;
            const auto result = render_on_one_and_two_host_threads(options, reference);
            REQUIRE(result.wide_bvh);
            CHECK(result.wide_bvh->width == scene::wide_bvh_width(structure));
            const double bytes = stat(result, "memory/bvh_nodes_bytes");
            if (boxes == scene::BvhBoxes::floats)
                float_bytes = bytes;
            else
                CHECK(bytes * 2 == float_bytes);  // half the bytes per node
        }
    }
}

TEST_CASE("every key a cycle-level render registers is documented in docs/statistics.md",
          "[render][docs]") {
    const std::vector<std::regex> documented = documented_stat_patterns();
    REQUIRE(documented.size() > 20);
    // The keys the run registers, each checked.
    const auto check_documented = [&](const render::RenderResult& result) {
        stats::Registry registry;
        render::register_stats(result, registry);
        std::set<std::string> keys;
        for (const stats::Entry& e : registry.entries()) {
            INFO(e.name);
            CHECK(std::any_of(documented.begin(), documented.end(),
                              [&](const std::regex& re) { return std::regex_match(e.name, re); }));
            keys.insert(e.name);
        }
        CHECK(keys.count("chip/rays_per_second") == 1);
        return keys;
    };
    // The finite I-cache's keys exist only with one.
    timing::ChipConfig finite_icache = tiny();
    timing::apply_override(finite_icache, "icache.size_bytes=1024");
    for (const timing::ChipConfig& chip : {tiny(), finite_icache}) {
        const auto keys = check_documented(render_cornell(render::Engine::timing, chip));
        CHECK((keys.count("chip/icache/misses") == 1) == chip.icache.finite());
    }
    // The wide BVH's keys exist only with one.
    const render::RenderOptions wide = structure_run("tracer_wide.elf");
    CHECK(check_documented(render::render(wide)).count("wide_bvh/nodes") == 1);
    // And the kd-tree's.
    CHECK(check_documented(render::render(structure_run("tracer_kdtree.elf")))
              .count("kdtree/references") == 1);
    // The BSP tree's under its own name.
    const auto bsp_keys = check_documented(render::render(structure_run("tracer_bsp.elf")));
    CHECK(bsp_keys.count("bsp/diagonal_planes") == 1);
    CHECK(bsp_keys.count("kdtree/references") == 0);
    // And the octree's.
    CHECK(check_documented(render::render(structure_run("tracer_octree.elf")))
              .count("octree/references") == 1);
}

TEST_CASE("The kd-tree renders the binary BVH's image, the same on one and on two host threads",
          "[render][invariance][kdtree]") {
    const auto reference = render_cornell(render::Engine::timing, tiny());
    const auto result =
        render_on_one_and_two_host_threads(structure_run("tracer_kdtree.elf"), reference);
    REQUIRE(result.kdtree);
    CHECK(result.kdtree->references >= result.scene.triangles.size());
}

TEST_CASE("The BSP tree renders the binary BVH's image, the same on one and on two host threads",
          "[render][invariance][bsp]") {
    const auto reference = render_cornell(render::Engine::timing, tiny());
    const auto result =
        render_on_one_and_two_host_threads(structure_run("tracer_bsp.elf"), reference);
    REQUIRE(result.kdtree);
    CHECK(result.accel == scene::AccelStructure::bsp);
    CHECK(result.kdtree->diagonal_planes > 0);
}

TEST_CASE("The octree renders the binary BVH's image, the same on one and on two host threads",
          "[render][invariance][octree]") {
    const auto reference = render_cornell(render::Engine::timing, tiny());
    const auto result =
        render_on_one_and_two_host_threads(structure_run("tracer_octree.elf"), reference);
    REQUIRE(result.octree);
    CHECK(result.octree->references >= result.scene.triangles.size());
    CHECK(result.octree->interior > 0);
}

TEST_CASE("Packets render the single-ray kernels' images, the same on one and on two host "
          "threads: tracer_packet the tracer's, ao_packet ao's",
          "[render][invariance][packets]") {
    // 31 x 29: the last column and row of 2 x 2 blocks hold one pixel of each packet's pairs.
    const auto odd_size = [](const char* kernel) {
        render::RenderOptions options = structure_run(kernel);
        options.image_width = 31;
        options.image_height = 29;
        return options;
    };
    for (const auto& [single, packet] :
         {std::pair{"tracer.elf", "tracer_packet.elf"}, std::pair{"ao.elf", "ao_packet.elf"}}) {
        INFO(single << " against " << packet);
        const auto reference = render::render(odd_size(single));
        const auto result = render_on_one_and_two_host_threads(odd_size(packet), reference);
        // The same rays: every camera ray, and every shadow or occlusion ray.
        CHECK(result.traversal.primary_rays == 31 * 29);
        CHECK(result.traversal.primary_rays == reference.traversal.primary_rays);
        CHECK(result.traversal.shadow_rays == reference.traversal.shadow_rays);
        CHECK(result.traversal.shadow_rays > result.traversal.primary_rays / 2);
    }
}

namespace {

/// The reference the machine source's run-ahead must match: every instruction executed at
/// the moment the chip fetches it.
class StepAtFetch : public timing::InstructionSource {
public:
    explicit StepAtFetch(core::Machine& machine) : machine_(machine) {}
    uint32_t next_pc(uint32_t thread) const override { return machine_.next_pc(thread); }
    void step(uint32_t thread, timing::StepInfo& out) override { out = machine_.step(thread); }

private:
    core::Machine& machine_;
};

struct ChipRun {
    std::string stats;             // every chip statistic, name=value lines
    std::vector<uint32_t> global;  // global memory afterwards (framebuffer included)
    std::string output;            // what the threads printed
};

/// Runs a kernel (the tracer unless named) on the 32x32 Cornell box; with `pause_every`, in
/// run_until() steps of that many cycles, the k-th on host_threads[k % size] host threads (if
/// any are given).
template <class Source>
ChipRun run_chip(const timing::ChipConfig& chip, uint64_t pause_every = 0,
                 const std::vector<uint32_t>& host_threads = {},
                 const std::string& kernel = "tracer") {
    const scene::Scene scene = scene::load_scene(small_cornell());
    scene::BvhConfig bvh_config;
    bvh_config.traversal_stack_entries = trax::layout::kTraversalStackEntries;
    const scene::Bvh bvh = scene::build_bvh(scene.triangles, bvh_config);
    const image::MemoryImage image =
        image::build_memory_image(scene, &bvh, chip.chip.num_tms * chip.chip.tps_per_tm);
    const auto machine_ptr =
        timing::make_machine(core::load_elf(TPSIM_KERNEL_DIR "/" + kernel + ".elf"), image.words,
                             image.read_only_bytes(), chip, uint64_t(1) << 32);
    core::Machine& machine = *machine_ptr;
    Source source(machine);
    timing::Chip model(chip, source);
    if (pause_every == 0)
        model.run();
    else
        for (uint64_t until = pause_every, k = 0;; until += pause_every, ++k) {
            if (!host_threads.empty())
                model.use_host_threads(host_threads[k % host_threads.size()]);
            if (model.run_until(until)) break;
            REQUIRE(model.cycles() == until);
        }
    CHECK(model.finished());
    CHECK(model.run_until(model.cycles() + 1));  // a finished chip stays finished
    stats::Registry registry;
    model.register_stats(registry);
    ChipRun run;
    for (const stats::Entry& e : registry.entries())
        run.stats += e.name + '=' + std::to_string(e.value()) + '\n';
    const auto global = machine.memory().global();
    run.global.resize(global.size() / 4);
    std::memcpy(run.global.data(), global.data(), global.size());
    run.output = machine.output().tagged();
    return run;
}

}  // namespace

TEST_CASE("running threads ahead through private instructions changes nothing the chip reports",
          "[render][determinism]") {
    // MachineSource runs stores ahead too and holds them until their turn (Machine::clock_by);
    // the kernels besides the tracer load what other threads store, racing or not.
    for (const char* kernel :
         {"tracer", "unlocked_counter", "semaphore_counter", "barrier_neighbour", "print_order"})
        for (const char* shape : {"chip.tps_per_tm=8", "chip.tps_per_tm=70"}) {
            timing::ChipConfig chip = tiny();
            timing::apply_override(chip, shape);
            timing::apply_override(chip, "icache.threads_per_icache=2");
            timing::apply_override(chip, "chip.num_tms=3");
            INFO(kernel << ' ' << shape);
            const ChipRun at_fetch = run_chip<StepAtFetch>(chip, 0, {}, kernel);
            for (uint32_t host_threads : {1u, 3u}) {
                INFO("host threads " << host_threads);
                const ChipRun ahead =
                    run_chip<timing::MachineSource>(chip, 997, {host_threads}, kernel);
                CHECK(ahead.stats == at_fetch.stats);
                CHECK(ahead.global == at_fetch.global);
                CHECK(ahead.output == at_fetch.output);
                CHECK(ahead.stats.find("chip/instructions=0\n") == std::string::npos);
            }
        }
}

TEST_CASE("a run that changes its host threads at every pause gives the run on one",
          "[render][determinism][parallel]") {
    // What is in flight between the TMs and the shared parts at a pause (their mailboxes, the
    // shared parts' queues) carries over into stretches of another length on other threads; 2
    // host threads come back after a run on one with the same lanes (Chip::use_host_threads).
    timing::ChipConfig chip = tiny();
    timing::apply_override(chip, "chip.num_tms=4");
    timing::apply_override(chip, "chip.tms_per_l2=2");
    const ChipRun whole = run_chip<timing::MachineSource>(chip);
    for (uint64_t pause_every : {300u, 997u, 4096u}) {
        INFO(pause_every);
        const ChipRun switched =
            run_chip<timing::MachineSource>(chip, pause_every, {2, 1, 2, 3, 8, 4});
        CHECK(switched.stats == whole.stats);
        CHECK(switched.global == whole.global);
    }
}

TEST_CASE("a run paused and resumed at any cycle gives the run without pauses",
          "[render][determinism]") {
    const timing::ChipConfig chip = tiny();
    const ChipRun whole = run_chip<timing::MachineSource>(chip);
    for (uint64_t pause_every : {1u, 997u, 65536u}) {
        INFO(pause_every);
        const ChipRun paused = run_chip<timing::MachineSource>(chip, pause_every);
        CHECK(paused.stats == whole.stats);
        CHECK(paused.global == whole.global);
    }
}
