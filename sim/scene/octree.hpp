// Octree over a triangle soup (Glassner, "Space Subdivision for Fast Ray Tracing", IEEE CG&A
// 4(10), 1984): each cell cut at its centre into eight, a triangle referenced by every child its
// bounding box reaches, until a cell holds few triangles, cutting it no longer pays by the
// surface area heuristic, or the depth limit. The duplicates are counted and limited, as the
// kd-tree's.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "kernel/scene_layout.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/scene.hpp"

namespace tpsim::scene {

/// The deepest an octree may be: its traversal stack (trax::layout::kOctreeStackEntries) holds
/// three entries per level.
constexpr uint32_t kOctreeMaxDepth = uint32_t(trax::layout::kOctreeStackEntries) / 3;
/// A cell with at most this many triangles stays a leaf.
constexpr uint32_t kOctreeLeafTriangles = 4;
/// Most leaf references per triangle, on average, before the build is refused.
constexpr double kOctreeMaxReferencesPerTriangle = 64;

struct OctreeConfig {
    /// Edges from the root to the deepest leaf, 1..kOctreeMaxDepth; 0: kOctreeMaxDepth.
    uint32_t max_depth = 0;
};

/// Nodes in groups of eight siblings (octant c: bit 0 set above the centre on x, bit 1 on y,
/// bit 2 on z), the root alone in the first group.
struct OctreeNode {
    bool leaf = true;
    std::array<float, 3> centre{};  ///< interior: where the cell is cut
    uint32_t first_child = 0;       ///< interior: the children's group, octant c at + c
    uint8_t occupied = 0;           ///< interior: bit c set when octant c holds triangles
    uint32_t first = 0, count = 0;  ///< leaf: Octree::references[first, first + count)
};

struct OctreeStats {
    uint32_t nodes = 0;  ///< node slots laid out (empty octants' and the root group's included)
    uint32_t interior = 0, leaves = 0;  ///< leaves with triangles; empty octants are neither
    uint32_t max_depth = 0;
    uint64_t references = 0;  ///< leaf entries (a triangle in k leaves counts k)
    uint32_t max_leaf_triangles = 0;
    uint32_t depth_limit = 0;  ///< the max_depth the build used
    uint64_t bytes() const {
        return uint64_t(nodes) * trax::layout::kOctreeNodeWords * 4 + references * 4;
    }
};

struct Octree {
    Aabb bounds;  ///< the root cell: the triangles' box, padded so that none lies on its faces
    std::vector<OctreeNode> nodes;
    std::vector<uint32_t> references;  ///< triangle indices (scene order)
    OctreeStats stats;
};

/// Builds the octree. A triangle goes to each child its bounding box reaches, widened by
/// kKdMargin of the cell's extent (and a little of the centre's magnitude) on every axis, so
/// the traversal's rounding of where a ray crosses a centre plane never loses a hit. Throws
/// std::invalid_argument on an empty soup, a vertex beyond +-1e18, a max_depth out of range, or
/// references beyond the limit (the message says how many).
Octree build_octree(std::span<const Triangle> triangles, const OctreeConfig& config = {});

}  // namespace tpsim::scene
