#include <cmath>
#include <random>
#include <set>

#include <catch2/catch.hpp>

#include "sim/scene/grid.hpp"
#include "sim/scene/load_scene.hpp"

using namespace tpsim::scene;

namespace {

/// Checks every promise build_grid makes, independently of how it was built: the cells are a
/// valid CSR list of scene triangle indices, each triangle is listed in every cell its
/// box (widened by kGridMargin of a cell) overlaps, computed here in double, and the statistics
/// count what is there.
void check_invariants(const Grid& grid, const std::vector<Triangle>& triangles) {
    const auto& res = grid.stats.resolution;
    const uint64_t cells = uint64_t(res[0]) * res[1] * res[2];
    REQUIRE(grid.stats.cells == cells);
    REQUIRE(grid.cell_start.size() == cells + 1);
    REQUIRE(grid.cell_start.front() == 0);
    REQUIRE(grid.cell_start.back() == grid.references.size());
    REQUIRE(grid.stats.references == grid.references.size());
    uint64_t empty = 0;
    uint32_t most = 0;
    std::vector<std::set<uint32_t>> listed(cells);
    for (uint64_t c = 0; c < cells; ++c) {
        REQUIRE(grid.cell_start[c] <= grid.cell_start[c + 1]);
        const uint32_t count = grid.cell_start[c + 1] - grid.cell_start[c];
        empty += count == 0;
        most = std::max(most, count);
        for (uint32_t i = grid.cell_start[c]; i < grid.cell_start[c + 1]; ++i) {
            REQUIRE(grid.references[i] < triangles.size());
            REQUIRE(listed[c].insert(grid.references[i]).second);  // once per cell
        }
    }
    CHECK(grid.stats.empty_cells == empty);
    CHECK(grid.stats.max_cell_triangles == most);
    for (int a = 0; a < 3; ++a) {
        REQUIRE(res[a] >= 1);
        REQUIRE(grid.lo[a] < grid.hi[a]);
        CHECK(double(grid.scale[a]) ==
              Approx(double(res[a]) / double(grid.hi[a] - grid.lo[a])).epsilon(1e-6));
    }
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        const Triangle& tri = triangles[t];
        int first[3], last[3];
        for (int a = 0; a < 3; ++a) {
            const double lo = std::min({tri.v0[a], tri.v1[a], tri.v2[a]});
            const double hi = std::max({tri.v0[a], tri.v1[a], tri.v2[a]});
            // The box inside the grid, and the cells it reaches within the margin.
            REQUIRE(lo > grid.lo[a]);
            REQUIRE(hi < grid.hi[a]);
            const double cell = double(grid.hi[a] - grid.lo[a]) / res[a];
            const double margin = 0.5 * double(kGridMargin) * cell;  // well inside it
            first[a] = std::max(0, int(std::floor((lo - margin - grid.lo[a]) / cell)));
            last[a] = std::min(int(res[a]) - 1, int(std::floor((hi + margin - grid.lo[a]) / cell)));
        }
        for (int z = first[2]; z <= last[2]; ++z)
            for (int y = first[1]; y <= last[1]; ++y)
                for (int x = first[0]; x <= last[0]; ++x) {
                    INFO("triangle " << t << " cell " << x << "," << y << "," << z);
                    REQUIRE(listed[x + res[0] * (y + uint64_t(res[1]) * z)].count(t) == 1);
                }
    }
}

std::vector<Triangle> random_soup(size_t n, uint32_t seed, float size) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> where(-10.0f, 10.0f), edge(-size, size);
    std::vector<Triangle> soup;
    for (size_t i = 0; i < n; ++i) {
        const glm::vec3 p(where(rng), where(rng), where(rng));
        soup.push_back({p, p + glm::vec3(edge(rng), edge(rng), edge(rng)),
                        p + glm::vec3(edge(rng), edge(rng), edge(rng))});
    }
    return soup;
}

}  // namespace

TEST_CASE("grid: every triangle is listed in every cell its box overlaps", "[grid]") {
    SECTION("random soup of small triangles") {
        const auto soup = random_soup(2000, 1, 0.5f);
        check_invariants(build_grid(soup), soup);
    }
    SECTION("random soup of long triangles, explicit resolution") {
        const auto soup = random_soup(300, 2, 8.0f);
        check_invariants(build_grid(soup, {.resolution = 40}), soup);
    }
    SECTION("the Cornell box and the bunny") {
        for (const char* name : {"/cornell.toml", "/bunny.toml"}) {
            INFO(name);
            const Scene scene = load_scene(std::string(TPSIM_SCENES_DIR) + name);
            check_invariants(build_grid(scene.triangles), scene.triangles);
        }
    }
    SECTION("one triangle, a flat quad, a point") {
        const std::vector<Triangle> one = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
        check_invariants(build_grid(one), one);
        const std::vector<Triangle> point = {{{3, 3, 3}, {3, 3, 3}, {3, 3, 3}}};
        check_invariants(build_grid(point), point);
    }
}

TEST_CASE("grid: the density rule gives cubic cells, about density x triangles of them", "[grid]") {
    const auto soup = random_soup(4000, 3, 0.3f);  // in a 20-unit cube
    for (double density : {0.5, 1.0, 4.0, 16.0}) {
        const Grid grid = build_grid(soup, {.density = density});
        INFO("density " << density << ": " << grid.stats.cells << " cells");
        CHECK(double(grid.stats.cells) == Approx(density * 4000).epsilon(0.25));
        const auto& r = grid.stats.resolution;
        CHECK(std::max({r[0], r[1], r[2]}) - std::min({r[0], r[1], r[2]}) <= 1);
    }
    // A flat scene (a floor in y = 0) gets one cell of thickness, the cells spread over x, z.
    std::vector<Triangle> floor;
    for (int i = 0; i < 50; ++i)
        for (int j = 0; j < 20; ++j) {
            const glm::vec3 p(float(i), 0.0f, float(j));
            floor.push_back({p, p + glm::vec3(1, 0, 0), p + glm::vec3(1, 0, 1)});
            floor.push_back({p, p + glm::vec3(1, 0, 1), p + glm::vec3(0, 0, 1)});
        }
    const Grid flat = build_grid(floor);
    CHECK(flat.stats.resolution[1] == 1);
    CHECK(double(flat.stats.cells) == Approx(4.0 * 2000).epsilon(0.25));
    CHECK(double(flat.stats.resolution[0]) / flat.stats.resolution[2] == Approx(2.5).epsilon(0.1));
    check_invariants(flat, floor);
    // An explicit resolution is the longest axis's; the others in proportion.
    const Grid explicit_grid = build_grid(floor, {.resolution = 100});
    CHECK(explicit_grid.stats.resolution[0] == 100);
    CHECK(explicit_grid.stats.resolution[1] == 1);
    CHECK(explicit_grid.stats.resolution[2] == 40);
}

TEST_CASE("grid: the same triangles give the same grid", "[grid]") {
    const auto soup = random_soup(1000, 4, 1.0f);
    const Grid a = build_grid(soup), b = build_grid(soup);
    CHECK(a.cell_start == b.cell_start);
    CHECK(a.references == b.references);
    CHECK(a.lo == b.lo);
    CHECK(a.hi == b.hi);
}

TEST_CASE("grid: bad input is refused with a message that says what to change", "[grid]") {
    const std::vector<Triangle> one = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
    CHECK_THROWS_WITH(build_grid({}), Catch::Contains("no triangles"));
    const float nan = std::nanf("");
    CHECK_THROWS_WITH(build_grid(std::vector<Triangle>{{{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}}}),
                      Catch::Contains("NaN"));
    CHECK_THROWS_WITH(build_grid(one, {.resolution = kGridMaxResolution + 1}),
                      Catch::Contains("1025") && Catch::Contains("1024"));
    CHECK_THROWS_WITH(build_grid(one, {.density = 0}), Catch::Contains("density"));
    // A cube of 1024^3 cells would need 4 GiB for its cells: refused before it is allocated.
    const std::vector<Triangle> cube_corners = {{{0, 0, 0}, {1, 1, 1}, {0, 1, 1}}};
    CHECK_THROWS_WITH(build_grid(cube_corners, {.resolution = 1024}),
                      Catch::Contains("MiB") && Catch::Contains("--grid-resolution"));
    // Long triangles through many cells: too many references, refused before they are filled.
    const auto long_ones = random_soup(2000, 5, 20.0f);
    CHECK_THROWS_WITH(build_grid(long_ones, {.resolution = 400}),
                      Catch::Contains("references") && Catch::Contains("MiB"));
}
