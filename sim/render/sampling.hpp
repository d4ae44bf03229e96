// Sampled cycle-level simulation: SMARTS (Wunderlich, Wenisch, Falsafi and Hoe, "SMARTS:
// Accelerating Microarchitecture Simulation via Rigorous Statistical Sampling", ISCA 2003)
// adapted to a chip of many threads. Every instruction executes; most of them under functional
// warming (timing::Chip::warm: caches and DRAM rows kept warm, no cycles), and at a fixed period
// of instructions the cycle-level model takes over for a warm-up stretch and a measured unit of
// cycles, then drains. The run's head (from the cold start through the first unit) and its tail
// (from the moment a thread runs out of work to the end) are simulated cycle by cycle and
// measured whole; the body between them is estimated from the units (stats::estimate).
// docs/error-vs-time.md says how it works, what it assumes, and how well it does.
#pragma once
#include <cstdint>
#include <functional>

#include "sim/stats/estimate.hpp"
#include "sim/stats/registry.hpp"
#include "sim/timing/chip.hpp"

namespace tpsim::render {

struct SamplingOptions {
    /// Share of the body's instructions simulated cycle by cycle (warm-up, unit and drain);
    /// the rest is warmed functionally.
    double rate = 0.02;
    uint64_t unit_cycles = 2000;    ///< cycles measured per unit
    uint64_t warmup_cycles = 2000;  ///< cycle-level warm-up before each unit, not measured
    uint32_t seed = 1;              ///< picks the sample's random start

    /// Throws tpsim::Error naming the bad field.
    void validate() const;
};

/// What a sampled run did, for the report.
struct SamplingSummary {
    SamplingOptions options;
    uint64_t units = 0;                ///< units measured
    uint64_t period_instructions = 0;  ///< instructions from one unit's start to the next
    uint64_t head_instructions = 0;    ///< measured whole, from the start
    uint64_t body_instructions = 0;    ///< estimated from the units
    uint64_t tail_instructions = 0;    ///< measured whole, to the end
    uint64_t warmed_instructions = 0;  ///< executed under functional warming
    uint64_t simulated_cycles = 0;     ///< cycles the cycle-level model ran, drains included
    /// The head reached the tail: every figure is measured, none estimated.
    bool exact = false;

    /// Fewest units whose intervals can be trusted: with fewer, a frame's rare slow stretches
    /// are missed by most samples and the intervals come out too narrow (measured coverage of
    /// frame cycles 28-62 % with 2-11 units, 95-100 % from 27 on: docs/error-vs-time.md).
    static constexpr uint64_t kTrustedUnits = 30;
    /// An estimate from fewer units than kTrustedUnits.
    bool too_few_units() const { return !exact && units < kTrustedUnits; }
    /// The rate at which this run would have measured about kTrustedUnits units.
    double rate_for_trusted_units() const;
};

/// Runs the chip (fresh, over a machine source) to its end, sampled. `chip_stats` holds the
/// chip's statistics (Chip::register_stats); `progress` is called now and then. Returns the
/// units and the exactly measured remainder for stats::estimate (nothing to estimate:
/// summary.exact).
stats::UnitSamples run_sampled(timing::Chip& chip, const stats::Registry& chip_stats,
                               const SamplingOptions& options, SamplingSummary& summary,
                               const std::function<void()>& progress);

}  // namespace tpsim::render
