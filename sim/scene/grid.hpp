// Uniform grid over a triangle soup, for the 3D-DDA traversal of Amanatides and Woo, "A Fast
// Voxel Traversal Algorithm for Ray Tracing" (Eurographics 1987): the scene's box cut into equal
// cells, each listing the triangles whose bounding box overlaps it.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "sim/scene/scene.hpp"

namespace tpsim::scene {

struct GridConfig {
    /// Cells along the box's longest axis (the others in proportion, at least 1); 0: by the
    /// density rule, cubic cells, about `density` of them per triangle.
    uint32_t resolution = 0;
    double density = 4.0;
};

/// Most cells a grid may have along one axis.
constexpr uint32_t kGridMaxResolution = 1024;
/// Most cells per triangle GridConfig::density may ask for.
constexpr double kGridMaxDensity = 64.0;

struct GridStats {
    std::array<uint32_t, 3> resolution{};
    uint64_t cells = 0;
    uint64_t references = 0;  ///< triangle entries over all cells (a triangle in k cells: k)
    uint64_t empty_cells = 0;
    uint32_t max_cell_triangles = 0;
    uint64_t bytes() const { return (cells + 1 + references) * 4; }
};

struct Grid {
    /// The box the cells divide: the triangles' bounds, padded so no triangle lies on its faces.
    glm::vec3 lo{0.f}, hi{0.f};
    /// Cells per unit length on each axis (resolution / extent): the cell of point p on axis a
    /// is floor((p[a] - lo[a]) * scale[a]), the mapping the kernel uses too.
    glm::vec3 scale{0.f};
    /// cell_start[i] .. cell_start[i + 1] index `references` for cell i (x fastest, then y, z).
    std::vector<uint32_t> cell_start;
    std::vector<uint32_t> references;  ///< triangle indices (scene order)
    GridStats stats;
};

/// Builds the grid. Every triangle is listed in every cell its bounding box, widened by
/// kGridMargin of a cell on each side, overlaps: the traversal's rounding (of where the ray
/// enters the grid and crosses cell faces) then never loses a hit. Throws std::invalid_argument
/// on an empty soup, a vertex beyond +-1e18, an out-of-range resolution, or a grid whose cells
/// and references would not fit a 32-bit memory image (the message says the size).
Grid build_grid(std::span<const Triangle> triangles, const GridConfig& config = {});

/// Fraction of a cell by which triangle boxes are widened when they are entered in the grid.
constexpr float kGridMargin = 1.0f / 256;

}  // namespace tpsim::scene
