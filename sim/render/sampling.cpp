#include "sim/render/sampling.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "sim/core/error.hpp"

namespace tpsim::render {

void SamplingOptions::validate() const {
    if (!(rate > 0 && rate <= 1))
        throw Error(fmt::format("the sampling rate must be in (0, 1], got {}", rate));
    if (unit_cycles == 0) throw Error("the sampling unit must be at least 1 cycle");
}

double SamplingSummary::rate_for_trusted_units() const {
    const double scaled =
        options.rate * double(kTrustedUnits) / double(std::max<uint64_t>(units, 1));
    return std::min(1.0, scaled);
}

namespace {

/// Every additive integer statistic of the chip: the ones a unit's interval measures.
std::vector<size_t> sampled_entries(const stats::Registry& chip_stats) {
    std::vector<size_t> sampled;
    const std::vector<stats::Entry>& entries = chip_stats.entries();
    for (size_t i = 0; i < entries.size(); ++i)
        if (entries[i].is_integer() && entries[i].additive) sampled.push_back(i);
    return sampled;
}

}  // namespace

stats::UnitSamples run_sampled(timing::Chip& chip, const stats::Registry& chip_stats,
                               const SamplingOptions& options, SamplingSummary& summary,
                               const std::function<void()>& progress) {
    options.validate();
    summary = {};
    summary.options = options;
    const std::vector<size_t> sampled = sampled_entries(chip_stats);
    const size_t instructions_entry = chip_stats.index("chip/instructions");
    const auto executed = [&](const stats::Snapshot& s) {
        return s.values()[instructions_entry].integer;  // issued cycle by cycle
    };
    // Instructions executed so far: issued by the cycle-level model plus warmed.
    const auto done = [&](const stats::Snapshot& s) {
        return executed(s) + chip.warmed_instructions();
    };
    const uint32_t threads = chip.running_threads();
    const auto tail_begun = [&] { return chip.finished() || chip.running_threads() < threads; };

    stats::UnitSamples samples;
    for (size_t i : sampled)
        samples.names.push_back(chip_stats.entries()[i].name);
    samples.per_unit.resize(sampled.size());
    const auto add_unit = [&](const stats::Snapshot& from, const stats::Snapshot& to) {
        for (size_t k = 0; k < sampled.size(); ++k)
            samples.per_unit[k].push_back(
                double(to.values()[sampled[k]].integer - from.values()[sampled[k]].integer));
        samples.unit_instructions.push_back(double(executed(to) - executed(from)));
    };

    // The head: from the cold start through one warm-up and one unit, cycle by cycle.
    chip.run_until(options.warmup_cycles + options.unit_cycles);
    const stats::Snapshot head(chip_stats);
    const uint64_t head_done = done(head);
    summary.head_instructions = head_done;
    // The period, fixed for the run so that where units fall does not depend on what they
    // measure: one cycle-level stretch like the head's per `rate` of the instructions.
    const uint64_t period =
        std::max<uint64_t>(uint64_t(std::ceil(double(head_done) / options.rate)), head_done);
    summary.period_instructions = period;

    // The body, until a thread runs out of work: a random start, then one stretch per period.
    stats::Snapshot tail_start = head;
    // Without a body the run was measured whole; with one, it needs units to be estimated,
    // even if the random start put the first unit past its end.
    const bool has_body = !tail_begun();
    if (has_body) {
        chip.drain();
        std::mt19937_64 random(options.seed);
        const double start = double(random() >> 11) * 0x1p-53;  // in [0, 1)
        bool exited = chip.warm(uint64_t(start * double(period))).reached_exit;
        while (!exited && !tail_begun()) {
            progress();
            const stats::Snapshot stretch(chip_stats);
            const uint64_t stretch_done = done(stretch);
            tail_start = stretch;
            chip.run_until(chip.cycles() + options.warmup_cycles);
            if (tail_begun()) break;
            const stats::Snapshot unit_start(chip_stats);
            chip.run_until(chip.cycles() + options.unit_cycles);
            if (tail_begun()) break;
            const stats::Snapshot unit_end(chip_stats);
            add_unit(unit_start, unit_end);
            chip.drain();
            tail_start = stats::Snapshot(chip_stats);
            if (tail_begun()) break;
            const uint64_t spent = done(tail_start) - stretch_done;
            exited = chip.warm(period > spent ? period - spent : 0).reached_exit;
            tail_start = stats::Snapshot(chip_stats);
        }
    }
    const uint64_t tail_done = done(tail_start);

    // The tail, cycle by cycle to the end.
    while (!chip.run_until(chip.cycles() + timing::Chip::kProgressInterval))
        progress();
    const stats::Snapshot end(chip_stats);

    summary.units = samples.unit_instructions.size();
    summary.body_instructions = tail_done - head_done;
    summary.tail_instructions = done(end) - tail_done;
    summary.warmed_instructions = chip.warmed_instructions();
    summary.simulated_cycles = chip.cycles();
    // Measured whole only if nothing was left to estimate (the head reached the tail).
    summary.exact = summary.body_instructions == 0;
    samples.body_instructions = double(summary.body_instructions);
    for (size_t k = 0; k < sampled.size(); ++k) {
        const size_t i = sampled[k];
        samples.exact.push_back(double(head.values()[i].integer + end.values()[i].integer -
                                       tail_start.values()[i].integer));
    }
    return samples;
}

}  // namespace tpsim::render
