#include "sim/render/render.hpp"

#include <chrono>
#include <cstring>
#include <ctime>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "sim/core/error.hpp"
#include "sim/core/fault.hpp"
#include "sim/core/host_threads.hpp"
#include "sim/core/machine.hpp"
#include "sim/core/stack_bound.hpp"
#include "sim/render/native_twin.hpp"
#include "sim/render/profile.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/timing/machine_source.hpp"

namespace tpsim::render {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Runs the kernel on the functional machine over the image, in place.
KernelRun run_functional(const core::Program& program, image::MemoryImage& image,
                         const timing::ChipConfig& chip, uint64_t max_instructions,
                         uint64_t max_item_instructions) {
    const auto machine = timing::make_machine(program, image.words, image.read_only_bytes(), chip,
                                              max_instructions, max_item_instructions);
    // Unless asked for more, one host thread: the functional machine is not faster on two
    // (docs/performance.md, "Host threads").
    machine->run(core::host_threads_set() ? core::host_threads() : 1);
    std::memcpy(image.words.data(), machine->memory().global().data(), image.bytes());
    return {InstructionCounts::of(machine->counters()), machine->output()};
}

}  // namespace

double process_cpu_seconds() {
    timespec now{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return double(now.tv_sec) + 1e-9 * double(now.tv_nsec);
}

InstructionCounts InstructionCounts::of(const core::Counters& counters) {
    InstructionCounts counts;
    counts.total = counters.instructions;
    counts.per_op = counters.per_op;
    for (size_t op = 0; op < counts.per_op.size(); ++op)
        counts.per_fu[size_t(isa::info(isa::Op(op)).fu)] += counts.per_op[op];
    return counts;
}

Kernel Kernel::load(const std::filesystem::path& elf) {
    Kernel kernel{elf, core::load_elf(elf.string()), {}};
    kernel.params = kernel_params(kernel.program);
    return kernel;
}

void Kernel::set_params(const std::vector<std::string>& assignments) {
    render::set_params(params, assignments, elf.filename().string());
    write_params(program, params);
}

bool Kernel::defines(std::string_view symbol_name) const {
    for (const core::Symbol& symbol : program.functions)
        if (symbol.name == symbol_name) return true;
    return false;
}

std::string Kernel::stale_warning() const {
    std::error_code ec;
    const auto built = std::filesystem::last_write_time(elf, ec);
    if (ec) return "";
    for (const core::Program::SourceFile& source : program.line_files) {
        const auto changed = std::filesystem::last_write_time(source.path, ec);
        if (!ec && changed > built)
            return fmt::format("{} is older than its source {}, changed since it was built: this "
                               "runs the old kernel (did the last build fail?); build it again",
                               elf.string(), source.path);
    }
    return "";
}

scene::AccelStructure Kernel::accel() const {
    std::optional<scene::AccelInfo> found;
    for (const scene::AccelInfo& info : scene::kAccelStructures) {
        if (!defines(info.marker)) continue;
        if (found && found->marker != info.marker)
            throw Error(fmt::format("kernel '{}' declares that it traverses both {} and {}; a "
                                    "kernel traverses one structure: keep the marker of the one "
                                    "it reads",
                                    elf.filename().string(), found->description, info.description));
        if (!found) found = info;
    }
    return found ? found->structure : scene::AccelStructure::none;
}

bool Kernel::traverses(scene::AccelStructure structure) const {
    const std::string_view marker = scene::accel_info(structure).marker;
    return marker.empty() ? accel() == scene::AccelStructure::none : defines(marker);
}

bool Kernel::uses_extras() const {
    return defines(trax::layout::kUsesExtrasSymbol);
}

uint64_t default_item_instructions(const scene::Scene& scene) {
    const uint64_t per_ray = std::max<uint64_t>(uint64_t(1) << 22, 256 * scene.triangles.size());
    const uint64_t rays =
        uint64_t(scene.samples_per_pixel) * (1 + (scene.shadows ? scene.lights.size() : 0));
    return per_ray * rays;
}

KernelRun run_kernel(const Kernel& kernel, Engine engine, image::MemoryImage& image,
                     const timing::ChipConfig& chip, uint64_t max_instructions,
                     uint64_t max_item_instructions, TwinProcess twin_process) {
    switch (engine) {
    case Engine::functional:
        return run_functional(kernel.program, image, chip, max_instructions, max_item_instructions);
    case Engine::native:
        return {{},
                run_native_twin(native_twin_of(kernel.elf), image.words,
                                chip.chip.num_tms * chip.chip.tps_per_tm, chip.chip.num_tms,
                                chip.chip.tps_per_tm, kernel.params, twin_process)};
    case Engine::timing: {
        TimingRunOptions watch;
        watch.max_instructions = max_instructions;
        watch.max_item_instructions = max_item_instructions;
        const auto run = run_timing(kernel.program, image, chip, watch);
        return {run->instructions, run->machine->output()};
    }
    }
    return {};
}

std::string check_stack(const Kernel& kernel, Engine engine, const timing::ChipConfig& chip) {
    const core::StackBound bound = core::stack_bound(kernel.program);
    const uint32_t local_store = chip.tp.local_store_bytes;
    if (bound.bounded && bound.bytes > local_store)
        throw Error(fmt::format(
            "stack overflow: kernel '{}' needs up to {} bytes of stack but a thread's local store "
            "holds {} (tp.local_store_bytes), along {}; make its large local arrays smaller or "
            "keep them in global memory, or give --set tp.local_store_bytes={}",
            kernel.elf.filename().string(), bound.bytes, local_store,
            fmt::join(bound.chain, " -> "), (bound.bytes + 15) / 16 * 16));
    if (!bound.bounded && engine == Engine::native)
        return fmt::format("the native twin cannot check the stack against the local store: {}; "
                           "run without --native to have the simulator check it",
                           bound.reason);
    return "";
}

RenderResult render(const RenderOptions& options) {
    RenderResult result;
    auto start = std::chrono::steady_clock::now();
    result.scene = scene::load_scene(options.scene, options.mesh_up);
    if (options.on_warning)
        for (const std::string& warning : result.scene.warnings)
            options.on_warning(warning);
    if (options.image_width != 0) result.scene.width = options.image_width;
    if (options.image_height != 0) result.scene.height = options.image_height;
    if (options.samples_per_pixel != 0) result.scene.samples_per_pixel = options.samples_per_pixel;
    result.load_seconds = seconds_since(start);

    Kernel kernel = Kernel::load(options.kernel);
    kernel.set_params(options.params);
    result.params = kernel.params;
    if (const std::string warning = kernel.stale_warning(); !warning.empty() && options.on_warning)
        options.on_warning(warning);
    if (const std::string warning = check_stack(kernel, options.engine, options.chip);
        !warning.empty() && options.on_warning)
        options.on_warning(warning);
    // The command's settings over the scene file's [accel] table over the kernel's structure.
    const scene::AccelSettings settings = result.scene.accel.under(options.accel);
    result.accel_configs = scene::accel_configs(settings);
    const scene::AccelConfigs& configs = result.accel_configs;
    result.accel = kernel.accel();
    if (settings.structure && !kernel.traverses(*settings.structure)) {
        const scene::AccelInfo asked = scene::accel_info(*settings.structure);
        // Every structure the kernel's marker serves (bvh4 and bvh8 share one).
        std::vector<std::string> traversed;
        for (const scene::AccelInfo& info : scene::kAccelStructures)
            if (kernel.traverses(info.structure)) traversed.emplace_back(info.description);
        throw Error(fmt::format(
            "{} asks for {} but kernel '{}' traverses {}; give a kernel that traverses it (e.g. "
            "--kernel {}) or {}",
            options.accel.structure ? fmt::format("--accel {}", asked.name)
                                    : fmt::format("{}'s [accel] structure = \"{}\"",
                                                  options.scene.string(), asked.name),
            asked.description, kernel.elf.filename().string(),
            traversed.empty() ? std::string(scene::accel_info(result.accel).description)
                              : fmt::format("{}", fmt::join(traversed, " or ")),
            asked.default_kernel,
            options.accel.structure
                ? std::string("leave --accel out")
                : fmt::format("--accel {} to build the kernel's", scene::to_string(result.accel))));
    }
    if (settings.structure) result.accel = *settings.structure;
    const uint32_t width = scene::wide_bvh_width(result.accel);
    if (configs.bvh.boxes == scene::BvhBoxes::quantized && width == 0)
        throw Error(fmt::format("--bvh-boxes quantized applies to the wide BVHs (--accel bvh4 or "
                                "bvh8), not to {}; leave it out (or bvh_boxes in the scene's "
                                "[accel] table) or pick a wide BVH",
                                scene::accel_info(result.accel).description));
    std::optional<scene::Bvh> bvh;
    std::optional<scene::WideBvh> wide_bvh;
    std::optional<scene::Grid> grid;
    std::optional<scene::KdTree> kdtree;
    std::optional<scene::Octree> octree;
    if (result.accel == scene::AccelStructure::bvh2 || width != 0) {
        start = std::chrono::steady_clock::now();
        scene::BvhConfig config = configs.bvh;
        config.traversal_stack_entries = trax::layout::kTraversalStackEntries;
        bvh = scene::build_bvh(result.scene.triangles, config);
        result.bvh_seconds = seconds_since(start);
        result.bvh = bvh->stats;
        if (width != 0) {
            wide_bvh = scene::collapse_bvh(*bvh, width);
            bvh.reset();
            result.wide_bvh = wide_bvh->stats;
            if (wide_bvh->stats.worst_stack > uint32_t(trax::layout::kWideStackEntries))
                throw Error(fmt::format(
                    "the {} may need {} traversal-stack entries on one path but the kernels' "
                    "stack holds {} (trax::layout::kWideStackEntries); use a narrower BVH "
                    "(--accel bvh4 or bvh2) or a larger stack",
                    scene::accel_info(result.accel).description, wide_bvh->stats.worst_stack,
                    trax::layout::kWideStackEntries));
        }
    }
    // Builds a structure, timed into `seconds`; the builder's std::invalid_argument (a scene or
    // option it cannot build from) becomes the run's one-line error.
    const auto timed_build = [](double& seconds, auto build) {
        const auto begin = std::chrono::steady_clock::now();
        try {
            auto built = build();
            seconds = seconds_since(begin);
            return built;
        } catch (const std::invalid_argument& e) {
            throw Error(e.what());
        }
    };
    if (result.accel == scene::AccelStructure::grid) {
        grid = timed_build(result.grid_seconds,
                           [&] { return scene::build_grid(result.scene.triangles, configs.grid); });
        result.grid = grid->stats;
    } else if (result.accel == scene::AccelStructure::kdtree ||
               result.accel == scene::AccelStructure::bsp) {
        scene::KdTreeConfig config = configs.kdtree;
        config.general_planes = result.accel == scene::AccelStructure::bsp;
        kdtree = timed_build(result.kdtree_seconds,
                             [&] { return scene::build_kdtree(result.scene.triangles, config); });
        result.kdtree = kdtree->stats;
    } else if (result.accel == scene::AccelStructure::octree) {
        octree = timed_build(result.octree_seconds, [&] {
            return scene::build_octree(result.scene.triangles, configs.octree);
        });
        result.octree = octree->stats;
    }
    result.threads = options.chip.chip.num_tms * options.chip.chip.tps_per_tm;
    const image::Accel accel = bvh ? image::Accel(&*bvh, configs.bvh.order, configs.bvh.align_pairs)
                               : wide_bvh
                                   ? image::Accel(&*wide_bvh, configs.bvh.order, configs.bvh.boxes)
                               : grid   ? image::Accel(&*grid)
                               : kdtree ? image::Accel(&*kdtree)
                               : octree ? image::Accel(&*octree)
                                        : nullptr;
    result.image = image::build_memory_image(result.scene, accel, result.threads, {},
                                             kernel.uses_extras() ? std::optional(options.seed)
                                                                  : std::nullopt);

    const uint64_t item_limit = options.max_item_instructions != 0
                                    ? options.max_item_instructions
                                    : default_item_instructions(result.scene);
    start = std::chrono::steady_clock::now();
    const double cpu_start = process_cpu_seconds();
    if (options.engine == Engine::timing) {
        result.timing =
            run_timing(kernel.program, result.image, options.chip,
                       {options.max_instructions, item_limit,
                        uint64_t(result.scene.width) * result.scene.height, options.on_progress,
                        options.timeline_interval, options.profile, options.sampling});
        if (options.profile)
            result.profile = std::make_shared<const Profile>(
                profile_of(result.timing->chip->profile(), kernel.program));
        result.instructions = result.timing->instructions;
        result.output = result.timing->machine->output();
        result.host_threads = result.timing->host_threads;
        result.host_threads_share = result.timing->host_threads_share;
    } else {
        KernelRun run = run_kernel(kernel, options.engine, result.image, options.chip,
                                   options.max_instructions, item_limit, options.twin_process);
        result.instructions = run.instructions;
        result.output = std::move(run.output);
        if (options.engine == Engine::functional && core::host_threads_set())
            result.host_threads = std::min(core::host_threads(), result.threads);
    }
    result.run_seconds = seconds_since(start);
    result.run_cpu_seconds = process_cpu_seconds() - cpu_start;
    result.traversal = image::read_thread_stats(result.image.header, result.image.words.data());
    if (result.traversal.stack_overflows > 0) {
        const std::string message = fmt::format(
            "the kernel's BVH traversal stack overflowed {} times: it filled at {} entries but the "
            "BVH is {} levels deep; give the stack {} entries (trax::layout::"
            "kTraversalStackEntries: tpsim builds no BVH deeper than a stack that size can walk)",
            result.traversal.stack_overflows, result.traversal.max_stack_depth,
            result.bvh ? result.bvh->max_depth : 0, trax::layout::kTraversalStackEntries);
        throw core::KernelError(message, std::move(result.output));
    }
    result.rgb = image::read_framebuffer(result.image.header, result.image.words.data());
    return result;
}

}  // namespace tpsim::render
