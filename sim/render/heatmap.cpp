#include "sim/render/heatmap.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/core/output_directory.hpp"
#include "sim/render/image_codec.hpp"
#include "sim/render/png_file.hpp"
#include "sim/stats/thousands.hpp"

namespace tpsim::render {
namespace {

constexpr std::array<std::string_view, 3> kMetricNames = {"cycles", "instructions", "dram_bytes"};
/// How the legend names each metric.
constexpr std::array<std::string_view, 3> kMetricLabels = {
    "cycles per pixel", "instructions per pixel", "DRAM bytes per pixel"};

uint64_t metric_of(const timing::WorkItemCounters& item, HeatMetric metric) {
    switch (metric) {
    case HeatMetric::Cycles:
        return item.cycles;
    case HeatMetric::Instructions:
        return item.instructions;
    case HeatMetric::DramBytes:
        return item.dram_bytes;
    }
    return 0;
}

/// "1,234,567": legend values are counts.
std::string grouped(double value) {
    return stats::with_thousands(fmt::format("{:.0f}", value));
}

// Layout of the PNG, in pixels.
constexpr uint32_t kMinWidth = 320;   ///< narrower maps are magnified, the legend needs room
constexpr uint32_t kMaxMagnify = 16;  ///< bounds the PNG of a tiny, oddly shaped image
constexpr int kLegendHeight = 50;     ///< the strip below the map
constexpr int kMargin = 10;           ///< around the bar, left and right
constexpr int kBarTop = 10, kBarHeight = 14, kTextBaseline = 42, kFontSize = 14;
constexpr int kTextRow = 20,
              kTextGap = 12;  ///< a second row of text; the least space between texts
constexpr std::array<float, 3> kBackground = {0.10f, 0.10f, 0.11f};
constexpr std::array<float, 3> kFrame = {0.55f, 0.55f, 0.55f};
constexpr std::array<float, 3> kText = {0.92f, 0.92f, 0.92f};
constexpr const char* kFont = "DejaVuSans";  // Debian fonts-dejavu-core

/// RGB float canvas, row 0 at the top.
struct Canvas {
    int width, height;
    std::vector<float> rgb;

    Canvas(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3) {
        for (size_t i = 0; i < rgb.size(); ++i)
            rgb[i] = kBackground[i % 3];
    }
    void set(int x, int y, const std::array<float, 3>& colour) {
        std::copy(colour.begin(), colour.end(), rgb.begin() + (size_t(y) * width + x) * 3);
    }
};

/// Writes float pixels as `file` says, naming the path in any error.
void write_pixels(const std::filesystem::path& path, const ImageLayout& file,
                  std::span<const float> pixels) {
    std::string error;
    if (!image_codec().write(path.string(), file, pixels, error))
        throw Error(fmt::format("cannot write heat map '{}': {}", path.string(), error));
}

}  // namespace

std::string_view metric_name(HeatMetric metric) {
    return kMetricNames[size_t(metric)];
}

HeatScale parse_heat_scale(std::string_view name) {
    if (name == "linear") return HeatScale::Linear;
    if (name == "log") return HeatScale::Log;
    throw Error(fmt::format("unknown heat-map scale '{}'; use linear or log", name));
}

HeatMetric parse_heat_metric(std::string_view name) {
    for (size_t i = 0; i < kMetricNames.size(); ++i)
        if (name == kMetricNames[i]) return HeatMetric(i);
    throw Error(
        fmt::format("unknown heat-map metric '{}'; use cycles, instructions or dram_bytes", name));
}

void check_heatmap_path(const std::filesystem::path& path) {
    if (!is_png(path))
        throw Error(fmt::format("cannot write heat map '{}': it is a PNG (its float EXR goes "
                                "beside it); give a name ending in .png",
                                path.string()));
    require_output_directory(path, fmt::format("cannot write heat map '{}'", path.string()));
}

std::vector<double> heat_values(const timing::WorkItemCosts& costs, uint32_t width, uint32_t height,
                                HeatMetric metric) {
    std::vector<double> values(size_t(width) * height, 0.0);
    for (size_t i = 0; i < std::min(values.size(), costs.items.size()); ++i)
        values[i] = double(metric_of(costs.items[i], metric));
    return values;
}

std::array<float, 3> inferno(float t) {
    // Coefficients of t^0 .. t^6 per channel (https://www.shadertoy.com/view/WlfXRN, CC0).
    constexpr std::array<std::array<double, 3>, 7> kC = {{
        {0.0002189403691192265, 0.001651004631001012, -0.01948089843709184},
        {0.1065134194856116, 0.5639564367884091, 3.932712388889277},
        {11.60249308247187, -3.972853965665698, -15.9423941062914},
        {-41.70399613139459, 17.43639888205313, 44.35414519872813},
        {77.162935699427, -33.40235894210092, -81.80730925738993},
        {-71.31942824499214, 32.62606426397723, 73.20951985803202},
        {25.13112622477341, -12.24266895238567, -23.07032500287172},
    }};
    const double x = std::clamp(double(t), 0.0, 1.0);
    std::array<float, 3> rgb;
    for (size_t c = 0; c < 3; ++c) {
        double v = 0;
        for (size_t k = kC.size(); k-- > 0;)
            v = v * x + kC[k][c];
        rgb[c] = float(std::clamp(v, 0.0, 1.0));
    }
    return rgb;
}

HeatmapFiles write_heatmap(const std::filesystem::path& png_path,
                           const timing::WorkItemCosts& costs, uint32_t width, uint32_t height,
                           HeatMetric metric, HeatScale scale) {
    check_heatmap_path(png_path);
    if (width == 0 || height == 0)
        throw Error(fmt::format("cannot write heat map '{}': the image has no pixels ({}x{})",
                                png_path.string(), width, height));
    HeatmapFiles files{png_path, std::filesystem::path(png_path).replace_extension(".exr"), ""};
    const std::vector<double> values = heat_values(costs, width, height, metric);

    const std::vector<float> raw(values.begin(), values.end());
    const std::pair<std::string, std::string> metric_attribute{"tpsim:metric",
                                                               std::string(metric_name(metric))};
    write_pixels(
        files.exr,
        ImageLayout{int(width), int(height), 1, PixelType::Float, {"Y"}, {metric_attribute}}, raw);

    const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
    const double low = *lowest, range = *highest - *lowest;
    // Position on the colour bar, 0 at the minimum, 1 at the maximum.
    const bool log_scale = scale == HeatScale::Log;
    const auto position = [&](double v) {
        if (range <= 0) return 0.0f;
        return float(log_scale ? std::log1p(v - low) / std::log1p(range) : (v - low) / range);
    };
    const auto colour = [&](double v) { return inferno(position(v)); };

    const ImageCodec& codec = image_codec();
    const std::string low_text = grouped(low), high_text = grouped(*highest);
    const std::string label =
        std::string(kMetricLabels[size_t(metric)]) + (log_scale ? " (log scale)" : "");
    const auto text_width = [&](const std::string& text) {
        return codec.text_width(text, kFontSize, kFont);
    };

    const uint32_t magnify = std::clamp((kMinWidth + width - 1) / width, 1u, kMaxMagnify);
    const int map_width = int(width * magnify), map_height = int(height * magnify);
    const int canvas_width = std::max(map_width, int(kMinWidth));
    // The label sits centred between the minimum and the maximum, or on a row of its own below
    // them when the numbers are too wide for that.
    const int room = (canvas_width - text_width(label)) / 2 - kMargin - kTextGap;
    const bool label_row = std::max(text_width(low_text), text_width(high_text)) > room;
    Canvas canvas(canvas_width, map_height + kLegendHeight + (label_row ? kTextRow : 0));
    const int left = (canvas.width - map_width) / 2;
    for (int y = 0; y < map_height; ++y)
        for (int x = 0; x < map_width; ++x)
            canvas.set(left + x, y, colour(values[size_t(y / magnify) * width + x / magnify]));

    // The legend: a framed bar from the minimum to the maximum colour.
    const int bar_left = kMargin, bar_right = canvas.width - kMargin;
    const int bar_top = map_height + kBarTop, bar_bottom = bar_top + kBarHeight;
    for (int y = bar_top - 1; y <= bar_bottom; ++y)
        for (int x = bar_left - 1; x <= bar_right; ++x) {
            const bool frame = y < bar_top || y == bar_bottom || x < bar_left || x == bar_right;
            canvas.set(x, y,
                       frame ? kFrame : inferno(float(x - bar_left) / (bar_right - bar_left - 1)));
        }

    const int baseline = map_height + kTextBaseline;
    std::string error;
    const auto draw = [&](int x, int y, const std::string& text, TextAlign align) {
        return codec.draw_text(canvas.rgb, canvas.width, canvas.height, x, y, text, kFontSize,
                               kFont, kText, align, error);
    };
    const bool text =
        draw(bar_left, baseline, low_text, TextAlign::Left) &&
        draw(canvas.width / 2, baseline + (label_row ? kTextRow : 0), label, TextAlign::Center) &&
        draw(bar_right, baseline, high_text, TextAlign::Right);
    if (!text)
        files.legend_problem = fmt::format(
            "heat map '{}' has no legend text: OpenImageIO could not draw it ({}); install the "
            "font {} (Debian fonts-dejavu-core)",
            png_path.string(), error, kFont);
    // The colour map's values are sRGB-encoded.
    write_pixels(files.png,
                 ImageLayout{canvas.width,
                             canvas.height,
                             3,
                             PixelType::UInt8,
                             {},
                             {{"oiio:ColorSpace", "sRGB"}, metric_attribute}},
                 canvas.rgb);
    return files;
}

}  // namespace tpsim::render
