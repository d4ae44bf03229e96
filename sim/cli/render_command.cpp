// `tpsim render SCENE`: renders a scene with a kernel on the simulated chip (or its native twin),
// writes the image and prints the statistics.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "sim/analysis/html_report.hpp"
#include "sim/analysis/stats_file.hpp"
#include "sim/cli/commands.hpp"
#include "sim/cli/progress_line.hpp"
#include "sim/core/error.hpp"
#include "sim/core/host_threads.hpp"
#include "sim/render/heatmap.hpp"
#include "sim/render/image_file.hpp"
#include "sim/render/profile.hpp"
#include "sim/render/render.hpp"
#include "sim/render/report.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/stats/registry.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::cli {
namespace {

struct RenderCommandOptions {
    std::string scene;
    std::string up;
    std::string output;
    std::string kernel;          // "": the tracer of the structure asked for
    scene::AccelSettings accel;  // the options given (--accel, --bvh-order ...), nothing else
    std::vector<std::string> params;
    std::string config;
    std::vector<std::string> overrides;
    bool native = false;
    bool no_fork = false;
    std::string timing = "cycle";
    render::SamplingOptions sampling;
    bool sampling_set = false;  // a --sample-* option was given
    std::string stats_json;
    bool verbose = false;
    uint64_t timeline_cycles = 0;
    bool profile = false;
    std::string annotate;
    std::string heatmap;
    std::string heatmap_metric = "cycles";
    std::string heatmap_scale = "log";
    std::string html;
    uint64_t max_instructions = uint64_t(1) << 32;
    uint64_t max_item_instructions = 0;
    uint32_t width = 0, height = 0, samples_per_pixel = 0, seed = 0;  // 0 size/spp: the scene's
};

int run_render(RenderCommandOptions& o) {
    render::RenderOptions options;
    options.scene = o.scene;
    if (!o.up.empty()) {
        if (options.scene.extension() == ".toml")
            throw Error(fmt::format("--up turns a bare mesh; in a scene file give the mesh's "
                                    "axis as up = \"{}\" in its [[meshes]] entry",
                                    o.up));
        const auto up = scene::parse_up_axis(o.up);
        if (!up)
            throw Error(fmt::format("--up must be one of {}, got '{}'", scene::kUpAxisNames, o.up));
        options.mesh_up = *up;
    }
    options.on_warning = [](const std::string& warning) {
        fmt::print(stderr, "tpsim: warning: {}\n", warning);
    };
    options.accel = o.accel;
    // No kernel: the tracer of the structure --accel or else the scene file's [accel] table
    // names (the file is read for it only then).
    if (o.kernel.empty()) {
        const scene::AccelStructure structure =
            o.accel.structure ? *o.accel.structure
                              : scene::load_accel_settings(o.scene).structure.value_or(
                                    scene::AccelStructure::bvh2);
        o.kernel = scene::accel_info(structure).default_kernel;
    }
    options.kernel = resolve_kernel(o.kernel);
    options.params = o.params;
    options.engine = o.native             ? render::Engine::native
                     : o.timing != "none" ? render::Engine::timing
                                          : render::Engine::functional;
    if (o.sampling_set && (o.timing != "sampled" || o.native))
        throw Error("--sample-rate, --sample-unit, --sample-warmup and --sample-seed set up "
                    "sampled simulation: give --timing sampled too");
    if (o.timing == "sampled" && !o.native) {
        o.sampling.validate();
        options.sampling = o.sampling;
    }
    options.image_width = o.width;
    options.image_height = o.height;
    options.samples_per_pixel = o.samples_per_pixel;
    options.seed = o.seed;
    if (o.no_fork && !o.native)
        throw Error("--no-fork runs the native twin in tpsim's own process: give --native too");
    options.twin_process = o.no_fork ? render::TwinProcess::in_process : render::TwinProcess::child;
    options.max_instructions = o.max_instructions;
    options.max_item_instructions = o.max_item_instructions;
    options.timeline_interval = o.timeline_cycles;
    if (!o.config.empty()) options.chip = timing::load_config(o.config);
    timing::apply_overrides(options.chip, o.overrides);

    // Bad output paths are found now, not after a render that may take hours.
    const std::filesystem::path output =
        o.output.empty() ? std::filesystem::path(o.scene).stem().string() + ".png" : o.output;
    render::check_image_path(output);
    if (!o.stats_json.empty()) check_output_path(o.stats_json, "statistics");
    if (!o.annotate.empty()) check_output_path(o.annotate, "the annotated listing");
    if (!o.html.empty()) check_output_path(o.html, "the report");
    // Read now, so a missing package is found before the run.
    const std::string chart_js = o.html.empty() ? "" : analysis::load_chart_js();
    const render::HeatMetric heat_metric = render::parse_heat_metric(o.heatmap_metric);
    const render::HeatScale heat_scale = render::parse_heat_scale(o.heatmap_scale);
    if (!o.heatmap.empty()) render::check_heatmap_path(o.heatmap);
    options.profile = o.profile || !o.annotate.empty();
    if (options.engine != render::Engine::timing) {
        const char* needs = options.profile      ? "--profile and --annotate need"
                            : !o.heatmap.empty() ? "--heatmap needs"
                                                 : nullptr;
        if (needs)
            throw Error(fmt::format("{} the cycle-level chip model: drop --native and --timing "
                                    "none",
                                    needs));
    }
    if (options.sampling && (options.profile || !o.heatmap.empty()))
        throw Error(
            fmt::format("{} every cycle simulated: use --timing cycle, not sampled",
                        options.profile ? "--profile and --annotate need" : "--heatmap needs"));

    ProgressLine progress_line;
    options.on_progress = [&](const render::Progress& p) { progress_line.update(p); };
    const render::RenderResult result = render::render(options);
    progress_line.clear();
    render::write_image(output, result.rgb, result.scene.width, result.scene.height);

    const render::RunStatistics statistics = render::run_statistics(result);
    const stats::Snapshot& snapshot = statistics.values;
    render::print_summary(options, result, statistics, std::cout);
    fmt::print("image    {}\n", output.string());
    render::print_traffic(snapshot, options.chip.l2.line_bytes, std::cout);
    render::print_energy(snapshot, std::cout);
    print_kernel_output(result.output, "\nkernel output (by thread):\n");
    if (result.profile) {
        fmt::print("\n");
        render::print_profile(*result.profile, std::cout);
    }
    if (!o.annotate.empty()) {
        render::write_annotated_listing(o.annotate, *result.profile, options.kernel.string());
        fmt::print("listing  {}\n", o.annotate);
    }
    if (!o.heatmap.empty()) {
        const render::HeatmapFiles files =
            render::write_heatmap(o.heatmap, result.timing->chip->work_items(), result.scene.width,
                                  result.scene.height, heat_metric, heat_scale);
        fmt::print("heatmap  {} ({} per pixel; raw values in {})\n", files.png.string(),
                   render::metric_name(heat_metric), files.exr.string());
        if (!files.legend_problem.empty())
            fmt::print(stderr, "tpsim: warning: the heat map's legend has no text: {}\n",
                       files.legend_problem);
    }
    if (o.verbose) {
        fmt::print("\n# chip configuration (resolved)\n{}\n", timing::to_toml(options.chip));
        stats::print_text(snapshot, std::cout);
    }
    const render::OutputPaths outputs{output, o.heatmap};
    if (!o.stats_json.empty()) {
        const std::filesystem::path json_path = o.stats_json;
        write_output(
            json_path,
            render::stats_document(options, result, statistics, json_path, outputs).dump(1) + '\n',
            "statistics");
        // The configuration as a file the user can pass back with -c.
        const std::filesystem::path config_path =
            std::filesystem::path(o.stats_json).replace_extension(".config.toml");
        write_output(config_path, timing::to_toml(options.chip), "the configuration");
    }
    if (!o.html.empty()) {
        // The page is made from the statistics file, as `tpsim report` makes it.
        const std::string document =
            render::stats_document(options, result, statistics, o.html, outputs).dump();
        const std::string source =
            o.stats_json.empty() ? "no statistics file (render with --stats-json FILE to keep one)"
                                 : "statistics file " + o.stats_json;
        write_output(
            o.html,
            analysis::report_page(analysis::parse_stats_file(document, o.html), chart_js, source),
            "the report");
        fmt::print("report   {}\n", o.html);
    }
    return 0;
}

}  // namespace

Command add_render_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "render", "Render a scene (.toml scene file or a mesh: .obj .ply .off ...) with a kernel "
                  "on the simulated chip; write the image and print statistics");
    auto o = std::make_shared<RenderCommandOptions>();
    command->add_option("scene", o->scene, "Scene file or mesh")
        ->required()
        ->check(CLI::ExistingFile);
    command->add_option("--up", o->up,
                        "A bare mesh's up axis (x, y, z, -x, -y, -z), turned to +y: z for "
                        "meshes authored z-up [default: y]");
    command->add_option(
        "-o,--output", o->output,
        "Image to write (.png 8-bit sRGB; .exr/.tif linear float) [default: SCENE.png]");
    command->add_option("-k,--kernel", o->kernel,
                        "Built kernel name, or a path to a kernel ELF [default: tracer, or the "
                        "tracer of --accel]");
    // Each sets its field of o->accel only when given, so that the scene file's [accel] table
    // fills in the rest (docs/scenes.md).
    const auto accel_option = [&]<class T>(std::string name,
                                           std::optional<T> scene::AccelSettings::*field,
                                           std::string help) {
        return command->add_option_function<T>(
            std::move(name), [o, field](const T& value) { o->accel.*field = value; },
            std::move(help));
    };
    // A choice by name (--accel kdtree), kept as the value `find` makes of it.
    const auto named_option =
        [&]<class T>(std::string name, std::optional<T> scene::AccelSettings::*field,
                     std::optional<T> (*find)(std::string_view),
                     const std::vector<std::string>& names, std::string help) {
            return command
                ->add_option_function<std::string>(
                    std::move(name),
                    [o, field, find](const std::string& value) { o->accel.*field = *find(value); },
                    std::move(help))
                ->check(CLI::IsMember(names));
        };
    named_option("--accel", &scene::AccelSettings::structure, scene::find_accel_structure,
                 scene::accel_names(),
                 "Acceleration structure: bvh2 (binary BVH, kernel tracer), bvh4 or bvh8 "
                 "(wide BVHs, kernel tracer_wide), grid (uniform grid, kernel tracer_grid), "
                 "kdtree (kernel tracer_kdtree), bsp (BSP tree with 13 plane orientations, "
                 "kernel tracer_bsp) or octree (kernel tracer_octree); with --kernel, one the "
                 "kernel traverses (docs/accel.md) [default: the scene file's [accel] "
                 "structure, else the kernel's]");
    accel_option("--grid-resolution", &scene::AccelSettings::grid_resolution,
                 "Uniform grid: cells along the scene's longest axis, the others in "
                 "proportion; 0: by --grid-density")
        ->check(whole_number_in(0, scene::kGridMaxResolution))
        ->default_str(fmt::format("{}", scene::GridConfig{}.resolution));
    accel_option("--grid-density", &scene::AccelSettings::grid_density,
                 "Uniform grid: cells per triangle (cubic cells) when --grid-resolution is 0")
        ->check(CLI::Range(1.0 / 1024, scene::kGridMaxDensity))
        ->default_str(fmt::format("{}", scene::GridConfig{}.density));
    accel_option("--kdtree-max-depth", &scene::AccelSettings::kdtree_max_depth,
                 "kd-tree and BSP tree: deepest leaf; 0: 8 + 1.3 log2(triangles), Havran's rule")
        ->check(whole_number_in(0, scene::kKdMaxDepth))
        ->default_str("0");
    accel_option("--kdtree-max-references", &scene::AccelSettings::kdtree_max_references,
                 "kd-tree and BSP tree: most leaf references per triangle, on average, before "
                 "the build is refused")
        ->check(CLI::Range(1.0, 1e6))
        ->default_str(fmt::format("{}", scene::KdTreeConfig{}.max_references_per_triangle));
    accel_option("--octree-max-depth", &scene::AccelSettings::octree_max_depth,
                 fmt::format("Octree: deepest leaf; 0: {}", scene::kOctreeMaxDepth))
        ->check(whole_number_in(0, scene::kOctreeMaxDepth))
        ->default_str("0");
    command
        ->add_option("-p,--param", o->params,
                     "Set one of the kernel's run-time parameters (TRAX_PARAM), e.g. --param "
                     "threshold=0.02 with --kernel adaptive; repeat for more")
        ->allow_extra_args(false);  // one NAME=VALUE each: a scene after it stays the scene
    command
        ->add_option(
            "-c,--config", o->config,
            "Chip configuration TOML (e.g. configs/tiny.toml) [default: built-in, the same as "
            "configs/trax.toml]")
        ->check(CLI::ExistingFile);
    command
        ->add_option("-s,--set", o->overrides,
                     "Override one chip configuration field, e.g. --set chip.num_tms=8")
        ->allow_extra_args(false);
    const scene::BvhConfig bvh_defaults;
    named_option("--bvh", &scene::AccelSettings::bvh_builder, scene::find_bvh_builder,
                 scene::bvh_builder_names(),
                 "BVH builder, used when the kernel traverses a BVH (TRAX_USES_BVH)")
        ->default_str(scene::to_string(bvh_defaults.builder));
    accel_option("--max-leaf", &scene::AccelSettings::max_leaf, "Most triangles in one BVH leaf")
        ->check(CLI::Range(1, 8))
        ->default_str(fmt::format("{}", bvh_defaults.max_leaf_size));
    named_option("--bvh-order", &scene::AccelSettings::bvh_order, scene::find_bvh_order,
                 scene::bvh_order_names(),
                 "Order of the BVH nodes in memory (docs/accel.md); moves traffic, never the "
                 "image")
        ->default_str(scene::to_string(bvh_defaults.order));
    command->add_flag_function(
        "--bvh-align-pairs", [o](int64_t) { o->accel.bvh_align_pairs = true; },
        "Start every BVH sibling pair on a 64-byte line (docs/accel.md); wide BVH nodes always "
        "start on one");
    named_option("--bvh-boxes", &scene::AccelSettings::bvh_boxes, scene::find_bvh_boxes,
                 scene::bvh_boxes_names(),
                 "How a wide BVH (--accel bvh4|bvh8) stores its child boxes: float, or quantized "
                 "to 8 bits per bound (docs/accel.md)")
        ->default_str(scene::to_string(bvh_defaults.boxes));
    // The same limits as the scene file's [image] keys (docs/scenes.md).
    command->add_option("--width", o->width, "Image width in pixels, instead of the scene's")
        ->check(whole_number_in(1, 16384));
    command->add_option("--height", o->height, "Image height in pixels, instead of the scene's")
        ->check(whole_number_in(1, 16384));
    command
        ->add_option("--spp", o->samples_per_pixel,
                     "Samples per pixel, instead of the scene's samples_per_pixel")
        ->check(whole_number_in(1, 65536));
    command
        ->add_option("--seed", o->seed,
                     "Run seed for the kernel's random numbers (trax_run_seed(), the default "
                     "seeding of trax_rand())")
        ->check(whole_number_in(0, UINT32_MAX))
        ->capture_default_str();
    command->add_flag("--native", o->native,
                      "Run the kernel's native twin on the host instead of the simulator");
    command->add_flag("--no-fork", o->no_fork,
                      "With --native: run the twin in tpsim's own process, for a debugger (gdb "
                      "--args tpsim render ... --native --no-fork; docs/debugging.md); a crash "
                      "then stops tpsim");
    command
        ->add_option("--timing", o->timing,
                     "cycle: the cycle-level chip model (cycles, stalls, caches, DRAM); "
                     "sampled: the chip model on a sample of the run, the rest functionally "
                     "warmed; estimates with 95 % intervals, same image "
                     "(docs/error-vs-time.md); none: the functional simulator only (fast, "
                     "same image)")
        ->check(CLI::IsMember({"cycle", "sampled", "none"}))
        ->capture_default_str();
    const auto sampling_option = [&](std::string_view name, auto& field, std::string help) {
        return command
            ->add_option_function<std::remove_reference_t<decltype(field)>>(
                std::string(name),
                [o, &field](const auto& value) {
                    field = value;
                    o->sampling_set = true;
                },
                std::move(help))
            ->default_str(fmt::format("{}", field));
    };
    sampling_option("--sample-rate", o->sampling.rate,
                    "--timing sampled: share of the instructions simulated cycle by cycle "
                    "(warm-up, unit, drain), in (0, 1]")
        ->check(CLI::Range(0.0, 1.0));
    sampling_option("--sample-unit", o->sampling.unit_cycles,
                    "--timing sampled: cycles measured per unit")
        ->check(kPositiveCount);
    sampling_option("--sample-warmup", o->sampling.warmup_cycles,
                    "--timing sampled: cycle-level warm-up before each unit, not measured")
        ->check(kWholeNumber);
    sampling_option("--sample-seed", o->sampling.seed,
                    "--timing sampled: picks the sample's random start")
        ->check(whole_number_in(0, UINT32_MAX));
    command->add_option("--stats-json", o->stats_json,
                        "Also write the statistics file (JSON, read by tpsim compare and tpsim "
                        "report) here, and the chip configuration beside it (PATH with "
                        "extension .config.toml)");
    command->add_flag("-v,--verbose", o->verbose,
                      "Also print the resolved chip configuration and every statistic "
                      "(docs/statistics.md)");
    command->add_flag("--profile", o->profile,
                      "Profile the kernel by function and source line on the cycle-level chip "
                      "(executions, stalls, L1 misses, DRAM bytes; about 11 % slower)");
    command->add_option("--annotate", o->annotate,
                        "Write the kernel's source annotated with its profile here (implies "
                        "--profile)");
    command->add_option("--heatmap", o->heatmap,
                        "Write a false-colour PNG of the cost per pixel here (with a legend), and "
                        "the raw values beside it as EXR");
    command
        ->add_option("--heatmap-metric", o->heatmap_metric,
                     "What the heat map shows: cycles, instructions or dram_bytes per pixel")
        ->capture_default_str();
    command
        ->add_option("--heatmap-scale", o->heatmap_scale,
                     "How the heat map's colours follow the values: log (a few costly pixels do "
                     "not darken the rest) or linear")
        ->capture_default_str();
    command->add_option("--html", o->html,
                        "Write a self-contained HTML report of the run here (as tpsim report "
                        "makes from a statistics file)");
    command
        ->add_option("--timeline-cycles", o->timeline_cycles,
                     "Cycles per row of the statistics file's timeline; 0: adapt to the run "
                     "(200-400 rows)")
        ->check(kWholeNumber)
        ->capture_default_str();
    command
        ->add_option_function<uint32_t>(
            "--threads", [](uint32_t threads) { core::set_host_threads(threads); },
            "Host threads to simulate on (the chip's TMs, the functional machine's threads); "
            "the image and every statistic are the same for any number. Unset: the "
            "cycle-level chip runs on all cores or on one, whichever is faster as it goes; "
            "the functional machine on one")
        ->check(kPositiveCount)
        ->default_str(fmt::format("up to {}", core::host_threads()));
    command
        ->add_option("--max-instructions", o->max_instructions,
                     "Instructions a thread may run before it is stopped as a runaway")
        ->check(kPositiveCount)
        ->capture_default_str();
    command
        ->add_option("--max-item-instructions", o->max_item_instructions,
                     "Instructions a thread may run on one pixel (between two atomicinc(0)) "
                     "before it is stopped as a runaway [default: 2^22 per ray, or 256 per "
                     "triangle per ray, times the rays of a pixel]")
        ->check(kPositiveCount);
    return {command, [o] { return run_render(*o); }};
}

}  // namespace tpsim::cli
