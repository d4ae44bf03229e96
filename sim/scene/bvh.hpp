// Binary bounding volume hierarchy over a triangle soup, built with the surface area
// heuristic (SAH). Two builders: binned SAH (Wald 2007, "On fast Construction of SAH-based
// Bounding Volume Hierarchies") and a full sweep over presorted centroids (exact SAH for object
// splits, as in MacDonald & Booth 1990 / Wald et al. 2007 "Ray tracing deformable scenes").
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
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
inline constexpr BvhBuilder kBvhBuilders[] = {BvhBuilder::sweep, BvhBuilder::binned,
                                              BvhBuilder::median};

/// The order the scene compiler lays the nodes out in (image::build_memory_image). The image
/// stores the two children of a node side by side (a sibling pair, 64 bytes), so every order is
/// an order of sibling pairs after the root; it moves which nodes share cache lines and DRAM
/// rows, never the tree or the image.
///   breadth_first: level by level, so the top levels share a few lines.
///   depth_first: pre-order, a pair's left child's pair right after it (the path a ray takes
///     most often lies close together).
///   van_emde_boas: cache-oblivious (van Emde Boas 1977; Bender, Demaine and Farach-Colton
///     2000; for BVHs, Yoon and Manocha 2006): the tree of pairs is cut at half its height, the
///     top stored first, then each bottom subtree, recursively, so every subtree of height 2^k
///     is contiguous, whatever the line and row sizes.
enum class BvhOrder { breadth_first, depth_first, van_emde_boas };
inline constexpr BvhOrder kBvhOrders[] = {BvhOrder::breadth_first, BvhOrder::depth_first,
                                          BvhOrder::van_emde_boas};

/// How the scene compiler stores a wide node's child boxes (image::compile_wide_bvh).
///   floats: six floats per child, as the binary BVH does.
///   quantized: the node's box origin and a power-of-two scale per axis, and each child's box as
///     six 8-bit offsets on that grid, rounded outwards (Ylitie, Karras and Laine, "Efficient
///     Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG 2017): half the
///     bytes per node, a few more instructions per box, and boxes a little larger, never
///     smaller, than the float ones.
enum class BvhBoxes { floats, quantized };
inline constexpr BvhBoxes kBvhBoxes[] = {BvhBoxes::floats, BvhBoxes::quantized};

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
    /// How the scene compiler lays the nodes out; the builder ignores both.
    BvhOrder order = BvhOrder::breadth_first;
    /// Leave the node after the root unused, so that every sibling pair starts on a 64-byte
    /// boundary and fills one line (32 bytes more). Off, the root fills the first half line and
    /// every pair straddles two lines: the layout the reference figures were measured with.
    bool align_pairs = false;
    /// How a wide BVH's child boxes are stored (the binary BVH's are floats).
    BvhBoxes boxes = BvhBoxes::floats;
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
/// Every builder's name (to_string), for the command line's and the sweep file's choices.
std::vector<std::string> bvh_builder_names();
std::optional<BvhBuilder> find_bvh_builder(std::string_view name);
const char* to_string(BvhOrder order);
/// Every order's name (to_string), for the command line's and the sweep file's choices.
std::vector<std::string> bvh_order_names();
/// The order that to_string names `name`, or nullopt.
std::optional<BvhOrder> find_bvh_order(std::string_view name);
const char* to_string(BvhBoxes boxes);
/// Every box format's name, for the command line's and the sweep file's choices.
std::vector<std::string> bvh_boxes_names();
std::optional<BvhBoxes> find_bvh_boxes(std::string_view name);

}  // namespace tpsim::scene
