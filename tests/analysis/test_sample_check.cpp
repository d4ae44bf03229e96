// tpsim sample-check on a small render: the truth is a plain cycle-level render's, each estimate
// and interval a plain sampled render's, covered means the interval holds the truth, and the
// table, the document and the page say the same.
#include <algorithm>
#include <cmath>
#include <sstream>

#include <catch2/catch.hpp>

#include "sim/analysis/html_report.hpp"
#include "sim/analysis/sample_check.hpp"
#include "sim/core/error.hpp"
#include "sim/render/report.hpp"

using namespace tpsim;
using namespace tpsim::analysis;

namespace {

SampleCheckOptions small_options() {
    SampleCheckOptions o;
    o.base.scene = std::filesystem::path(TPSIM_SOURCE_DIR) / "scenes" / "bunny.toml";
    o.base.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / "tracer.elf";
    o.base.image_width = o.base.image_height = 64;
    o.sampling.unit_cycles = 200;
    o.sampling.warmup_cycles = 200;
    // Given out of order: the runs come by rate, ascending. 0.001 is too low for this frame.
    o.rates = {0.2, 0.05, 0.001};
    o.seeds = 2;
    o.repeat = 2;
    return o;
}

/// The lines of `text` that start with `start`.
std::vector<std::string> lines_starting(const std::string& text, const std::string& start) {
    std::vector<std::string> found;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        if (line.starts_with(start)) found.push_back(line);
    return found;
}

}  // namespace

TEST_CASE("sample-check: truth, estimates, coverage and timings are the renders' own",
          "[analysis][sample_check]") {
    SampleCheckOptions o = small_options();
    std::vector<std::string> announced;
    o.on_run = [&](size_t index, size_t count, const std::string& label) {
        CHECK(index == announced.size());
        CHECK(count == 2 * (2 + 3) + 3 * (2 - 1));  // rounds of every kind, more seeds in one
        announced.push_back(label);
    };
    const SampleCheckResult r = sample_check(o);
    REQUIRE(announced.size() == 13);
    CHECK(announced[0] == "full cycle-level run");
    CHECK(announced[1] == "functional run");
    CHECK(announced[2] == "rate 0.001, seed 1");
    CHECK(announced[8] == "full cycle-level run");  // the second round

    // The truth is a plain cycle-level render's.
    render::RenderOptions plain = o.base;
    plain.engine = render::Engine::timing;
    const render::RunStatistics truth = render::run_statistics(render::render(plain));
    const auto& statistics = checked_statistics();
    REQUIRE(r.truth.size() == statistics.size());
    for (size_t s = 0; s < statistics.size(); ++s)
        CHECK(r.truth[s] == truth.values.value(statistics[s].key));
    CHECK(r.width == 64);
    CHECK(r.threads == 128);
    CHECK(r.full_cpu_seconds.size() == 2);
    CHECK(r.functional_cpu_seconds.size() == 2);
    for (double seconds : r.full_cpu_seconds)
        CHECK(seconds > 0);
    CHECK(r.setup_cpu_seconds > 0);

    CHECK(r.rates == std::vector<double>{0.001, 0.05, 0.2});
    REQUIRE(r.runs.size() == 6);
    for (size_t i = 0; i < r.runs.size(); ++i) {
        const SampledRun& run = r.runs[i];
        INFO("rate " << run.rate << ", seed " << run.seed);
        CHECK(run.rate == r.rates[i / 2]);
        CHECK(run.seed == i % 2 + 1);
        if (run.rate == 0.001) {
            CHECK(run.refused.find("too few to estimate from") != std::string::npos);
            CHECK(run.checks.empty());
            CHECK(run.cpu_seconds.empty());
            continue;
        }
        CHECK(run.cpu_seconds.size() == (run.seed == 1 ? 2u : 1u));  // seed 1 in every round
        REQUIRE(run.refused.empty());
        CHECK_FALSE(run.exact);
        CHECK(run.units >= 2);
        CHECK(run.same_image);
        CHECK(run.cycle_level_share > 0);
        CHECK(run.cycle_level_share < 1);
        // Each estimate and interval is a plain sampled render's at that rate and seed.
        render::RenderOptions sampled = plain;
        sampled.sampling = o.sampling;
        sampled.sampling->rate = run.rate;
        sampled.sampling->seed = run.seed;
        const render::RunStatistics estimate = render::run_statistics(render::render(sampled));
        REQUIRE(estimate.estimate);
        REQUIRE(run.checks.size() == statistics.size());
        for (size_t s = 0; s < statistics.size(); ++s) {
            const StatisticCheck& c = run.checks[s];
            INFO(statistics[s].key);
            CHECK(c.estimate == estimate.values.value(statistics[s].key));
            CHECK(c.half_width == estimate.estimate->interval(statistics[s].key));
            CHECK(c.half_width > 0);
            CHECK(c.truth == r.truth[s]);
            CHECK(c.error() == Approx((c.estimate - c.truth) / c.truth));
            CHECK(c.covered() == (std::abs(c.error()) <= c.relative_half_width()));
        }
    }

    // Coverage counts the seeds whose interval holds the truth; refused runs do not count.
    CHECK(r.coverage(0.001, 0).runs == 0);
    CHECK(std::isnan(r.cpu_seconds(0.001)));
    for (double rate : {0.05, 0.2})
        for (size_t s = 0; s < statistics.size(); ++s) {
            const Coverage c = r.coverage(rate, s);
            const StatisticCheck& a = r.at(rate)[0]->checks[s];
            const StatisticCheck& b = r.at(rate)[1]->checks[s];
            CHECK(c.runs == 2);
            CHECK(c.covered == size_t(a.covered()) + size_t(b.covered()));
            CHECK(c.mean_error == Approx((a.error() + b.error()) / 2));
            CHECK(c.rms_error ==
                  Approx(std::sqrt((a.error() * a.error() + b.error() * b.error()) / 2)));
            CHECK(c.median_half_width ==
                  Approx((a.relative_half_width() + b.relative_half_width()) / 2));
        }
    std::vector<double> times = r.at(0.2)[0]->cpu_seconds;
    times.push_back(r.at(0.2)[1]->cpu_seconds[0]);
    CHECK(r.cpu_seconds(0.2) == median(times));
    // Speedups pair the runs of one round: the median of two rounds' ratios is their mean.
    const auto& full = r.full_cpu_seconds;
    const auto& seed1 = r.at(0.2)[0]->cpu_seconds;
    CHECK(r.speedup(0.2) == Approx((full[0] / seed1[0] + full[1] / seed1[1]) / 2));
    const auto& functional = r.functional_cpu_seconds;
    CHECK(r.functional_speedup() ==
          Approx((full[0] / functional[0] + full[1] / functional[1]) / 2));

    SECTION("the table: one row per rate, seed 1's figures, coverage over the seeds") {
        const std::string table = sample_check_table(o, r);
        const std::vector<std::string> rows = lines_starting(table, "0.");
        REQUIRE(rows.size() == 3);
        CHECK(rows[0].find("not estimated") != std::string::npos);
        const StatisticCheck& c = r.at(0.2)[0]->checks[0];
        std::istringstream row(rows[2]);
        std::string rate, units, share, seconds, speedup, estimate, true_value, error, pm;
        row >> rate >> units >> share >> share >> seconds >> speedup >> estimate >> true_value;
        CHECK(rate == "0.2");
        CHECK(units == std::to_string(r.at(0.2)[0]->units));
        CHECK(std::stod(seconds) == Approx(r.cpu_seconds(0.2)).margin(0.005));
        CHECK(std::stod(speedup) == Approx(r.speedup(0.2)).margin(0.05));
        estimate.erase(std::remove(estimate.begin(), estimate.end(), ','), estimate.end());
        true_value.erase(std::remove(true_value.begin(), true_value.end(), ','), true_value.end());
        CHECK(std::stod(estimate) == c.estimate);
        CHECK(std::stod(true_value) == c.truth);
        CHECK(rows[2].ends_with(c.covered() ? "yes" : "NO"));
        // Other statistics: three, at the two rates that gave estimates.
        CHECK(lines_starting(table, "DRAM bytes read ").size() == 2 + 2);  // seed 1, coverage
        CHECK(lines_starting(table, "L1 hit rate ").size() == 2 + 2);
        CHECK(lines_starting(table, "frame cycles ").size() == 2);  // coverage only
        CHECK(table.find("coverage over 2 seeds") != std::string::npos);
        CHECK(table.find("WARNING") == std::string::npos);  // every image the full run's
    }

    SECTION("the document and its page") {
        const nlohmann::ordered_json doc = sample_check_document(o, r);
        CHECK(doc["format"] == "tpsim-sample-check");
        CHECK(doc["version"] == 1);
        CHECK(doc["full"]["values"]["chip/cycles"] == r.truth[0]);
        CHECK(doc["functional"]["speedup"] == r.functional_speedup());
        REQUIRE(doc["rates"].size() == 3);
        CHECK(doc["rates"][0]["runs"][0].contains("refused"));
        const auto& top = doc["rates"][2];
        CHECK(top["rate"] == 0.2);
        CHECK(top["speedup"] == r.speedup(0.2));
        CHECK(doc["rates"][0]["median_cpu_seconds"].is_null());  // every run refused
        CHECK(top["runs"].size() == 2);
        CHECK(top["runs"][1]["statistics"]["chip/l1/hit_rate"]["estimate"] ==
              r.at(0.2)[1]->checks[3].estimate);
        CHECK(top["coverage"]["chip/cycles"]["covered"] == r.coverage(0.2, 0).covered);

        const std::string page = sample_check_page(doc, "");
        const std::string open = "<script id=\"tpsim-data\" type=\"application/json\">";
        const size_t start = page.find(open) + open.size();
        const auto blob = Json::parse(page.substr(start, page.find("</script>", start) - start));
        // Speedups, one error chart per statistic (unless every error is 0), coverage.
        REQUIRE(blob["charts"].size() >= 3);
        CHECK(blob["charts"][0]["labels"].back() == "functional (bound)");
        const Json& cycles = blob["charts"][1];
        CHECK(cycles["type"] == "scatter");
        REQUIRE(cycles["datasets"].size() == 3);
        CHECK(cycles["datasets"][0]["data"].empty());  // the refused rate: no points
        const Json& point = cycles["datasets"][2]["data"][0];
        const StatisticCheck& c = r.at(0.2)[0]->checks[0];
        CHECK(point["y"].get<double>() == Approx(100 * c.error()));
        CHECK(point["yMax"].get<double>() - point["yMin"].get<double>() ==
              Approx(200 * c.relative_half_width()));
        // The value axis holds every error, whatever the error bars' lengths.
        const double low = cycles["range"][0], high = cycles["range"][1];
        for (const Json& dataset : cycles["datasets"])
            for (const Json& p : dataset["data"]) {
                CHECK(p["y"].get<double>() >= low);
                CHECK(p["y"].get<double>() <= high);
            }
        CHECK(blob["charts"].back()["title"] == "Coverage of the 95 % intervals over 2 seeds");
        CHECK(page.find("not estimated: ") != std::string::npos);
    }
}

TEST_CASE("sample-check: options that cannot give a measurement are refused",
          "[analysis][sample_check]") {
    SampleCheckOptions o = small_options();
    o.rates = {};
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("at least one sampling rate"));
    o.rates = {0.01, 0};
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("must be in (0, 1]"));
    o.rates = {0.01, 0.02, 0.01};
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("0.01 is given twice"));
    o.rates = {0.01};
    o.seeds = 0;
    CHECK_THROWS_AS(o.validate(), Error);
    o.seeds = 1;
    o.repeat = 0;
    CHECK_THROWS_AS(o.validate(), Error);
    o.repeat = 1;
    o.sampling.unit_cycles = 0;
    CHECK_THROWS_WITH(sample_check(o), Catch::Contains("at least 1 cycle"));  // before any render
}

TEST_CASE("median", "[analysis][sample_check]") {
    CHECK(median({3}) == 3);
    CHECK(median({5, 1, 3}) == 3);
    CHECK(median({4, 1, 3, 2}) == 2.5);
}
