// The cycle-level engine: the functional machine executes each instruction when the chip model
// (sim/timing) fetches it, and the chip decides when it issues and completes.
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>

#include "kernel/memory_map.hpp"
#include "sim/core/machine.hpp"
#include "sim/image/memory_image.hpp"
#include "sim/render/render.hpp"
#include "sim/render/sampling.hpp"
#include "sim/render/timeline.hpp"
#include "sim/timing/chip.hpp"
#include "sim/timing/machine_source.hpp"

namespace tpsim::render {

/// A finished cycle-level run. The chip keeps its counters for register_stats(); the machine
/// and source stay alive beside it because the chip refers to them.
struct TimingRun {
    std::unique_ptr<core::Machine> machine;
    std::unique_ptr<timing::MachineSource> source;
    std::unique_ptr<timing::Chip> chip;
    timing::ChipConfig config;  ///< the chip's configuration, for the energy and area estimate
    std::unique_ptr<Timeline> timeline;  ///< none for a sampled run
    InstructionCounts instructions;
    /// The host threads it ran on: at most `host_threads`, for this share of its instructions
    /// (with --threads unset a run chooses between one and all cores as it goes).
    uint32_t host_threads = 1;
    double host_threads_share = 1;
    /// A sampled run: what it did, and what it measured for stats::estimate().
    std::optional<SamplingSummary> sampling;
    stats::UnitSamples samples;
};

/// What the chip is told about a run: the image's non-empty sections and the kernel's ELF
/// segments as regions, the kernel's text, and one work item per pixel (per ray for a batch).
inline timing::ChipLayout chip_layout(const image::MemoryImage& image,
                                      const core::Machine& machine) {
    timing::ChipLayout layout;
    for (const image::SectionSize& section : image.sections)
        if (section.bytes != 0)
            layout.regions.push_back(
                {section.name, uint32_t(trax::map::kGlobalBase + section.begin),
                 uint32_t(trax::map::kGlobalBase + section.begin + section.bytes)});
    // The kernel's own ELF image (constants in .rodata, .data, .bss): below the global memory.
    const auto& segments = machine.program().segments;
    if (!segments.empty())
        layout.regions.push_back({"kernel_data", segments.front().vaddr, segments.back().end()});
    for (const core::Machine::CodeRange& range : machine.code())
        layout.text.push_back({range.base, range.words});
    const auto& header = image.header;
    layout.work_items =
        uint32_t(header.rays.count > 0 ? header.rays.count : header.framebuffer.count);
    return layout;
}

/// How a cycle-level run is watched while it runs.
struct TimingRunOptions {
    uint64_t max_instructions = uint64_t(1) << 32;  ///< per thread, for runaway kernels
    uint64_t max_item_instructions = 0;             ///< per work item (0: no limit)
    uint64_t pixels = 0;                            ///< scales the progress reports (0: none)
    ProgressCallback on_progress;    ///< every timing::Chip::kProgressInterval cycles
    uint64_t timeline_interval = 0;  ///< cycles between timeline samples; 0: adapt (Timeline)
    /// Collect the chip's per-instruction profile (Chip::profile(); about 11 % slower).
    bool profile = false;
    /// Sampled simulation (sampling.hpp) instead of every cycle; no timeline, no profile.
    std::optional<SamplingOptions> sampling;
};

/// Runs `program` over `image` (in place) on the chip `chip`. Throws core::Fault on a guest
/// fault and std::runtime_error on a timing deadlock.
std::shared_ptr<TimingRun> run_timing(const core::Program& program, image::MemoryImage& image,
                                      const timing::ChipConfig& chip,
                                      const TimingRunOptions& options = {});

}  // namespace tpsim::render
