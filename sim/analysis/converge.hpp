// `tpsim converge`: image error against render cost. Renders a scene at several sample counts,
// and with adaptive super-sampling at several thresholds, on the cycle-level chip; measures each
// image against a high-sample reference from the native twin (RMSE and PSNR, compare_images)
// and reports them beside the frame cycles, rays and host time (docs/error-vs-time.md).
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/analysis/images.hpp"
#include "sim/render/render.hpp"

namespace tpsim::analysis {

struct ConvergeOptions {
    /// What every run shares: scene, kernel and its parameters, chip, image size, seed. The
    /// engine and the samples per pixel are set per run.
    render::RenderOptions base;
    std::vector<uint32_t> spp;  ///< the uniform runs: base.kernel at these samples per pixel
    /// The adaptive runs: this kernel (it declares a float parameter `threshold`) with its
    /// parameters `adaptive_params` and each threshold, at `adaptive_spp` samples per pixel.
    std::filesystem::path adaptive_kernel;
    std::vector<std::string> adaptive_params;
    std::vector<float> thresholds;
    uint32_t adaptive_spp = 0;
    /// The reference: base.kernel on the native twin at this many samples per pixel, with seed
    /// base.seed + 1 so that its random numbers are not the runs' (a path tracer seeded per
    /// pixel and sample would otherwise share its first samples with every run).
    uint32_t reference_spp = 0;
    std::filesystem::path output_dir = ".";  ///< the images, converge-SCENE-LABEL.png
    /// Called before each render (index from 0, of `count`; the reference is index 0).
    std::function<void(size_t index, size_t count, const std::string& label)> on_render;
};

struct ConvergeRun {
    enum class Kind { reference, uniform, adaptive };
    Kind kind = Kind::uniform;
    std::string label;                    ///< "4 spp", "adaptive 0.05", "reference 1024 spp"
    uint32_t samples_per_pixel = 0;       ///< uniform: all pixels; adaptive: the most one may take
    std::optional<float> threshold = {};  ///< adaptive runs
    double camera_rays_per_pixel = 0;     ///< primary rays / pixels: what an adaptive run spent
    uint64_t cycles = 0;                  ///< simulated frame cycles (0 for the reference)
    double frame_seconds = 0;             ///< at the chip's clock
    uint64_t rays = 0;                    ///< camera and shadow rays
    uint64_t instructions = 0;
    double host_seconds = 0;     ///< the kernel run on the host (not a result)
    ImageDifference error = {};  ///< against the reference (none for the reference)
    /// Adaptive runs: the PSNR uniform sampling reaches at the same frame cycles, interpolated
    /// linearly in log(cycles) between the uniform runs around it; absent outside their range.
    std::optional<double> uniform_psnr_at_same_cycles = {};
    std::filesystem::path image = {};
};

struct ConvergeResult {
    uint32_t width = 0, height = 0;                    ///< the image, as the runs render it
    std::vector<render::KernelParam> params;           ///< the kernel's, as the runs set them
    std::vector<render::KernelParam> adaptive_params;  ///< the adaptive kernel's, but threshold
    ConvergeRun reference;
    std::vector<ConvergeRun> runs;  ///< uniform by samples per pixel, then adaptive
};

/// Throws tpsim::Error for options that cannot give a measurement (no runs, a reference with no
/// more samples than a run, an adaptive kernel without a float `threshold` parameter, bad
/// kernel parameters) before anything renders. Then renders the reference and every run, and
/// calls `on_progress` with the result so far after each: the reference alone first, then each
/// run as the last of `runs`.
ConvergeResult converge(const ConvergeOptions& options,
                        const std::function<void(const ConvergeResult&)>& on_progress = {});

/// The table, printed as the runs finish: a header (the setup, the reference and the column
/// titles) once the reference is done, then one row per run.
std::string converge_header(const ConvergeOptions& options, const ConvergeResult& result);
std::string converge_row(const ConvergeRun& run);

/// The result as a file (format "tpsim-converge", version 1; docs/error-vs-time.md), image paths
/// relative to the directory of `json_path`; converge_page() (html_report.hpp) makes the page
/// from it.
nlohmann::ordered_json converge_document(const ConvergeOptions& options,
                                         const ConvergeResult& result,
                                         const std::filesystem::path& json_path);

}  // namespace tpsim::analysis
