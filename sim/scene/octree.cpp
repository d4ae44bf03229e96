#include "sim/scene/octree.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>
#include <oneapi/tbb/scalable_allocator.h>
#include <oneapi/tbb/task_group.h>

#include "sim/scene/cells.hpp"
#include "sim/scene/kdtree.hpp"

namespace tpsim::scene {

namespace {

/// The kd-tree's costs (Wald and Havran 2006); an octree step tests three planes.
constexpr double kTraversalCost = 3 * 15, kIntersectionCost = 20;
/// Cuts on one path that leave some octant with all of its cell's triangles: past this many
/// the cell stays a leaf. Around a vertex where more than kOctreeLeafTriangles triangles meet no
/// cut separates them, yet each one pays by the area heuristic, since the cell holding the
/// vertex shrinks; pbrt's kd-tree builder limits its "bad refines" the same way.
constexpr uint32_t kMaxBadCuts = 2;
/// Subtrees with fewer references than this are built on the calling thread.
constexpr size_t kParallelReferences = 4096;

double area(const glm::vec3& lo, const glm::vec3& hi) {
    const glm::dvec3 d = glm::max(glm::dvec3(hi) - glm::dvec3(lo), glm::dvec3(0));
    return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

/// Triangle indices. Each level of the build makes new lists for the octants and frees the
/// parent's: oneTBB's allocator keeps the freed memory for the next lists, where malloc would
/// return large ones to the kernel and fault in zeroed pages again.
using References = std::vector<uint32_t, tbb::scalable_allocator<uint32_t>>;

/// Part of the tree laid out as the kernel walks it (a node's group of eight children after
/// it, then the children's subtrees in octant order), with node and reference indices of its
/// own from 0: its root, and the groups below it.
struct Subtree {
    OctreeNode root;
    std::vector<OctreeNode> nodes;
    References references;
};

/// The top of the tree, whose octants are built in parallel. A node of at most
/// kParallelReferences references has its whole subtree built on one thread straight into its
/// layout: the millions of nodes below are never allocated one by one.
struct TopNode {
    bool cut = false;  ///< false: `subtree` holds the node's subtree
    glm::vec3 centre{0.0f};
    std::array<std::unique_ptr<TopNode>, 8> children;  ///< null: an empty octant
    Subtree subtree;
};

/// Octant c's cell of `box` cut at `centre`.
Aabb octant_box(const Aabb& box, glm::vec3 centre, int c) {
    Aabb out = box;
    for (int axis = 0; axis < 3; ++axis)
        if (c >> axis & 1)
            out.lo[axis] = centre[axis];
        else
            out.hi[axis] = centre[axis];
    return out;
}

class Builder {
public:
    Builder(std::span<const Triangle> triangles, uint32_t depth_limit)
        : depth_limit_(depth_limit),
          max_references_(uint64_t(kOctreeMaxReferencesPerTriangle * double(triangles.size()))),
          lo_(triangles.size()), hi_(triangles.size()) {
        for (size_t i = 0; i < triangles.size(); ++i) {
            const Triangle& t = triangles[i];
            lo_[i] = glm::min(t.v0, glm::min(t.v1, t.v2));
            hi_[i] = glm::max(t.v0, glm::max(t.v1, t.v2));
        }
    }

    std::unique_ptr<TopNode> build(const Aabb& box, References refs, uint32_t depth,
                                   uint32_t bad_cuts) const {
        auto out = std::make_unique<TopNode>();
        if (refs.size() <= kParallelReferences) {
            out->subtree.root = build(box, std::move(refs), depth, bad_cuts, out->subtree);
            check_references(references_ += out->subtree.references.size());
            return out;
        }
        Cut cut = choose_cut(box, refs, depth, bad_cuts);
        if (!cut.made) {
            check_references(references_ += refs.size());
            out->subtree.root.count = uint32_t(refs.size());
            out->subtree.references = std::move(refs);
            return out;
        }
        out->cut = true;
        out->centre = cut.centre;
        tbb::task_group tasks;
        for (int c = 0; c < 8; ++c)
            if (!cut.octants[size_t(c)].empty())
                tasks.run([&, c] {
                    out->children[size_t(c)] =
                        build(octant_box(box, cut.centre, c), std::move(cut.octants[size_t(c)]),
                              depth + 1, bad_cuts + cut.bad);
                });
        tasks.wait();
        return out;
    }

private:
    /// Refuses the build as soon as the leaves hold too many references, before they fill the
    /// memory.
    void check_references(uint64_t total) const {
        if (total > max_references_)
            throw std::invalid_argument(fmt::format(
                "octree: more than {} leaf references, {:g} per triangle, the limit: the "
                "scene's triangles reach across many cells; lower --octree-max-depth, or "
                "use a BVH (--accel bvh2), which references each triangle once",
                max_references_, kOctreeMaxReferencesPerTriangle));
    }

    /// A node's choice: a leaf, or a cut at the cell's centre and what lies in each octant.
    struct Cut {
        bool made = false, bad = false;
        glm::vec3 centre{0.0f};
        std::array<References, 8> octants;
    };

    /// Builds `refs`' subtree on this thread, its groups at the end of `out`; returns its root.
    OctreeNode build(const Aabb& box, References refs, uint32_t depth, uint32_t bad_cuts,
                     Subtree& out) const {
        OctreeNode node;
        Cut cut = choose_cut(box, refs, depth, bad_cuts);
        if (!cut.made) {
            node.first = uint32_t(out.references.size());
            node.count = uint32_t(refs.size());
            out.references.insert(out.references.end(), refs.begin(), refs.end());
            // The subtree's references join the total when it is done (one thread's
            // additions to a shared count would stall the other's).
            check_references(references_.load(std::memory_order_relaxed) + out.references.size());
            return node;
        }
        refs = {};
        const auto group = uint32_t(out.nodes.size());
        out.nodes.resize(out.nodes.size() + 8);
        node.leaf = false;
        node.centre = {cut.centre.x, cut.centre.y, cut.centre.z};
        node.first_child = group;
        for (uint32_t c = 0; c < 8; ++c) {
            if (cut.octants[c].empty()) continue;
            node.occupied |= uint8_t(1u << c);
            const OctreeNode child =
                build(octant_box(box, cut.centre, int(c)), std::move(cut.octants[c]), depth + 1,
                      bad_cuts + cut.bad, out);
            out.nodes[group + c] = child;
        }
        return node;
    }

    /// The cut of the node of `refs` at its cell's centre, or none when a leaf costs less.
    Cut choose_cut(const Aabb& box, const References& refs, uint32_t depth,
                   uint32_t bad_cuts) const {
        Cut cut;
        const glm::vec3 extent = box.hi - box.lo;
        cut.centre = box.lo + extent * 0.5f;
        if (refs.size() > kOctreeLeafTriangles && depth < depth_limit_) {
            glm::vec3 margin;
            for (int axis = 0; axis < 3; ++axis)
                margin[axis] = extent[axis] * kKdMargin + std::abs(cut.centre[axis]) * 0x1p-20f;
            for (uint32_t r : refs) {
                // Bit a of `sides[s]`: the triangle reaches side s (0 below, 1 above) on axis a.
                uint32_t below = 0, above = 0;
                for (int axis = 0; axis < 3; ++axis) {
                    if (lo_[r][axis] <= cut.centre[axis] + margin[axis]) below |= 1u << axis;
                    if (hi_[r][axis] >= cut.centre[axis] - margin[axis]) above |= 1u << axis;
                }
                for (uint32_t c = 0; c < 8; ++c)
                    if (((c & above) | (~c & 7u & below)) == 7u) cut.octants[c].push_back(r);
            }
        }
        for (const References& octant : cut.octants)
            cut.bad = cut.bad || octant.size() == refs.size();
        // A cut whose children (duplicates included) cost more than the leaf is not made.
        cut.made = cut_pays(box, cut.centre, refs.size(), cut.octants) &&
                   !(cut.bad && bad_cuts == kMaxBadCuts);
        return cut;
    }

    static bool cut_pays(const Aabb& box, glm::vec3 centre, size_t n,
                         const std::array<References, 8>& octants) {
        double weighted = 0;
        size_t held = 0;
        for (int c = 0; c < 8; ++c) {
            const Aabb child = octant_box(box, centre, c);
            weighted += area(child.lo, child.hi) * double(octants[size_t(c)].size());
            held += octants[size_t(c)].size();
        }
        const double parent = area(box.lo, box.hi);
        if (held == 0 || !(parent > 0)) return false;
        return kTraversalCost + kIntersectionCost * weighted / parent <
               kIntersectionCost * double(n);
    }

    uint32_t depth_limit_;
    uint64_t max_references_;
    std::vector<glm::vec3> lo_, hi_;
    mutable std::atomic<uint64_t> references_{0};
};

/// The node slots and references of `node`'s tree, its root's slot not counted.
std::pair<size_t, size_t> sizes(const TopNode& node) {
    if (!node.cut) return {node.subtree.nodes.size(), node.subtree.references.size()};
    std::pair<size_t, size_t> out{8, 0};
    for (const auto& child : node.children)
        if (child) {
            const auto [nodes, references] = sizes(*child);
            out.first += nodes;
            out.second += references;
        }
    return out;
}

/// `node` of a subtree moved to node `node_base` and reference `reference_base` of the tree.
OctreeNode moved(OctreeNode node, uint32_t node_base, uint32_t reference_base) {
    if (!node.leaf)
        node.first_child += node_base;
    else if (node.count != 0)  // an empty octant's slot stays as it is
        node.first += reference_base;
    return node;
}

/// Lays `node`'s tree out at `index`, its groups at the end of the tree's nodes, freeing its
/// subtrees as it goes.
void lay_out(TopNode& node, uint32_t index, Octree& tree) {
    if (!node.cut) {
        const auto node_base = uint32_t(tree.nodes.size());
        const auto reference_base = uint32_t(tree.references.size());
        tree.nodes[index] = moved(node.subtree.root, node_base, reference_base);
        for (const OctreeNode& n : node.subtree.nodes)
            tree.nodes.push_back(moved(n, node_base, reference_base));
        tree.references.insert(tree.references.end(), node.subtree.references.begin(),
                               node.subtree.references.end());
        node.subtree = {};
        return;
    }
    const auto group = uint32_t(tree.nodes.size());
    tree.nodes.resize(tree.nodes.size() + 8);
    uint8_t occupied = 0;
    for (uint32_t c = 0; c < 8; ++c) {
        if (!node.children[c]) continue;
        occupied |= uint8_t(1u << c);
        lay_out(*node.children[c], group + c, tree);
    }
    OctreeNode& interior = tree.nodes[index];
    interior.leaf = false;
    interior.centre = {node.centre.x, node.centre.y, node.centre.z};
    interior.first_child = group;
    interior.occupied = occupied;
}

void fill_stats(Octree& tree) {
    OctreeStats& s = tree.stats;
    s.nodes = uint32_t(tree.nodes.size());
    s.references = tree.references.size();
    std::vector<std::pair<uint32_t, uint32_t>> pending{{0, 0}};  // (node, depth)
    while (!pending.empty()) {
        const auto [index, depth] = pending.back();
        pending.pop_back();
        const OctreeNode& node = tree.nodes[index];
        s.max_depth = std::max(s.max_depth, depth);
        if (node.leaf) {
            ++s.leaves;
            s.max_leaf_triangles = std::max(s.max_leaf_triangles, node.count);
            continue;
        }
        ++s.interior;
        for (uint32_t c = 0; c < 8; ++c)
            if (node.occupied >> c & 1) pending.push_back({node.first_child + c, depth + 1});
    }
}

}  // namespace

Octree build_octree(std::span<const Triangle> triangles, const OctreeConfig& config) {
    if (config.max_depth > kOctreeMaxDepth)
        throw std::invalid_argument(fmt::format("octree: max_depth must be in 1..{}, got {}",
                                                kOctreeMaxDepth, config.max_depth));
    Octree tree;
    tree.bounds = padded_cells_box(triangles, "octree");
    tree.stats.depth_limit = config.max_depth != 0 ? config.max_depth : kOctreeMaxDepth;
    References all(triangles.size());
    for (uint32_t i = 0; i < all.size(); ++i)
        all[i] = i;
    const std::unique_ptr<TopNode> root =
        Builder(triangles, tree.stats.depth_limit).build(tree.bounds, std::move(all), 0, 0);
    // The root alone in the first group, so that every group of siblings starts on a line.
    const auto [nodes, references] = sizes(*root);
    tree.nodes.reserve(8 + nodes);
    tree.references.reserve(references);
    tree.nodes.resize(8);
    lay_out(*root, 0, tree);
    fill_stats(tree);
    return tree;
}

}  // namespace tpsim::scene
