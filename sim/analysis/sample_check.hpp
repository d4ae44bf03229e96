// `tpsim sample-check`: how accurate and how fast sampled cycle-level simulation
// (render --timing sampled, sim/render/sampling.hpp) is on one scene and chip. Renders the frame
// once cycle by cycle (the truth), once functionally (the bound: every instruction still
// executes when sampled), and sampled at several rates and seeds; compares each estimate and
// its 95 % interval with the truth, and each run's host CPU time with the full run's
// (docs/error-vs-time.md, "Measured").
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/render/render.hpp"
#include "sim/render/sampling.hpp"

namespace tpsim::analysis {

/// A statistic sample-check holds against the truth.
struct CheckedStatistic {
    const char* key;    ///< its name in the statistics (docs/statistics.md)
    const char* label;  ///< for a person: "frame cycles"
};
/// Frame cycles, DRAM bytes read and written, L1 hit rate.
const std::vector<CheckedStatistic>& checked_statistics();

struct SampleCheckOptions {
    /// What every run shares: scene, kernel, chip, image size. The engine and the sampling are
    /// set per run; on_progress hears from the cycle-level and sampled runs.
    render::RenderOptions base;
    std::vector<double> rates = {0.005, 0.01, 0.02, 0.05};
    /// Unit and warm-up of every sampled run; its rate and seed are set per run.
    render::SamplingOptions sampling;
    uint32_t seeds = 1;  ///< seeds 1..seeds at each rate
    /// The full run, the functional run and each rate's seed 1 are timed this many times, in
    /// rounds (each round runs every kind once, so a slow spell of the host touches all).
    uint32_t repeat = 1;
    /// Called before each render, with its number (from 0), how many there are and what it is
    /// ("rate 0.01, seed 3").
    std::function<void(size_t index, size_t count, const std::string& label)> on_run;

    /// Throws tpsim::Error for rates, seeds or repeats that cannot give a measurement.
    void validate() const;
};

/// One statistic of one sampled run against the full run.
struct StatisticCheck {
    double estimate = 0;
    /// Of the 95 % interval; 0 when measured whole (exact), NaN when unknown (too rare).
    double half_width = 0;
    double truth = 0;  ///< the full run's value

    /// Relative to the truth (0 when both are 0).
    double error() const;
    double relative_half_width() const;
    /// The interval contains the truth (an unknown one contains nothing).
    bool covered() const;
};

struct SampledRun {
    double rate = 0;
    uint32_t seed = 0;
    /// Why this rate gave no estimate (too few units before the threads ran out of work), or
    /// empty.
    std::string refused;
    bool exact = false;  ///< the run ended within its head: measured whole
    uint64_t units = 0;
    double cycle_level_share = 0;        ///< of the instructions, not warmed functionally
    bool same_image = false;             ///< bit for bit the full run's
    std::vector<double> cpu_seconds;     ///< of the kernel run, one per timing
    std::vector<StatisticCheck> checks;  ///< as checked_statistics()
};

/// Coverage and error of one statistic over the seeds of one rate.
struct Coverage {
    size_t covered = 0, runs = 0;
    double mean_error = 0;         ///< the bias, relative
    double rms_error = 0;          ///< root mean square, relative
    double median_half_width = 0;  ///< relative
};

struct SampleCheckResult {
    uint32_t width = 0, height = 0, samples_per_pixel = 0, threads = 0;
    uint64_t instructions = 0;
    std::vector<double> truth;  ///< the full run's, as checked_statistics()
    std::vector<double> full_cpu_seconds, functional_cpu_seconds;
    /// CPU time of what every render does before its kernel runs (scene, BVH, memory image),
    /// left out of the timings: the first full run's.
    double setup_cpu_seconds = 0;
    std::vector<double> rates;     ///< the options' rates, ascending
    std::vector<SampledRun> runs;  ///< by rate, then seed

    /// The runs at `rate`.
    std::vector<const SampledRun*> at(double rate) const;
    /// Median CPU seconds of every timing at `rate`; NaN when every run there was refused.
    double cpu_seconds(double rate) const;
    /// The full run's CPU time over the functional run's: the median of the rounds' ratios,
    /// each of two runs made minutes apart (a drift of the host's speed between rounds, which
    /// CPU time shows too on a shared virtual machine, cancels).
    double functional_speedup() const;
    /// The same for seed 1 at `rate`; when seed 1 was refused, the full run's median time over
    /// cpu_seconds(rate).
    double speedup(double rate) const;
    /// Over the seeds at `rate` that gave an estimate.
    Coverage coverage(double rate, size_t statistic) const;
};

/// Runs the measurement. Throws tpsim::Error for bad options before anything renders, or with
/// what failed in a render.
SampleCheckResult sample_check(const SampleCheckOptions& options);

/// The median of `values` (not empty).
double median(std::vector<double> values);

/// The tables: setup, full run and bound; frame cycles by rate (seed 1) with host time and
/// speedup; the other statistics by rate (seed 1); coverage over the seeds when there are
/// several.
std::string sample_check_table(const SampleCheckOptions& options, const SampleCheckResult& result);

/// The result as a file (format "tpsim-sample-check", version 1; docs/error-vs-time.md), from
/// which the HTML page is made (html_report.hpp).
nlohmann::ordered_json sample_check_document(const SampleCheckOptions& options,
                                             const SampleCheckResult& result);

}  // namespace tpsim::analysis
