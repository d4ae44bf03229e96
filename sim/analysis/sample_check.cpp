#include "sim/analysis/sample_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/render/report.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/stats/thousands.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::analysis {

const std::vector<CheckedStatistic>& checked_statistics() {
    static const std::vector<CheckedStatistic> list = {{"chip/cycles", "frame cycles"},
                                                       {"dram/bytes_read", "DRAM bytes read"},
                                                       {"dram/bytes_written", "DRAM bytes written"},
                                                       {"chip/l1/hit_rate", "L1 hit rate"}};
    return list;
}

void SampleCheckOptions::validate() const {
    if (rates.empty()) throw Error("give at least one sampling rate (--rates 0.01,0.02)");
    for (double rate : rates) {
        render::SamplingOptions one = sampling;
        one.rate = rate;
        one.validate();
        if (std::count(rates.begin(), rates.end(), rate) > 1)
            throw Error(fmt::format("the rate {} is given twice in --rates", rate));
    }
    if (seeds == 0) throw Error("--seeds must be at least 1");
    if (repeat == 0) throw Error("--repeat must be at least 1");
}

double StatisticCheck::error() const {
    if (estimate == truth) return 0;
    return (estimate - truth) / std::abs(truth);  // +-inf for a true 0: no relative error
}

double StatisticCheck::relative_half_width() const {
    if (half_width == 0) return 0;
    return half_width / std::abs(truth);
}

bool StatisticCheck::covered() const {
    return std::abs(estimate - truth) <= half_width;
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

std::vector<const SampledRun*> SampleCheckResult::at(double rate) const {
    std::vector<const SampledRun*> found;
    for (const SampledRun& run : runs)
        if (run.rate == rate) found.push_back(&run);
    return found;
}

double SampleCheckResult::cpu_seconds(double rate) const {
    std::vector<double> all;
    for (const SampledRun* run : at(rate))
        all.insert(all.end(), run->cpu_seconds.begin(), run->cpu_seconds.end());
    return all.empty() ? std::nan("") : median(all);
}

namespace {

/// The median over rounds of full[k] / other[k].
double median_ratio(const std::vector<double>& full, const std::vector<double>& other) {
    std::vector<double> ratios;
    for (size_t k = 0; k < full.size(); ++k)
        ratios.push_back(full[k] / other[k]);
    return median(ratios);
}

}  // namespace

double SampleCheckResult::functional_speedup() const {
    return median_ratio(full_cpu_seconds, functional_cpu_seconds);
}

double SampleCheckResult::speedup(double rate) const {
    const SampledRun& first = *at(rate).front();
    if (first.cpu_seconds.size() == full_cpu_seconds.size())
        return median_ratio(full_cpu_seconds, first.cpu_seconds);
    return median(full_cpu_seconds) / cpu_seconds(rate);
}

Coverage SampleCheckResult::coverage(double rate, size_t statistic) const {
    Coverage c;
    std::vector<double> widths;
    for (const SampledRun* run : at(rate)) {
        if (!run->refused.empty()) continue;
        const StatisticCheck& check = run->checks[statistic];
        ++c.runs;
        c.covered += check.covered();
        c.mean_error += check.error();
        c.rms_error += check.error() * check.error();
        // An unknown interval is the widest of all.
        const double width = check.relative_half_width();
        widths.push_back(std::isnan(width) ? std::numeric_limits<double>::infinity() : width);
    }
    if (c.runs == 0) return c;
    c.mean_error /= double(c.runs);
    c.rms_error = std::sqrt(c.rms_error / double(c.runs));
    c.median_half_width = median(widths);
    return c;
}

namespace {

std::string rate_text(double rate) {
    return fmt::format("{}", rate);
}

/// Renders one run; the setup's CPU time (all but the kernel run) goes to `setup_cpu_seconds`.
render::RenderResult render_timed(const render::RenderOptions& options,
                                  double* setup_cpu_seconds = nullptr) {
    const double start = render::process_cpu_seconds();
    render::RenderResult result = render::render(options);
    if (setup_cpu_seconds)
        *setup_cpu_seconds = render::process_cpu_seconds() - start - result.run_cpu_seconds;
    return result;
}

std::vector<double> values_of(const render::RunStatistics& statistics) {
    std::vector<double> values;
    for (const CheckedStatistic& s : checked_statistics())
        values.push_back(statistics.values.value(s.key));
    return values;
}

/// What a later round found differs from the first: a run that is not deterministic.
void check_same(bool same, const std::string& what) {
    if (!same)
        throw Error(fmt::format("{} gave different statistics when run again; tpsim runs are "
                                "meant to be deterministic: please report this as a bug",
                                what));
}

/// One sampled render at `rate` and `seed`, checked against the full run's values and image.
SampledRun sampled_run(const SampleCheckOptions& options, double rate, uint32_t seed,
                       const std::vector<double>& truth, const std::vector<float>& full_image) {
    render::RenderOptions sampled = options.base;
    sampled.engine = render::Engine::timing;
    sampled.sampling = options.sampling;
    sampled.sampling->rate = rate;
    sampled.sampling->seed = seed;
    SampledRun run;
    run.rate = rate;
    run.seed = seed;
    try {
        const render::RenderResult r = render_timed(sampled);
        const render::RunStatistics statistics = render::run_statistics(r);
        const render::SamplingSummary& summary = *r.timing->sampling;
        run.cpu_seconds.push_back(r.run_cpu_seconds);
        run.exact = summary.exact;
        run.units = summary.units;
        run.cycle_level_share =
            1 - double(summary.warmed_instructions) / double(r.instructions.total);
        run.same_image = r.rgb == full_image;
        const std::vector<double> estimates = values_of(statistics);
        for (size_t s = 0; s < estimates.size(); ++s) {
            const char* key = checked_statistics()[s].key;
            run.checks.push_back({estimates[s],
                                  statistics.estimate ? statistics.estimate->interval(key) : 0.0,
                                  truth[s]});
        }
    } catch (const Error& e) {
        // Too few units at this rate: a finding for the table, not a failure. A kernel fault
        // would have stopped the full run already.
        run.refused = e.what();
    }
    return run;
}

}  // namespace

SampleCheckResult sample_check(const SampleCheckOptions& options) {
    options.validate();
    SampleCheckResult result;
    result.rates = options.rates;
    std::sort(result.rates.begin(), result.rates.end());
    const std::vector<double>& rates = result.rates;
    const size_t count = options.repeat * (2 + rates.size()) + rates.size() * (options.seeds - 1);
    size_t index = 0;
    const auto announce = [&](const std::string& label) {
        if (options.on_run) options.on_run(index, count, label);
        ++index;
    };

    std::vector<float> full_image;
    render::RenderOptions full = options.base;
    full.engine = render::Engine::timing;
    full.sampling.reset();
    render::RenderOptions functional = options.base;
    functional.engine = render::Engine::functional;
    functional.sampling.reset();
    functional.on_progress = nullptr;  // only the chip model reports progress

    for (uint32_t round = 0; round < options.repeat; ++round) {
        announce("full cycle-level run");
        {
            const render::RenderResult r =
                render_timed(full, round == 0 ? &result.setup_cpu_seconds : nullptr);
            const std::vector<double> truth = values_of(render::run_statistics(r));
            result.full_cpu_seconds.push_back(r.run_cpu_seconds);
            if (round == 0) {
                result.truth = truth;
                result.width = r.scene.width;
                result.height = r.scene.height;
                result.samples_per_pixel = r.scene.samples_per_pixel;
                result.threads = r.threads;
                result.instructions = r.instructions.total;
                full_image = r.rgb;
            }
            check_same(truth == result.truth, "the full cycle-level run");
        }
        announce("functional run");
        result.functional_cpu_seconds.push_back(render_timed(functional).run_cpu_seconds);

        for (double rate : rates)
            for (uint32_t seed = 1; seed <= (round == 0 ? options.seeds : 1); ++seed) {
                announce(fmt::format("rate {}, seed {}", rate_text(rate), seed));
                SampledRun run = sampled_run(options, rate, seed, result.truth, full_image);
                if (round == 0) {
                    result.runs.push_back(std::move(run));
                    continue;
                }
                SampledRun& first =
                    *std::find_if(result.runs.begin(), result.runs.end(), [&](const SampledRun& r) {
                        return r.rate == rate && r.seed == seed;
                    });
                const auto estimates = [](const SampledRun& r) {
                    std::vector<double> v;
                    for (const StatisticCheck& c : r.checks)
                        v.push_back(c.estimate);
                    return v;
                };
                check_same(
                    estimates(run) == estimates(first) && run.refused == first.refused,
                    fmt::format("the sampled run at rate {}, seed {}", rate_text(rate), seed));
                first.cpu_seconds.insert(first.cpu_seconds.end(), run.cpu_seconds.begin(),
                                         run.cpu_seconds.end());
            }
    }
    return result;
}

namespace {

std::string count_text(double value) {
    return stats::with_thousands(fmt::format("{:.0f}", value));
}

/// A statistic's value as its table shows it: counts whole, rates to four places.
std::string value_text(size_t statistic, double value) {
    return std::string_view(checked_statistics()[statistic].key).ends_with("_rate")
               ? fmt::format("{:.4f}", value)
               : count_text(value);
}

std::string percent(double share, bool sign = false) {
    if (!std::isfinite(share)) return "-";
    return sign ? fmt::format("{:+.2f} %", 100 * share) : fmt::format("{:.2f} %", 100 * share);
}

/// "yes", "no", or why there is no interval.
std::string covered_text(const SampledRun& run, const StatisticCheck& check) {
    if (run.exact) return "exact";
    if (std::isnan(check.half_width)) return "unknown";
    return check.covered() ? "yes" : "NO";
}

std::string chip_text(const render::RenderOptions& base) {
    std::string changed;
    const std::vector<timing::ConfigField> defaults = timing::config_fields({});
    const std::vector<timing::ConfigField> fields = timing::config_fields(base.chip);
    for (size_t i = 0; i < fields.size(); ++i)
        if (fields[i] != defaults[i])
            changed += fmt::format("{}{}={}", changed.empty() ? "" : ", ", fields[i].key,
                                   fields[i].text());
    return fmt::format("{} TMs x {} TPs, {}", base.chip.chip.num_tms, base.chip.chip.tps_per_tm,
                       changed.empty() ? "the default chip" : "the default chip but " + changed);
}

}  // namespace

std::string sample_check_table(const SampleCheckOptions& o, const SampleCheckResult& r) {
    std::ostringstream out;
    const std::vector<double>& rates = r.rates;
    const double full = median(r.full_cpu_seconds);
    const double functional = median(r.functional_cpu_seconds);
    const auto& statistics = checked_statistics();

    out << fmt::format("scene      {}, {}x{} pixels, {} spp, kernel {}\n", o.base.scene.string(),
                       r.width, r.height, r.samples_per_pixel, o.base.kernel.stem().string());
    out << fmt::format("chip       {}\n", chip_text(o.base));
    out << fmt::format("sampling   units of {} cycles after {} cycles of warm-up; seeds {}\n",
                       count_text(double(o.sampling.unit_cycles)),
                       count_text(double(o.sampling.warmup_cycles)),
                       o.seeds == 1 ? "1" : fmt::format("1-{}", o.seeds));
    out << fmt::format(
        "host time  CPU seconds of the kernel run: median of {} (full and functional "
        "runs) and of {} per rate (seed 1 in every round, other seeds once); speedups: "
        "median of the rounds' ratios to the full run; scene, BVH and memory image take "
        "{:.2f} s more per run, not counted\n",
        o.repeat, o.repeat + o.seeds - 1, r.setup_cpu_seconds);
    out << fmt::format("full run   {} cycles, {} instructions in {:.2f} s ({:.1f} M "
                       "instructions/s)\n",
                       count_text(r.truth[0]), count_text(double(r.instructions)), full,
                       double(r.instructions) / full / 1e6);
    out << fmt::format("bound      functional only (--timing none): {:.2f} s, {:.1f}x faster than "
                       "the full run\n",
                       functional, r.functional_speedup());

    out << fmt::format("\nframe cycles, seed 1 (error and interval relative to the true value)\n"
                       "{:<7} {:>6} {:>10} {:>8} {:>7} {:>14} {:>14} {:>9} {:>8} {:>7}\n",
                       "rate", "units", "cycle-lvl", "host s", "speedup", "estimate", "true",
                       "error", "±95 %", "covered");
    for (double rate : rates) {
        const SampledRun& run = *r.at(rate).front();
        if (!run.refused.empty()) {
            out << fmt::format("{:<7} not estimated: {}\n", rate_text(rate), run.refused);
            continue;
        }
        const StatisticCheck& c = run.checks[0];
        const double seconds = r.cpu_seconds(rate);
        out << fmt::format(
            "{:<7} {:>6} {:>10} {:>8.2f} {:>6.1f}x {:>14} {:>14} {:>9} {:>8} {:>7}\n",
            rate_text(rate), run.units, percent(run.cycle_level_share), seconds, r.speedup(rate),
            value_text(0, c.estimate), value_text(0, c.truth), percent(c.error(), true),
            percent(c.relative_half_width()), covered_text(run, c));
    }

    out << fmt::format("\nother statistics, seed 1\n{:<20} {:<7} {:>14} {:>14} {:>9} {:>8} {:>7}\n",
                       "statistic", "rate", "estimate", "true", "error", "±95 %", "covered");
    for (size_t s = 1; s < statistics.size(); ++s)
        for (double rate : rates) {
            const SampledRun& run = *r.at(rate).front();
            if (!run.refused.empty()) continue;
            const StatisticCheck& c = run.checks[s];
            out << fmt::format("{:<20} {:<7} {:>14} {:>14} {:>9} {:>8} {:>7}\n",
                               statistics[s].label, rate_text(rate), value_text(s, c.estimate),
                               value_text(s, c.truth), percent(c.error(), true),
                               percent(c.relative_half_width()), covered_text(run, c));
        }

    bool images_differ = false;
    for (const SampledRun& run : r.runs)
        images_differ |= run.refused.empty() && !run.same_image;
    if (images_differ)
        out << "\nWARNING: a sampled run's image differs from the full run's (it must not: every "
               "instruction executes)\n";

    if (o.seeds == 1) return out.str();
    out << fmt::format("\ncoverage over {} seeds: intervals that contain the true value; the "
                       "error's mean and root mean square and the median interval, relative to "
                       "the true value\n{:<20} {:<7} {:>8} {:>8} {:>11} {:>10} {:>13}\n",
                       o.seeds, "statistic", "rate", "covered", "share", "mean error", "rms error",
                       "median ±95 %");
    for (size_t s = 0; s < statistics.size(); ++s)
        for (double rate : rates) {
            const Coverage c = r.coverage(rate, s);
            if (c.runs == 0) continue;
            out << fmt::format(
                "{:<20} {:<7} {:>8} {:>8} {:>11} {:>10} {:>13}\n", statistics[s].label,
                rate_text(rate), fmt::format("{}/{}", c.covered, c.runs),
                fmt::format("{:.1f} %", 100.0 * double(c.covered) / double(c.runs)),
                percent(c.mean_error, true), percent(c.rms_error), percent(c.median_half_width));
        }
    return out.str();
}

nlohmann::ordered_json sample_check_document(const SampleCheckOptions& o,
                                             const SampleCheckResult& r) {
    using Json = nlohmann::ordered_json;
    const auto number = [](double value) { return std::isfinite(value) ? Json(value) : Json(); };
    const std::vector<double>& rates = r.rates;
    const double full = median(r.full_cpu_seconds);
    const double functional = median(r.functional_cpu_seconds);
    const auto& statistics = checked_statistics();

    Json doc;
    doc["format"] = "tpsim-sample-check";
    doc["version"] = 1;
    doc["scene"] = o.base.scene.string();
    doc["kernel"] = o.base.kernel.string();
    doc["chip"] = chip_text(o.base);
    Json config = Json::object();
    const std::vector<timing::ConfigField> defaults = timing::config_fields({});
    const std::vector<timing::ConfigField> fields = timing::config_fields(o.base.chip);
    for (size_t i = 0; i < fields.size(); ++i)
        if (fields[i] != defaults[i])
            config[fields[i].key] = fields[i].is_real   ? Json(fields[i].real)
                                    : fields[i].is_bool ? Json(fields[i].value != 0)
                                                        : Json(fields[i].value);
    doc["config_changes"] = config;
    doc["width"] = r.width;
    doc["height"] = r.height;
    doc["samples_per_pixel"] = r.samples_per_pixel;
    doc["threads"] = r.threads;
    doc["instructions"] = r.instructions;
    doc["unit_cycles"] = o.sampling.unit_cycles;
    doc["warmup_cycles"] = o.sampling.warmup_cycles;
    doc["seeds"] = o.seeds;
    doc["repeat"] = o.repeat;
    doc["confidence"] = 0.95;
    doc["setup_cpu_seconds"] = r.setup_cpu_seconds;
    Json truth = Json::object();
    Json list = Json::array();
    for (size_t s = 0; s < statistics.size(); ++s) {
        list.push_back({{"key", statistics[s].key}, {"label", statistics[s].label}});
        truth[statistics[s].key] = r.truth[s];
    }
    doc["statistics"] = list;
    doc["full"] = {
        {"cpu_seconds", r.full_cpu_seconds}, {"median_cpu_seconds", full}, {"values", truth}};
    doc["functional"] = {{"cpu_seconds", r.functional_cpu_seconds},
                         {"median_cpu_seconds", functional},
                         {"speedup", r.functional_speedup()}};
    Json by_rate = Json::array();
    for (double rate : rates) {
        Json entry;
        entry["rate"] = rate;
        const double seconds = r.cpu_seconds(rate);
        entry["median_cpu_seconds"] = number(seconds);
        entry["speedup"] = number(r.speedup(rate));
        Json coverage = Json::object();
        for (size_t s = 0; s < statistics.size(); ++s) {
            const Coverage c = r.coverage(rate, s);
            coverage[statistics[s].key] = {{"covered", c.covered},
                                           {"runs", c.runs},
                                           {"mean_error", number(c.mean_error)},
                                           {"rms_error", number(c.rms_error)},
                                           {"median_half_width", c.median_half_width}};
        }
        entry["coverage"] = coverage;
        Json runs = Json::array();
        for (const SampledRun* run : r.at(rate)) {
            Json j;
            j["seed"] = run->seed;
            j["cpu_seconds"] = run->cpu_seconds;
            if (!run->refused.empty()) {
                j["refused"] = run->refused;
                runs.push_back(j);
                continue;
            }
            j["units"] = run->units;
            j["exact"] = run->exact;
            j["cycle_level_share"] = run->cycle_level_share;
            j["same_image"] = run->same_image;
            Json checks = Json::object();
            for (size_t s = 0; s < statistics.size(); ++s) {
                const StatisticCheck& c = run->checks[s];
                checks[statistics[s].key] = {
                    {"estimate", c.estimate},
                    {"half_width", c.half_width},
                    {"error", number(c.error())},
                    {"relative_half_width", number(c.relative_half_width())},
                    {"covered", c.covered()}};
            }
            j["statistics"] = checks;
            runs.push_back(j);
        }
        entry["runs"] = runs;
        by_rate.push_back(entry);
    }
    doc["rates"] = by_rate;
    return doc;
}

}  // namespace tpsim::analysis
