// One render: scene file -> BVH -> memory image -> kernel on the simulated machine (or its native
// twin) -> framebuffer, with everything the report needs.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "isa/isa.hpp"
#include "sim/image/memory_image.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/scene.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::render {

enum class Engine {
    functional,  ///< the simulator without timing: every instruction, no cycles
    native,      ///< the kernel's native twin on the host: the reference image
};

struct RenderOptions {
    std::filesystem::path scene;   ///< scene file (.toml) or a bare mesh
    std::filesystem::path kernel;  ///< kernel ELF; its twin is found next to it
    Engine engine = Engine::functional;
    /// BVH to build, or none for kernels that do not traverse one (it is then left out of the
    /// memory image).
    std::optional<scene::BvhConfig> bvh = scene::BvhConfig{};
    timing::ChipConfig chip;       ///< shape (TMs x TPs) and local-store size
    uint64_t max_instructions = uint64_t(1) << 32;  ///< per thread, for runaway kernels
};

/// Instruction counts of a simulated run.
struct InstructionCounts {
    uint64_t total = 0;
    std::array<uint64_t, size_t(isa::Op::Count)> per_op{};
    std::array<uint64_t, size_t(isa::FuClass::Count)> per_fu{};
};

struct RenderResult {
    scene::Scene scene;                      ///< as loaded (triangles included)
    std::optional<scene::BvhStats> bvh;      ///< when a BVH was built
    image::MemoryImage image;                ///< the memory image after the run
    std::vector<float> rgb;                  ///< framebuffer, linear RGB, row 0 at the top
    InstructionCounts instructions;          ///< zero for the native engine
    uint32_t threads = 0;
    double load_seconds = 0, bvh_seconds = 0, run_seconds = 0;  ///< host wall clock
};

/// Runs the whole pipeline. Throws tpsim::Error (or a scene::SceneError) with one clear line.
RenderResult render(const RenderOptions& options);

}  // namespace tpsim::render
