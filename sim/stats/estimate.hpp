// Estimates of a whole run's statistics from a systematic sample of measured intervals, with
// confidence intervals: the statistics side of sampled simulation (sim/render/sampling.hpp).
//
// The run is split into three parts: a head and a tail measured exactly, and a body of which
// n short units were measured. Every counter's body total is estimated with the ratio
// estimator against the body's instructions, which are known exactly (Cochran, Sampling
// Techniques, 3rd ed., 1977, ch. 6): T = W * sum(x_i) / sum(w_i), with w_i the instructions of
// unit i and W those of the body. Its variance, treating the systematic sample as a simple
// random one as SMARTS does (Wunderlich et al., ISCA 2003), is N^2 (1 - n/N) s_d^2 / n with
// d_i = x_i - R w_i and N = W / mean(w_i) units in the body. Sums and formulas (rates, hit
// rates, utilisations) are recomputed from the estimated counters (Registry::derive); their
// intervals come from the same residuals, linearised through each formula (the delta method).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "sim/stats/registry.hpp"

namespace tpsim::stats {

/// What a sampled run measured, for the chip statistics it sampled (integer counters, each
/// also registered under the same name in the registry estimate() is given).
struct UnitSamples {
    std::vector<std::string> names;             ///< the sampled counters
    std::vector<std::vector<double>> per_unit;  ///< [counter][unit]: each unit's increase
    std::vector<double> exact;                  ///< [counter]: head + tail, measured whole
    std::vector<double> unit_instructions;      ///< [unit]: the ratio estimator's weights
    double body_instructions = 0;               ///< instructions in the sampled body
};

/// Estimated statistics of a whole run.
struct Estimate {
    Snapshot values;  ///< every statistic; sampled ones and their formulas estimated
    /// Per value: the interval's half-width; 0: exact; NaN: unknown, for an event so rare
    /// that fewer than 5 units saw one (or none did, but the head or tail did).
    std::vector<double> half_width;
    double confidence = 0.95;
    size_t units = 0;  ///< n

    /// The half-width of the value called `name` (0 when exact, NaN when unknown); throws
    /// std::out_of_range.
    double interval(std::string_view name) const;
};

/// Estimates every statistic of `registry` from the run's final snapshot `measured` (whose
/// values for sampled counters cover only the simulated stretches) and the samples. Values
/// the samples do not name are exact and kept, formulas are recomputed. Throws
/// std::invalid_argument with fewer than two units (no variance can be estimated).
Estimate estimate(const Registry& registry, const Snapshot& measured, const UnitSamples& samples,
                  double confidence = 0.95);

/// The two-sided quantile of Student's t distribution with `dof` degrees of freedom for a
/// `confidence` interval (0.95: about 1.96 for many degrees of freedom, 2.26 for 9).
double student_t_quantile(double confidence, double dof);

}  // namespace tpsim::stats
