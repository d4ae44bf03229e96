// `tpsim converge SCENE`: image error against render cost. Renders the scene at several sample
// counts and adaptive thresholds on the cycle-level chip, measures each image against a
// high-sample reference from the native twin, and prints the table as the runs finish
// (docs/error-vs-time.md).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "sim/analysis/converge.hpp"
#include "sim/analysis/html_report.hpp"
#include "sim/cli/commands.hpp"
#include "sim/cli/progress_line.hpp"
#include "sim/core/error.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::cli {
namespace {

/// The thresholds the adaptive runs take when --adaptive is not given (with the tracer).
constexpr const char* kDefaultThresholds = "0.2,0.1,0.05,0.02";

struct ConvergeCommandOptions {
    std::string scene;
    std::string kernel = "tracer";
    std::vector<std::string> params;
    std::vector<uint32_t> spp{1, 2, 4, 8, 16};
    std::string adaptive;  // "" when not given
    std::string adaptive_kernel;
    std::vector<std::string> adaptive_params;
    uint32_t adaptive_spp = 0, reference_spp = 0;  // 0: derived from --spp
    uint32_t width = 0, height = 0, seed = 0;
    std::string config;
    std::vector<std::string> overrides;
    std::string output_dir = ".";
    std::string json;
    std::string html;
};

/// --adaptive's list: "none", or thresholds such as 0.1,0.05.
std::vector<float> parse_thresholds(const std::string& list) {
    std::vector<float> thresholds;
    if (list == "none") return thresholds;
    for (size_t start = 0; start <= list.size();) {
        const size_t comma = std::min(list.find(',', start), list.size());
        const std::string item = list.substr(start, comma - start);
        float value = 0;
        const auto [end, error] = std::from_chars(item.data(), item.data() + item.size(), value);
        if (item.empty() || error != std::errc{} || end != item.data() + item.size() ||
            !std::isfinite(value))
            throw Error(fmt::format("--adaptive: give thresholds as numbers separated by commas, "
                                    "such as {}, or none; '{}' is not a number",
                                    kDefaultThresholds, item));
        if (std::find(thresholds.begin(), thresholds.end(), value) != thresholds.end())
            throw Error(fmt::format("--adaptive lists the threshold {} twice", item));
        thresholds.push_back(value);
        start = comma + 1;
    }
    return thresholds;
}

int run_converge(const ConvergeCommandOptions& o) {
    analysis::ConvergeOptions options;
    render::RenderOptions& base = options.base;
    base.scene = o.scene;
    base.kernel = resolve_kernel(o.kernel);
    base.params = o.params;
    base.image_width = o.width;
    base.image_height = o.height;
    base.seed = o.seed;
    base.on_warning = [](const std::string& warning) {
        fmt::print(stderr, "tpsim: warning: {}\n", warning);
    };
    if (!o.config.empty()) base.chip = timing::load_config(o.config);
    timing::apply_overrides(base.chip, o.overrides);

    for (size_t i = 0; i < o.spp.size(); ++i)
        if (std::count(o.spp.begin(), o.spp.end(), o.spp[i]) > 1)
            throw Error(fmt::format("--spp lists {} twice", o.spp[i]));
    options.spp = o.spp;
    // The adaptive kernel renders the tracer's shading: its images compare with the tracer's
    // reference, not another kernel's, so another kernel needs its own adaptive version.
    std::error_code ec;
    const bool tracer = std::filesystem::equivalent(base.kernel, resolve_kernel("tracer"), ec);
    options.adaptive_kernel =
        resolve_kernel(o.adaptive_kernel.empty() ? "adaptive" : o.adaptive_kernel);
    if (o.adaptive.empty())
        options.thresholds =
            parse_thresholds(tracer || !o.adaptive_kernel.empty() ? kDefaultThresholds : "none");
    else
        options.thresholds = parse_thresholds(o.adaptive);
    if (!options.thresholds.empty() && !tracer && o.adaptive_kernel.empty())
        throw Error(fmt::format("--adaptive renders with the kernel adaptive, which shades like "
                                "tracer, so its images cannot be measured against {}'s "
                                "reference: give --adaptive-kernel with an adaptive version of "
                                "{}, or --adaptive none",
                                o.kernel, o.kernel));
    options.adaptive_params = o.adaptive_params;
    const uint32_t largest = *std::max_element(o.spp.begin(), o.spp.end());
    options.adaptive_spp = o.adaptive_spp != 0 ? o.adaptive_spp : largest;
    const uint32_t most =
        options.thresholds.empty() ? largest : std::max(largest, options.adaptive_spp);
    // 16 times the most samples a run takes: the reference's own noise then adds at most 1/16
    // to a run's squared error (0.26 dB of PSNR).
    options.reference_spp =
        o.reference_spp != 0 ? o.reference_spp : std::clamp<uint32_t>(16 * most, 256, 65536);

    make_output_dir(o.output_dir);
    options.output_dir = o.output_dir;
    if (!o.json.empty()) check_output_path(o.json, "the results");
    if (!o.html.empty()) check_output_path(o.html, "the report");
    const std::string chart_js = o.html.empty() ? "" : analysis::load_chart_js();

    ProgressLine progress;
    options.on_render = [&](size_t index, size_t count, const std::string& label) {
        progress.start(fmt::format("converge: {} ({} of {}) ", label, index + 1, count));
    };
    base.on_progress = [&](const render::Progress& p) { progress.update(p); };
    const analysis::ConvergeResult result =
        analysis::converge(options, [&](const analysis::ConvergeResult& so_far) {
            progress.clear();
            std::cout << (so_far.runs.empty() ? analysis::converge_header(options, so_far)
                                              : analysis::converge_row(so_far.runs.back()))
                      << std::flush;
        });
    progress.clear();
    if (!o.json.empty()) {
        write_output(o.json, analysis::converge_document(options, result, o.json).dump(1) + '\n',
                     "the results");
        fmt::print("results   {}\n", o.json);
    }
    if (!o.html.empty()) {
        const std::filesystem::path html = o.html;
        write_output(html,
                     analysis::converge_page(analysis::converge_document(options, result, html),
                                             html.has_parent_path() ? html.parent_path() : ".",
                                             chart_js),
                     "the report");
        fmt::print("report    {}\n", o.html);
    }
    return 0;
}

}  // namespace

Command add_converge_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "converge", "Image error against render cost: render a scene at several samples per "
                    "pixel and adaptive thresholds on the simulated chip, and measure each image "
                    "against a high-sample reference (RMSE, PSNR) beside its frame cycles");
    auto o = std::make_shared<ConvergeCommandOptions>();
    command->add_option("scene", o->scene, "Scene file or mesh")
        ->required()
        ->check(CLI::ExistingFile);
    command->add_option("-k,--kernel", o->kernel, "Built kernel name, or a path to a kernel ELF")
        ->capture_default_str();
    command
        ->add_option("-p,--param", o->params,
                     "Set one of the kernel's run-time parameters (TRAX_PARAM), NAME=VALUE; "
                     "repeat for more")
        ->allow_extra_args(false);
    command
        ->add_option("--spp", o->spp,
                     "Samples per pixel of the uniform runs, separated by commas [default: "
                     "1,2,4,8,16]")
        ->delimiter(',')
        ->allow_extra_args(false)
        ->check(whole_number_in(1, 65536));
    command->add_option("--adaptive", o->adaptive,
                        fmt::format("Thresholds of the adaptive runs, separated by commas, or "
                                    "none [default: {} with the tracer kernel, none with "
                                    "another unless --adaptive-kernel is given]",
                                    kDefaultThresholds));
    command->add_option("--adaptive-kernel", o->adaptive_kernel,
                        "The kernel of the adaptive runs: one with a float parameter threshold "
                        "that renders --kernel's image in the limit [default: adaptive]");
    command
        ->add_option("--adaptive-param", o->adaptive_params,
                     "Set one of the adaptive kernel's other parameters, NAME=VALUE (e.g. "
                     "first_samples=2)")
        ->allow_extra_args(false);
    command
        ->add_option("--adaptive-spp", o->adaptive_spp,
                     "The most samples per pixel an adaptive run takes [default: the largest "
                     "--spp]")
        ->check(whole_number_in(1, 65536));
    command
        ->add_option("--reference-spp", o->reference_spp,
                     "Samples per pixel of the reference (native twin) [default: 16 times the "
                     "most a run takes, at least 256]")
        ->check(whole_number_in(1, 65536));
    command->add_option("--width", o->width, "Image width in pixels, instead of the scene's")
        ->check(whole_number_in(1, 16384));
    command->add_option("--height", o->height, "Image height in pixels, instead of the scene's")
        ->check(whole_number_in(1, 16384));
    command->add_option("--seed", o->seed, "Run seed for the kernels' random numbers")
        ->check(whole_number_in(0, UINT32_MAX))
        ->capture_default_str();
    command
        ->add_option("-c,--config", o->config,
                     "Chip configuration TOML [default: built-in, the same as configs/trax.toml]")
        ->check(CLI::ExistingFile);
    command
        ->add_option("-s,--set", o->overrides,
                     "Override one chip configuration field, e.g. --set chip.num_tms=8")
        ->allow_extra_args(false);
    command
        ->add_option("--output-dir", o->output_dir,
                     "Where the images go (converge-SCENE-reference.png, -spp4.png, "
                     "-adaptive-0.05.png ...)")
        ->capture_default_str();
    command->add_option("--json", o->json,
                        "Also write the results as JSON here (format tpsim-converge)");
    command->add_option("--html", o->html,
                        "Also write a self-contained HTML page here: the chart of error against "
                        "cycles, the table and the images");
    return {command, [o] { return run_converge(*o); }};
}

}  // namespace tpsim::cli
