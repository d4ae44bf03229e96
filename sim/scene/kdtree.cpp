#include "sim/scene/kdtree.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>
#include <oneapi/tbb/parallel_invoke.h>

#include "sim/scene/cells.hpp"

namespace tpsim::scene {

namespace {

constexpr int kBins = 32;
constexpr double kTraversalCost = 15, kIntersectionCost = 20, kEmptyBonus = 0.8;
/// Subtrees with fewer references than this are built on the calling thread.
constexpr size_t kParallelReferences = 4096;

double area(const glm::vec3& lo, const glm::vec3& hi) {
    const glm::dvec3 d = glm::max(glm::dvec3(hi) - glm::dvec3(lo), glm::dvec3(0));
    return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

/// A node as the build makes it, before the tree is laid out depth-first (once, at the end).
struct BuildNode {
    int axis = -1;  ///< -1: a leaf
    float split = 0;
    std::unique_ptr<BuildNode> below, above;
    std::vector<uint32_t> references;  ///< leaf only
};

class Builder {
public:
    Builder(std::span<const Triangle> triangles, uint32_t depth_limit, double max_per_triangle)
        : depth_limit_(depth_limit),
          max_references_(uint64_t(max_per_triangle * double(triangles.size()))),
          max_per_triangle_(max_per_triangle), lo_(triangles.size()), hi_(triangles.size()) {
        for (size_t i = 0; i < triangles.size(); ++i) {
            const Triangle& t = triangles[i];
            lo_[i] = glm::min(t.v0, glm::min(t.v1, t.v2));
            hi_[i] = glm::max(t.v0, glm::max(t.v1, t.v2));
        }
    }

    std::unique_ptr<BuildNode> build(const Aabb& box, std::vector<uint32_t> refs,
                                     uint32_t depth) const {
        auto out = std::make_unique<BuildNode>();
        const auto [axis, split] = choose_split(box, refs, depth);
        std::vector<uint32_t> left, right;
        if (axis >= 0) {
            const glm::vec3 extent = box.hi - box.lo;
            const float margin = extent[axis] * kKdMargin + std::abs(split) * 0x1p-20f;
            for (uint32_t r : refs) {
                if (lo_[r][axis] <= split + margin) left.push_back(r);
                if (hi_[r][axis] >= split - margin) right.push_back(r);
            }
        }
        // The margin puts triangles on or near the plane on both sides, which the binned cost
        // did not count: a split that then costs more than the leaf (or moves nothing) is none.
        if (axis < 0 || split_cost(box, axis, split, left.size(), right.size()) >=
                            kIntersectionCost * double(refs.size())) {
            // Refused as soon as the leaves hold too many, before they fill the memory.
            const uint64_t total = references_ += refs.size();
            if (total > max_references_)
                throw std::invalid_argument(fmt::format(
                    "kd-tree: more than {} leaf references, {:g} per triangle, the limit: the "
                    "scene's triangles reach across many leaves; use a BVH (--accel bvh2), "
                    "which references each triangle once",
                    max_references_, max_per_triangle_));
            out->references = std::move(refs);
            return out;
        }
        refs = {};
        Aabb left_box = box, right_box = box;
        left_box.hi[axis] = split;
        right_box.lo[axis] = split;
        out->axis = axis;
        out->split = split;
        if (left.size() + right.size() > kParallelReferences)
            tbb::parallel_invoke(
                [&] { out->below = build(left_box, std::move(left), depth + 1); },
                [&] { out->above = build(right_box, std::move(right), depth + 1); });
        else {
            out->below = build(left_box, std::move(left), depth + 1);
            out->above = build(right_box, std::move(right), depth + 1);
        }
        return out;
    }

private:
    /// The SAH's best plane over kBins bins per axis, or axis -1 when a leaf costs less.
    std::pair<int, float> choose_split(const Aabb& box, const std::vector<uint32_t>& refs,
                                       uint32_t depth) const {
        const double n = double(refs.size());
        if (refs.size() <= 1 || depth >= depth_limit_) return {-1, 0.f};
        const double box_area = area(box.lo, box.hi);
        double best_cost = kIntersectionCost * n;
        std::pair<int, float> best{-1, 0.f};
        for (int axis = 0; axis < 3; ++axis) {
            const double lo = box.lo[axis], extent = double(box.hi[axis]) - lo;
            if (!(extent > 0) || box_area <= 0) continue;
            std::array<uint32_t, kBins> starts{}, ends{};
            const auto bin = [&](float x) {
                return int(std::clamp(std::floor((double(x) - lo) / extent * kBins), 0.0,
                                      double(kBins - 1)));
            };
            for (uint32_t r : refs) {
                ++starts[size_t(bin(lo_[r][axis]))];
                ++ends[size_t(bin(hi_[r][axis]))];
            }
            // Plane b lies between bins b - 1 and b: the triangles starting before it reach
            // left, those ending at or after it reach right.
            std::array<uint32_t, kBins> right_count{};
            uint32_t sum = 0;
            for (int b = kBins - 1; b >= 1; --b) {
                sum += ends[size_t(b)];
                right_count[size_t(b)] = sum;
            }
            uint32_t left_count = 0;
            for (int b = 1; b < kBins; ++b) {
                left_count += starts[size_t(b - 1)];
                const float split = float(lo + extent * b / kBins);
                if (!(split > box.lo[axis] && split < box.hi[axis])) continue;
                const double cost =
                    split_cost(box, axis, split, left_count, right_count[size_t(b)]);
                if (cost < best_cost) {
                    best_cost = cost;
                    best = {axis, split};
                }
            }
        }
        return best;
    }

    /// The SAH cost of splitting `box` at `split` with nl and nr triangles on the two sides.
    static double split_cost(const Aabb& box, int axis, float split, size_t nl, size_t nr) {
        glm::vec3 left_hi = box.hi, right_lo = box.lo;
        left_hi[axis] = split;
        right_lo[axis] = split;
        const double cost = kTraversalCost + kIntersectionCost *
                                                 (area(box.lo, left_hi) * double(nl) +
                                                  area(right_lo, box.hi) * double(nr)) /
                                                 area(box.lo, box.hi);
        return nl == 0 || nr == 0 ? cost * kEmptyBonus : cost;
    }

    uint32_t depth_limit_;
    uint64_t max_references_;
    double max_per_triangle_;
    std::vector<glm::vec3> lo_, hi_;
    mutable std::atomic<uint64_t> references_{0};
};

/// Lays `node`'s subtree out depth-first at the end of the tree's nodes and references.
void flatten(const BuildNode& node, KdTree& tree) {
    const size_t index = tree.nodes.size();
    tree.nodes.emplace_back();
    if (node.axis < 0) {
        KdNode& leaf = tree.nodes[index];
        leaf.first = uint32_t(tree.references.size());
        leaf.count = uint32_t(node.references.size());
        tree.references.insert(tree.references.end(), node.references.begin(),
                               node.references.end());
        return;
    }
    flatten(*node.below, tree);
    const auto right = uint32_t(tree.nodes.size());
    flatten(*node.above, tree);
    KdNode& interior = tree.nodes[index];
    interior.axis = uint32_t(node.axis);
    interior.split = node.split;
    interior.right_child = right;
}

uint64_t references_of(const BuildNode& node) {
    return node.axis < 0 ? node.references.size()
                         : references_of(*node.below) + references_of(*node.above);
}

void fill_stats(KdTree& tree) {
    KdTreeStats& s = tree.stats;
    s.nodes = uint32_t(tree.nodes.size());
    s.references = tree.references.size();
    std::vector<std::pair<uint32_t, uint32_t>> pending{{0, 0}};  // (node, depth)
    while (!pending.empty()) {
        const auto [index, depth] = pending.back();
        pending.pop_back();
        const KdNode& node = tree.nodes[index];
        if (node.is_leaf()) {
            ++s.leaves;
            s.empty_leaves += node.count == 0;
            s.max_leaf_triangles = std::max(s.max_leaf_triangles, node.count);
            s.max_depth = std::max(s.max_depth, depth);
        } else {
            pending.push_back({node.right_child, depth + 1});
            pending.push_back({index + 1, depth + 1});
        }
    }
}

}  // namespace

KdTree build_kdtree(std::span<const Triangle> triangles, const KdTreeConfig& config) {
    if (!(config.max_references_per_triangle >= 1))
        throw std::invalid_argument(
            fmt::format("kd-tree: max_references_per_triangle must be >= 1, got {}",
                        config.max_references_per_triangle));
    if (config.max_depth > kKdMaxDepth)
        throw std::invalid_argument(fmt::format("kd-tree: max_depth must be in 1..{}, got {}",
                                                kKdMaxDepth, config.max_depth));
    KdTree tree;
    tree.bounds = padded_cells_box(triangles, "kd-tree");
    const uint32_t limit =
        config.max_depth != 0
            ? config.max_depth
            : std::min(kKdMaxDepth, uint32_t(8 + 1.3 * std::log2(double(triangles.size())) + 0.5));
    tree.stats.depth_limit = limit;
    std::vector<uint32_t> all(triangles.size());
    for (uint32_t i = 0; i < all.size(); ++i)
        all[i] = i;
    const std::unique_ptr<BuildNode> root =
        Builder(triangles, limit, config.max_references_per_triangle)
            .build(tree.bounds, std::move(all), 0);
    tree.references.reserve(references_of(*root));
    flatten(*root, tree);
    fill_stats(tree);
    return tree;
}

}  // namespace tpsim::scene
