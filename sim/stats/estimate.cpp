#include "sim/stats/estimate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

namespace tpsim::stats {

namespace {

/// The standard normal quantile: P. J. Acklam's rational approximation (relative error below
/// 1.2e-9), refined by one Halley step.
double normal_quantile(double p) {
    constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                            1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
    constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                            6.680131188771972e+01, -1.328068155288572e+01};
    constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                            -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
    constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                            3.754408661907416e+00};
    constexpr double low = 0.02425;
    double x = 0;
    if (p < low) {
        const double q = std::sqrt(-2 * std::log(p));
        x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    } else if (p <= 1 - low) {
        const double q = p - 0.5, r = q * q;
        x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
            (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
    } else {
        const double q = std::sqrt(-2 * std::log(1 - p));
        x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
            ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    }
    const double e = 0.5 * std::erfc(-x / std::numbers::sqrt2) - p;
    const double u = e * std::sqrt(2 * std::numbers::pi) * std::exp(x * x / 2);
    return x - u / (1 + x * u / 2);
}

}  // namespace

double student_t_quantile(double confidence, double dof) {
    const double p = 0.5 + confidence / 2;  // upper quantile of the two-sided interval
    if (dof <= 1) return std::tan(std::numbers::pi * (p - 0.5));
    if (dof <= 2) {
        const double a = 4 * p * (1 - p);
        return 2 * (p - 0.5) * std::sqrt(2 / a);
    }
    // Abramowitz & Stegun 26.7.5: the Cornish-Fisher expansion in 1/dof, four terms (within
    // 0.1 % of the tables from 3 degrees of freedom on).
    const double z = normal_quantile(p), z2 = z * z;
    const double g1 = (z2 + 1) * z / 4;
    const double g2 = ((5 * z2 + 16) * z2 + 3) * z / 96;
    const double g3 = (((3 * z2 + 19) * z2 + 17) * z2 - 15) * z / 384;
    const double g4 = ((((79 * z2 + 776) * z2 + 1482) * z2 - 1920) * z2 - 945) * z / 92160;
    return z + g1 / dof + g2 / (dof * dof) + g3 / (dof * dof * dof) + g4 / (dof * dof * dof * dof);
}

double Estimate::interval(std::string_view name) const {
    const std::vector<Value>& v = values.values();
    for (size_t i = 0; i < v.size(); ++i)
        if (v[i].name == name) return half_width[i];
    throw std::out_of_range(fmt::format("no statistic named '{}' in the estimate", name));
}

Estimate estimate(const Registry& registry, const Snapshot& measured, const UnitSamples& samples,
                  double confidence) {
    const size_t n = samples.unit_instructions.size();
    if (n < 2)
        throw std::invalid_argument(
            fmt::format("estimate: {} measured unit{}; at least 2 are needed for an interval", n,
                        n == 1 ? "" : "s"));
    double weights = 0;
    for (double w : samples.unit_instructions)
        weights += w;
    const double units_in_body = std::max(double(n), samples.body_instructions / (weights / n));
    // Var(total) = scale * sample variance of the residuals.
    const double scale = units_in_body * units_in_body * (1 - double(n) / units_in_body) / n;

    Estimate result;
    result.confidence = confidence;
    result.units = n;
    result.values = measured;
    std::vector<Value>& values = result.values.values();
    // Each value's residuals d_i (empty: exact), from which its variance follows.
    std::vector<std::vector<double>> residuals(values.size());
    // Rare events (cold misses, DRAM reads) that most units never see: with fewer than
    // kFewestUnitsSeen units seeing one, the residuals say little of their spread (the usual
    // rule for a normal approximation to counts: at least 5 of them), and with none the body
    // may still hold many if the head or tail saw some. Their intervals are unknown.
    constexpr size_t kFewestUnitsSeen = 5;
    std::vector<bool> unknown(values.size(), false);
    std::map<std::string, size_t, std::less<>> sampled;
    for (size_t k = 0; k < samples.names.size(); ++k)
        sampled.emplace(samples.names[k], k);
    for (size_t i = 0; i < values.size(); ++i) {
        const auto it = sampled.find(values[i].name);
        if (it == sampled.end()) continue;
        const std::vector<double>& x = samples.per_unit[it->second];
        double sum = 0;
        size_t seen = 0;
        for (double xi : x) {
            sum += xi;
            seen += xi != 0;
        }
        const double ratio = sum / weights;
        const double total = ratio * samples.body_instructions + samples.exact[it->second];
        values[i].integer = uint64_t(std::llround(std::max(total, 0.0)));
        residuals[i].resize(n);
        for (size_t u = 0; u < n; ++u)
            residuals[i][u] = x[u] - ratio * samples.unit_instructions[u];
        const bool rare = seen < n && seen < kFewestUnitsSeen;
        unknown[i] =
            rare && (seen > 0 || samples.exact[it->second] > 0) && units_in_body > double(n);
    }
    result.values = registry.derive(result.values);

    // Sums and formulas: residuals linearised through the formula at the estimate, with
    // central differences (the formulas are smooth where their denominators are not 0).
    const std::vector<Entry>& entries = registry.entries();
    std::vector<double> inputs;
    for (size_t i = 0; i < entries.size(); ++i) {
        const Entry& e = entries[i];
        if (e.inputs.empty() || !residuals[i].empty()) continue;
        const bool any_sampled = std::any_of(e.inputs.begin(), e.inputs.end(),
                                             [&](size_t k) { return !residuals[k].empty(); });
        if (!any_sampled) continue;
        std::vector<double>& d = residuals[i];
        d.assign(n, 0.0);
        inputs.clear();
        for (size_t k : e.inputs)
            inputs.push_back(values[k].value());
        for (size_t j = 0; j < e.inputs.size(); ++j) {
            const std::vector<double>& dj = residuals[e.inputs[j]];
            if (dj.empty()) continue;
            // Not linearised: the unknown part of the input may be large.
            if (unknown[e.inputs[j]]) unknown[i] = true;
            double slope = 1;  // a sum
            if (e.formula) {
                const double h = 1e-6 * std::max(std::abs(inputs[j]), 1.0);
                std::vector<double> up = inputs, down = inputs;
                up[j] += h, down[j] -= h;
                slope = (e.formula(up) - e.formula(down)) / (2 * h);
            }
            for (size_t u = 0; u < n; ++u)
                d[u] += slope * dj[u];
        }
    }

    const double t = student_t_quantile(confidence, double(n - 1));
    result.half_width.assign(values.size(), 0.0);
    for (size_t i = 0; i < values.size(); ++i) {
        const std::vector<double>& d = residuals[i];
        if (d.empty()) continue;
        if (unknown[i]) {
            result.half_width[i] = std::numeric_limits<double>::quiet_NaN();
            continue;
        }
        double mean = 0;
        for (double di : d)
            mean += di;
        mean /= double(n);
        double squares = 0;
        for (double di : d)
            squares += (di - mean) * (di - mean);
        result.half_width[i] = t * std::sqrt(scale * squares / double(n - 1));
    }
    return result;
}

}  // namespace tpsim::stats
