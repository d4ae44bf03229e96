// The per-pixel heat map: exact raw values in the EXR, the false-colour PNG and its legend, and
// clear errors for a bad metric or path.
#include <cmath>
#include <fstream>
#include <iterator>

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include "sim/core/error.hpp"
#include "sim/render/heatmap.hpp"
#include "tests/scratch.hpp"

using namespace tpsim;
using tpsim::testing::scratch_path;

namespace {

struct Pixels {
    int width = 0, height = 0, channels = 0;
    std::vector<float> values;
    float at(int x, int y, int c = 0) const {
        return values[(size_t(y) * width + x) * channels + c];
    }
};

/// The image as stored: floats for the EXR, 0..255 for the 8-bit PNG.
Pixels read(const std::filesystem::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    REQUIRE(in);
    const OIIO::ImageSpec& spec = in->spec();
    Pixels p{spec.width, spec.height, spec.nchannels, {}};
    p.values.resize(size_t(p.width) * p.height * p.channels);
    const bool png = spec.format == OIIO::TypeDesc::UINT8;
    if (png) {
        std::vector<uint8_t> bytes(p.values.size());
        REQUIRE(in->read_image(0, 0, 0, p.channels, OIIO::TypeDesc::UINT8, bytes.data()));
        std::copy(bytes.begin(), bytes.end(), p.values.begin());
    } else {
        REQUIRE(in->read_image(0, 0, 0, p.channels, OIIO::TypeDesc::FLOAT, p.values.data()));
    }
    return p;
}

/// Items whose metrics differ per field, so a wrong field shows.
timing::WorkItemCosts pattern(size_t items) {
    timing::WorkItemCosts costs;
    for (size_t i = 0; i < items; ++i)
        costs.items.push_back({1000 + 37 * i, 500 + (i * 7) % 101, 64 * (i % 13)});
    costs.unassigned = {999999, 999999, 999999};
    return costs;
}

std::array<float, 3> as_bytes(const std::array<float, 3>& rgb) {
    return {std::round(rgb[0] * 255), std::round(rgb[1] * 255), std::round(rgb[2] * 255)};
}

}  // namespace

TEST_CASE("heat map: the EXR holds each pixel's metric exactly", "[heatmap]") {
    constexpr uint32_t w = 37, h = 23;
    SECTION("fewer items than pixels: the rest are 0") {
        const timing::WorkItemCosts costs = pattern(w * h - 10);
        const auto files = render::write_heatmap(scratch_path("few.png"), costs, w, h,
                                                 render::HeatMetric::Instructions);
        CHECK(files.exr == scratch_path("few.exr"));
        const Pixels exr = read(files.exr);
        REQUIRE(exr.width == int(w));
        REQUIRE(exr.height == int(h));
        REQUIRE(exr.channels == 1);
        for (uint32_t i : {0u, 1u, 36u, 37u, 500u, w * h - 11})
            CHECK(exr.at(i % w, i / w) == float(costs.items[i].instructions));
        CHECK(exr.at(w - 1, h - 1) == 0.0f);
        CHECK(exr.at((w * h - 10) % w, h - 1) == 0.0f);
    }
    SECTION("more items than pixels: the extra ones are ignored") {
        const timing::WorkItemCosts costs = pattern(w * h + 50);
        for (const auto metric : {render::HeatMetric::Cycles, render::HeatMetric::DramBytes}) {
            const auto files = render::write_heatmap(scratch_path("many.png"), costs, w, h, metric);
            const Pixels exr = read(files.exr);
            for (uint32_t i : {0u, 5u, 100u, w * h - 1}) {
                const auto& item = costs.items[i];
                const uint64_t expected =
                    metric == render::HeatMetric::Cycles ? item.cycles : item.dram_bytes;
                CHECK(exr.at(i % w, i / w) == float(expected));
            }
            CHECK(render::heat_values(costs, w, h, metric).size() == w * h);
        }
    }
}

TEST_CASE("heat map: the PNG maps the values to inferno with a legend below", "[heatmap]") {
    constexpr uint32_t w = 100, h = 40;  // 100 wide: magnified 4 times to 400
    timing::WorkItemCosts costs;
    for (uint32_t i = 0; i < w * h; ++i)
        costs.items.push_back({uint64_t(10 + (i % w) * 10), 0, 0});  // 10 .. 1000 left to right
    const auto files =
        render::write_heatmap(scratch_path("ramp.png"), costs, w, h, render::HeatMetric::Cycles);
    CHECK(files.legend_problem.empty());  // fonts-dejavu-core is installed by scripts/setup
    const Pixels png = read(files.png);
    REQUIRE(png.channels == 3);
    CHECK(png.width == int(4 * w));
    REQUIRE(png.height > int(4 * h) + 30);

    // Left column the minimum, right column the maximum colour.
    const auto pixel = [&](int x, int y) {
        return std::array<float, 3>{png.at(x, y, 0), png.at(x, y, 1), png.at(x, y, 2)};
    };
    CHECK(pixel(0, 0) == as_bytes(render::inferno(0)));
    CHECK(pixel(4 * w - 1, 4 * h - 1) == as_bytes(render::inferno(1)));
    CHECK(pixel(4 * 50, 10) == as_bytes(render::inferno(500.f / 990.f)));

    // The legend strip: a bar that runs from dark to bright, and text (bright pixels) below it.
    const int strip = 4 * h;
    int brightest_row = -1;
    float bar_left = 0, bar_right = 0;
    for (int y = strip; y < png.height; ++y) {
        const float left = png.at(12, y, 0) + png.at(12, y, 1) + png.at(12, y, 2);
        const float right = png.at(png.width - 13, y, 0) + png.at(png.width - 13, y, 1) +
                            png.at(png.width - 13, y, 2);
        if (right > bar_right) bar_right = right, bar_left = left, brightest_row = y;
    }
    REQUIRE(brightest_row > strip);
    CHECK(bar_right > bar_left + 400);
    size_t text_pixels = 0;
    for (int y = brightest_row + 4; y < png.height; ++y)
        for (int x = 0; x < png.width; ++x)
            text_pixels += png.at(x, y, 0) > 200 && png.at(x, y, 2) > 200;  // white, not yellow
    CHECK(text_pixels > 100);

    // Numbers too wide to share a row with the label push it onto a row of its own.
    for (timing::WorkItemCounters& item : costs.items)
        item.cycles *= 1'000'000'000;
    const Pixels wide = read(render::write_heatmap(scratch_path("ramp_wide.png"), costs, w, h,
                                                   render::HeatMetric::Cycles)
                                 .png);
    CHECK(wide.width == png.width);
    CHECK(wide.height > png.height);
}

TEST_CASE("heat map: the log scale spreads heavy-tailed costs", "[heatmap]") {
    constexpr uint32_t w = 100, h = 4;
    timing::WorkItemCosts costs;
    for (uint32_t i = 0; i < w * h; ++i)  // 100 everywhere, one pixel per row 100x that
        costs.items.push_back({i % w == 99 ? 10'000u : 100u + i % w, 0, 0});
    const auto linear = render::write_heatmap(scratch_path("tail_linear.png"), costs, w, h,
                                              render::HeatMetric::Cycles);
    const auto log = render::write_heatmap(scratch_path("tail_log.png"), costs, w, h,
                                           render::HeatMetric::Cycles, render::HeatScale::Log);
    const Pixels a = read(linear.png), b = read(log.png);
    const auto pixel = [](const Pixels& png, int x) {
        return std::array<float, 3>{png.at(x, 0, 0), png.at(x, 0, 1), png.at(x, 0, 2)};
    };
    // Pixel 50 (value 150) is 50 above the minimum in a range of 9,900.
    CHECK(pixel(a, 4 * 50) == as_bytes(render::inferno(50.f / 9900.f)));
    CHECK(pixel(b, 4 * 50) ==
          as_bytes(render::inferno(float(std::log1p(50.0) / std::log1p(9900.0)))));
    CHECK(pixel(b, 0) == as_bytes(render::inferno(0)));       // the minimum stays black
    CHECK(pixel(b, 4 * 99) == as_bytes(render::inferno(1)));  // the maximum stays yellow
    CHECK(render::parse_heat_scale("log") == render::HeatScale::Log);
    CHECK_THROWS_WITH(render::parse_heat_scale("sqrt"),
                      Catch::Contains("unknown heat-map scale 'sqrt'; use linear or log"));
}

TEST_CASE("heat map: the same costs give the same bytes", "[heatmap]") {
    const timing::WorkItemCosts costs = pattern(64 * 64);
    const auto read_bytes = [](const std::filesystem::path& path) {
        std::ifstream in(path, std::ios::binary);
        return std::vector<char>(std::istreambuf_iterator<char>(in), {});
    };
    render::write_heatmap(scratch_path("a.png"), costs, 64, 64, render::HeatMetric::Cycles);
    render::write_heatmap(scratch_path("b.png"), costs, 64, 64, render::HeatMetric::Cycles);
    CHECK(read_bytes(scratch_path("a.png")) == read_bytes(scratch_path("b.png")));
    CHECK(read_bytes(scratch_path("a.exr")) == read_bytes(scratch_path("b.exr")));
}

TEST_CASE("heat map: inferno rises in lightness from black to yellow", "[heatmap]") {
    const auto luminance = [](const std::array<float, 3>& srgb) {
        const auto linear = [](float v) {
            return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
        };
        return 0.2126f * linear(srgb[0]) + 0.7152f * linear(srgb[1]) + 0.0722f * linear(srgb[2]);
    };
    float previous = -1;
    for (int i = 0; i <= 255; ++i) {
        const float y = luminance(render::inferno(i / 255.f));
        CHECK(y > previous);
        previous = y;
    }
    CHECK(luminance(render::inferno(0)) < 0.01f);
    const auto top = render::inferno(1);
    CHECK(top[0] > 0.95f);
    CHECK(top[1] > 0.95f);
    CHECK(top[2] < 0.7f);  // yellow, not white
}

TEST_CASE("heat map: a bad metric or path is a clear error", "[heatmap]") {
    for (const auto metric : {render::HeatMetric::Cycles, render::HeatMetric::Instructions,
                              render::HeatMetric::DramBytes})
        CHECK(render::parse_heat_metric(render::metric_name(metric)) == metric);
    CHECK_THROWS_WITH(render::parse_heat_metric("stalls"),
                      Catch::Contains("'stalls'") &&
                          Catch::Contains("cycles, instructions or dram_bytes"));

    const timing::WorkItemCosts costs = pattern(16);
    CHECK_THROWS_WITH(
        render::write_heatmap(scratch_path("heat.jpg"), costs, 4, 4, render::HeatMetric::Cycles),
        Catch::Contains("heat.jpg") && Catch::Contains(".png"));
    CHECK_THROWS_WITH(render::write_heatmap("/nonexistent/tpsim/heat.png", costs, 4, 4,
                                            render::HeatMetric::Cycles),
                      Catch::Contains("directory '/nonexistent/tpsim' does not exist"));
    CHECK_THROWS_AS(render::check_heatmap_path("heat.exr"), Error);
    CHECK_NOTHROW(render::check_heatmap_path(scratch_path("HEAT.PNG")));
    CHECK_THROWS_WITH(
        render::write_heatmap(scratch_path("empty.png"), costs, 0, 4, render::HeatMetric::Cycles),
        Catch::Contains("no pixels"));
}
