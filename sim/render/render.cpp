#include "render.hpp"

#include <chrono>
#include <cstring>

#include <fmt/format.h>

#include "native_twin.hpp"
#include "sim/core/elf_loader.hpp"
#include "sim/core/error.hpp"
#include "sim/core/machine.hpp"
#include "sim/scene/load_scene.hpp"

namespace tpsim::render {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Runs the kernel ELF on the functional machine over the image, in place.
InstructionCounts run_functional(const RenderOptions& options, image::MemoryImage& image,
                                 uint32_t threads) {
    core::MachineConfig config;
    config.threads = threads;
    config.threads_per_tm = options.chip.chip.tps_per_tm;
    config.local_store_bytes = options.chip.tp.local_store_bytes;
    config.global_bytes = uint32_t(image.bytes());
    config.max_instructions = options.max_instructions;
    core::Machine machine(core::load_elf(options.kernel), config);
    std::memcpy(machine.memory().global().data(), image.words.data(), image.bytes());
    machine.run();
    std::memcpy(image.words.data(), machine.memory().global().data(), image.bytes());

    InstructionCounts counts;
    counts.total = machine.counters().instructions;
    counts.per_op = machine.counters().per_op;
    for (size_t op = 0; op < counts.per_op.size(); ++op)
        counts.per_fu[size_t(isa::info(isa::Op(op)).fu)] += counts.per_op[op];
    return counts;
}

}  // namespace

RenderResult render(const RenderOptions& options) {
    RenderResult result;
    auto start = std::chrono::steady_clock::now();
    result.scene = scene::load_scene(options.scene);
    result.load_seconds = seconds_since(start);

    std::optional<scene::Bvh> bvh;
    if (options.bvh) {
        start = std::chrono::steady_clock::now();
        bvh = scene::build_bvh(result.scene.triangles, *options.bvh);
        result.bvh_seconds = seconds_since(start);
        result.bvh = bvh->stats;
    }
    result.image = image::build_memory_image(result.scene, bvh ? &*bvh : nullptr);
    result.threads = options.chip.chip.num_tms * options.chip.chip.tps_per_tm;

    start = std::chrono::steady_clock::now();
    switch (options.engine) {
        case Engine::functional:
            result.instructions = run_functional(options, result.image, result.threads);
            break;
        case Engine::native:
            run_native_twin(native_twin_of(options.kernel), result.image.words, result.threads,
                            options.chip.chip.num_tms, options.chip.chip.tps_per_tm);
            break;
    }
    result.run_seconds = seconds_since(start);
    result.rgb = image::read_framebuffer(result.image.header, result.image.words.data());
    return result;
}

}  // namespace tpsim::render
