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

    timing::Chip::ProgressHook hook;
    if (on_progress)
        hook = [&](uint64_t cycles) {
            // Threads take one pixel past the end before they stop, hence the cap.
            on_progress({std::min<uint64_t>(machine.global_register(0), pixels), pixels, cycles});
        };
    run->chip->run(UINT64_MAX, hook);
    std::memcpy(image.words.data(), machine.memory().global().data(), image.bytes());

    run->instructions = InstructionCounts::of(machine.counters());
    return run;
}

}  // namespace tpsim::render
