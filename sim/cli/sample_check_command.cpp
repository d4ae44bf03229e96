// `tpsim sample-check SCENE`: how accurate and how fast sampled simulation is on this scene and
// chip: the full cycle-level run, the functional bound and sampled runs at several rates and
// seeds, as a table, a JSON file and an HTML page.
#include <charconv>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "sim/analysis/html_report.hpp"
#include "sim/analysis/sample_check.hpp"
#include "sim/cli/commands.hpp"
#include "sim/cli/progress_line.hpp"
#include "sim/core/error.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::cli {
namespace {

/// A sampling rate: a number in (0, 1].
const CLI::Validator kRate(
    [](std::string& value) -> std::string {
        double rate = 0;
        const char* end = value.data() + value.size();
        const auto [parsed_to, error] = std::from_chars(value.data(), end, rate);
        if (error == std::errc{} && parsed_to == end && rate > 0 && rate <= 1) return {};
        return "must be a number in (0, 1], got '" + value + "'";
    },
    "RATE");

struct SampleCheckCommandOptions {
    std::string scene;
    std::string kernel = "tracer";
    std::string config;
    std::vector<std::string> overrides;
    uint32_t width = 0, height = 0, samples_per_pixel = 0;  // 0: the scene's
    analysis::SampleCheckOptions check;
    std::string json;
    std::string html;
};

int run_sample_check(SampleCheckCommandOptions& o) {
    analysis::SampleCheckOptions& check = o.check;
    render::RenderOptions& base = check.base;
    base.scene = o.scene;
    base.kernel = resolve_kernel(o.kernel);
    if (!o.config.empty()) base.chip = timing::load_config(o.config);
    timing::apply_overrides(base.chip, o.overrides);
    base.image_width = o.width;
    base.image_height = o.height;
    base.samples_per_pixel = o.samples_per_pixel;
    base.on_warning = [](const std::string& warning) {
        fmt::print(stderr, "tpsim: warning: {}\n", warning);
    };
    check.validate();
    // Bad output paths and a missing Chart.js are found now, not after the runs.
    if (!o.json.empty()) check_output_path(o.json, "the JSON result");
    if (!o.html.empty()) check_output_path(o.html, "the page");
    const std::string chart_js = o.html.empty() ? "" : analysis::load_chart_js();

    ProgressLine progress;
    check.on_run = [&](size_t index, size_t count, const std::string& label) {
        progress.start(fmt::format("run {} of {} ({}): ", index + 1, count, label));
    };
    base.on_progress = [&](const render::Progress& p) { progress.update(p); };
    const analysis::SampleCheckResult result = analysis::sample_check(check);
    progress.clear();

    const nlohmann::ordered_json document = analysis::sample_check_document(check, result);
    if (!o.json.empty()) write_output(o.json, document.dump(1) + '\n', "the JSON result");
    if (!o.html.empty())
        write_output(o.html, analysis::sample_check_page(document, chart_js), "the page");
    std::cout << analysis::sample_check_table(check, result);
    if (!o.json.empty()) fmt::print("json       {}\n", o.json);
    if (!o.html.empty()) fmt::print("page       {}\n", o.html);
    return 0;
}

}  // namespace

Command add_sample_check_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "sample-check",
        "Measure sampled simulation (render --timing sampled) on a scene and chip: a full "
        "cycle-level run, a functional one and sampled runs at several rates and seeds; each "
        "estimate's error and 95 % interval against the full run, and the speedup in CPU time "
        "(docs/error-vs-time.md)");
    auto o = std::make_shared<SampleCheckCommandOptions>();
    command->add_option("scene", o->scene, "Scene file or mesh")
        ->required()
        ->check(CLI::ExistingFile);
    command->add_option("-k,--kernel", o->kernel, "Built kernel name, or a path to a kernel ELF")
        ->capture_default_str();
    command
        ->add_option("-c,--config", o->config,
                     "Chip configuration TOML (e.g. configs/tiny.toml) [default: built-in, the "
                     "same as configs/trax.toml]")
        ->check(CLI::ExistingFile);
    command->add_option("-s,--set", o->overrides,
                        "Override one chip configuration field, e.g. --set chip.num_tms=16");
    command->add_option("--width", o->width, "Image width in pixels, instead of the scene's")
        ->check(whole_number_in(1, 16384));
    command->add_option("--height", o->height, "Image height in pixels, instead of the scene's")
        ->check(whole_number_in(1, 16384));
    command
        ->add_option("--spp", o->samples_per_pixel,
                     "Samples per pixel, instead of the scene's samples_per_pixel")
        ->check(whole_number_in(1, 65536));
    command
        ->add_option("--rates", o->check.rates,
                     "Sampling rates to measure (share of the instructions simulated cycle by "
                     "cycle), comma-separated")
        ->delimiter(',')
        ->allow_extra_args(false)
        ->check(kRate)
        ->default_str("0.005,0.01,0.02,0.05");
    command
        ->add_option("--seeds", o->check.seeds,
                     "Sampled runs per rate, with seeds 1..N: the share of their 95 % intervals "
                     "that contain the true value is the measured coverage")
        ->check(whole_number_in(1, 100000))
        ->capture_default_str();
    command
        ->add_option("--sample-unit", o->check.sampling.unit_cycles,
                     "Cycles measured per unit (render --sample-unit)")
        ->check(kPositiveCount)
        ->capture_default_str();
    command
        ->add_option("--sample-warmup", o->check.sampling.warmup_cycles,
                     "Cycle-level warm-up before each unit (render --sample-warmup)")
        ->check(kWholeNumber)
        ->capture_default_str();
    command
        ->add_option("--repeat", o->check.repeat,
                     "Time the full run, the functional run and each rate's seed 1 this many "
                     "times, in interleaved rounds; host times are medians")
        ->check(whole_number_in(1, 1000))
        ->capture_default_str();
    command->add_option("--json", o->json, "Write the result as JSON here");
    command->add_option("--html", o->html,
                        "Write a self-contained HTML page with charts here (error against "
                        "speedup with the intervals, coverage)");
    return {command, [o] { return run_sample_check(*o); }};
}

}  // namespace tpsim::cli
