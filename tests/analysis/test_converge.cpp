// tpsim converge's measurements on a small render: the reference, the runs in order, each
// image's error, the uniform PSNR an adaptive run is set against, and the JSON document.
#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>

#include "sim/analysis/converge.hpp"
#include "sim/core/error.hpp"
#include "tests/scratch.hpp"

using namespace tpsim;
using namespace tpsim::analysis;

namespace {

ConvergeOptions small_options(const std::filesystem::path& dir) {
    ConvergeOptions o;
    o.base.scene = std::filesystem::path(TPSIM_SOURCE_DIR) / "tests" / "cli" / "cornell_32.toml";
    o.base.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / "tracer.elf";
    o.base.image_width = o.base.image_height = 16;
    o.base.chip.chip.num_tms = 1;
    o.spp = {8, 2, 4};
    o.adaptive_kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / "adaptive.elf";
    o.thresholds = {0.01f, 0.2f};
    o.adaptive_spp = 8;
    o.reference_spp = 128;
    o.output_dir = dir;
    return o;
}

}  // namespace

TEST_CASE("converge: runs in order, each measured against the reference", "[analysis][converge]") {
    const std::filesystem::path dir = tpsim::testing::fresh_scratch_dir("runs");
    const ConvergeOptions o = small_options(dir);
    size_t reports = 0;
    const ConvergeResult r = converge(o, [&](const ConvergeResult& so_far) {
        CHECK(so_far.runs.size() == reports++);  // the reference first, then one run at a time
    });
    CHECK(reports == 6);
    CHECK(r.width == 16);
    CHECK(r.reference.kind == ConvergeRun::Kind::reference);
    CHECK(r.reference.cycles == 0);  // the twin has no cycles
    CHECK(r.reference.camera_rays_per_pixel == 128);
    CHECK(std::filesystem::is_regular_file(r.reference.image));

    REQUIRE(r.runs.size() == 5);
    const uint32_t order[] = {2, 4, 8};  // uniform by samples, then adaptive by threshold, down
    for (size_t i = 0; i < 3; ++i) {
        const ConvergeRun& run = r.runs[i];
        CHECK(run.kind == ConvergeRun::Kind::uniform);
        CHECK(run.samples_per_pixel == order[i]);
        CHECK(run.camera_rays_per_pixel == order[i]);
        CHECK(run.error.compared());
        CHECK(run.error.rmse > 0);
        CHECK(run.error.psnr == Approx(20 * std::log10(1 / run.error.rmse)));
        CHECK(std::filesystem::is_regular_file(run.image));
        if (i > 0) CHECK(run.cycles > r.runs[i - 1].cycles);
    }
    CHECK(r.runs[2].error.psnr > r.runs[0].error.psnr);  // 8 samples beat 2
    for (size_t i = 3; i < 5; ++i) {
        const ConvergeRun& run = r.runs[i];
        CHECK(run.kind == ConvergeRun::Kind::adaptive);
        CHECK(run.samples_per_pixel == 8);
        CHECK(run.camera_rays_per_pixel >= 4);
        CHECK(run.camera_rays_per_pixel <= 8);
    }
    CHECK(*r.runs[3].threshold == 0.2f);
    CHECK(r.runs[3].label == "adaptive 0.2");
    CHECK(r.runs[3].camera_rays_per_pixel < r.runs[4].camera_rays_per_pixel);
    // The uniform PSNR at an adaptive run's cycles lies on the uniform curve between its
    // neighbours, or is absent outside it.
    for (size_t i = 3; i < 5; ++i) {
        const ConvergeRun& run = r.runs[i];
        INFO(run.label << " at " << run.cycles << " cycles");
        const bool inside = run.cycles >= r.runs[0].cycles && run.cycles <= r.runs[2].cycles;
        REQUIRE(run.uniform_psnr_at_same_cycles.has_value() == inside);
        if (!inside) continue;
        const size_t below = run.cycles <= r.runs[1].cycles ? 0 : 1;
        const double a = r.runs[below].error.psnr, b = r.runs[below + 1].error.psnr;
        CHECK(*run.uniform_psnr_at_same_cycles >= std::min(a, b) - 1e-9);
        CHECK(*run.uniform_psnr_at_same_cycles <= std::max(a, b) + 1e-9);
    }

    const nlohmann::ordered_json doc = converge_document(o, r, dir / "c.json");
    CHECK(doc["format"] == "tpsim-converge");
    CHECK(doc["reference"]["seed"] == 1);
    CHECK(doc["reference"]["cycles"].is_null());
    CHECK(doc["reference"]["image"] == "converge-cornell_32-reference.png");
    CHECK(doc["adaptive_params"]["first_samples"] == 4);
    CHECK_FALSE(doc["adaptive_params"].contains("threshold"));
    REQUIRE(doc["runs"].size() == 5);
    CHECK(doc["runs"][0]["cycles"] == r.runs[0].cycles);
    CHECK(doc["runs"][0]["psnr"] == r.runs[0].error.psnr);
    CHECK(doc["runs"][3]["threshold"] == 0.2);
    CHECK(doc["runs"][3]["image"] == "converge-cornell_32-adaptive-0.2.png");
}

TEST_CASE("converge: options that cannot measure are refused before any render",
          "[analysis][converge]") {
    const std::filesystem::path dir = tpsim::testing::fresh_scratch_dir("refused");
    ConvergeOptions o = small_options(dir);
    o.reference_spp = 8;
    CHECK_THROWS_WITH(converge(o), "the reference (8 spp, --reference-spp) must take more "
                                   "samples per pixel than any run (8): it stands for the "
                                   "converged image");
    o = small_options(dir);
    o.adaptive_kernel = o.base.kernel;
    CHECK_THROWS_AS(converge(o), Error);
    o = small_options(dir);
    o.spp.clear();
    o.thresholds.clear();
    CHECK_THROWS_AS(converge(o), Error);
    CHECK(std::filesystem::is_empty(dir));
}
