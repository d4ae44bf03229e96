// Sweeps: a sweep file's expansion (cross product, zip), stable job ids, its errors (file:line),
// the plan file, resume and failures, and collecting statistics files into one table.
#include <fstream>
#include <map>
#include <set>
#include <string>

#include <catch2/catch.hpp>

#include "sim/core/error.hpp"
#include "sim/sweep/sweep.hpp"
#include "tests/scratch.hpp"

using namespace tpsim::sweep;
using tpsim::testing::fresh_scratch_dir;

namespace {

const std::filesystem::path kSource = TPSIM_SOURCE_DIR;
const std::filesystem::path kFixtures = kSource / "tests" / "analysis";

/// Kernels by name resolve to a fake path: expansion does not need them built.
std::filesystem::path fake_kernel(const std::string& name) {
    if (name == "no_such_kernel") throw tpsim::Error("no built kernel named 'no_such_kernel'");
    return "/kernels/" + name + ".elf";
}

/// Writes `text` as DIR/sweep.toml, with scenes/a.toml and scenes/b.toml beside it, and loads it.
Sweep load_text(const std::filesystem::path& dir, const std::string& text) {
    std::filesystem::create_directories(dir / "scenes");
    for (const char* scene : {"a.toml", "b.toml"})
        std::ofstream(dir / "scenes" / scene) << "# scene\n";
    std::ofstream(dir / "sweep.toml") << text;
    return load_sweep(dir / "sweep.toml", fake_kernel);
}

std::string error_of(const std::filesystem::path& dir, const std::string& text) {
    try {
        load_text(dir, text);
    } catch (const tpsim::Error& e) {
        return e.what();
    }
    return "(no error)";
}

std::map<std::string, std::string> ids_by_description(const Sweep& sweep) {
    std::map<std::string, std::string> ids;
    for (const Job& job : sweep.jobs)
        ids[sweep.describe(job)] = job.id;
    return ids;
}

}  // namespace

TEST_CASE("sweep: axes are crossed in the file's order, the first varying slowest", "[sweep]") {
    const auto dir = fresh_scratch_dir("cross");
    const Sweep sweep = load_text(dir, R"(scene = ["scenes/a.toml", "scenes/b.toml"]
width = 16
bvh = ["sweep", "binned", "median"]
[l1]
size_bytes = [8192, 16384]
)");
    REQUIRE(sweep.axes.size() == 3);
    CHECK(sweep.axes[0].name == "scene");
    CHECK(sweep.axes[1].name == "bvh");
    CHECK(sweep.axes[2].name == "l1.size_bytes");
    REQUIRE(sweep.fixed.size() == 1);
    CHECK(sweep.fixed[0].name == "width");
    REQUIRE(sweep.jobs.size() == 12);
    CHECK(sweep.describe(sweep.jobs[0]) == "scene=scenes/a.toml, bvh=sweep, l1.size_bytes=8192");
    CHECK(sweep.describe(sweep.jobs[1]) == "scene=scenes/a.toml, bvh=sweep, l1.size_bytes=16384");
    CHECK(sweep.describe(sweep.jobs[2]) == "scene=scenes/a.toml, bvh=binned, l1.size_bytes=8192");
    CHECK(sweep.describe(sweep.jobs[11]) == "scene=scenes/b.toml, bvh=median, l1.size_bytes=16384");
    // Each job's run is resolved from its settings.
    const JobRun& last = sweep.jobs[11].run;
    CHECK(last.scene == std::filesystem::absolute(dir / "scenes" / "b.toml").lexically_normal());
    CHECK(last.accel.bvh_builder == tpsim::scene::BvhBuilder::median);
    CHECK(last.width == 16);
    CHECK(last.chip.l1.size_bytes == 16384);
    CHECK(last.kernel == "/kernels/tracer.elf");  // the default kernel
    std::set<std::string> ids;
    for (const Job& job : sweep.jobs) {
        CHECK(job.id.size() == 12);
        CHECK(job.id.find_first_not_of("0123456789abcdef") == std::string::npos);
        ids.insert(job.id);
    }
    CHECK(ids.size() == 12);
}

TEST_CASE("sweep: zipped axes advance together and are crossed with the rest", "[sweep]") {
    const auto dir = fresh_scratch_dir("zip");
    const Sweep sweep = load_text(dir, R"(scene = ["scenes/a.toml", "scenes/b.toml"]
l1.size_bytes = [8192, 16384, 32768]
l2.size_bytes = [131072, 262144, 524288]
zip = ["l1.size_bytes", "l2.size_bytes"]
)");
    REQUIRE(sweep.jobs.size() == 6);
    CHECK(sweep.describe(sweep.jobs[1]) ==
          "scene=scenes/a.toml, l1.size_bytes=16384, l2.size_bytes=262144");
    CHECK(sweep.jobs[5].run.chip.l1.size_bytes == 32768);
    CHECK(sweep.jobs[5].run.chip.l2.size_bytes == 524288);
    // Several groups.
    const Sweep groups = load_text(dir, R"(scene = "scenes/a.toml"
l1.size_bytes = [8192, 16384]
l1.ways = [2, 4]
l2.size_bytes = [131072, 262144]
l2.ways = [4, 8]
zip = [["l1.size_bytes", "l1.ways"], ["l2.size_bytes", "l2.ways"]]
)");
    CHECK(groups.jobs.size() == 4);
    CHECK(groups.describe(groups.jobs[2]) ==
          "l1.size_bytes=16384, l1.ways=4, l2.size_bytes=131072, l2.ways=4");
}

TEST_CASE("sweep: a job's id depends only on its own settings", "[sweep]") {
    const auto dir = fresh_scratch_dir("ids");
    const auto small = ids_by_description(load_text(dir, R"(scene = "scenes/a.toml"
bvh = ["sweep", "binned"]
l1.size_bytes = [8192, 16384]
)"));
    // More values on both axes, written in another order: the four jobs keep their ids.
    const auto large = ids_by_description(load_text(dir, R"(l1.size_bytes = [4096, 8192, 16384]
bvh = ["median", "sweep", "binned"]
scene = "scenes/a.toml"
)"));
    REQUIRE(large.size() == 9);
    for (const auto& [description, id] : small) {
        // The axis order differs, so look the job up by its values.
        const std::string bvh =
            description.substr(description.find("bvh=") + 4, description.find(',') - 4);
        const std::string l1 = description.substr(description.find("l1.size_bytes=") + 14);
        CHECK(large.at("l1.size_bytes=" + l1 + ", bvh=" + bvh) == id);
    }
    // A fixed value is part of the job: changing it changes every id ...
    const auto wider = ids_by_description(load_text(dir, R"(scene = "scenes/a.toml"
width = 64
bvh = ["sweep", "binned"]
l1.size_bytes = [8192, 16384]
)"));
    for (const auto& [description, id] : small)
        CHECK(wider.at(description) != id);
    // ... but a setting written as a one-value axis or as a value is the same job.
    const auto one_value_axis = ids_by_description(load_text(dir, R"(scene = ["scenes/a.toml"]
bvh = ["sweep", "binned"]
l1.size_bytes = [8192, 16384]
)"));
    for (const auto& [description, id] : small)
        CHECK(one_value_axis.at("scene=scenes/a.toml, " + description) == id);
}

TEST_CASE("sweep: bad sweep files are one line naming file:line", "[sweep]") {
    const auto dir = fresh_scratch_dir("errors");
    const std::string file = (dir / "sweep.toml").string();
    CHECK(error_of(dir, "scene = [\"scenes/a.toml\"\n").starts_with(file + ":"));
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nl1.size_bites = [1024]\n") ==
          file + ":2: unknown setting 'l1.size_bites': give a run setting (scene, kernel, "
                 "config, accel, grid_resolution, grid_density, kdtree_max_depth, "
                 "kdtree_max_references, octree_max_depth, bvh, max_leaf, bvh_order, "
                 "bvh_align_pairs, bvh_boxes, "
                 "width, height, spp, seed, timing), a chip "
                 "configuration key such as l1.size_bytes (configs/trax.toml lists them), or "
                 "zip");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nbvh = []\n") ==
          file + ":2: the axis bvh has no values: give at least one");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nbvh = [\"sweep\",\n  \"sweep\"]\n") ==
          file + ":3: the axis bvh has the value \"sweep\" twice");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nbvh = [\"sweep\", \"octree\"]\n") ==
          file + ":2: bvh must be one of sweep, binned, median, got \"octree\"");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nmax_leaf = [4, 9]\n") ==
          file + ":2: max_leaf must be a whole number in [1, 8], got 9");
    CHECK(error_of(dir, "scene = [\"scenes/a.toml\", \"scenes/c.toml\"]\n")
              .starts_with(file + ":1: scene 'scenes/c.toml' does not exist"));
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nkernel = \"no_such_kernel\"\n") ==
          file + ":2: no built kernel named 'no_such_kernel'");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\n\n[l1]\nsize_bytes = [8192, 3]\n")
              .starts_with(file + ":4: l1.size_bytes = 3 is out of range"));
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nl1.size_bytes = [1.5]\n") ==
          file + ":2: l1.size_bytes must be an integer, got 1.5");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nl1.size_bytes = [{a = 1}]\n") ==
          file + ":2: l1.size_bytes must be a string, a number or true/false, or an array of "
                 "them (an axis)");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nenergy.l1_access_pj = [\"big\"]\n") ==
          file + ":2: energy.l1_access_pj must be a number, got \"big\"");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nenergy.l1_access_pj = [100, -1.5]\n")
              .starts_with(file + ":2: energy.l1_access_pj = -1.5 is out of range"));
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nl1.size_bytes = [\"big\"]\n") ==
          file + ":2: l1.size_bytes must be an integer, got \"big\"");
    CHECK(error_of(dir, "bvh = [\"sweep\"]\n") ==
          file + ":1: no scene: give one or more, e.g. scene = [\"scenes/cornell.toml\"]");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nbvh = [\"sweep\", \"binned\"]\nwidth = "
                        "[16, 32, 64]\nzip = [\"bvh\", \"width\"]\n") ==
          file + ":4: zip: the axis width has 3 values but bvh has 2: axes that advance "
                 "together need as many values");
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nbvh = [\"sweep\", \"binned\"]\nzip = "
                        "[\"bvh\", \"width\"]\n") ==
          file + ":3: zip names 'width', which is not an axis (a setting with an array of "
                 "values)");
    // A combination the chip refuses, though each value alone is fine.
    CHECK(error_of(dir, "scene = \"scenes/a.toml\"\nl1.line_bytes = [64, 128]\n")
              .starts_with(file + ":2: the job l1.line_bytes=128 has a chip configuration tpsim "
                                  "refuses: l2.line_bytes = 64 must equal l1.line_bytes = 128"));
    // ... which zipped axes can leave out.
    CHECK(load_text(dir, "scene = \"scenes/a.toml\"\nl1.line_bytes = [64, 128]\nl2.line_bytes "
                         "= [64, 128]\nzip = [\"l1.line_bytes\", \"l2.line_bytes\"]\n")
              .jobs.size() == 2);
}

TEST_CASE("sweep: with no kernel, a job gets the tracer of the structure it or its scene file "
          "names",
          "[sweep]") {
    const auto dir = fresh_scratch_dir("default_kernel");
    std::filesystem::create_directories(dir / "scenes");
    std::ofstream(dir / "scenes" / "grid.toml") << "[accel]\nstructure = \"grid\"\n";
    std::ofstream(dir / "sweep.toml") << "scene = [\"scenes/grid.toml\", \"scenes/a.toml\"]\n";
    std::ofstream(dir / "scenes" / "a.toml") << "# scene\n";
    const Sweep by_scene = load_sweep(dir / "sweep.toml", fake_kernel);
    CHECK(by_scene.jobs[0].run.kernel == "/kernels/tracer_grid.elf");
    CHECK(by_scene.jobs[1].run.kernel == "/kernels/tracer.elf");
    // The sweep's own accel wins over the scene file's.
    std::ofstream(dir / "sweep.toml") << "scene = \"scenes/grid.toml\"\naccel = \"octree\"\n";
    CHECK(load_sweep(dir / "sweep.toml", fake_kernel).jobs[0].run.kernel ==
          "/kernels/tracer_octree.elf");
    // A bad [accel] table is the scene file's error, on the sweep file's scene line.
    std::ofstream(dir / "scenes" / "grid.toml") << "[accel]\nstructure = 4\n";
    std::ofstream(dir / "sweep.toml") << "scene = \"scenes/grid.toml\"\n";
    CHECK_THROWS_WITH(load_sweep(dir / "sweep.toml", fake_kernel),
                      Catch::Contains("sweep.toml:1: ") &&
                          Catch::Contains("grid.toml:2:13: accel.structure must be one of"));
}

TEST_CASE("sweep: the plan file holds every job's resolved run", "[sweep]") {
    const auto dir = fresh_scratch_dir("plan");
    const Sweep sweep = load_text(dir, R"(scene = ["scenes/a.toml", "scenes/b.toml"]
config = ")" + (kSource / "configs" / "tiny.toml").string() +
                                           R"("
timing = "none"
l2.size_bytes = [4096, 8192]
bvh = "median"
bvh_align_pairs = true
grid_density = 0.5
)");
    write_plan(sweep, dir / "results");
    const Sweep back = read_plan(dir / "results");
    REQUIRE(back.jobs.size() == sweep.jobs.size());
    for (size_t j = 0; j < sweep.jobs.size(); ++j) {
        CHECK(back.jobs[j].id == sweep.jobs[j].id);
        CHECK(back.jobs[j].values == sweep.jobs[j].values);
        CHECK(back.jobs[j].run.scene == sweep.jobs[j].run.scene);
        CHECK(back.jobs[j].run.timing == "none");
        CHECK(back.jobs[j].run.chip == sweep.jobs[j].run.chip);
        CHECK(back.jobs[j].run.chip.chip.num_tms == 1);  // from the base configuration
        CHECK(back.jobs[j].run.accel == sweep.jobs[j].run.accel);
        CHECK(back.jobs[j].run.accel.grid_density == 0.5);
        CHECK_FALSE(back.jobs[j].run.accel.structure);  // unset stays unset: the scene's decides
    }
    CHECK(back.jobs[1].run.chip.l2.size_bytes == 8192);
    CHECK(back.describe(back.jobs[3]) == sweep.describe(sweep.jobs[3]));
    // Not a results directory, and a damaged plan.
    CHECK_THROWS_WITH(read_plan(dir), Catch::Contains("is not a sweep's results directory"));
    std::ofstream(plan_path(dir / "results")) << "{\"format\": \"tpsim-sweep\", \"version\": 7}";
    CHECK_THROWS_WITH(read_plan(dir / "results"),
                      Catch::Contains("written by plan version 7; this tpsim reads version 4"));
}

TEST_CASE("sweep: finished, pending and failed jobs; collect reads the statistics files",
          "[sweep]") {
    const auto dir = fresh_scratch_dir("collect");
    const Sweep sweep = load_text(dir, R"(scene = "scenes/a.toml"
bvh = ["sweep", "binned"]
l1.size_bytes = [4096, 8192]
)");
    const std::filesystem::path results = dir / "results";
    write_plan(sweep, results);
    CHECK(pending(sweep, results).size() == 4);
    // Two jobs finished (with the fixture statistics files), one failed, one never ran.
    std::filesystem::copy_file(kFixtures / "base.json", stats_path(results, sweep.jobs[0].id));
    std::filesystem::copy_file(kFixtures / "faster.json", stats_path(results, sweep.jobs[1].id));
    std::ofstream(error_path(results, sweep.jobs[2].id)) << "scene.toml:3: bad camera\n";
    // A temporary file of a job killed half way does not count as finished.
    std::ofstream(results / "jobs" / ("." + sweep.jobs[3].id + ".tmp.json")) << "{\"form";
    const auto left = pending(sweep, results);
    REQUIRE(left.size() == 2);
    CHECK(left[0] == &sweep.jobs[2]);
    CHECK(left[1] == &sweep.jobs[3]);
    const auto failed = failures(sweep, results);
    REQUIRE(failed.size() == 2);
    CHECK(failed[0].reason == "scene.toml:3: bad camera");
    CHECK(failed[1].reason.starts_with("no error recorded: not run yet, still running, or killed"));

    const Table table = collect(sweep, results, default_columns());
    REQUIRE(table.rows.size() == 4);
    CHECK(table.rows[0].status == "ok");
    CHECK(table.rows[2].status == "failed");
    CHECK(table.rows[3].status == "missing");
    CHECK(table.rows[0].stats[0] == 520000);  // chip/cycles of base.json
    CHECK(table.rows[1].stats[0] == 480000);  // of faster.json
    CHECK(table.rows[1].stats[3] == 0.94);    // chip/l1/hit_rate
    CHECK(!table.rows[2].stats[0]);
    const std::string csv = table_csv(table, false);
    CHECK(csv.substr(0, csv.find('\n')) ==
          "id,bvh,l1.size_bytes,status,cycles,instructions,rays,l1_hit_rate,l2_hit_rate,"
          "dram_bytes_read,dram_bytes_written,frame_seconds,energy_joules,watts,mrays_per_joule,"
          "area_mm2");
    CHECK(csv.find(sweep.jobs[1].id + ",sweep,8192,ok,480000,2900000,1900,0.94,0.74,520000,"
                                      "12288,0.00048,0.0016,3.333333,1.1875,1.576586\n") !=
          std::string::npos);
    CHECK(csv.find(sweep.jobs[3].id + ",binned,8192,missing,,,,,,,,,,,,\n") != std::string::npos);
    CHECK(table_csv(table, true).find(",host_seconds\n") != std::string::npos);
    const std::string md = table_markdown(table, false);
    CHECK(md.find("| " + sweep.jobs[1].id +
                  " | sweep | 8192 | ok | 480,000 | 2,900,000 | 1,900 | 0.94 | 0.74 | 520,000 | "
                  "12,288 |") != std::string::npos);

    // The page's document: the chosen axis and metrics must exist.
    const Json doc = table_document(table, default_charts(table), "t");
    CHECK(doc["charts"]["x"] == "bvh");
    CHECK(doc["rows"][2]["status"] == "failed");
    CHECK_THROWS_WITH(table_document(table, {{"cycles"}, "l2.size_bytes", ""}, "t"),
                      Catch::Contains("--x l2.size_bytes: the sweep has no such axis"));
    CHECK_THROWS_WITH(table_document(table, {{"cycles"}, "bvh", "bvh"}, "t"),
                      Catch::Contains("--by bvh: give an axis other than --x bvh"));
    CHECK(table_document(table, {{"cycles"}, "bvh", "l1.size_bytes"}, "t")["charts"]["by"] ==
          "l1.size_bytes");
    CHECK_THROWS_WITH(table_document(table, {{"energy"}, "bvh", ""}, "t"),
                      Catch::Contains("--metric energy: the table has no such column"));

    // A column the user names must exist in the finished jobs' files: a typo is an error, not
    // a column of "-". The default columns may be absent (no cycles without --timing cycles).
    std::vector<Column> asked = default_columns();
    asked.push_back({"bogus", "region/nope/x", true});
    CHECK_THROWS_WITH(collect(sweep, results, asked),
                      Catch::Contains("--column bogus=region/nope/x: no finished job has the "
                                      "statistic 'region/nope/x'; keys under 'region/' are e.g."));
    asked.back() = {"l1_reads", "region/camera/l1/reads", true};
    CHECK(collect(sweep, results, asked).rows[0].stats.back().has_value());
    asked.back().given = false;
    asked.back().stat = "region/nope/x";
    CHECK(!collect(sweep, results, asked).rows[0].stats.back().has_value());
}

TEST_CASE("sweep: the Slurm script runs each pending job as one array task", "[sweep]") {
    const auto dir = fresh_scratch_dir("slurm");
    const Sweep sweep = load_text(dir, R"(scene = "scenes/a.toml"
l1.size_bytes = [4096, 8192, 16384]
)");
    const std::filesystem::path results = dir / "results";
    write_plan(sweep, results);
    std::filesystem::copy_file(kFixtures / "base.json", stats_path(results, sweep.jobs[1].id));
    const std::string script =
        slurm_script(sweep, results, "/opt/tp sim/tpsim", {"--partition=long"});
    CHECK(script.starts_with("#!/bin/bash\n"));
    CHECK(script.find("#SBATCH --array=0-1\n") != std::string::npos);
    CHECK(script.find("#SBATCH --partition=long\n") != std::string::npos);
    CHECK(script.find("ids=(" + sweep.jobs[0].id + " " + sweep.jobs[2].id + ")\n") !=
          std::string::npos);
    CHECK(script.find("exec '/opt/tp sim/tpsim' sweep job '" + results.string() +
                      "' \"${ids[$SLURM_ARRAY_TASK_ID]}\"\n") != std::string::npos);
}
