// `tpsim render SCENE`: renders a scene with a kernel on the simulated chip (or its native twin),
// writes the image and prints the statistics.
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "sim/core/error.hpp"
#include "sim/render/image_file.hpp"
#include "sim/render/render.hpp"
#include "sim/render/report.hpp"
#include "sim/stats/registry.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::cli {
namespace {

/// A kernel given by name is one of the built kernels; anything with a slash or ".elf" is a path.
std::filesystem::path resolve_kernel(const std::string& kernel) {
    if (kernel.find('/') != std::string::npos || kernel.ends_with(".elf")) return kernel;
    const std::filesystem::path built = std::filesystem::path(TPSIM_KERNEL_DIR) / (kernel + ".elf");
    if (!std::filesystem::exists(built))
        throw Error(fmt::format("no built kernel named '{}' (looked for {}); give a path to an ELF "
                                "or build the kernel's NAME_elf target",
                                kernel, built.string()));
    return built;
}

struct RenderCommandOptions {
    std::string scene;
    std::string output;
    std::string kernel = "primary_brute";
    std::string config;
    std::vector<std::string> overrides;
    std::string bvh = "none";
    uint32_t max_leaf = 8;
    bool native = false;
    std::string stats_json;
    uint64_t max_instructions = uint64_t(1) << 32;
};

int run_render(const RenderCommandOptions& o) {
    render::RenderOptions options;
    options.scene = o.scene;
    options.kernel = resolve_kernel(o.kernel);
    options.engine = o.native ? render::Engine::native : render::Engine::functional;
    options.max_instructions = o.max_instructions;
    if (!o.config.empty()) options.chip = timing::load_config(o.config);
    for (const std::string& assignment : o.overrides) timing::apply_override(options.chip, assignment);
    if (o.bvh == "none") {
        options.bvh.reset();
    } else {
        options.bvh->builder = o.bvh == "binned" ? scene::BvhBuilder::binned : scene::BvhBuilder::sweep;
        options.bvh->max_leaf_size = o.max_leaf;
    }

    const render::RenderResult result = render::render(options);
    const std::filesystem::path output =
        o.output.empty() ? std::filesystem::path(o.scene).stem().string() + ".png" : o.output;
    render::write_image(output, result.rgb, result.scene.width, result.scene.height);

    render::print_summary(options, result, std::cout);
    fmt::print("image    {}\n\n", output.string());
    stats::Registry registry;
    render::register_stats(result, registry);
    stats::print_text(registry, std::cout);
    if (!o.stats_json.empty()) {
        std::ofstream json(o.stats_json);
        stats::print_json(registry, json);
        if (!json) throw Error(fmt::format("cannot write statistics to '{}'", o.stats_json));
    }
    return 0;
}

}  // namespace

Command add_render_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "render", "Render a scene (.toml scene file or a mesh: .obj .ply .off ...) with a kernel "
                  "on the simulated chip; write the image and print statistics");
    auto o = std::make_shared<RenderCommandOptions>();
    command->add_option("scene", o->scene, "Scene file or mesh")->required()->check(CLI::ExistingFile);
    command->add_option("-o,--output", o->output,
                        "Image to write (.png 8-bit sRGB; .exr/.tif linear float) [default: SCENE.png]");
    command->add_option("-k,--kernel", o->kernel, "Built kernel name, or a path to a kernel ELF")
        ->capture_default_str();
    command->add_option("-c,--config", o->config, "Chip configuration TOML (e.g. configs/trax.toml)")
        ->check(CLI::ExistingFile);
    command->add_option("-s,--set", o->overrides,
                        "Override one chip configuration field, e.g. --set chip.num_tms=8");
    command->add_option("--bvh", o->bvh, "BVH builder, or none for brute-force kernels")
        ->check(CLI::IsMember({"sweep", "binned", "none"}))
        ->capture_default_str();
    command->add_option("--max-leaf", o->max_leaf, "Most triangles in one BVH leaf")
        ->check(CLI::Range(1, 8))
        ->capture_default_str();
    command->add_flag("--native", o->native,
                      "Run the kernel's native twin on the host instead of the simulator");
    command->add_option("--stats-json", o->stats_json, "Also write the statistics as JSON here");
    command->add_option("--max-instructions", o->max_instructions,
                        "Instructions a thread may run before it is stopped as a runaway")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    return {command, [o] { return run_render(*o); }};
}

}  // namespace tpsim::cli
