// kd-tree over a triangle soup: axis-aligned split planes chosen by the surface area heuristic
// over binned candidate planes (Wald and Havran, "On building fast kd-Trees for Ray Tracing, and
// on doing that in O(N log N)", RT 2006, for the cost model: traversal 15, intersection 20, an
// empty side's cost scaled by 0.8), and a triangle referenced by every leaf its bounding box
// reaches, so a triangle may sit in many leaves: the duplicates are counted and limited.
// The same builder makes the BSP tree with general planes (Ize, Wald and Parker, "Ray Tracing
// with the BSP Tree", RT 2008): a kd-tree whose planes may also take the ten diagonal
// orientations of trax::layout::kBspDirections, each cell bounded by a box for the heuristic.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "kernel/scene_layout.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/scene.hpp"

namespace tpsim::scene {

/// The deepest a kd-tree may be: its traversal stack (trax::layout::kKdStackEntries) holds one
/// entry per level.
constexpr uint32_t kKdMaxDepth = uint32_t(trax::layout::kKdStackEntries);

struct KdTreeConfig {
    /// Edges from the root to the deepest leaf, 1..kKdMaxDepth; 0: Havran's rule,
    /// 8 + 1.3 log2(triangles).
    uint32_t max_depth = 0;
    /// Most leaf references per triangle, on average, before the build is refused (a scene of
    /// long thin triangles crossing many cells duplicates without bound).
    double max_references_per_triangle = 64;
    /// A BSP tree: planes of all kBspPlaneDirections orientations, not only the three axes.
    bool general_planes = false;
};

/// The orientations a BSP tree's planes take: the three axes, then the six face diagonals and
/// the four space diagonals of the cube (integer normals, so n.x is a sum of coordinates).
constexpr uint32_t kBspPlaneDirections = uint32_t(trax::layout::kBspDirections);

/// Nodes depth-first from the root at 0: an interior node's left child (below the plane) is
/// the next node, its right child at `right_child`.
struct KdNode {
    static constexpr uint32_t kLeaf = 255;
    /// Interior: the plane's orientation, trax::layout::kBspDirection[axis] (0..2: the x, y, z
    /// axes; up to kBspPlaneDirections - 1 in a BSP tree); kLeaf for a leaf.
    uint32_t axis = kLeaf;
    float split = 0;  ///< interior: the plane is n.x = split, n its orientation
    uint32_t right_child = 0;
    uint32_t first = 0, count = 0;  ///< leaf: KdTree::references[first, first + count)
    bool is_leaf() const { return axis == kLeaf; }
};

struct KdTreeStats {
    uint32_t nodes = 0, leaves = 0, empty_leaves = 0, max_depth = 0;
    uint64_t references = 0;  ///< leaf entries (a triangle in k leaves counts k)
    uint32_t max_leaf_triangles = 0;
    uint32_t depth_limit = 0;      ///< the max_depth the build used
    uint32_t diagonal_planes = 0;  ///< interior nodes whose plane is not an axis's (BSP only)
    uint64_t bytes() const { return uint64_t(nodes) * 8 + references * 4; }
};

struct KdTree {
    bool general_planes = false;  ///< a BSP tree (KdTreeConfig::general_planes)
    Aabb bounds;                  ///< the triangles' box, padded so that none lies on its faces
    std::vector<KdNode> nodes;
    std::vector<uint32_t> references;  ///< triangle indices (scene order)
    KdTreeStats stats;
};

/// Builds the tree. A triangle goes to each side of a plane its bounding box reaches, widened
/// by kKdMargin of the node's extent (and a little of the plane's magnitude): the traversal's
/// rounding of where a ray crosses a plane never loses a hit. Throws std::invalid_argument on
/// an empty soup, a vertex beyond +-1e18, a max_depth out of range, or references beyond the
/// limit (the message says how many).
KdTree build_kdtree(std::span<const Triangle> triangles, const KdTreeConfig& config = {});

constexpr float kKdMargin = 1.0f / 1024;

}  // namespace tpsim::scene
