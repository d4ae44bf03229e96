#include "sim/scene/grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "sim/scene/cells.hpp"

namespace tpsim::scene {

namespace {

/// Most bytes the cells and references may take: a quarter of the 32-bit memory image, so the
/// triangles and the framebuffer still fit beside them.
constexpr uint64_t kMaxGridBytes = uint64_t(1) << 30;

/// The cells a triangle's widened box covers on one axis, [first, last].
struct CellRange {
    uint32_t first, last;
};

CellRange cell_range(float lo, float hi, float grid_lo, float scale, uint32_t resolution) {
    const auto cell = [&](float x) {
        const double c = std::floor(double(x - grid_lo) * double(scale));
        return uint32_t(std::clamp(c, 0.0, double(resolution - 1)));
    };
    return {cell(lo - kGridMargin / scale), cell(hi + kGridMargin / scale)};
}

/// Cubic cells, about `cells` of them (Ize, Shirley and Parker, "Grid Creation Strategies for
/// Efficient Ray Tracing", 2007: O(N) cells are best for well-behaved models): cell edge
/// a = cbrt(volume / cells), each axis round(extent / a) cells. An axis thinner than one cell
/// gets one, and the cells are shared out over the other axes again, so a flat scene gets a
/// square grid of the same number of cells, not a few cells of a thin slab's edge.
std::array<uint32_t, 3> density_resolution(const std::array<double, 3>& extent, double cells) {
    std::array<bool, 3> flat{};
    double edge = 0;
    for (int round = 0; round < 3; ++round) {
        double volume = 1;
        int free_axes = 0;
        for (int a = 0; a < 3; ++a)
            if (!flat[a]) {
                volume *= extent[a];
                ++free_axes;
            }
        edge = std::pow(volume / std::max(cells, 1.0), 1.0 / free_axes);
        bool changed = false;
        for (int a = 0; a < 3; ++a)
            if (!flat[a] && extent[a] < edge && free_axes > 1) {
                flat[a] = true;
                changed = true;
            }
        if (!changed) break;
    }
    std::array<uint32_t, 3> resolution;
    for (int a = 0; a < 3; ++a)
        resolution[a] = flat[a] ? 1u
                                : uint32_t(std::clamp(std::round(extent[a] / edge), 1.0,
                                                      double(kGridMaxResolution)));
    return resolution;
}

}  // namespace

Grid build_grid(std::span<const Triangle> triangles, const GridConfig& config) {
    if (config.resolution > kGridMaxResolution)
        throw std::invalid_argument(
            fmt::format("grid resolution {} is more than the {} cells per axis tpsim builds",
                        config.resolution, kGridMaxResolution));
    if (!(config.density > 0 && config.density <= kGridMaxDensity))
        throw std::invalid_argument(
            fmt::format("grid density {} is not in (0, {}] cells per triangle", config.density,
                        kGridMaxDensity));
    Grid grid;
    const Aabb box = padded_cells_box(triangles, "build_grid");
    grid.lo = box.lo;
    grid.hi = box.hi;
    const glm::vec3 size = grid.hi - grid.lo;
    const float size_longest = std::max({size.x, size.y, size.z});

    GridStats& stats = grid.stats;
    const std::array<double, 3> d = {size.x, size.y, size.z};
    if (config.resolution != 0) {
        for (int a = 0; a < 3; ++a)
            stats.resolution[a] =
                uint32_t(std::clamp(std::round(config.resolution * d[a] / double(size_longest)),
                                    1.0, double(config.resolution)));
    } else {
        stats.resolution = density_resolution(d, config.density * double(triangles.size()));
    }
    for (int a = 0; a < 3; ++a)
        grid.scale[a] = float(double(stats.resolution[a]) / d[a]);
    const std::array<uint32_t, 3>& res = stats.resolution;
    stats.cells = uint64_t(res[0]) * res[1] * res[2];

    if ((stats.cells + 1) * 4 > kMaxGridBytes)
        throw std::invalid_argument(fmt::format(
            "a grid of {}x{}x{} cells needs {} MiB for its cells alone, more than the {} MiB "
            "tpsim allows it; give a smaller --grid-resolution",
            res[0], res[1], res[2], ((stats.cells + 1) * 4) >> 20, kMaxGridBytes >> 20));

    // Three passes over the triangles: how many references (so a grid too big is refused
    // before it is filled), each cell's count, then the references themselves.
    const auto ranges = [&](const Triangle& t) {
        const glm::vec3 tlo = glm::min(t.v0, glm::min(t.v1, t.v2));
        const glm::vec3 thi = glm::max(t.v0, glm::max(t.v1, t.v2));
        std::array<CellRange, 3> r;
        for (int a = 0; a < 3; ++a)
            r[a] = cell_range(tlo[a], thi[a], grid.lo[a], grid.scale[a], res[a]);
        return r;
    };
    uint64_t references = 0;
    for (const Triangle& t : triangles) {
        const std::array<CellRange, 3> r = ranges(t);
        references += uint64_t(r[0].last - r[0].first + 1) * (r[1].last - r[1].first + 1) *
                      (r[2].last - r[2].first + 1);
    }
    const uint64_t bytes = (stats.cells + 1 + references) * 4;
    if (bytes > kMaxGridBytes)
        throw std::invalid_argument(fmt::format(
            "a grid of {}x{}x{} cells with {} triangle references needs {} MiB, more than the "
            "{} MiB tpsim allows it; give a smaller --grid-resolution",
            res[0], res[1], res[2], references, bytes >> 20, kMaxGridBytes >> 20));
    std::vector<uint32_t> counts(stats.cells + 1, 0);
    for (const Triangle& t : triangles) {
        const std::array<CellRange, 3> r = ranges(t);
        for (uint32_t z = r[2].first; z <= r[2].last; ++z)
            for (uint32_t y = r[1].first; y <= r[1].last; ++y)
                for (uint32_t x = r[0].first; x <= r[0].last; ++x)
                    ++counts[x + res[0] * (y + uint64_t(res[1]) * z)];
    }
    stats.references = references;

    grid.cell_start.resize(stats.cells + 1);
    uint64_t sum = 0;
    for (uint64_t i = 0; i < stats.cells; ++i) {
        grid.cell_start[i] = uint32_t(sum);
        sum += counts[i];
        stats.empty_cells += counts[i] == 0;
        stats.max_cell_triangles = std::max(stats.max_cell_triangles, uint32_t(counts[i]));
        counts[i] = grid.cell_start[i];  // from here on: the cell's next free slot
    }
    grid.cell_start[stats.cells] = uint32_t(sum);
    grid.references.resize(references);
    for (uint32_t i = 0; i < triangles.size(); ++i) {
        const std::array<CellRange, 3> r = ranges(triangles[i]);
        for (uint32_t z = r[2].first; z <= r[2].last; ++z)
            for (uint32_t y = r[1].first; y <= r[1].last; ++y)
                for (uint32_t x = r[0].first; x <= r[0].last; ++x)
                    grid.references[counts[x + res[0] * (y + uint64_t(res[1]) * z)]++] = i;
    }
    return grid;
}

}  // namespace tpsim::scene
