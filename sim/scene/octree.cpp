#include "sim/scene/octree.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>
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

/// A node as the build makes it, before the tree is laid out (once, at the end).
struct BuildNode {
    bool leaf = true;
    glm::vec3 centre{0.0f};
    std::array<std::unique_ptr<BuildNode>, 8> children;  ///< null: an empty octant
    std::vector<uint32_t> references;                    ///< leaf only
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

    std::unique_ptr<BuildNode> build(const Aabb& box, std::vector<uint32_t> refs, uint32_t depth,
                                     uint32_t bad_cuts) const {
        auto out = std::make_unique<BuildNode>();
        std::array<std::vector<uint32_t>, 8> octants;
        const glm::vec3 extent = box.hi - box.lo;
        const glm::vec3 centre = box.lo + extent * 0.5f;
        if (refs.size() > kOctreeLeafTriangles && depth < depth_limit_) {
            glm::vec3 margin;
            for (int axis = 0; axis < 3; ++axis)
                margin[axis] = extent[axis] * kKdMargin + std::abs(centre[axis]) * 0x1p-20f;
            for (uint32_t r : refs) {
                // Bit a of `sides[s]`: the triangle reaches side s (0 below, 1 above) on axis a.
                uint32_t below = 0, above = 0;
                for (int axis = 0; axis < 3; ++axis) {
                    if (lo_[r][axis] <= centre[axis] + margin[axis]) below |= 1u << axis;
                    if (hi_[r][axis] >= centre[axis] - margin[axis]) above |= 1u << axis;
                }
                for (uint32_t c = 0; c < 8; ++c)
                    if (((c & above) | (~c & 7u & below)) == 7u) octants[c].push_back(r);
            }
        }
        bool bad = false;
        for (const std::vector<uint32_t>& octant : octants)
            bad = bad || octant.size() == refs.size();
        // A cut whose children (duplicates included) cost more than the leaf is not made.
        if (!cut_pays(box, centre, refs.size(), octants) || (bad && bad_cuts == kMaxBadCuts)) {
            // Refused as soon as the leaves hold too many, before they fill the memory.
            const uint64_t total = references_ += refs.size();
            if (total > max_references_)
                throw std::invalid_argument(fmt::format(
                    "octree: more than {} leaf references, {:g} per triangle, the limit: the "
                    "scene's triangles reach across many cells; lower --octree-max-depth, or "
                    "use a BVH (--accel bvh2), which references each triangle once",
                    max_references_, kOctreeMaxReferencesPerTriangle));
            out->references = std::move(refs);
            return out;
        }
        const bool parallel = refs.size() > kParallelReferences;
        refs = {};
        out->leaf = false;
        out->centre = centre;
        tbb::task_group tasks;
        for (int c = 0; c < 8; ++c) {
            if (octants[size_t(c)].empty()) continue;
            const auto child = [&, c] {
                out->children[size_t(c)] =
                    build(octant_box(box, centre, c), std::move(octants[size_t(c)]), depth + 1,
                          bad_cuts + (bad ? 1 : 0));
            };
            if (parallel)
                tasks.run(child);
            else
                child();
        }
        tasks.wait();
        return out;
    }

private:
    static bool cut_pays(const Aabb& box, glm::vec3 centre, size_t n,
                         const std::array<std::vector<uint32_t>, 8>& octants) {
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

/// Lays `node` out at `index`, its children's group at the end of the nodes.
void flatten(const BuildNode& node, uint32_t index, uint32_t depth, Octree& tree) {
    OctreeStats& s = tree.stats;
    s.max_depth = std::max(s.max_depth, depth);
    if (node.leaf) {
        OctreeNode& leaf = tree.nodes[index];
        leaf.first = uint32_t(tree.references.size());
        leaf.count = uint32_t(node.references.size());
        tree.references.insert(tree.references.end(), node.references.begin(),
                               node.references.end());
        ++s.leaves;
        s.max_leaf_triangles = std::max(s.max_leaf_triangles, leaf.count);
        return;
    }
    ++s.interior;
    const auto group = uint32_t(tree.nodes.size());
    tree.nodes.resize(tree.nodes.size() + 8);
    uint8_t occupied = 0;
    for (uint32_t c = 0; c < 8; ++c) {
        if (!node.children[c]) continue;
        occupied |= uint8_t(1u << c);
        flatten(*node.children[c], group + c, depth + 1, tree);
    }
    OctreeNode& interior = tree.nodes[index];
    interior.leaf = false;
    interior.centre = {node.centre.x, node.centre.y, node.centre.z};
    interior.first_child = group;
    interior.occupied = occupied;
}

}  // namespace

Octree build_octree(std::span<const Triangle> triangles, const OctreeConfig& config) {
    if (config.max_depth > kOctreeMaxDepth)
        throw std::invalid_argument(fmt::format("octree: max_depth must be in 1..{}, got {}",
                                                kOctreeMaxDepth, config.max_depth));
    Octree tree;
    tree.bounds = padded_cells_box(triangles, "octree");
    tree.stats.depth_limit = config.max_depth != 0 ? config.max_depth : kOctreeMaxDepth;
    std::vector<uint32_t> all(triangles.size());
    for (uint32_t i = 0; i < all.size(); ++i)
        all[i] = i;
    const std::unique_ptr<BuildNode> root =
        Builder(triangles, tree.stats.depth_limit).build(tree.bounds, std::move(all), 0, 0);
    // The root alone in the first group, so that every group of siblings starts on a line.
    tree.nodes.resize(8);
    flatten(*root, 0, 0, tree);
    tree.stats.nodes = uint32_t(tree.nodes.size());
    tree.stats.references = tree.references.size();
    return tree;
}

}  // namespace tpsim::scene
