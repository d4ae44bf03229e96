// The HTML pages as text: what they embed. (That their charts draw is checked in a headless
// browser, see CMakeLists.txt.)
#include <cmath>
#include <fstream>
#include <string>

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include "sim/analysis/html_report.hpp"
#include "tests/scratch.hpp"

using namespace tpsim::analysis;

namespace {

const std::filesystem::path kFixtures = TPSIM_ANALYSIS_FIXTURES;

/// The page's JSON blob of charts.
Json blob_of(const std::string& page) {
    const std::string open = "<script id=\"tpsim-data\" type=\"application/json\">";
    const size_t start = page.find(open);
    REQUIRE(start != std::string::npos);
    const size_t end = page.find("</script>", start);
    return Json::parse(page.substr(start + open.size(), end - start - open.size()));
}

size_t count(const std::string& text, const std::string& part) {
    size_t n = 0;
    for (size_t at = 0; (at = text.find(part, at)) != std::string::npos; at += part.size())
        ++n;
    return n;
}

}  // namespace

TEST_CASE("report: one page embeds images, Chart.js, charts and the configuration", "[analysis]") {
    const std::string chart_js = load_chart_js();
    CHECK(chart_js.find("Chart") != std::string::npos);
    const StatsFile run = load_stats_file(kFixtures / "base.json");
    const std::string page = report_page(run, chart_js);
    CHECK(page.find(chart_js) != std::string::npos);
    CHECK(count(page, "<img ") == 2);  // image and heat map
    CHECK(count(page, "src=\"data:image/png;base64,") == 2);
    CHECK(page.find("src=\"http") == std::string::npos);  // nothing fetched: opens offline
    const Json blob = blob_of(page);
    // stalls, FU utilisation, traffic, energy and area by part, 4 timeline charts (the hit
    // rates share one)
    CHECK(blob["charts"].size() == 9);
    std::vector<std::string> titles;
    for (const Json& chart : blob["charts"])
        titles.push_back(chart["title"]);
    CHECK(titles[3] == "Energy by part (share of the frame's energy)");
    CHECK(titles[4] == "Area by part (share of the chip)");
    // Shares of the fixture's energy/total (0.002 J) and area/total (1.576586 mm^2).
    CHECK(blob["charts"][3]["labels"] ==
          Json::array({"fu/fp_add", "l1", "dram", "dram_background"}));
    CHECK(blob["charts"][3]["datasets"][0]["data"][2].get<double>() == Approx(60));  // dram
    CHECK(blob["charts"][4]["datasets"][0]["data"][1].get<double>() ==
          Approx(100 * 1.550098 / 1.576586));
    CHECK(page.find("<div class=\"value\">2 mJ</div><div class=\"label\">energy per frame") !=
          std::string::npos);
    CHECK(page.find("<tr><td class=\"code\">l1</td><td class=\"num\">1.55</td>") !=
          std::string::npos);  // the area table
    CHECK(count(page, "<canvas data-chart=") == blob["charts"].size());
    CHECK(page.find("<details><summary>Resolved chip configuration (7 keys)") != std::string::npos);
    CHECK(page.find("trax::rt::intersect_bvh(trax::rt::Ray const&amp;, trax::rt::Hit&amp;)") !=
          std::string::npos);  // profile names escaped
    CHECK(page.find("rt.hpp:123") != std::string::npos);
    CHECK(page.find("not a result") != std::string::npos);  // host time labelled as such
    CHECK(report_page(run, chart_js) == page);              // deterministic
}

TEST_CASE("report: a functional run gets a page without chip charts", "[analysis]") {
    const std::string page = report_page(load_stats_file(kFixtures / "functional.json"), "");
    CHECK(blob_of(page)["charts"].empty());
    CHECK(page.find("functional engine: no cycles") != std::string::npos);
}

TEST_CASE("report: the comparison page has grouped charts and the side-by-side tables",
          "[analysis]") {
    std::vector<StatsFile> runs;
    for (const char* name : {"base.json", "faster.json", "brute.json"})
        runs.push_back(load_stats_file(kFixtures / name));
    const Comparison c = compare(runs);
    const std::string page = comparison_page(runs, c, "");
    const Json charts = blob_of(page)["charts"];
    // summary, stalls, FU utilisation, per ray, energy and area by part, DRAM by region
    REQUIRE(charts.size() == 7);
    CHECK(charts[4]["title"] == "Energy by part (J)");
    CHECK(charts[5]["title"] == "Area by part (mm²)");
    // One dataset per run; the summary and per-ray charts show B's and C's change against A,
    // in per cent: the base line of their bars is A.
    for (const Json& chart : charts) {
        const bool relative = chart["unit"] == "change against A";
        CHECK(chart["datasets"].size() == (relative ? 2 : 3));
    }
    CHECK(charts[0]["title"] == "Summary: change against A");
    CHECK(charts[0]["datasets"][0]["label"] == "B");
    CHECK(charts[0]["percent"] == true);
    // base: 520000 cycles, faster: 480000, -7.69 %
    CHECK(std::abs(charts[0]["datasets"][0]["data"][0].get<double>() - (-100.0 * 40 / 520)) < 1e-9);
    CHECK(count(page, "<img ") == 3);
    CHECK(page.find("config l1.size_bytes") != std::string::npos);
    CHECK(page.find("C against A: RMSE") != std::string::npos);
    CHECK(page.find("B against A: identical") != std::string::npos);
}

TEST_CASE("report: text from the file cannot inject markup or end the data blob", "[analysis]") {
    const StatsFile run = parse_stats_file(
        R"({"format": "tpsim-stats", "version": 2,
            "run": {"scene": "<script>alert(1)</script>", "kernel_name": "<b>k</b>"},
            "stats": {"chip/cycles": 1},
            "timeline": {"columns": ["cycle", "</script><i>"], "rows": [[1, 2]]}})",
        kFixtures / "hostile.json");
    const std::string page = report_page(run, "");
    CHECK(page.find("<script>alert") == std::string::npos);
    CHECK(page.find("&lt;script&gt;alert(1)&lt;/script&gt;") != std::string::npos);
    CHECK(page.find("<b>k") == std::string::npos);
    CHECK(page.find("</script><i>") == std::string::npos);
    const Json blob = blob_of(page);  // still parses, the title intact
    CHECK(blob.at("charts").at(0).at("title") == "</script><i>");
}

TEST_CASE("report: a float image is embedded as an sRGB PNG, as render writes it", "[analysis]") {
    const std::filesystem::path dir = tpsim::testing::fresh_scratch_dir("images");
    // The second pixel: a NaN (black, as render writes it), below 0 and above 1 (clamped).
    const float linear[] = {0.5f, 0.0f, 1.0f, std::nanf(""), -1.0f, 2.0f};
    auto out = OIIO::ImageOutput::create((dir / "one.exr").string());
    REQUIRE(out);
    REQUIRE(out->open((dir / "one.exr").string(), OIIO::ImageSpec(2, 1, 3, OIIO::TypeDesc::FLOAT)));
    REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, linear));
    REQUIRE(out->close());
    const std::string png = png_bytes(dir / "one.exr");
    REQUIRE(png.substr(0, 4) == "\x89PNG");
    std::ofstream(dir / "back.png", std::ios::binary) << png;
    auto in = OIIO::ImageInput::open((dir / "back.png").string());
    REQUIRE(in);
    unsigned char rgb[6];
    REQUIRE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, rgb));
    CHECK(int(rgb[0]) == 188);  // sRGB(0.5) = 0.7354 -> 188
    CHECK(int(rgb[1]) == 0);
    CHECK(int(rgb[2]) == 255);
    CHECK(int(rgb[3]) == 0);
    CHECK(int(rgb[4]) == 0);
    CHECK(int(rgb[5]) == 255);
    // An image that cannot be read leaves a note; the rest of the page is still written.
    std::ofstream(dir / "broken.exr") << "not an image";
    const StatsFile run = parse_stats_file(
        R"({"format": "tpsim-stats", "version": 2, "run": {"image": "broken.exr"}, "stats": {}})",
        dir / "run.json");
    const std::string page = report_page(run, "");
    CHECK(page.find("<p class=\"note\">image: cannot read image ") != std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST_CASE("difference images: grey where equal, red brighter, blue darker, and an enlarged copy",
          "[analysis]") {
    // Three pixels: equal, brighter by 40, darker by 200.
    const Rgb8 ref{3, 1, {100, 100, 100, 50, 50, 50, 250, 250, 250}};
    const Rgb8 image{3, 1, {100, 100, 100, 90, 50, 50, 50, 250, 250}};
    const auto dir = tpsim::testing::fresh_scratch_dir("difference");
    const auto files = write_difference_images(image, ref, 0, dir / "B-vs-A");
    REQUIRE(files.size() == 2);
    CHECK(files[0] == dir / "B-vs-A.diff.png");
    CHECK(files[1] == dir / "B-vs-A.diff-x170.png");  // 512 pixels across, in whole pixels
    const Rgb8 diff = read_rgb8(files[0], "difference image");
    CHECK(diff.pixels == std::vector<uint8_t>{25, 25, 25, 168, 0, 0, 0, 0, 255});
    const Rgb8 large = read_rgb8(files[1], "difference image");
    CHECK(large.width == 510);
    CHECK(large.height == 170);
    CHECK(std::vector<uint8_t>(large.pixels.end() - 3, large.pixels.end()) ==
          std::vector<uint8_t>{0, 0, 255});
    // Within the tolerance, the brighter pixel is grey too.
    const auto tolerant = write_difference_images(image, ref, 40, dir / "tolerant");
    CHECK(read_rgb8(tolerant[0], "difference image").pixels[3] == 50 * 3 / 3 / 4);
}
