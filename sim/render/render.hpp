// One render: scene file -> BVH -> memory image -> kernel on the simulated machine (or its native
// twin) -> framebuffer, with everything the report needs.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "isa/isa.hpp"
#include "kernel/kernel_output.hpp"
#include "sim/core/elf_loader.hpp"
#include "sim/image/memory_image.hpp"
#include "sim/render/kernel_params.hpp"
#include "sim/render/native_twin.hpp"
#include "sim/render/sampling.hpp"
#include "sim/scene/accel.hpp"
#include "sim/scene/accel_settings.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/grid.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/scene/scene.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::core {
struct Counters;
}

namespace tpsim::render {

enum class Engine {
    functional,  ///< the simulator without timing: every instruction, no cycles
    native,      ///< the kernel's native twin on the host: the reference image
    timing,      ///< the simulator under the cycle-level chip model (sim/timing): cycles too
};

/// How far a cycle-level run has come, for a progress display.
struct Progress {
    uint64_t pixels_done = 0;  ///< global register 0 (the kernels' pixel counter), capped
    uint64_t pixels = 0;       ///< pixels in the image
    uint64_t cycles = 0;       ///< simulated so far
};
using ProgressCallback = std::function<void(const Progress&)>;

struct TimingRun;  // timing_run.hpp
struct Profile;    // profile.hpp

/// A kernel, its ELF parsed once: the program every engine runs (the native twin is found next
/// to the ELF) and what the pipeline needs to know of it.
struct Kernel {
    std::filesystem::path elf;
    core::Program program;
    /// The run-time parameters it declares (TRAX_PARAM), with the values every engine runs with.
    std::vector<KernelParam> params;

    /// Throws tpsim::Error (one line) for an ELF tpsim cannot run.
    static Kernel load(const std::filesystem::path& elf);
    /// Sets parameters from NAME=VALUE assignments (render --param) in the program and for the
    /// twin. Throws tpsim::Error for an unknown name or a bad value (set_params).
    void set_params(const std::vector<std::string>& assignments);
    /// The structure the kernel traverses, from the marker its ELF defines (trax::layout::
    /// kUsesBvhSymbol, kUsesGridSymbol); none for brute force. Throws tpsim::Error for a kernel
    /// that defines more than one.
    scene::AccelStructure accel() const;
    /// Can the kernel traverse `structure` (does it define the structure's marker; for none:
    /// no marker at all)? bvh4 and bvh8 share one.
    bool traverses(scene::AccelStructure structure) const;
    /// Does the kernel read the SceneExtras record (define trax::layout::kUsesExtrasSymbol)?
    bool uses_extras() const;
    /// Does the ELF define a function (or code label) of this name?
    bool defines(std::string_view symbol_name) const;
    /// A warning when a source file the ELF was compiled from (its DWARF line table names them)
    /// changed after the ELF was written: the build that would have replaced it failed or was
    /// not run, and the run is of the old kernel. Empty when the ELF is up to date.
    std::string stale_warning() const;
};

struct RenderOptions {
    std::filesystem::path scene;                   ///< scene file (.toml) or a bare mesh
    scene::UpAxis mesh_up = scene::UpAxis::pos_y;  ///< a bare mesh's up axis, turned to +y
    std::filesystem::path kernel;                  ///< kernel ELF; its twin is found next to it
    /// The kernel's run-time parameters as NAME=VALUE (render --param); the rest keep their
    /// defaults.
    std::vector<std::string> params;
    Engine engine = Engine::functional;
    /// Engine::native: in a child process (a crash becomes an error) or in this one (gdb).
    TwinProcess twin_process = TwinProcess::child;
    /// The structure to build and its settings, as the command asked for them (render --accel,
    /// --bvh-order ...); what it leaves unset comes from the scene file's [accel] table, then
    /// from the kernel (the structure it traverses; bvh4 for a wide-BVH kernel) and the
    /// builders' defaults. Only that structure is built: a kernel that traverses another is
    /// refused. render() sets the BVH's depth limit to the kernels' stack capacity
    /// (trax::layout::kTraversalStackEntries); a BSP tree is the kd-tree's builder with
    /// general planes.
    scene::AccelSettings accel;
    /// Override the scene file's image size and samples per pixel when non-zero
    /// (render --width/--height/--spp; tests render small images).
    uint32_t image_width = 0, image_height = 0, samples_per_pixel = 0;
    /// The run seed trax_rand() mixes into its default seeding (render --seed); reaches the
    /// kernel in the SceneExtras record, which only kernels that read it get.
    uint32_t seed = 0;
    timing::ChipConfig chip;                        ///< shape (TMs x TPs) and local-store size
    uint64_t max_instructions = uint64_t(1) << 32;  ///< per thread, for runaway kernels
    /// Per work item (core::MachineConfig::max_item_instructions), for runaway kernels;
    /// 0: default_item_instructions(scene).
    uint64_t max_item_instructions = 0;
    ProgressCallback on_progress;  ///< Engine::timing calls it now and then while it runs
    /// Called with each of the scene's warnings (Scene::warnings) as soon as it is loaded.
    std::function<void(const std::string&)> on_warning;
    uint64_t timeline_interval = 0;  ///< Engine::timing: cycles per timeline row, 0 = adapt
    bool profile = false;  ///< Engine::timing: collect the source-line profile (RenderResult)
    /// Engine::timing: sampled simulation (sampling.hpp) instead of every cycle.
    std::optional<SamplingOptions> sampling;
};

/// Instruction counts of a simulated run.
struct InstructionCounts {
    uint64_t total = 0;
    std::array<uint64_t, size_t(isa::Op::Count)> per_op{};
    std::array<uint64_t, size_t(isa::FuClass::Count)> per_fu{};

    /// A machine's counts, with the per-FU-class totals derived from the per-opcode ones.
    static InstructionCounts of(const core::Counters& counters);
};

/// What run_kernel() reports of a run.
struct KernelRun {
    InstructionCounts instructions;  ///< zero for the native twin
    trax::KernelOutput output;       ///< what the kernel printed
};

struct RenderResult {
    scene::Scene scene;                                         ///< as loaded (triangles included)
    scene::AccelStructure accel = scene::AccelStructure::none;  ///< what the kernel traverses
    /// The builders' settings the run used (RenderOptions::accel over the scene file's).
    scene::AccelConfigs accel_configs;
    /// When a BVH was built (for a wide BVH, the binary tree it was collapsed from).
    std::optional<scene::BvhStats> bvh;
    std::optional<scene::WideBvhStats> wide_bvh;  ///< when a wide BVH was built
    std::optional<scene::GridStats> grid;         ///< when a grid was built
    std::optional<scene::KdTreeStats> kdtree;     ///< when a kd-tree or BSP tree was built
    std::optional<scene::OctreeStats> octree;     ///< when an octree was built
    image::MemoryImage image;                     ///< the memory image after the run
    image::TraversalTotals traversal;             ///< the kernel's per-thread statistics, summed
    std::vector<float> rgb;                       ///< framebuffer, linear RGB, row 0 at the top
    InstructionCounts instructions;               ///< zero for the native engine
    trax::KernelOutput output;                    ///< what the kernel printed (trax_printf)
    std::vector<KernelParam> params;              ///< the kernel's parameters as the run set them
    uint32_t threads = 0;
    std::shared_ptr<const TimingRun> timing;  ///< Engine::timing: the chip and its counters
    std::shared_ptr<const Profile> profile;   ///< RenderOptions::profile: by function and line
    /// Host wall clock: loading the scene, building the BVH or the grid, running the kernel.
    double load_seconds = 0, bvh_seconds = 0, grid_seconds = 0, kdtree_seconds = 0,
           octree_seconds = 0, run_seconds = 0;
    /// The host threads the kernel run used: at most `host_threads`, for this share of its
    /// instructions (the rest on one; TimingRun).
    uint32_t host_threads = 1;
    double host_threads_share = 1;
    /// Host CPU time of the kernel run (process CPU time around it): the simulator's cost,
    /// which the machine's load disturbs much less than wall time (tpsim sample-check); it
    /// does not see the native twin's child process.
    double run_cpu_seconds = 0;
};

/// This process's CPU time so far, every thread's, user and system (CLOCK_PROCESS_CPUTIME_ID).
double process_cpu_seconds();

/// Runs the whole pipeline. Throws tpsim::Error (or a scene::SceneError) with one clear line,
/// also when a traversal stack overflowed.
RenderResult render(const RenderOptions& options);

/// The default limit on the instructions a thread retires on one work item (a pixel) before it
/// is stopped as a runaway: 2^22 per ray, or 256 per triangle per ray above 16,384 triangles,
/// times the rays of a pixel (samples x (1 + shadow rays)). The kernels here need ~2,000
/// instructions per ray with the BVH and ~140 per triangle per ray by brute force, so no real
/// render comes near it, while an endless loop on the default chip and scene (the Cornell box,
/// 128 threads) is stopped after about 10^9 instructions (under a minute of cycle-level
/// simulation).
uint64_t default_item_instructions(const scene::Scene& scene);

/// Runs a kernel over a memory image, in place, on the chosen engine with the chip's thread
/// shape: the building block of render() and of tests that bring their own image (ray_query).
KernelRun run_kernel(const Kernel& kernel, Engine engine, image::MemoryImage& image,
                     const timing::ChipConfig& chip, uint64_t max_instructions = uint64_t(1) << 32,
                     uint64_t max_item_instructions = 0,
                     TwinProcess twin_process = TwinProcess::child);

/// Throws tpsim::Error when the kernel's deepest call chain (core::stack_bound) needs more stack
/// than a thread's local store holds: every engine refuses such a kernel before it runs, the
/// simulator as the twin, whose host stack would not notice. Returns a warning when the stack
/// cannot be bounded (recursion, calls through pointers) and the engine is the twin, which then
/// cannot tell an overflow; "" otherwise.
std::string check_stack(const Kernel& kernel, Engine engine, const timing::ChipConfig& chip);

}  // namespace tpsim::render
