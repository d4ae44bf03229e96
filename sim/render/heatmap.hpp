// The per-pixel heat map: what each work item (pixel) cost the chip, as a false-colour PNG with a
// colour-scale legend and, beside it, a float EXR of the raw values.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "sim/timing/attribution.hpp"

namespace tpsim::render {

/// Which WorkItemCounters field the heat map shows.
enum class HeatMetric { Cycles, Instructions, DramBytes };

/// "cycles", "instructions" or "dram_bytes" (the field's name).
std::string_view metric_name(HeatMetric metric);

/// The metric called `name`; throws tpsim::Error naming the choices for anything else.
HeatMetric parse_heat_metric(std::string_view name);

/// How values map to colours: evenly from the minimum to the maximum, or by the logarithm of
/// their distance from the minimum (costs per pixel are heavy-tailed: a few grazing rays would
/// otherwise darken the rest).
enum class HeatScale { Linear, Log };

/// The scale called "linear" or "log"; throws tpsim::Error naming the choices otherwise.
HeatScale parse_heat_scale(std::string_view name);

/// Throws tpsim::Error unless a heat map can be written at `path`: a .png name in an existing
/// directory. Called before a render so a long run cannot end in a bad path.
void check_heatmap_path(const std::filesystem::path& path);

/// The metric per pixel, row-major (item y * width + x); pixels without an item are 0, items
/// beyond width * height are ignored.
std::vector<double> heat_values(const timing::WorkItemCosts& costs, uint32_t width, uint32_t height,
                                HeatMetric metric);

/// The inferno colour map (Smith and van der Walt's matplotlib map, as the degree-6 polynomial
/// fit by Matt Zucconi): t in [0, 1] from black through purple and orange to yellow, lightness
/// rising monotonically. sRGB-encoded components in [0, 1].
std::array<float, 3> inferno(float t);

struct HeatmapFiles {
    std::filesystem::path png, exr;
    /// Empty, or why the legend has no text (the PNG was written all the same).
    std::string legend_problem;
};

/// Writes the heat map of `metric` to `png_path` (false colour from the minimum to the maximum
/// pixel value on `scale`, magnified for small images, a legend bar with the minimum, the
/// maximum and the metric's name below it) and the raw per-pixel values as one float channel to the
/// same stem with .exr (exact up to 2^24). Throws tpsim::Error for a bad path or a failed write.
HeatmapFiles write_heatmap(const std::filesystem::path& png_path,
                           const timing::WorkItemCosts& costs, uint32_t width, uint32_t height,
                           HeatMetric metric, HeatScale scale = HeatScale::Linear);

}  // namespace tpsim::render
