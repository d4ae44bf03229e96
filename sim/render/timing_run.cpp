#include "timing_run.hpp"

#include <algorithm>
#include <cstring>


namespace tpsim::render {

std::shared_ptr<TimingRun> run_timing(const core::Program& program, image::MemoryImage& image,
                                      const timing::ChipConfig& chip,
                                      uint64_t max_instructions, uint64_t pixels,
                                      const ProgressCallback& on_progress) {
    auto run = std::make_shared<TimingRun>();
    run->machine =
        timing::make_machine(program, image.words, image.read_only_bytes(), chip, max_instructions);
    core::Machine& machine = *run->machine;
    run->source = std::make_unique<timing::MachineSource>(machine);
    run->chip = std::make_unique<timing::Chip>(chip, *run->source);

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
