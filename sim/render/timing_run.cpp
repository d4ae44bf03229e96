#include "sim/render/timing_run.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <optional>

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/core/host_threads.hpp"

namespace tpsim::render {

std::shared_ptr<TimingRun> run_timing(const core::Program& program, image::MemoryImage& image,
                                      const timing::ChipConfig& chip,
                                      const TimingRunOptions& options) {
    auto run = std::make_shared<TimingRun>();
    run->machine = timing::make_machine(program, image.words, image.read_only_bytes(), chip,
                                        options.max_instructions, options.max_item_instructions);
    core::Machine& machine = *run->machine;
    run->source = std::make_unique<timing::MachineSource>(machine);
    timing::ChipLayout layout = chip_layout(image, machine);
    layout.profile = options.profile;
    run->chip = std::make_unique<timing::Chip>(chip, *run->source, layout);
    run->config = chip;
    timing::Chip& model = *run->chip;
    // --threads unset: sampled runs stay on one host thread (their units of a few thousand
    // cycles are too short to share), full runs choose as they go.
    std::optional<core::HostThreadChoice> choice;
    // At most one host thread per TM (Chip::use_host_threads).
    const uint32_t most = std::min(core::host_threads(), chip.chip.num_tms);
    if (core::host_threads_set()) {
        model.use_host_threads(core::host_threads());
        run->host_threads = most;
    } else if (!options.sampling) {
        choice.emplace(core::host_threads());
    }
    stats::Registry chip_stats;
    model.register_stats(chip_stats);
    const auto report = [&] {
        if (options.on_progress)
            options.on_progress({std::min<uint64_t>(machine.global_register(0), options.pixels),
                                 options.pixels, model.cycles()});
    };
    if (options.sampling) {
        if (options.profile)
            throw Error("the profile needs every cycle simulated: use --timing cycle");
        SamplingSummary summary;
        run->samples = run_sampled(model, chip_stats, *options.sampling, summary, report);
        if (!summary.exact && summary.units < 2)
            throw Error(fmt::format(
                "sampled simulation measured {} unit{} before the threads ran out of work, too "
                "few to estimate from; raise --sample-rate or shorten --sample-unit, or use "
                "--timing cycle for a run this short",
                summary.units, summary.units == 1 ? "" : "s"));
        run->sampling = summary;
        std::memcpy(image.words.data(), machine.memory().global().data(), image.bytes());
        run->instructions = InstructionCounts::of(machine.counters());
        return run;
    }
    run->timeline = std::make_unique<Timeline>(
        chip_stats, chip.chip.num_tms * chip.chip.tps_per_tm,
        [&model] { return model.running_threads(); }, options.timeline_interval);
    Timeline& timeline = *run->timeline;

    // The chip pauses for each timeline sample and progress report. Threads take one pixel
    // past the end before they stop, hence the cap.
    constexpr uint64_t kInterval = timing::Chip::kProgressInterval;
    uint64_t next_report = kInterval;
    uint64_t on_most = 0;  // instructions simulated on `most` host threads, as chosen
    const auto run_chunk = [&](uint64_t until) {
        if (!choice) return model.run_until(until);
        const uint32_t threads = choice->next();
        model.use_host_threads(threads);
        const uint64_t before = machine.counters().instructions;
        const auto start = std::chrono::steady_clock::now();
        const bool finished = model.run_until(until);
        const uint64_t work = machine.counters().instructions - before;
        choice->ran(
            work, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        if (threads > 1) on_most += work;
        return finished;
    };
    while (!run_chunk(std::min(next_report, timeline.next_sample()))) {
        if (model.cycles() == timeline.next_sample()) timeline.sample(model.cycles());
        if (model.cycles() == next_report) {
            next_report += kInterval;
            report();
        }
    }
    timeline.sample(model.cycles());
    std::memcpy(image.words.data(), machine.memory().global().data(), image.bytes());

    run->instructions = InstructionCounts::of(machine.counters());
    if (choice && on_most != 0) {
        run->host_threads = most;
        run->host_threads_share = double(on_most) / double(run->instructions.total);
    }
    return run;
}

}  // namespace tpsim::render
