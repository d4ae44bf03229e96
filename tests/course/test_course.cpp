// The checker's pieces: the image comparison's figures, and the shipped assignments load,
// name existing scenes and have their reference images.
#include <cmath>
#include <filesystem>
#include <vector>

#include <catch2/catch.hpp>

#include "sim/core/error.hpp"
#include "sim/course/assignment.hpp"
#include "sim/course/check.hpp"

namespace {

using tpsim::course::compare_rgb8;

const std::filesystem::path kCourse = TPSIM_COURSE_DIR;

}  // namespace

TEST_CASE("compare_rgb8 measures PSNR, differing pixels and their direction", "[course]") {
    const std::vector<uint8_t> ref(4 * 3, 100);
    SECTION("identical images") {
        const auto c = compare_rgb8(ref, ref, 0);
        CHECK(c.identical);
        CHECK(std::isinf(c.psnr));
        CHECK(c.differing_share == 0);
    }
    SECTION("one channel of one pixel off by 10, another pixel darker by 3") {
        std::vector<uint8_t> image = ref;
        image[4] = 110;  // pixel 1, green
        image[9] = 97;   // pixel 3, red
        const auto tolerant = compare_rgb8(image, ref, 8);
        CHECK_FALSE(tolerant.identical);
        // RMSE over 12 samples: sqrt((100 + 9) / 12) / 255.
        CHECK(tolerant.psnr == Approx(20 * std::log10(255 / std::sqrt(109.0 / 12))));
        CHECK(tolerant.differing_share == Approx(0.25));  // only the pixel beyond 8/255
        CHECK(tolerant.brighter_share == Approx(1.0));
        const auto strict = compare_rgb8(image, ref, 2);
        CHECK(strict.differing_share == Approx(0.5));
        CHECK(strict.brighter_share == Approx(0.5));
    }
}

TEST_CASE("the shipped assignments load and have what the checker needs", "[course]") {
    for (const char* id :
         {"1-gradient", "2-sphere", "3-shadows", "4-bvh", "5-path-tracing", "6-performance"}) {
        INFO(id);
        const std::filesystem::path dir = tpsim::course::find_assignment(kCourse, id);
        CHECK(dir.filename() == id);
        // By number too.
        CHECK(tpsim::course::find_assignment(kCourse, std::string(1, id[0])) == dir);
        const tpsim::course::Assignment a = tpsim::course::load_assignment(dir / "assignment.toml");
        CHECK(a.id == id);
        CHECK_FALSE(a.title.empty());
        REQUIRE_FALSE(a.scenes.empty());
        CHECK(a.width <= 128);  // the checker takes seconds, not minutes
        CHECK(std::filesystem::is_regular_file(dir / "starter.cpp"));
        for (const auto& scene : a.scenes)
            CHECK(std::filesystem::is_regular_file(scene.reference));
    }
    CHECK_THROWS_AS(tpsim::course::find_assignment(kCourse, "3-shadow"), tpsim::Error);
    CHECK_THROWS_AS(tpsim::course::find_assignment(kCourse, "33"), tpsim::Error);
}
