// Binary bounding volume hierarchy over a triangle soup, built with the surface area
// heuristic (SAH). Two builders: binned SAH (Wald 2007, "On fast Construction of SAH-based
// Bounding Volume Hierarchies") and a full sweep over presorted centroids (exact SAH for object
// splits, as in MacDonald & Booth 1990 / Wald et al. 2007 "Ray tracing deformable scenes").
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "sim/scene/scene.hpp"

namespace tpsim::scene {

struct Aabb {
    glm::vec3 lo{0.f}, hi{0.f};
    float surface_area() const;
    bool contains(const Aabb& inner) const;
};

/// Nodes are stored depth-first with the root at index 0: an interior node's left child is the
/// node right after it, its right child is at `right_child`.
struct BvhNode {
    Aabb bounds;
    uint32_t right_child = 0;     ///< interior only
    uint32_t first_triangle = 0;  ///< leaf only: first entry in Bvh::triangle_order
    uint32_t triangle_count = 0;  ///< 0 for interior nodes; leaves hold 1..max_leaf_size
    bool is_leaf() const { return triangle_count != 0; }
};

/// median: no SAH, the object median on the widest centroid axis until a node fits in a leaf;
/// the baseline the SAH builders are measured against (docs/course/experiments.md).
enum class BvhBuilder { binned, sweep, median };

struct BvhConfig {
    BvhBuilder builder = BvhBuilder::sweep;
    /// Most triangles in one leaf (1..8). Smaller leaves are made when the SAH says so.
    uint32_t max_leaf_size = 8;
    /// Entries in the kernel's traversal stack. Contract: the traversal keeps the node it is
    /// visiting in a register and pushes only the far child of each interior node it enters,
    /// so it holds at most (depth of the deepest leaf) entries, the root being at depth 0.
    /// The builder guarantees that depth <= traversal_stack_entries. A traversal that also
    /// pushes the root (or both children) needs one more entry: pass its capacity minus one.
    uint32_t traversal_stack_entries = 32;
    /// Bins per axis for the binned builder (2..256).
    uint32_t bins = 32;
};

struct BvhStats {
    uint32_t nodes = 0;
    uint32_t leaves = 0;
    uint32_t max_depth = 0;  ///< edges from the root to the deepest leaf
    /// Sum over interior nodes of A(node)/A(root) plus sum over leaves of
    /// A(leaf)/A(root) * triangles (traversal and intersection cost both 1).
    double sah_cost = 0.0;
    double build_seconds = 0.0;  ///< wall clock; informational only, never affects the tree
    /// Nodes where the depth limit overrode the SAH choice (forced a split or rejected the best
    /// split for a more balanced one). Non-zero means the limit shaped the tree: print it.
    uint32_t depth_limited_nodes = 0;
    std::vector<uint32_t> leaf_size_histogram;  ///< [k] = leaves holding k triangles
};

struct Bvh {
    std::vector<BvhNode> nodes;
    std::vector<uint32_t> triangle_order;  ///< leaf ranges index this; values index triangles
    BvhStats stats;
};

/// Builds the BVH. Throws std::invalid_argument on an empty soup, a vertex beyond +-1e18, an
/// out-of-range config, or more triangles than max_leaf_size * 2^traversal_stack_entries.
Bvh build_bvh(std::span<const Triangle> triangles, const BvhConfig& config = {});

/// The SAH cost of a finished tree, as defined in BvhStats::sah_cost.
double sah_cost(const Bvh& bvh);

const char* to_string(BvhBuilder builder);

}  // namespace tpsim::scene
