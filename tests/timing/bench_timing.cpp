// bench_timing [--profile] SCENE KERNEL_ELF [CONFIG.toml] [STATS.json]: renders on the
// cycle-level engine (with --profile, collecting the per-instruction profile)
// without the image-file libraries (so valgrind --tool=callgrind can run it) and prints the
// simulation speed in host CPU time. STATS.json gets the chip statistics, for comparing runs
// before and after an optimisation (they must be identical).
#include "sim/core/elf_loader.hpp"
#include "sim/image/memory_image.hpp"
#include "sim/render/timing_run.hpp"  // chip_layout() only (inline): no image-file libraries
#include "sim/scene/bvh.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/timing/machine_source.hpp"

#include <fmt/format.h>

#include <cstring>
#include <ctime>
#include <fstream>
#include <iostream>

using namespace tpsim;

int main(int argc, char** argv) try {
    const bool profile = argc > 1 && std::string_view(argv[1]) == "--profile";
    argc -= profile;
    argv += profile;
    if (argc < 3) {
        std::cerr << "usage: bench_timing [--profile] SCENE KERNEL_ELF [CONFIG.toml] "
                     "[STATS.json]\n";
        return 2;
    }
    const timing::ChipConfig chip = argc > 3 ? timing::load_config(argv[3]) : timing::ChipConfig{};
    const scene::Scene scene = scene::load_scene(argv[1]);
    scene::BvhConfig bvh_config;
    bvh_config.traversal_stack_entries = trax::layout::kTraversalStackEntries;
    const scene::Bvh bvh = scene::build_bvh(scene.triangles, bvh_config);
    const uint32_t threads = chip.chip.num_tms * chip.chip.tps_per_tm;
    image::MemoryImage image = image::build_memory_image(scene, &bvh, threads);

    const auto machine_ptr = timing::make_machine(core::load_elf(argv[2]), image.words,
                                                  image.read_only_bytes(), chip, uint64_t(1) << 32);
    core::Machine& machine = *machine_ptr;
    timing::MachineSource source(machine);
    timing::ChipLayout layout = render::chip_layout(image, machine);
    layout.profile = profile;
    timing::Chip model(chip, source, layout);

    const std::clock_t start = std::clock();
    model.run();
    const double seconds = double(std::clock() - start) / CLOCKS_PER_SEC;
    const uint64_t instructions = machine.counters().instructions;
    fmt::print("{} instructions, {} cycles, {:.3f} s CPU = {:.2f} M instructions/s\n", instructions,
               model.cycles(), seconds, double(instructions) / seconds / 1e6);
    if (argc > 4) {
        stats::Registry registry;
        model.register_stats(registry);
        std::ofstream json(argv[4]);
        json << stats::values_json(stats::Snapshot(registry)).dump(1) << "\n";
    }
    return 0;
} catch (const std::exception& e) {
    std::cerr << "bench_timing: " << e.what() << '\n';
    return 1;
}
