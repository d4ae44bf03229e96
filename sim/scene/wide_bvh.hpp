// Wide BVHs: 4 or 8 children per node, collapsed from the binary SAH tree (bvh.hpp) by opening,
// at each wide node, the child with the largest surface area until the node has `width`
// children or only leaves are left: the greedy collapse of Wald, Benthin and Boulos, "Getting
// Rid of Packets" (RT 2008) and Dammertz, Hanika and Keller, "Shallow Bounding Volume
// Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays" (EGSR 2008). Leaves stay the binary
// tree's leaves, so the triangles keep its leaf order.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "sim/scene/bvh.hpp"

namespace tpsim::scene {

constexpr uint32_t kMaxWideBvhWidth = 8;

/// One child of a wide node: an interior node or a leaf (a range of Bvh::triangle_order).
struct WideChild {
    Aabb bounds;
    uint32_t node = 0;            ///< interior only: index in WideBvh::nodes
    uint32_t first_triangle = 0;  ///< leaf only
    uint32_t triangle_count = 0;  ///< 0 for an interior child
    bool is_leaf() const { return triangle_count != 0; }
};

/// Children in the binary tree's left-to-right order; child_count is 2..width (1 only for a
/// root that is a single leaf).
struct WideNode {
    std::array<WideChild, kMaxWideBvhWidth> children{};
    uint32_t child_count = 0;
};

struct WideBvhStats {
    uint32_t width = 0;
    uint32_t nodes = 0;
    uint32_t leaves = 0;
    uint32_t max_depth = 0;  ///< wide nodes from the root to the deepest leaf (root's leaf: 1)
    double mean_children = 0;
    /// The most traversal-stack entries a ray can need: over every path from the root to a
    /// leaf, the sum of (children - 1) of its nodes (the traversal pushes every child it hits
    /// but the nearest).
    uint32_t worst_stack = 0;
    double collapse_seconds = 0;  ///< wall clock; informational only
};

struct WideBvh {
    Aabb bounds;                  ///< the root's box
    std::vector<WideNode> nodes;  ///< the root at 0, every node before its children (pre-order)
    std::vector<uint32_t> triangle_order;  ///< the binary tree's, which the leaves index
    WideBvhStats stats;
};

/// Collapses `binary` into a tree of `width` (4 or 8) children per node. Throws
/// std::invalid_argument for another width.
WideBvh collapse_bvh(const Bvh& binary, uint32_t width);

}  // namespace tpsim::scene
