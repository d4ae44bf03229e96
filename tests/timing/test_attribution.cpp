// Where the cycles and the bytes go (timing/attribution.hpp): every breakdown the chip keeps
// beside its totals (by memory region, by work item, by instruction address) adds up exactly
// to those totals, on real renders over chips of several shapes.
#include "sim/core/elf_loader.hpp"
#include "sim/render/profile.hpp"
#include "sim/render/render.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/timing/machine_source.hpp"

#include <catch2/catch.hpp>

#include <cstring>
#include <memory>
#include <string>

using namespace tpsim;
using namespace tpsim::timing;

namespace {

ChipConfig tiny() {
    return load_config(TPSIM_CONFIG_DIR "/tiny.toml");
}

/// A chip of odd shape: two L2s (the second with one TM), 70 TPs per TM (the multi-word bit
/// sets), a write-combining buffer too small for the TPs' open lines.
ChipConfig odd_chip() {
    ChipConfig c = tiny();
    for (const char* o : {"chip.num_tms=3", "chip.tps_per_tm=70", "chip.tms_per_l2=2",
                          "icache.threads_per_icache=35", "l2.write_combining_lines=3"})
        apply_override(c, o);
    return c;
}

/// The odd chip with a small finite I-cache (2 KiB per 35 TPs): its misses add instruction
/// lines to the L2 and DRAM traffic and fetch-miss stalls to the profile.
ChipConfig finite_icache_chip() {
    ChipConfig c = odd_chip();
    apply_override(c, "icache.size_bytes=2048");
    return c;
}

render::RenderResult render_on(const ChipConfig& chip, const char* scene, uint32_t size) {
    render::RenderOptions options;
    options.scene = scene;
    options.kernel = TPSIM_KERNEL_DIR "/tracer.elf";
    options.engine = render::Engine::timing;
    options.image_width = options.image_height = size;
    options.chip = chip;
    return render::render(options);
}

/// The chip's statistics, read by name.
struct Stats {
    explicit Stats(const Chip& chip) : chip(chip) { chip.register_stats(registry); }
    uint64_t operator()(const std::string& name) const { return registry.at(name).integer(); }
    /// `leaf` (e.g. "l1/reads") summed over every region, "other" included, and a finite
    /// I-cache's instruction lines where it has the leaf.
    uint64_t regions(const std::string& leaf) const {
        uint64_t sum = (*this)("region/other/" + leaf);
        for (const Region& r : chip.layout().regions)
            sum += (*this)("region/" + r.name + "/" + leaf);
        if (registry.contains("region/instruction_fetch/" + leaf))
            sum += (*this)("region/instruction_fetch/" + leaf);
        return sum;
    }
    const Chip& chip;
    stats::Registry registry;
};

void check_region_totals(const Chip& chip, const ChipConfig& config) {
    const Stats s(chip);
    const uint64_t line = config.l1.line_bytes;
    for (const char* level : {"l1", "l2"})
        for (const char* leaf : {"reads", "writes", "hits", "misses", "merged_misses"}) {
            INFO(level << '/' << leaf);
            CHECK(s.regions(fmt::format("{}/{}", level, leaf)) ==
                  s(fmt::format("chip/{}/{}", level, leaf)));
        }
    const uint64_t icache_misses = config.icache.finite() ? s("chip/icache/misses") : 0;
    CHECK(s.regions("l2/reads") == s("chip/l1/misses") + icache_misses);
    if (config.icache.finite()) {
        CHECK(icache_misses > 0);
        CHECK(s("region/instruction_fetch/l2/reads") == icache_misses);
        CHECK(s("region/instruction_fetch/l2/payload_bytes") == line * icache_misses);
        CHECK(s("region/instruction_fetch/dram/reads") > 0);
        CHECK(s("chip/stalls/fetch_miss") > 0);
    } else {
        CHECK_FALSE(s.registry.contains("chip/stalls/fetch_miss"));
        CHECK_FALSE(s.registry.contains("region/instruction_fetch/l2/reads"));
    }
    CHECK(s.regions("l2/writes") == s("chip/l1/writes"));
    CHECK(s.regions("dram/reads") == s("dram/reads"));
    CHECK(s.regions("dram/writes") == s("dram/writes"));
    const uint64_t dram_bytes = s("dram/bytes_read") + s("dram/bytes_written");
    CHECK(s.regions("dram/moved_bytes") == dram_bytes);
    CHECK(s.regions("l2/moved_bytes") == dram_bytes);
    CHECK(s.regions("dram/payload_bytes") == s("dram/bytes_read") + s("dram/store_payload_bytes"));
    // L1 moves its missed lines and the stores' payload; L2 is asked for both.
    const uint64_t store_bytes = s.regions("l1/moved_bytes") - line * s("chip/l1/misses");
    CHECK(s.regions("l2/payload_bytes") == line * s("chip/l2/reads") + store_bytes);
    if (config.l2.write_combining_lines == 0)
        CHECK(s("dram/store_payload_bytes") == store_bytes);
    else
        CHECK(s("dram/store_payload_bytes") <= store_bytes);
    // Every load and store went to the L1 or the local store once; every fetch issued.
    CHECK(s.regions("l1/reads") + s.regions("l1/writes") +
              s("region/local_store/local_store/loads") +
              s("region/local_store/local_store/stores") ==
          s("chip/class/load") + s("chip/class/store"));
    // A finite I-cache's fetches that missed (or found no MSHR) used their bank too.
    const uint64_t refetches =
        config.icache.finite()
            ? icache_misses + s("chip/icache/merged_misses") + s("chip/icache/mshr_full")
            : 0;
    CHECK(s("region/instruction_fetch/icache/fetches") == s("chip/instructions") + refetches);
}

}  // namespace

TEST_CASE("traffic by region adds up to the chip's totals", "[attribution][regions]") {
    struct Case {
        const char* name;
        ChipConfig chip;
        const char* scene;
        uint32_t size;
    };
    const Case cases[] = {
        {"cornell, default chip", ChipConfig{}, TPSIM_SCENE_DIR "/cornell.toml", 32},
        {"cornell, tiny chip", tiny(), TPSIM_SCENE_DIR "/cornell.toml", 32},
        {"bunny, default chip", ChipConfig{}, TPSIM_SCENE_DIR "/bunny.toml", 24},
        {"cornell, odd chip", odd_chip(), TPSIM_SCENE_DIR "/cornell.toml", 32},
        {"cornell, odd chip, finite I-cache", finite_icache_chip(), TPSIM_SCENE_DIR "/cornell.toml",
         32},
    };
    for (const Case& c : cases) {
        INFO(c.name);
        const render::RenderResult result = render_on(c.chip, c.scene, c.size);
        const Chip& chip = *result.timing->chip;
        REQUIRE(chip.layout().regions.size() >= 7);
        check_region_totals(chip, c.chip);
        // The tracer writes each pixel's three floats once and each thread's record once.
        const Stats s(chip);
        const uint32_t threads = c.chip.chip.num_tms * c.chip.chip.tps_per_tm;
        CHECK(s("region/framebuffer/l1/writes") == 3 * c.size * c.size);
        CHECK(s("region/framebuffer/l1/reads") == 0);
        CHECK(s("region/thread_stats/l1/writes") == 8 * threads);
        CHECK(s("region/bvh_nodes/l1/reads") > 0);
        CHECK(s("region/triangles/l1/reads") > 0);
        CHECK(s("region/bvh_nodes/l1/writes") == 0);
        CHECK(s("region/local_store/local_store/payload_bytes") > 0);  // the kernel's stack
    }
}

namespace {

constexpr uint32_t kFramebuffer = 0x1000'1000;  // programs/framebuffer.S
constexpr uint32_t kPixels = 256;

/// programs/framebuffer.S on `config`, with its framebuffer as the one region.
struct FramebufferRun {
    explicit FramebufferRun(const ChipConfig& config) {
        core::MachineConfig machine_config = machine_config_for(config);
        machine_config.global_bytes = 1 << 16;
        machine = std::make_unique<core::Machine>(
            core::load_elf(TPSIM_TIMING_PROGRAMS "/framebuffer.elf"), machine_config);
        source = std::make_unique<MachineSource>(*machine);
        ChipLayout layout;
        layout.regions = {{"framebuffer", kFramebuffer, kFramebuffer + 12 * kPixels}};
        for (const core::Machine::CodeRange& range : machine->code())
            layout.text.push_back({range.base, range.words});
        layout.work_items = kPixels;
        chip = std::make_unique<Chip>(config, *source, layout);
        chip->run(10'000'000);
    }
    std::vector<uint8_t> framebuffer() const {
        const auto global = machine->memory().global();
        const size_t at = kFramebuffer - trax::map::kGlobalBase;
        return {global.begin() + at, global.begin() + at + 12 * kPixels};
    }
    std::unique_ptr<core::Machine> machine;
    std::unique_ptr<MachineSource> source;
    std::unique_ptr<Chip> chip;
};

}  // namespace

TEST_CASE("write-combining writes a framebuffer to DRAM once per line, write-around once per "
          "store",
          "[attribution][regions][write_combining]") {
    ChipConfig around = tiny();
    ChipConfig combining = around;
    apply_override(combining, "l2.write_combining_lines=4");  // 4 TPs keep at most 3 lines open
    const FramebufferRun a(around), c(combining);
    const Stats sa(*a.chip), sc(*c.chip);
    const uint64_t line = around.l2.line_bytes;
    const uint64_t stores = 3 * kPixels, lines = 12 * kPixels / line;
    CHECK(sa("region/framebuffer/l1/writes") == stores);
    CHECK(sa("region/framebuffer/dram/writes") == stores);
    CHECK(sa("region/framebuffer/dram/moved_bytes") == stores * line);
    CHECK(sa("region/framebuffer/dram/payload_bytes") == stores * 4);
    CHECK(sc("region/framebuffer/l1/writes") == stores);
    CHECK(sc("region/framebuffer/dram/writes") == lines);
    CHECK(sc("region/framebuffer/dram/moved_bytes") == lines * line);
    CHECK(sc("region/framebuffer/dram/payload_bytes") == lines * line);
    CHECK(sc("dram/bytes_written") == 12 * kPixels);
    CHECK(sa("dram/bytes_written") == 16 * sc("dram/bytes_written"));
    check_region_totals(*a.chip, around);
    check_region_totals(*c.chip, combining);
    // Both policies write the same image: pixel p holds p, p + 1, p + 2.
    const std::vector<uint8_t> image = a.framebuffer();
    CHECK(image == c.framebuffer());
    for (uint32_t p = 0; p < kPixels; ++p)
        for (uint32_t k = 0; k < 3; ++k) {
            uint32_t word;
            std::memcpy(&word, &image[12 * p + 4 * k], 4);
            REQUIRE(word == p + k);
        }
}

namespace {

WorkItemCounters sum(const WorkItemCosts& costs) {
    WorkItemCounters total = costs.unassigned;
    for (const WorkItemCounters& item : costs.items) {
        total.cycles += item.cycles;
        total.instructions += item.instructions;
        total.dram_bytes += item.dram_bytes;
    }
    return total;
}

/// Items plus unassigned hold every instruction, every DRAM byte and every TP-cycle of every
/// thread until it exited.
void check_work_item_totals(const Chip& chip) {
    const Stats s(chip);
    const WorkItemCounters total = sum(chip.work_items());
    CHECK(total.instructions == s("chip/instructions"));
    CHECK(total.dram_bytes == s("dram/bytes_read") + s("dram/bytes_written"));
    CHECK(total.cycles == s("chip/active_tp_cycles"));
    CHECK(chip.work_items().unassigned.instructions > 0);  // startup and the fetch past the end
}

}  // namespace

TEST_CASE("costs by work item add up to the chip's totals", "[attribution][work_items]") {
    for (const ChipConfig& chip : {ChipConfig{}, tiny(), odd_chip(), finite_icache_chip()}) {
        const render::RenderResult result = render_on(chip, TPSIM_SCENE_DIR "/cornell.toml", 32);
        const WorkItemCosts& costs = result.timing->chip->work_items();
        REQUIRE(costs.items.size() == 32 * 32);
        check_work_item_totals(*result.timing->chip);
        for (const WorkItemCounters& item : costs.items) {
            REQUIRE(item.instructions > 0);
            REQUIRE(item.cycles >= item.instructions);
        }
    }
}

TEST_CASE("each framebuffer pixel costs its 12 instructions and, with write-around, its three "
          "line writes",
          "[attribution][work_items]") {
    const FramebufferRun run(tiny());
    const WorkItemCosts& costs = run.chip->work_items();
    REQUIRE(costs.items.size() == kPixels);
    check_work_item_totals(*run.chip);
    for (const WorkItemCounters& item : costs.items) {
        REQUIRE(item.instructions == 12);  // atominc, bge, 6 address and value ops, 3 sw, j
        REQUIRE(item.dram_bytes == 3 * 64);
    }
    CHECK(costs.unassigned.dram_bytes == 0);
}

namespace {

/// The tracer on the 32x32 Cornell box with the profile on.
struct ProfiledRun {
    explicit ProfiledRun(const ChipConfig& config) {
        scene::Scene scene = scene::load_scene(TPSIM_SCENE_DIR "/cornell.toml");
        scene.width = scene.height = 32;
        scene::BvhConfig bvh_config;
        bvh_config.traversal_stack_entries = trax::layout::kTraversalStackEntries;
        const scene::Bvh bvh = scene::build_bvh(scene.triangles, bvh_config);
        image =
            image::build_memory_image(scene, &bvh, config.chip.num_tms * config.chip.tps_per_tm);
        core::MachineConfig machine_config = machine_config_for(config);
        machine_config.global_bytes = uint32_t(image.bytes());
        machine_config.read_only_global_bytes = uint32_t(image.read_only_bytes());
        machine = std::make_unique<core::Machine>(core::load_elf(TPSIM_KERNEL_DIR "/tracer.elf"),
                                                  machine_config);
        std::memcpy(machine->memory().global().data(), image.words.data(), image.bytes());
        source = std::make_unique<MachineSource>(*machine);
        ChipLayout layout = render::chip_layout(image, *machine);
        layout.profile = true;
        chip = std::make_unique<Chip>(config, *source, layout);
        chip->run();
    }
    image::MemoryImage image;
    std::unique_ptr<core::Machine> machine;
    std::unique_ptr<MachineSource> source;
    std::unique_ptr<Chip> chip;
};

}  // namespace

TEST_CASE("the profile by instruction adds up to the chip's totals", "[attribution][profile]") {
    for (const ChipConfig& config : {ChipConfig{}, tiny(), odd_chip(), finite_icache_chip()}) {
        const ProfiledRun run(config);
        const Chip& chip = *run.chip;
        const Stats s(chip);
        const PcProfile& profile = chip.profile();
        REQUIRE(run.machine->code().size() == 1);
        REQUIRE(profile.words.size() == run.machine->code().front().words);
        PcCounters total;
        for (const PcCounters& pc : profile.words) {
            total.executions += pc.executions;
            for (size_t c = 0; c < kStallCauses; ++c)
                total.stalls[c] += pc.stalls[c];
            total.l1_misses += pc.l1_misses;
            total.dram_bytes += pc.dram_bytes;
        }
        CHECK(total.executions == s("chip/instructions"));
        for (size_t c = 0; c < kStallCauses; ++c) {
            const std::string_view cause = render::kStallNames[c];
            INFO(cause);
            // The tracer stalls for every cause but sync (it uses no barrier or semaphore), and
            // for fetch misses with a finite I-cache only (which alone has the key).
            const bool stalls =
                Stall(c) == Stall::FetchMiss ? config.icache.finite() : Stall(c) != Stall::Sync;
            CHECK((total.stalls[c] > 0) == stalls);
            if (Stall(c) != Stall::FetchMiss || config.icache.finite())
                CHECK(total.stalls[c] == s(fmt::format("chip/stalls/{}", cause)));
        }
        CHECK(total.l1_misses == s("chip/l1/misses"));
        CHECK(total.dram_bytes == s("dram/bytes_read") + s("dram/bytes_written"));
        // The same run without the profile: the profile changes nothing else.
        const render::RenderResult plain = render_on(config, TPSIM_SCENE_DIR "/cornell.toml", 32);
        CHECK(plain.timing->chip->profile().words.empty());
        CHECK(Stats(*plain.timing->chip)("chip/cycles") == s("chip/cycles"));
    }
}
