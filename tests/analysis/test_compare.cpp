// tpsim compare: ratios, the differing setup, every output format, and image differences.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include "sim/analysis/compare.hpp"
#include "tests/scratch.hpp"

using namespace tpsim::analysis;

namespace {

const std::filesystem::path kFixtures = TPSIM_ANALYSIS_FIXTURES;

std::vector<StatsFile> load(std::initializer_list<const char*> names) {
    std::vector<StatsFile> runs;
    for (const char* name : names)
        runs.push_back(load_stats_file(kFixtures / name));
    return runs;
}

const Row* find_row(const Comparison& c, std::string_view key) {
    for (const Section& s : c.sections)
        for (const Row& row : s.rows)
            if (row.key == key) return &row;
    return nullptr;
}

const SetupDifference* find_difference(const Comparison& c, std::string_view field) {
    for (const SetupDifference& d : c.differences)
        if (d.field == field) return &d;
    return nullptr;
}

std::string written(const Comparison& c, Format format, bool colour = false) {
    std::ostringstream out;
    write_comparison(c, format, out, colour);
    return out.str();
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        lines.push_back(line);
    return lines;
}

/// Fields of one CSV line (quoted fields may hold commas and doubled quotes).
std::vector<std::string> csv_fields(const std::string& line) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
        const char ch = line[i];
        if (quoted && ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
            fields.back() += '"';
            ++i;
        } else if (ch == '"') {
            quoted = !quoted;
        } else if (ch == ',' && !quoted) {
            fields.emplace_back();
        } else {
            fields.back() += ch;
        }
    }
    return fields;
}

void write_png(const std::filesystem::path& path, int width, int height,
               const std::vector<unsigned char>& rgb) {
    auto out = OIIO::ImageOutput::create(path.string());
    REQUIRE(out);
    REQUIRE(out->open(path.string(), OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::UINT8)));
    REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, rgb.data()));
    REQUIRE(out->close());
}

StatsFile run_with_image(const std::filesystem::path& directory, const std::string& image) {
    return parse_stats_file(R"({"format": "tpsim-stats", "version": 2, "run": {"image": ")" +
                                image + R"("}, "stats": {}})",
                            directory / (image + ".json"));
}

}  // namespace

TEST_CASE("compare: a ratio is the value over the first run's", "[analysis]") {
    const Row row{"k", "", Better::lower, {4.0, 3.0, std::nullopt, 4.1}, {}};
    CHECK(row.ratio(0) == 1.0);
    CHECK(row.ratio(1) == 0.75);
    CHECK_FALSE(row.ratio(2));
    CHECK(row.differs_notably(1));
    CHECK_FALSE(row.differs_notably(3));  // 1.025: inside 0.95 .. 1.05
    const Row zero{"z", "", Better::lower, {0.0, 0.0, 2.0}, {}};
    CHECK(zero.ratio(1) == 1.0);  // both zero: the same
    CHECK_FALSE(zero.ratio(2));   // undefined against zero
}

TEST_CASE("compare: every section's rows carry each run's value and its ratio", "[analysis]") {
    const std::vector<StatsFile> runs = load({"base.json", "faster.json"});
    const Comparison c = compare(runs);
    REQUIRE(c.runs.size() == 2);
    for (const char* key :
         {"chip/cycles", "chip/frame_seconds", "chip/rays_per_second", "instructions/total",
          "chip/issue_rate", "chip/stalls/operand", "chip/fu/fp_add/utilisation",
          "region/bvh_nodes/dram/moved_bytes", "traversal/nodes_per_ray"}) {
        INFO(key);
        const Row* row = find_row(c, key);
        REQUIRE(row);
        REQUIRE(row->values.size() == 2);
        CHECK(row->values[0] == runs[0].stat(key));
        CHECK(row->values[1] == runs[1].stat(key));
        CHECK(*row->ratio(1) == Approx(*runs[1].stat(key) / *runs[0].stat(key)));
    }
    CHECK(find_row(c, "chip/cycles")->unit == "cycles");
    // Stall causes are the per-cause totals, not their operand_from/<pool> breakdown.
    CHECK_FALSE(find_row(c, "chip/stalls/operand_from/load_store"));
    // Host time is never a result.
    for (const Section& s : c.sections)
        for (const Row& row : s.rows)
            CHECK_FALSE(row.key.starts_with("host/"));
    CHECK(c.host.key == "host/run_seconds");
    CHECK(c.host.values[1] == runs[1].stat("host/run_seconds"));
}

TEST_CASE("compare: region hit rates and per-ray figures are derived per run", "[analysis]") {
    const std::vector<StatsFile> runs = load({"base.json", "faster.json"});
    const Comparison c = compare(runs);
    const Row* hit_rate = find_row(c, "region/triangles/l1/hit_rate");
    REQUIRE(hit_rate);
    for (size_t r = 0; r < 2; ++r)
        CHECK(*hit_rate->values[r] == Approx(*runs[r].stat("region/triangles/l1/hits") /
                                             *runs[r].stat("region/triangles/l1/reads")));
    const Row* dram = find_row(c, "per_ray/dram_bytes");
    REQUIRE(dram);
    CHECK(*dram->values[0] ==
          Approx((*runs[0].stat("dram/bytes_read") + *runs[0].stat("dram/bytes_written")) /
                 *runs[0].stat("rays/total")));
    CHECK(*find_row(c, "per_ray/instructions")->values[1] ==
          Approx(*runs[1].stat("instructions/total") / *runs[1].stat("rays/total")));
    // Rows that are zero in every run (the empty local-store region) are left out.
    CHECK_FALSE(find_row(c, "region/local_store/l1/reads"));
    CHECK_FALSE(find_row(c, "region/camera/dram/writes"));
}

TEST_CASE("compare: the energy and area estimate has summary rows and sections by part",
          "[analysis][energy]") {
    const std::vector<StatsFile> runs = load({"base.json", "faster.json", "brute.json"});
    const Comparison c = compare(runs);
    for (const char* key : {"energy/total", "energy/average_watts", "energy/mrays_per_joule",
                            "area/total", "energy/per_ray", "energy/dram", "area/l1"}) {
        INFO(key);
        const Row* row = find_row(c, key);
        REQUIRE(row);
        CHECK(row->values[0] == runs[0].stat(key));
        CHECK(row->values[1] == runs[1].stat(key));
        CHECK_FALSE(row->values[2]);  // brute.json predates the estimate: absent, not 0
    }
    CHECK(*find_row(c, "energy/total")->ratio(1) == Approx(0.0016 / 0.002));
    CHECK(find_row(c, "energy/total")->better == Better::lower);
    CHECK(find_row(c, "energy/mrays_per_joule")->better == Better::higher);
    std::vector<std::string> energy_keys, area_keys;
    for (const Section& s : c.sections) {
        if (s.title == "energy by part")
            for (const Row& row : s.rows)
                energy_keys.push_back(row.key);
        if (s.title == "area by part")
            for (const Row& row : s.rows)
                area_keys.push_back(row.key);
    }
    // The parts only: totals and rates are in the summary and per-ray sections.
    CHECK(energy_keys == std::vector<std::string>{"energy/fu/fp_add", "energy/l1", "energy/dram",
                                                  "energy/dram_background"});
    CHECK(area_keys == std::vector<std::string>{"area/fu/fp_add", "area/l1"});
}

TEST_CASE("compare: --keys keeps only the matching rows and the sections that have any",
          "[analysis]") {
    const auto runs = load({"base.json", "brute.json"});
    const Comparison all = compare(runs);
    const Comparison some = compare(runs, {"chip/cycles", "region/camera/l1/*"});
    REQUIRE(find_row(all, "chip/l2/hit_rate") != nullptr);
    CHECK(find_row(some, "chip/l2/hit_rate") == nullptr);
    REQUIRE(find_row(some, "chip/cycles") != nullptr);
    CHECK(find_row(some, "chip/cycles")->values == find_row(all, "chip/cycles")->values);
    CHECK(find_row(some, "region/camera/l1/reads") != nullptr);
    CHECK(find_row(some, "region/camera/l2/reads") == nullptr);
    std::vector<std::string> titles;
    for (const Section& section : some.sections)
        titles.push_back(section.title);
    CHECK(titles == std::vector<std::string>{"summary", "traffic by region and level"});
    CHECK(compare(runs, {"no/such/*"}).sections.empty());
}

TEST_CASE("compare: only the setup fields that differ are listed", "[analysis]") {
    const Comparison c = compare(load({"base.json", "faster.json", "brute.json"}));
    const SetupDifference* l1 = find_difference(c, "config l1.size_bytes");
    REQUIRE(l1);
    CHECK(l1->values == std::vector<std::string>{"4096", "8192", "4096"});
    const SetupDifference* kernel = find_difference(c, "kernel");
    REQUIRE(kernel);
    CHECK(kernel->values[2] == "build/kernels/primary_brute.elf");
    CHECK_FALSE(find_difference(c, "config chip.clock_mhz"));
    CHECK_FALSE(find_difference(c, "scene"));
    CHECK_FALSE(find_difference(c, "image size"));
    CHECK(find_difference(compare(load({"base.json", "base.json"})), "kernel") == nullptr);
    CHECK(compare(load({"base.json", "base.json"})).differences.empty());
}

TEST_CASE("compare: a functional run beside a cycle-level one has no ratios for chip figures",
          "[analysis]") {
    const Comparison c = compare(load({"base.json", "functional.json"}));
    const Row* cycles = find_row(c, "chip/cycles");
    REQUIRE(cycles);
    CHECK_FALSE(cycles->values[1]);
    CHECK_FALSE(cycles->ratio(1));
    REQUIRE(find_difference(c, "engine"));
    CHECK(find_row(c, "instructions/total")->ratio(1) == 1.0);
    CHECK(written(c, Format::text).find("chip/cycles") != std::string::npos);
}

TEST_CASE("compare: text output aligns columns and colours only when asked", "[analysis]") {
    const Comparison c = compare(load({"base.json", "faster.json"}));
    const std::string plain = written(c, Format::text);
    CHECK(plain.find("\033[") == std::string::npos);
    CHECK(plain.find("A  " + c.runs[0]) != std::string::npos);
    CHECK(plain.find("config l1.size_bytes") != std::string::npos);
    CHECK(plain.find("host wall time, not a result") != std::string::npos);
    const std::string ratio = fmt::format("{:.3f}x", *find_row(c, "chip/cycles")->ratio(1));
    CHECK(plain.find(ratio) != std::string::npos);
    const std::string coloured = written(c, Format::text, true);
    // Fewer cycles is better: green; more operand stalls would be red.
    CHECK(coloured.find("\033[32m " + std::string(8 - ratio.size(), ' ') + ratio + "\033[0m") !=
          std::string::npos);
    CHECK(written(c, Format::text) == plain);  // deterministic
}

TEST_CASE("compare: markdown tables have one cell per column", "[analysis]") {
    const Comparison c = compare(load({"base.json", "faster.json", "brute.json"}));
    const std::string md = written(c, Format::markdown);
    size_t tables = 0;
    for (const std::string& line : lines_of(md)) {
        if (!line.starts_with("| ") || line.starts_with("| run") || line.starts_with("| A ") ||
            line.starts_with("| B ") || line.starts_with("| C "))
            continue;
        if (line.starts_with("| differs") || line.starts_with("| config") ||
            line.starts_with("| kernel") || line.starts_with("| kernel_name"))
            continue;
        // A statistics row: key, unit, A, then value and ratio for B and C.
        CHECK(std::count(line.begin(), line.end(), '|') == 8);
        tables += line.starts_with("| summary");
    }
    CHECK(tables == 1);
    CHECK(md.find("| `chip/cycles` | cycles | 520000 |") != std::string::npos);
}

TEST_CASE("compare: CSV has one field per column and exact numbers", "[analysis]") {
    const std::vector<StatsFile> runs = load({"base.json", "faster.json"});
    const Comparison c = compare(runs);
    const std::vector<std::string> lines = lines_of(written(c, Format::csv));
    REQUIRE(lines.size() > 10);
    const std::vector<std::string> header = csv_fields(lines[0]);
    REQUIRE(header.size() == 6);
    CHECK(header[3] == c.runs[0]);
    bool found_cycles = false;
    for (const std::string& line : lines) {
        const std::vector<std::string> fields = csv_fields(line);
        CHECK(fields.size() == 6);
        if (fields[1] == "chip/issue_rate") {
            found_cycles = true;
            CHECK(std::stod(fields[3]) == *runs[0].stat("chip/issue_rate"));  // round-trips
            CHECK(std::stod(fields[5]) ==
                  Approx(*runs[1].stat("chip/issue_rate") / *runs[0].stat("chip/issue_rate")));
        }
    }
    CHECK(found_cycles);
}

TEST_CASE("compare: JSON output parses back to the same figures", "[analysis]") {
    const Comparison c = compare(load({"base.json", "faster.json"}));
    const Json doc = Json::parse(written(c, Format::json));
    CHECK(doc["format"] == "tpsim-compare");
    CHECK(doc["runs"][1] == c.runs[1]);
    CHECK(doc["sections"].size() == c.sections.size());
    const Row& first = c.sections[0].rows[0];
    CHECK(doc["sections"][0]["rows"][0]["key"] == first.key);
    CHECK(doc["sections"][0]["rows"][0]["values"][1].get<double>() == *first.values[1]);
    CHECK(doc["sections"][0]["rows"][0]["ratios"][1].get<double>() == *first.ratio(1));
    CHECK(doc["differences"][0]["field"] == c.differences[0].field);
    CHECK(doc["host"]["key"] == "host/run_seconds");
}

TEST_CASE("compare: images are compared pixel by pixel", "[analysis]") {
    const std::filesystem::path dir = tpsim::testing::fresh_scratch_dir("images");
    std::vector<unsigned char> a(4 * 4 * 3, 100), b = a;
    b[0] = 200;        // pixel 0: one channel off by 100/255
    b[3 * 5 + 2] = 0;  // pixel 5: one channel off by 100/255
    write_png(dir / "a.png", 4, 4, a);
    write_png(dir / "b.png", 4, 4, b);
    write_png(dir / "small.png", 2, 2, std::vector<unsigned char>(2 * 2 * 3, 100));

    const ImageDifference same = compare_images(dir / "a.png", dir / "a.png");
    CHECK(same.compared());
    CHECK(same.differing_pixels == 0);
    CHECK(same.rmse == 0);
    CHECK(std::isinf(same.psnr));

    const ImageDifference d = compare_images(dir / "a.png", dir / "b.png");
    REQUIRE(d.compared());
    CHECK(d.pixels == 16);
    CHECK(d.differing_pixels == 2);
    CHECK(d.differing_share() == 2.0 / 16);
    const double expected_rmse = std::sqrt(2 * std::pow(100 / 255.0, 2) / 48);
    CHECK(d.rmse == Approx(expected_rmse));
    CHECK(d.psnr == Approx(20 * std::log10(1 / expected_rmse)));

    CHECK(compare_images(dir / "a.png", dir / "small.png").note ==
          "images differ in size: a.png is 4x4 (3 channels), small.png is 2x2 (3 channels)");
    CHECK(compare_images(dir / "a.png", dir / "gone.png").note ==
          "image " + (dir / "gone.png").string() + " does not exist");

    // Through compare(): run.image is resolved against each JSON file's directory.
    const Comparison c = compare({run_with_image(dir, "a.png"), run_with_image(dir, "b.png"),
                                  run_with_image(dir, "gone.png")});
    REQUIRE(c.images.size() == 2);
    REQUIRE(c.images[0]);
    CHECK(c.images[0]->differing_pixels == 2);
    CHECK(c.images[1]->note.ends_with("gone.png does not exist"));
    const std::string text = written(c, Format::text);
    CHECK(text.find("image     B vs A: RMSE") != std::string::npos);
    CHECK(text.find("2 of 16 pixels differ (12.50 %)") != std::string::npos);
    CHECK(text.find("C vs A: image ") != std::string::npos);
    const Json doc = Json::parse(written(c, Format::json));
    CHECK(doc["images"][0]["differing_pixels"] == 2);
    CHECK(doc["images"][1]["note"].get<std::string>().ends_with("does not exist"));
    std::filesystem::remove_all(dir);
}

TEST_CASE("compare: a sampled run's figures are shown as estimates with their intervals",
          "[analysis]") {
    std::vector<StatsFile> runs = load({"base.json"});
    std::ifstream in(kFixtures / "faster.json");
    Json sampled = Json::parse(in);
    sampled["run"]["timing"] = "sampled";
    sampled["sampling"] = {{"estimated", true},   {"confidence", 0.95},    {"units", 12},
                           {"trusted_units", 30}, {"too_few_units", true}, {"rate", 0.02}};
    // chip/cycles 480000 ± 50000 against 520000: within; the hit rate's interval is unknown.
    sampled["intervals"] = {
        {"chip/cycles", 50000}, {"chip/l1/hit_rate", nullptr}, {"chip/l1/hits", nullptr}};
    runs.push_back(parse_stats_file(sampled.dump(), kFixtures / "sampled.json"));
    const Comparison c = compare(runs);
    REQUIRE(c.estimates.size() == 2);
    CHECK(c.estimates[0].empty());
    CHECK(c.estimates[1].starts_with("sampled (--timing sampled): its cycle-level figures are "
                                     "estimates, ± the half-width of their 95 % confidence "
                                     "interval, from 12 units at rate 0.02; fewer than 30 units"));
    const Row& cycles = c.sections[0].rows[0];
    REQUIRE(cycles.key == "chip/cycles");
    CHECK(cycles.estimated(1));
    CHECK_FALSE(cycles.estimated(0));
    CHECK(cycles.within_intervals(1));  // 40000 apart, within 50000
    std::ostringstream text;
    write_comparison(c, Format::text, text);
    CHECK(text.str().find("estimates B  sampled (--timing sampled)") != std::string::npos);
    CHECK(text.str().find("480000 ±50000   0.923x~") != std::string::npos);
    CHECK(text.str().find(" ±?") != std::string::npos);  // the hit rate
    CHECK(text.str().find("~ after a ratio: the two values differ by less than") !=
          std::string::npos);
    // A measured difference is not marked: the DRAM bytes read are exact in both.
    CHECK(text.str().find("0.812x~") == std::string::npos);
    CHECK(text.str().find("0.812x") != std::string::npos);
    std::ostringstream json;
    write_comparison(c, Format::json, json);
    const Json doc = Json::parse(json.str());
    CHECK(doc["estimates"][1].get<std::string>().starts_with("sampled"));
    CHECK(doc["sections"][0]["rows"][0]["intervals"] == Json::array({0.0, 50000.0}));
    // Two measured runs: no estimates anywhere.
    const Comparison exact = compare(load({"base.json", "faster.json"}));
    std::ostringstream plain;
    write_comparison(exact, Format::text, plain);
    CHECK(plain.str().find("±") == std::string::npos);
    CHECK(plain.str().find("estimates") == std::string::npos);
}
