#include "timing_run.hpp"

#include <algorithm>
#include <cstring>

#include "sim/core/elf_loader.hpp"

namespace tpsim::render {

std::shared_ptr<TimingRun> run_timing(const std::filesystem::path& kernel_elf,
                                      image::MemoryImage& image, const timing::ChipConfig& chip,
                                      uint64_t max_instructions, uint64_t pixels,
                                      const ProgressCallback& on_progress) {
    core::MachineConfig config = timing::machine_config_for(chip);
    config.global_bytes = uint32_t(image.bytes());
    config.read_only_global_bytes = uint32_t(image.read_only_bytes());
    config.max_instructions = max_instructions;

    auto run = std::make_shared<TimingRun>();
    run->machine = std::make_unique<core::Machine>(core::load_elf(kernel_elf), config);
    core::Machine& machine = *run->machine;
    std::memcpy(machine.memory().global().data(), image.words.data(), image.bytes());
    run->source = std::make_unique<timing::MachineSource>(machine);
    run->chip = std::make_unique<timing::Chip>(chip, *run->source, chip_layout(image, machine));

    // Paused every kProgressInterval cycles for the progress report. Threads take one pixel
    // past the end before they stop, hence the cap.
    timing::Chip& model = *run->chip;
    constexpr uint64_t kInterval = timing::Chip::kProgressInterval;
    for (uint64_t until = kInterval; !model.run_until(until); until += kInterval)
        if (on_progress)
            on_progress({std::min<uint64_t>(machine.global_register(0), pixels), pixels,
                         model.cycles()});
    std::memcpy(image.words.data(), machine.memory().global().data(), image.bytes());

    run->instructions = InstructionCounts::of(machine.counters());
    return run;
}

}  // namespace tpsim::render
