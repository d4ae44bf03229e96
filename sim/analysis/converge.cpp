#include "sim/analysis/converge.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/render/image_file.hpp"
#include "sim/render/report.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/stats/thousands.hpp"

namespace tpsim::analysis {
namespace {

using Kind = ConvergeRun::Kind;

/// The shortest text that reads back as the same float: "0.05".
std::string float_text(float value) {
    return fmt::format("{}", value);
}

std::string count_text(double count) {
    return stats::with_thousands(fmt::format("{:.0f}", count));
}

std::string psnr_text(double psnr) {
    return std::isinf(psnr) ? "identical" : fmt::format("{:.2f} dB", psnr);
}

const render::KernelParam* find_param(const std::vector<render::KernelParam>& params,
                                      std::string_view name) {
    const auto found = std::find_if(params.begin(), params.end(),
                                    [&](const render::KernelParam& p) { return p.name == name; });
    return found == params.end() ? nullptr : &*found;
}

/// The uniform runs' PSNR at `cycles`, linear in log(cycles) between the two around it (Monte
/// Carlo error falls as 1/sqrt(samples), so PSNR grows by 10 dB per tenfold samples and about
/// as much per tenfold cycles); absent outside the uniform runs' range.
std::optional<double> uniform_psnr_at(const std::vector<ConvergeRun>& runs, uint64_t cycles) {
    std::vector<const ConvergeRun*> uniform;
    for (const ConvergeRun& run : runs)
        if (run.kind == Kind::uniform && std::isfinite(run.error.psnr)) uniform.push_back(&run);
    std::sort(uniform.begin(), uniform.end(),
              [](const ConvergeRun* a, const ConvergeRun* b) { return a->cycles < b->cycles; });
    for (size_t i = 0; i + 1 < uniform.size(); ++i) {
        const ConvergeRun &a = *uniform[i], &b = *uniform[i + 1];
        if (cycles < a.cycles || cycles > b.cycles || a.cycles == b.cycles) continue;
        const double at = std::log(double(cycles) / double(a.cycles)) /
                          std::log(double(b.cycles) / double(a.cycles));
        return a.error.psnr + at * (b.error.psnr - a.error.psnr);
    }
    if (uniform.size() == 1 && uniform[0]->cycles == cycles) return uniform[0]->error.psnr;
    return std::nullopt;
}

/// Checks what can be checked before the first render, and records the two kernels'
/// parameters as the runs will set them.
void check(const ConvergeOptions& o, ConvergeResult& result) {
    if (o.spp.empty() && o.thresholds.empty())
        throw Error("nothing to measure: give sample counts (--spp) or adaptive thresholds "
                    "(--adaptive)");
    uint32_t largest = o.spp.empty() ? 0 : *std::max_element(o.spp.begin(), o.spp.end());
    if (!o.thresholds.empty()) largest = std::max(largest, o.adaptive_spp);
    if (o.reference_spp <= largest)
        throw Error(fmt::format("the reference ({} spp, --reference-spp) must take more samples "
                                "per pixel than any run ({}): it stands for the converged image",
                                o.reference_spp, largest));
    render::Kernel kernel = render::Kernel::load(o.base.kernel);
    kernel.set_params(o.base.params);
    result.params = kernel.params;
    render::check_stack(kernel, render::Engine::timing, o.base.chip);
    if (o.thresholds.empty()) return;

    render::Kernel adaptive = render::Kernel::load(o.adaptive_kernel);
    const std::string name = o.adaptive_kernel.filename().string();
    const render::KernelParam* threshold = find_param(adaptive.params, "threshold");
    if (!threshold || threshold->type != render::KernelParam::Type::float32)
        throw Error(fmt::format("the adaptive kernel {} has no float parameter 'threshold' "
                                "(TRAX_PARAM(float, threshold, ...)); give --adaptive-kernel a "
                                "kernel that has, such as adaptive",
                                name));
    for (const std::string& assignment : o.adaptive_params)
        if (assignment.starts_with("threshold="))
            throw Error("each adaptive run sets the threshold itself: give the thresholds with "
                        "--adaptive, not --adaptive-param threshold=...");
    adaptive.set_params(o.adaptive_params);
    render::check_stack(adaptive, render::Engine::timing, o.base.chip);
    for (const render::KernelParam& p : adaptive.params)
        if (p.name != "threshold") result.adaptive_params.push_back(p);
    // The adaptive kernel's own rule (kernel/kernels/adaptive.cpp): it takes first_samples
    // everywhere, so at no more samples than that no pixel is refined.
    if (const render::KernelParam* first = find_param(adaptive.params, "first_samples");
        first && first->type == render::KernelParam::Type::int32 &&
        int64_t(o.adaptive_spp) <= int32_t(first->bits))
        throw Error(fmt::format("adaptive runs at {} spp (--adaptive-spp) take no more than the "
                                "{} samples {} gives every pixel first (first_samples): give "
                                "--adaptive-spp more than {}, or --adaptive-param "
                                "first_samples=N with N < {}",
                                o.adaptive_spp, first->text(), name, first->text(),
                                o.adaptive_spp));
}

}  // namespace

ConvergeResult converge(const ConvergeOptions& o,
                        const std::function<void(const ConvergeResult&)>& on_progress) {
    ConvergeResult result;
    check(o, result);
    std::vector<uint32_t> spp = o.spp;
    std::sort(spp.begin(), spp.end());
    const size_t count = 1 + spp.size() + o.thresholds.size();
    const std::string scene = o.base.scene.stem().string();
    size_t index = 0;

    // One render, written and measured; the options are base's with these changes.
    const auto measure = [&](ConvergeRun run, render::RenderOptions options,
                             const std::string& file_label) {
        if (o.on_render) o.on_render(index++, count, run.label);
        const render::RenderResult r = render::render(options);
        run.image = o.output_dir / fmt::format("converge-{}-{}.png", scene, file_label);
        render::write_image(run.image, r.rgb, r.scene.width, r.scene.height);
        const double pixels = double(r.scene.width) * r.scene.height;
        run.camera_rays_per_pixel = double(r.traversal.primary_rays) / pixels;
        run.rays = r.traversal.rays();
        run.instructions = r.instructions.total;
        run.host_seconds = r.run_seconds;
        if (r.timing) {
            run.cycles = r.timing->chip->cycles();
            run.frame_seconds = double(run.cycles) / (options.chip.chip.clock_mhz * 1e6);
        }
        if (run.kind == Kind::reference) {
            result.width = r.scene.width;
            result.height = r.scene.height;
            result.reference = std::move(run);
        } else {
            run.error = compare_images(result.reference.image, run.image);
            if (!run.error.compared()) throw Error(run.error.note);
            // The uniform runs come first: all of them are measured by now.
            if (run.kind == Kind::adaptive)
                run.uniform_psnr_at_same_cycles = uniform_psnr_at(result.runs, run.cycles);
            result.runs.push_back(std::move(run));
        }
        if (on_progress) on_progress(result);
    };

    render::RenderOptions reference = o.base;
    reference.engine = render::Engine::native;
    reference.samples_per_pixel = o.reference_spp;
    reference.seed = o.base.seed + 1;
    measure({.kind = Kind::reference,
             .label = fmt::format("reference {} spp", o.reference_spp),
             .samples_per_pixel = o.reference_spp},
            reference, "reference");

    for (const uint32_t samples : spp) {
        render::RenderOptions uniform = o.base;
        uniform.engine = render::Engine::timing;
        uniform.samples_per_pixel = samples;
        measure({.kind = Kind::uniform,
                 .label = fmt::format("{} spp", samples),
                 .samples_per_pixel = samples},
                uniform, fmt::format("spp{}", samples));
    }

    std::vector<float> thresholds = o.thresholds;
    std::sort(thresholds.begin(), thresholds.end(), std::greater<>());  // cheapest first
    for (const float threshold : thresholds) {
        render::RenderOptions adaptive = o.base;
        adaptive.engine = render::Engine::timing;
        adaptive.kernel = o.adaptive_kernel;
        adaptive.params = o.adaptive_params;
        adaptive.params.push_back("threshold=" + float_text(threshold));
        adaptive.samples_per_pixel = o.adaptive_spp;
        measure({.kind = Kind::adaptive,
                 .label = "adaptive " + float_text(threshold),
                 .samples_per_pixel = o.adaptive_spp,
                 .threshold = threshold},
                adaptive, "adaptive-" + float_text(threshold));
    }
    return result;
}

std::string converge_header(const ConvergeOptions& o, const ConvergeResult& result) {
    const timing::ChipConfig& chip = o.base.chip;
    const auto kernel = [](const std::filesystem::path& elf,
                           const std::vector<render::KernelParam>& params) {
        return render::display_path(elf) +
               (params.empty() ? "" : " (" + render::describe_params(params) + ")");
    };
    std::string text =
        fmt::format("converge  {}, {}x{} pixels, seed {}\n"
                    "kernel    {} on the cycle-level chip model ({} TMs x {} TPs)\n"
                    "config    {}\n",
                    render::display_path(o.base.scene), result.width, result.height, o.base.seed,
                    kernel(o.base.kernel, result.params), chip.chip.num_tms, chip.chip.tps_per_tm,
                    render::describe_config(chip));
    if (!o.thresholds.empty())
        text += fmt::format("adaptive  {} at up to {} spp, threshold as below\n",
                            kernel(o.adaptive_kernel, result.adaptive_params), o.adaptive_spp);
    const ConvergeRun& ref = result.reference;
    text += fmt::format("reference {} spp on the native twin, seed {}: {} rays in {:.1f} s, {}\n"
                        "error     RMSE and PSNR of each image against the reference, over the "
                        "8-bit sRGB PNGs (peak 1); uniform PSNR: what uniform sampling reaches "
                        "at the same frame cycles (interpolated)\n\n",
                        ref.samples_per_pixel, o.base.seed + 1, count_text(double(ref.rays)),
                        ref.host_seconds, render::display_path(ref.image));
    text += fmt::format("{:<16}{:>14}{:>14}{:>12}{:>10}{:>11}{:>16}{:>10}\n", "run", "samples/px",
                        "frame cycles", "rays", "RMSE", "PSNR", "uniform PSNR", "host s");
    return text;
}

std::string converge_row(const ConvergeRun& run) {
    const std::string samples =
        run.kind == Kind::adaptive
            ? fmt::format("{:.2f} of {}", run.camera_rays_per_pixel, run.samples_per_pixel)
            : std::to_string(run.samples_per_pixel);
    const std::string uniform = run.kind != Kind::adaptive ? ""
                                : run.uniform_psnr_at_same_cycles
                                    ? psnr_text(*run.uniform_psnr_at_same_cycles)
                                    : "-";
    return fmt::format("{:<16}{:>14}{:>14}{:>12}{:>10.6f}{:>11}{:>16}{:>10.1f}\n", run.label,
                       samples, count_text(double(run.cycles)), count_text(double(run.rays)),
                       run.error.rmse, psnr_text(run.error.psnr), uniform, run.host_seconds);
}

nlohmann::ordered_json converge_document(const ConvergeOptions& o, const ConvergeResult& result,
                                         const std::filesystem::path& json_path) {
    using Json = nlohmann::ordered_json;
    const std::filesystem::path base =
        json_path.has_parent_path() ? json_path.parent_path() : std::filesystem::path(".");
    const auto params_json = [](const std::vector<render::KernelParam>& params) {
        Json out = Json::object();
        for (const render::KernelParam& p : params)
            out[p.name] = Json::parse(p.text());
        return out;
    };
    const auto number_or_null = [](double v) { return std::isfinite(v) ? Json(v) : Json(); };
    const auto run_json = [&](const ConvergeRun& run) {
        Json j;
        j["kind"] = run.kind == Kind::reference ? "reference"
                    : run.kind == Kind::uniform ? "uniform"
                                                : "adaptive";
        j["label"] = run.label;
        j["samples_per_pixel"] = run.samples_per_pixel;
        j["threshold"] = run.threshold ? Json::parse(float_text(*run.threshold)) : Json();
        j["camera_rays_per_pixel"] = run.camera_rays_per_pixel;
        j["cycles"] = run.kind == Kind::reference ? Json() : Json(run.cycles);
        j["frame_seconds"] = run.kind == Kind::reference ? Json() : Json(run.frame_seconds);
        j["rays"] = run.rays;
        j["instructions"] = run.kind == Kind::reference ? Json() : Json(run.instructions);
        if (run.kind != Kind::reference) {
            j["rmse"] = run.error.rmse;
            j["psnr"] = number_or_null(run.error.psnr);  // null: identical to the reference
            j["differing_pixels"] = run.error.differing_pixels;
        }
        if (run.kind == Kind::adaptive)
            j["uniform_psnr_at_same_cycles"] =
                run.uniform_psnr_at_same_cycles ? Json(*run.uniform_psnr_at_same_cycles) : Json();
        j["host_seconds"] = run.host_seconds;
        j["image"] = std::filesystem::proximate(run.image, base).generic_string();
        return j;
    };
    Json doc;
    doc["format"] = "tpsim-converge";
    doc["version"] = 1;
    doc["scene"] = o.base.scene.generic_string();
    doc["width"] = result.width;
    doc["height"] = result.height;
    doc["seed"] = o.base.seed;
    doc["kernel"] = o.base.kernel.generic_string();
    doc["params"] = params_json(result.params);
    if (!o.thresholds.empty()) {
        doc["adaptive_kernel"] = o.adaptive_kernel.generic_string();
        doc["adaptive_params"] = params_json(result.adaptive_params);
    }
    Json& config = doc["config"];
    for (const timing::ConfigField& field : timing::config_fields(o.base.chip))
        config[field.key] = field.is_real   ? Json(field.real)
                            : field.is_bool ? Json(field.value != 0)
                                            : Json(field.value);
    doc["reference"] = run_json(result.reference);
    doc["reference"]["seed"] = o.base.seed + 1;
    doc["runs"] = Json::array();
    for (const ConvergeRun& run : result.runs)
        doc["runs"].push_back(run_json(run));
    return doc;
}

}  // namespace tpsim::analysis
