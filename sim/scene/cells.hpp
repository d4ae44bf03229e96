// What the structures that cut space into cells (the uniform grid, the kd-tree, the octree)
// share: the box they cut.
#pragma once
#include <span>
#include <string_view>

#include "sim/scene/bvh.hpp"
#include "sim/scene/scene.hpp"

namespace tpsim::scene {

/// The triangles' box padded by a little of its largest extent (1 for a point), so a flat scene
/// still has cells of some thickness and no triangle lies on the box's faces, where rounding
/// decides whether a ray enters. Throws std::invalid_argument, the message starting with
/// `structure`, for no triangles or a vertex beyond +-1e18 (or NaN).
Aabb padded_cells_box(std::span<const Triangle> triangles, std::string_view structure);

}  // namespace tpsim::scene
