// Sampled simulation: the estimator's arithmetic on made-up samples, statistics re-derived from
// replaced values, and sampled renders of the tracer against full cycle-level ones.
#include "sim/core/error.hpp"
#include "sim/render/render.hpp"
#include "sim/render/report.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/stats/estimate.hpp"
#include "sim/stats/registry.hpp"
#include "sim/timing/config.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <span>

using namespace tpsim;

TEST_CASE("Student's t quantiles match the tables", "[sampling]") {
    // Two-sided 95 % and 99 % intervals (the tables' t_{0.975} and t_{0.995}).
    CHECK(stats::student_t_quantile(0.95, 1) == Approx(12.706).epsilon(1e-3));
    CHECK(stats::student_t_quantile(0.95, 2) == Approx(4.303).epsilon(1e-3));
    CHECK(stats::student_t_quantile(0.95, 3) == Approx(3.182).epsilon(2e-3));
    CHECK(stats::student_t_quantile(0.95, 9) == Approx(2.262).epsilon(1e-3));
    CHECK(stats::student_t_quantile(0.95, 30) == Approx(2.042).epsilon(1e-3));
    CHECK(stats::student_t_quantile(0.95, 1e6) == Approx(1.960).epsilon(1e-3));
    CHECK(stats::student_t_quantile(0.99, 20) == Approx(2.845).epsilon(1e-3));
}

TEST_CASE("formulas and sums are recomputed from replaced values; levels survive intervals",
          "[stats][sampling]") {
    stats::Registry r;
    uint64_t a = 3, b = 4, cycles = 10, high = 7;
    r.add_counter("tm0/x", a, "x");
    r.add_counter("tm1/x", b, "x");
    r.add_sum("chip/x", "*/x", "sum");
    r.add_counter("chip/cycles", cycles, "cycles");
    r.add_formula(
        "chip/x_per_cycle", {"chip/x", "chip/cycles"},
        [](std::span<const double> v) { return v[0] / v[1]; }, "rate");
    r.add_level("chip/high", high, "high-water mark");
    stats::Snapshot s(r);
    CHECK(s.value("chip/x_per_cycle") == Approx(0.7));
    s.values()[r.index("tm0/x")].integer = 13;
    s.values()[r.index("chip/cycles")].integer = 34;
    const stats::Snapshot derived = r.derive(s);
    CHECK(derived.at("chip/x").integer == 17);
    CHECK(derived.value("chip/x_per_cycle") == Approx(0.5));
    const stats::Snapshot before(r);
    a = 5, high = 9;
    const stats::Snapshot interval = stats::Snapshot(r).since(before);
    CHECK(interval.at("tm0/x").integer == 2);
    CHECK(interval.at("chip/high").integer == 9);  // a level, not a difference
}

namespace {

/// A registry of instructions, a counter x and their ratio, with the run's measured values.
struct Toy {
    uint64_t instructions = 0, x = 0;
    stats::Registry registry;
    Toy() {
        registry.add_counter("chip/instructions", instructions, "instructions");
        registry.add_counter("x", x, "x");
        registry.add_formula(
            "x_per_instruction", {"x", "chip/instructions"},
            [](std::span<const double> v) { return v[0] / v[1]; }, "ratio");
    }
};

stats::UnitSamples toy_samples(std::vector<double> w, std::vector<double> x, double body) {
    stats::UnitSamples s;
    s.names = {"chip/instructions", "x"};
    s.unit_instructions = w;
    s.per_unit = {w, x};
    s.exact = {100, 40};  // head and tail
    s.body_instructions = body;
    return s;
}

}  // namespace

TEST_CASE("a counter proportional to the instructions is estimated exactly", "[sampling]") {
    Toy toy;
    const stats::UnitSamples samples = toy_samples({10, 20, 30}, {20, 40, 60}, 600);
    const stats::Estimate e = stats::estimate(toy.registry, stats::Snapshot(toy.registry), samples);
    CHECK(e.values.at("chip/instructions").integer == 700);  // the body plus head and tail
    CHECK(e.values.at("x").integer == 2 * 600 + 40);
    CHECK(e.interval("x") == Approx(0).margin(1e-9));
    CHECK(e.values.value("x_per_instruction") == Approx(1240.0 / 700));
    CHECK(e.interval("x_per_instruction") == Approx(0).margin(1e-9));
}

TEST_CASE("the ratio estimator's interval follows Cochran's formula", "[sampling]") {
    Toy toy;
    // w = 10 each, x = 1, 3, 5, 7: R = 0.4, residuals -3, -1, 1, 3 (variance 20/3); the body
    // holds N = 400 / 10 = 40 units, n = 4: Var = 40^2 (1 - 4/40) (20/3) / 4.
    const stats::UnitSamples samples = toy_samples({10, 10, 10, 10}, {1, 3, 5, 7}, 400);
    const stats::Estimate e = stats::estimate(toy.registry, stats::Snapshot(toy.registry), samples);
    CHECK(e.units == 4);
    CHECK(e.values.at("x").integer == 160 + 40);
    const double half = stats::student_t_quantile(0.95, 3) * std::sqrt(1600 * 0.9 * (20.0 / 3) / 4);
    CHECK(e.interval("x") == Approx(half));
    // Through the formula x / instructions (instructions have no residual): half / 500.
    CHECK(e.interval("x_per_instruction") == Approx(half / 500).epsilon(1e-4));
    CHECK_THROWS_AS(
        stats::estimate(toy.registry, stats::Snapshot(toy.registry), toy_samples({10}, {1}, 400)),
        std::invalid_argument);
}

TEST_CASE("an event fewer than 5 units saw has an unknown interval, not a narrow one",
          "[sampling]") {
    Toy toy;
    // The head and tail saw 40 of x (toy_samples); no unit saw one: the body may hold any number.
    const stats::Estimate e = stats::estimate(toy.registry, stats::Snapshot(toy.registry),
                                              toy_samples({10, 10, 10}, {0, 0, 0}, 400));
    CHECK(e.values.at("x").integer == 40);
    CHECK(std::isnan(e.interval("x")));
    CHECK(std::isnan(e.interval("x_per_instruction")));  // through the formula
    CHECK(e.interval("chip/instructions") == Approx(0).margin(1e-9));
    // Nothing anywhere: most likely nothing in the body either; an interval of 0.
    stats::UnitSamples none = toy_samples({10, 10, 10}, {0, 0, 0}, 400);
    none.exact = {100, 0};
    CHECK(stats::estimate(toy.registry, stats::Snapshot(toy.registry), none).interval("x") == 0);
    // Seen by 4 of 8 units: too few to tell the spread; by 5, an interval.
    const auto seen_by = [&](size_t units) {
        std::vector<double> x(8, 0.0);
        std::fill_n(x.begin(), units, 3.0);
        return stats::estimate(toy.registry, stats::Snapshot(toy.registry),
                               toy_samples(std::vector<double>(8, 10.0), x, 800))
            .interval("x");
    };
    CHECK(std::isnan(seen_by(4)));
    CHECK(seen_by(5) > 0);
    CHECK(seen_by(8) == Approx(0).margin(1e-9));  // every unit saw the same: proportional
}

namespace {

render::RenderResult render_bunny(std::optional<render::SamplingOptions> sampling,
                                  uint32_t size = 64) {
    render::RenderOptions options;
    options.scene = TPSIM_SCENE_DIR "/bunny.toml";
    options.kernel = TPSIM_KERNEL_DIR "/tracer.elf";
    options.engine = render::Engine::timing;
    options.image_width = options.image_height = size;
    options.sampling = sampling;
    return render::render(options);
}

std::string json_text(const render::RenderResult& r, const render::RunStatistics& s) {
    std::string text = render::stats_document({}, r, s, "x.json", {}).dump();
    // Host times differ between runs.
    return text.substr(0, text.find("\"host/"));
}

}  // namespace

TEST_CASE("a sampled render: the same image, estimates near the full run's, deterministic",
          "[sampling][render]") {
    render::SamplingOptions sampling;
    sampling.rate = 0.05;
    sampling.unit_cycles = 500;
    sampling.warmup_cycles = 500;
    const render::RenderResult full = render_bunny(std::nullopt, 128);
    const render::RenderResult sampled = render_bunny(sampling, 128);
    REQUIRE(sampled.timing->sampling);
    const render::SamplingSummary& summary = *sampled.timing->sampling;
    CHECK_FALSE(summary.exact);
    CHECK(summary.units >= 10);
    CHECK(summary.warmed_instructions > summary.body_instructions / 2);
    CHECK(std::memcmp(full.rgb.data(), sampled.rgb.data(), full.rgb.size() * 4) == 0);

    const render::RunStatistics truth = render::run_statistics(full);
    const render::RunStatistics estimate = render::run_statistics(sampled);
    REQUIRE(estimate.estimate);
    for (const char* key : {"chip/cycles", "chip/l1/hit_rate", "chip/stalls/operand"}) {
        INFO(key);
        const double real = truth.values.value(key);
        const double guess = estimate.values.value(key);
        const double half = estimate.estimate->interval(key);
        CHECK(half > 0);
        CHECK(std::abs(guess - real) <= half);  // this seed's intervals cover the truth
        CHECK(std::abs(guess - real) <= 0.05 * real);
    }
    // Every instruction ran: the instruction counters are exact, not estimated.
    CHECK(estimate.values.at("instructions/total").integer == sampled.instructions.total);
    CHECK(estimate.estimate->interval("instructions/total") == 0);

    const render::RenderResult again = render_bunny(sampling, 128);
    CHECK(json_text(sampled, estimate) == json_text(again, render::run_statistics(again)));
    sampling.seed = 2;
    const render::RenderResult other_seed = render_bunny(sampling, 128);
    CHECK(render::run_statistics(other_seed).values.value("chip/cycles") !=
          estimate.values.value("chip/cycles"));
}

TEST_CASE("a run that ends within the sample's head is measured whole, as a full run",
          "[sampling][render]") {
    render::SamplingOptions sampling;
    sampling.unit_cycles = 100'000'000;  // far beyond a 16x16 frame
    const render::RenderResult full = render_bunny(std::nullopt, 16);
    const render::RenderResult sampled = render_bunny(sampling, 16);
    REQUIRE(sampled.timing->sampling);
    CHECK(sampled.timing->sampling->exact);
    const render::RunStatistics a = render::run_statistics(full);
    const render::RunStatistics b = render::run_statistics(sampled);
    CHECK_FALSE(b.estimate);
    CHECK(b.values.at("chip/cycles").integer == a.values.at("chip/cycles").integer);
    CHECK(b.values.at("dram/bytes_read").integer == a.values.at("dram/bytes_read").integer);
}

TEST_CASE("sampling options are checked", "[sampling]") {
    render::SamplingOptions bad;
    bad.rate = 0;
    CHECK_THROWS_AS(bad.validate(), Error);
    bad.rate = 1.5;
    CHECK_THROWS_AS(bad.validate(), Error);
    bad.rate = 0.5;
    bad.unit_cycles = 0;
    CHECK_THROWS_AS(bad.validate(), Error);
}

TEST_CASE("a random start past the end of the body is refused, not taken as measured whole",
          "[sampling][render]") {
    // At this rate the period is longer than the body: the first unit falls past its end for
    // most seeds, and then nothing but the head was simulated cycle by cycle.
    render::SamplingOptions sampling;
    sampling.rate = 0.001;
    sampling.unit_cycles = 200;
    sampling.warmup_cycles = 200;
    for (uint32_t seed = 1; seed <= 4; ++seed) {
        INFO("seed " << seed);
        sampling.seed = seed;
        CHECK_THROWS_WITH(render_bunny(sampling, 64), Catch::Contains("too few to estimate from"));
    }
}
