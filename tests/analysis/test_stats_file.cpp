// Reading statistics files: the fields the analysis tools rely on, and one clear line (never a
// crash) for every kind of bad file.
#include <fstream>
#include <string>

#include <catch2/catch.hpp>

#include "sim/analysis/stats_file.hpp"
#include "sim/core/error.hpp"
#include "sim/render/profile.hpp"
#include "tests/scratch.hpp"

using namespace tpsim;
using namespace tpsim::analysis;

namespace {

const std::filesystem::path kFixtures = TPSIM_ANALYSIS_FIXTURES;

/// The message parse_stats_file throws for `text`, or "" when it accepts it.
std::string error_for(const std::string& text) {
    try {
        parse_stats_file(text, "x.json");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

const std::string kHeader = R"("format": "tpsim-stats", "version": 2, "run": {})";

}  // namespace

TEST_CASE("stats file: a cycle-level run reads back with every section", "[analysis]") {
    const StatsFile f = load_stats_file(kFixtures / "base.json");
    CHECK(f.run_text("kernel_name") == "tracer");
    CHECK(f.run_text("width") == "32");
    CHECK(f.run_file("image") == kFixtures / "base.png");
    CHECK(f.run_file("heatmap") == kFixtures / "base.heat.png");
    CHECK_FALSE(f.run_file("no_such_field"));
    REQUIRE(f.stat("chip/cycles"));
    CHECK(*f.stat("chip/cycles") == 520000);
    CHECK_FALSE(f.stat("chip/no_such_key"));
    CHECK(f.unit("chip/cycles") == "cycles");
    CHECK(f.stats.front().first == "scene/triangles");  // file order kept
    CHECK(f.regions.size() == 9);
    REQUIRE(f.timeline);
    CHECK(f.timeline->column("issue_rate") == 1u);
    CHECK(f.timeline->rows.size() == 4);
    REQUIRE(f.profile);
    CHECK(f.profile->functions.size() == 4);
    CHECK(f.profile->lines.at(0).file == "rt.hpp");
    CHECK(f.profile->lines.at(0).line == 123);
    CHECK(f.profile->functions.at(0).stalls.size() == 5);
    CHECK(f.config.at(3).first == "l1.size_bytes");
}

TEST_CASE("stats file: a functional run has no chip sections", "[analysis]") {
    const StatsFile f = load_stats_file(kFixtures / "functional.json");
    CHECK(f.run_text("engine") == "functional");
    CHECK_FALSE(f.stat("chip/cycles"));
    CHECK(f.stat("instructions/total"));
    CHECK(f.regions.empty());
    CHECK_FALSE(f.timeline);
    CHECK_FALSE(f.profile);
}

TEST_CASE("stats file: a null statistic (non-finite when written) reads as NaN", "[analysis]") {
    const StatsFile f = parse_stats_file("{" + kHeader + R"(, "stats": {"a/b": null}})", "x.json");
    REQUIRE(f.stat("a/b"));
    CHECK(std::isnan(*f.stat("a/b")));
}

TEST_CASE("stats file: each bad file gets its own one-line message", "[analysis]") {
    CHECK(error_for("hello") == "x.json is not a tpsim statistics file: not JSON (syntax error "
                                "at byte 1); give a file written by tpsim render --stats-json");
    CHECK(error_for("").starts_with("x.json is not a tpsim statistics file: not JSON"));
    CHECK(error_for("[1, 2]") == "x.json is not a tpsim statistics file: a JSON array, not an "
                                 "object; give a file written by tpsim render --stats-json");
    CHECK(error_for(R"({"a": 1})") ==
          "x.json is not a tpsim statistics file (it has no \"format\", which is not "
          "\"tpsim-stats\"); give a file written by tpsim render --stats-json");
    CHECK(error_for(R"({"format": "png"})") ==
          "x.json is not a tpsim statistics file (its \"format\" \"png\" is not \"tpsim-stats\"); "
          "give a file written by tpsim render --stats-json");
    CHECK(error_for(R"({"format": "tpsim-stats", "version": 1})") ==
          "x.json was written by statistics format version 1; this tpsim reads version 2: render "
          "it again");
    CHECK(error_for(R"({"format": "tpsim-stats", "version": 3})") ==
          "x.json was written by statistics format version 3; this tpsim reads version 2: render "
          "it again");
    // Version 1 was a flat object of numbers.
    CHECK(error_for(R"({"instructions/total": 5, "chip/cycles": 9})") ==
          "x.json was written by statistics format version 1; this tpsim reads version 2: render "
          "it again");
    CHECK(error_for(R"({"format": "tpsim-stats", "version": "2"})") ==
          "x.json: \"version\" must be a whole number, got \"2\"; the file is damaged or was not "
          "written by tpsim");
    CHECK(error_for(R"({"format": "tpsim-stats", "version": 2, "stats": {}})") ==
          "x.json: the file has no \"run\"; the file is damaged or was not written by tpsim");
    CHECK(error_for("{" + kHeader + R"(, "stats": {"chip/cycles": "many"}})") ==
          "x.json: \"stats\".\"chip/cycles\" must be a number, got a string; the file is damaged "
          "or was not written by tpsim");
    CHECK(error_for("{" + kHeader + R"(, "stats": {}, "timeline": {"columns": ["cycle", "x"],
          "rows": [[1, 2], [3]]}})") ==
          "x.json: \"timeline\".\"rows\"[1] has 1 values for 2 columns; the file is damaged or "
          "was not written by tpsim");
    CHECK(error_for("{" + kHeader + R"(, "stats": {}, "profile": {"functions": [{"function":
          "f", "executions": 1}]}})") ==
          "x.json: \"profile\".\"functions\"[0] has no \"cycles\"; the file is damaged or was not "
          "written by tpsim");
    CHECK(error_for("{" + kHeader + R"(, "stats": {}, "config": {"l1": {"ways": 4}}})") ==
          "x.json: \"config\".\"l1\" must be a number, string or boolean; the file is damaged or "
          "was not written by tpsim");
}

TEST_CASE("stats file: deep nesting is refused before anything recurses", "[analysis]") {
    const std::string deep = std::string(1000000, '[') + std::string(1000000, ']');
    CHECK(error_for(deep) == "x.json is not a tpsim statistics file: JSON nested more than 16 "
                             "levels deep; give a file written by tpsim render --stats-json");
    const std::string deep_inside = "{" + kHeader + R"(, "stats": {"a": )" +
                                    std::string(100000, '[') + std::string(100000, ']') + "}}";
    CHECK(error_for(deep_inside).find("nested more than 16 levels") != std::string::npos);
}

TEST_CASE("stats file: missing, directory and oversized files are named", "[analysis]") {
    const auto message = [](const std::filesystem::path& path) {
        try {
            load_stats_file(path);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    CHECK(message("no/such.json") == "cannot read no/such.json: No such file or directory; give "
                                     "a file written by tpsim render --stats-json");
    CHECK(message(kFixtures) == "cannot read " + kFixtures.string() +
                                    ": it is a directory; give a file written by tpsim render "
                                    "--stats-json");
    // A sparse file: huge to stat, nothing written to disk.
    const std::filesystem::path huge = tpsim::testing::scratch_path("huge.json");
    std::ofstream(huge).put('{');
    std::filesystem::resize_file(huge, kMaxStatsFileBytes + 1);
    CHECK(message(huge) == huge.string() + " is not a tpsim statistics file: 257 MiB, more than "
                                           "the 256 MiB this tpsim reads; give a file written by "
                                           "tpsim render --stats-json");
}

TEST_CASE("stats file: the profile the renderer writes reads back field for field", "[analysis]") {
    render::Profile written;
    written.total = {.executions = 10,
                     .cycles = 30,
                     .stalls = {1, 2, 3, 4, 10},
                     .l1_misses = 5,
                     .dram_bytes = 640};
    written.functions.push_back({"trax_main", 0x100, written.total});
    written.lines.push_back({"tracer.cpp", "/src/tracer.cpp", 42, "trax_main", written.total});
    Json doc = {{"format", "tpsim-stats"},
                {"version", 2},
                {"run", Json::object()},
                {"stats", Json::object()}};
    doc["profile"] = render::profile_json(written);
    const StatsFile f = parse_stats_file(doc.dump(), "x.json");
    REQUIRE(f.profile);
    CHECK(f.profile->total_cycles == 30);
    REQUIRE(f.profile->functions.size() == 1);
    REQUIRE(f.profile->lines.size() == 1);
    for (const ProfileEntry* e : {&f.profile->functions[0], &f.profile->lines[0]}) {
        CHECK(e->function == "trax_main");
        CHECK(e->executions == 10);
        CHECK(e->cycles == 30);
        CHECK(e->l1_misses == 5);
        CHECK(e->dram_bytes == 640);
        // Without fetch-miss stalls (an I-cache that never misses) there is no fetch_miss.
        REQUIRE(e->stalls.size() == size_t(timing::Stall::FetchMiss));
        for (size_t cause = 0; cause < e->stalls.size(); ++cause) {
            CHECK(e->stalls[cause].first == render::kStallNames[cause]);
            CHECK(e->stalls[cause].second == written.total.stalls[cause]);
        }
    }
    CHECK(f.profile->lines[0].file == "tracer.cpp");
    CHECK(f.profile->lines[0].line == 42);
}
