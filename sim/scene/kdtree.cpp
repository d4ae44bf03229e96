#include "sim/scene/kdtree.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
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
/// BSP splits on one path that left one side with all of the node's triangles: past this many
/// the node stays a leaf. Around a vertex where many triangles meet no plane separates them,
/// yet, cells measured by boxes, each cut pays by the heuristic (the octree's rule; pbrt's
/// kd-tree limits its "bad refines" the same way).
constexpr uint32_t kMaxBadCuts = 2;
/// Subtrees with fewer references than this are built on the calling thread.
constexpr size_t kParallelReferences = 4096;
/// A BSP node prices every kPricedEvery-th diagonal plane first and bounds the others from them
/// (Builder::choose_split); the bound is lowered by kBoundSlack for the rounding of the boxes.
constexpr int kPricedEvery = 8;
constexpr double kBoundSlack = 1 - 1e-5;

/// The surface area of a box of extent d.
double surface(const glm::dvec3& d) {
    return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

double area(const glm::vec3& lo, const glm::vec3& hi) {
    return surface(glm::max(glm::dvec3(hi) - glm::dvec3(lo), glm::dvec3(0)));
}

/// n.p for the plane orientation n = kBspDirection[direction], in double (exact for the axes).
double project(uint32_t direction, const glm::dvec3& p) {
    const auto& n = trax::layout::kBspDirection[direction];
    return double(n[0]) * p.x + double(n[1]) * p.y + double(n[2]) * p.z;
}

/// The range of n.x over `box` for orientation `direction`.
std::pair<double, double> project(uint32_t direction, const Aabb& box) {
    if (direction < 3) return {box.lo[int(direction)], box.hi[int(direction)]};
    const auto& n = trax::layout::kBspDirection[direction];
    double lo = 0, hi = 0;
    for (int a = 0; a < 3; ++a) {
        lo += n[a] * double(n[a] > 0 ? box.lo[a] : box.hi[a]);
        hi += n[a] * double(n[a] > 0 ? box.hi[a] : box.lo[a]);
    }
    return {lo, hi};
}

/// The next float below (above) x, as std::nextafter(x, -inf) (+inf) gives it for a finite x,
/// without the library call: the builder rounds millions of clipped boxes outwards.
float next_down(float x) {
    if (x == 0) return -std::numeric_limits<float>::denorm_min();
    const auto bits = std::bit_cast<uint32_t>(x);
    return std::bit_cast<float>(x > 0 ? bits - 1 : bits + 1);
}
float next_up(float x) {
    return -next_down(-x);
}

/// A box cut by planes n.x = split of one orientation, for every split the builder tries on it:
/// the corners and their n.x are worked out once. Each half is exact for an axis; for a
/// diagonal, it is the box of the corners on its side and the edge crossings, rounded outwards.
class BoxCut {
public:
    BoxCut(const Aabb& box, uint32_t direction)
        : box_(box), direction_(direction),
          extent_(glm::max(glm::dvec3(box.hi) - glm::dvec3(box.lo), glm::dvec3(0))),
          area_(surface(extent_)) {
        if (direction < 3) return;
        for (int c = 0; c < 8; ++c) {
            corner_[size_t(c)] =
                glm::dvec3(c & 1 ? box.hi.x : box.lo.x, c & 2 ? box.hi.y : box.lo.y,
                           c & 4 ? box.hi.z : box.lo.z);
            n_dot_[size_t(c)] = project(direction, corner_[size_t(c)]);
        }
    }

    /// The part below the plane (n.x <= split) and the part above.
    std::pair<Aabb, Aabb> halves(float split) const {
        Aabb below = box_, above = box_;
        if (direction_ < 3) {
            below.hi[int(direction_)] = split;
            above.lo[int(direction_)] = split;
            return {below, above};
        }
        const glm::dvec3 none(std::numeric_limits<double>::infinity());
        glm::dvec3 below_lo = none, below_hi = -none, above_lo = none, above_hi = -none;
        const auto keep = [](glm::dvec3& lo, glm::dvec3& hi, const glm::dvec3& p) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        };
        for (size_t c = 0; c < 8; ++c) {
            const glm::dvec3& p = corner_[c];
            const double sp = n_dot_[c] - double(split);
            if (sp <= 0) keep(below_lo, below_hi, p);
            if (sp >= 0) keep(above_lo, above_hi, p);
            for (size_t a = 0; a < 3; ++a) {  // the edge from corner c along axis a, once
                if (c >> a & 1) continue;
                const size_t q = c | size_t(1) << a;
                const double sq = n_dot_[q] - double(split);
                if ((sp < 0) == (sq < 0)) continue;
                const glm::dvec3 crossing = p + (corner_[q] - p) * (sp / (sp - sq));
                keep(below_lo, below_hi, crossing);
                keep(above_lo, above_hi, crossing);
            }
        }
        return {rounded_out(below_lo, below_hi), rounded_out(above_lo, above_hi)};
    }

    /// The surface areas of the two halves, as area() of halves() gives them; for an axis,
    /// without making the boxes (the kd-tree prices millions of planes).
    std::pair<double, double> half_areas(float split) const {
        if (direction_ >= 3) {
            const auto [below, above] = halves(split);
            return {area(below.lo, below.hi), area(above.lo, above.hi)};
        }
        const int a = int(direction_);
        glm::dvec3 below = extent_, above = extent_;
        below[a] = std::max(double(split) - double(box_.lo[a]), 0.0);
        above[a] = std::max(double(box_.hi[a]) - double(split), 0.0);
        return {surface(below), surface(above)};
    }

    double box_area() const { return area_; }

private:
    Aabb rounded_out(const glm::dvec3& lo, const glm::dvec3& hi) const {
        if (!(lo.x <= hi.x)) return box_;  // nothing on that side (not chosen by the heuristic)
        Aabb out;
        for (int a = 0; a < 3; ++a) {
            out.lo[a] = std::max(box_.lo[a], next_down(float(lo[a])));
            out.hi[a] = std::min(box_.hi[a], next_up(float(hi[a])));
        }
        return out;
    }

    Aabb box_;
    uint32_t direction_;
    glm::dvec3 extent_;
    double area_;
    std::array<glm::dvec3, 8> corner_{};
    std::array<double, 8> n_dot_{};
};

/// A node as the build makes it, before the tree is laid out depth-first (once, at the end).
struct BuildNode {
    int axis = -1;  ///< -1: a leaf
    float split = 0;
    std::unique_ptr<BuildNode> below, above;
    std::vector<uint32_t> references;  ///< leaf only
};

class Builder {
public:
    Builder(std::span<const Triangle> triangles, uint32_t depth_limit, double max_per_triangle,
            uint32_t directions, const char* name)
        : name_(name), depth_limit_(depth_limit),
          max_references_(uint64_t(max_per_triangle * double(triangles.size()))),
          max_per_triangle_(max_per_triangle), directions_(directions),
          lo_(triangles.size() * directions), hi_(triangles.size() * directions) {
        for (size_t i = 0; i < triangles.size(); ++i) {
            const Triangle& t = triangles[i];
            for (uint32_t k = 0; k < directions; ++k) {
                const double a = project(k, t.v0), b = project(k, t.v1), c = project(k, t.v2);
                lo_[i * directions + k] = std::min({a, b, c});
                hi_[i * directions + k] = std::max({a, b, c});
            }
        }
    }

    std::unique_ptr<BuildNode> build(const Aabb& box, std::vector<uint32_t> refs, uint32_t depth,
                                     uint32_t bad_cuts) const {
        auto out = std::make_unique<BuildNode>();
        const auto [axis, split] = choose_split(box, refs, depth);
        std::vector<uint32_t> left, right;
        const BoxCut cut(box, uint32_t(std::max(axis, 0)));
        if (axis >= 0) {
            const auto k = uint32_t(axis);
            const glm::vec3 extent = box.hi - box.lo;
            const auto [lo, hi] = project(k, box);
            const float width = k < 3 ? extent[axis] : float(hi - lo);
            const float margin = width * kKdMargin + std::abs(split) * 0x1p-20f;
            for (uint32_t r : refs) {
                if (lo_[r * directions_ + k] <= double(split + margin)) left.push_back(r);
                if (hi_[r * directions_ + k] >= double(split - margin)) right.push_back(r);
            }
        }
        // A BSP split that leaves one side with every triangle and still gives the other some is
        // a bad cut (one that cuts off empty space is not); past kMaxBadCuts on a path the node
        // stays a leaf (the kd-tree builds without this limit).
        const bool bad = directions_ > 3 && !left.empty() && !right.empty() &&
                         (left.size() == refs.size() || right.size() == refs.size());
        // The margin puts triangles on or near the plane on both sides, which the binned cost
        // did not count: a split that then costs more than the leaf (or moves nothing) is none.
        if (axis < 0 || (bad && bad_cuts == kMaxBadCuts) ||
            split_cost(cut, axis, split, left.size(), right.size()) >=
                kIntersectionCost * double(refs.size())) {
            // Refused as soon as the leaves hold too many, before they fill the memory.
            const uint64_t total = references_ += refs.size();
            if (total > max_references_)
                throw std::invalid_argument(fmt::format(
                    "{}: more than {} leaf references, {:g} per triangle, the limit: the "
                    "scene's triangles reach across many leaves; use a BVH (--accel bvh2), "
                    "which references each triangle once",
                    name_, max_references_, max_per_triangle_));
            out->references = std::move(refs);
            return out;
        }
        refs = {};
        const auto [left_box, right_box] = cut.halves(split);
        out->axis = axis;
        out->split = split;
        if (left.size() + right.size() > kParallelReferences)
            tbb::parallel_invoke(
                [&] { out->below = build(left_box, std::move(left), depth + 1, bad_cuts + bad); },
                [&] {
                    out->above = build(right_box, std::move(right), depth + 1, bad_cuts + bad);
                });
        else {
            out->below = build(left_box, std::move(left), depth + 1, bad_cuts + bad);
            out->above = build(right_box, std::move(right), depth + 1, bad_cuts + bad);
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
        for (int axis = 0; axis < int(directions_); ++axis) {
            const auto k = uint32_t(axis);
            const auto [lo, hi] = project(k, box);
            const double extent = hi - lo;
            if (!(extent > 0) || box_area <= 0) continue;
            const BoxCut cut(box, k);
            std::array<uint32_t, kBins> starts{}, ends{};
            const auto bin = [&](float x) {
                return int(std::clamp(std::floor((double(x) - lo) / extent * kBins), 0.0,
                                      double(kBins - 1)));
            };
            for (uint32_t r : refs) {
                ++starts[size_t(bin(lo_[r * directions_ + k]))];
                ++ends[size_t(bin(hi_[r * directions_ + k]))];
            }
            // Plane b lies between bins b - 1 and b: the triangles starting before it reach
            // left, those ending at or after it reach right.
            std::array<uint32_t, kBins> right_count{};
            uint32_t sum = 0;
            for (int b = kBins - 1; b >= 1; --b) {
                sum += ends[size_t(b)];
                right_count[size_t(b)] = sum;
            }
            const auto split_at = [&](int b) { return float(lo + extent * b / kBins); };
            // A diagonal plane's price clips the box, so most are bounded first: the half below
            // only grows with the split and the half above only shrinks, so the areas at the
            // priced planes around b bound b's from below (a little less, for the rounding).
            // A plane whose bound is not below the best so far cannot become the best: the
            // choice is the one pricing every plane gives.
            std::array<std::pair<double, double>, kBins> priced{};  // (0, 0): no bound
            if (k >= 3)
                for (int b = 1; b < kBins + kPricedEvery - 1; b += kPricedEvery) {
                    const int p = std::min(b, kBins - 1);  // ... and the last plane
                    const float split = split_at(p);
                    if (split > lo && split < hi) priced[size_t(p)] = cut.half_areas(split);
                }
            uint32_t left_count = 0;
            for (int b = 1; b < kBins; ++b) {
                left_count += starts[size_t(b - 1)];
                const float split = split_at(b);
                if (!(split > lo && split < hi)) continue;
                const uint32_t nl = left_count, nr = right_count[size_t(b)];
                if (k >= 3 && (nl == 0 || nr == 0)) continue;  // split_cost: infinite
                double cost;
                if (k >= 3 && (b - 1) % kPricedEvery == 0) {
                    cost = sah_cost(priced[size_t(b)].first, priced[size_t(b)].second, box_area, nl,
                                    nr);
                } else if (k >= 3) {
                    const int below = b - (b - 1) % kPricedEvery;
                    const int above = std::min(below + kPricedEvery, kBins - 1);
                    const double bound =
                        sah_cost(priced[size_t(below)].first * kBoundSlack,
                                 priced[size_t(above)].second * kBoundSlack, box_area, nl, nr);
                    if (bound >= best_cost) continue;
                    cost = split_cost(cut, axis, split, nl, nr);
                } else {
                    cost = split_cost(cut, axis, split, nl, nr);
                }
                if (cost < best_cost) {
                    best_cost = cost;
                    best = {axis, split};
                }
            }
        }
        return best;
    }

    /// The SAH cost of splitting `box` at `split` with nl and nr triangles on the two sides.
    static double split_cost(const BoxCut& cut, int axis, float split, size_t nl, size_t nr) {
        // A diagonal plane that cuts off an empty corner leaves the other side's box as it was:
        // by boxes it would look free, and a chain of them would fill the depth with nothing.
        if (axis >= 3 && (nl == 0 || nr == 0)) return std::numeric_limits<double>::infinity();
        const auto [left, right] = cut.half_areas(split);
        return sah_cost(left, right, cut.box_area(), nl, nr);
    }

    static double sah_cost(double left_area, double right_area, double box_area, size_t nl,
                           size_t nr) {
        const double cost =
            kTraversalCost +
            kIntersectionCost * (left_area * double(nl) + right_area * double(nr)) / box_area;
        return nl == 0 || nr == 0 ? cost * kEmptyBonus : cost;
    }

    const char* name_;  ///< for messages: "kd-tree" or "BSP tree"
    uint32_t depth_limit_;
    uint64_t max_references_;
    double max_per_triangle_;
    uint32_t directions_;
    std::vector<double> lo_, hi_;  ///< each triangle's range of n.x, directions_ per triangle
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
            s.diagonal_planes += node.axis >= 3;
            pending.push_back({node.right_child, depth + 1});
            pending.push_back({index + 1, depth + 1});
        }
    }
}

}  // namespace

KdTree build_kdtree(std::span<const Triangle> triangles, const KdTreeConfig& config) {
    const char* name = config.general_planes ? "BSP tree" : "kd-tree";
    if (!(config.max_references_per_triangle >= 1))
        throw std::invalid_argument(
            fmt::format("{}: max_references_per_triangle must be >= 1, got {}", name,
                        config.max_references_per_triangle));
    if (config.max_depth > kKdMaxDepth)
        throw std::invalid_argument(fmt::format("{}: max_depth must be in 1..{}, got {}", name,
                                                kKdMaxDepth, config.max_depth));
    KdTree tree;
    tree.general_planes = config.general_planes;
    tree.bounds = padded_cells_box(triangles, name);
    const uint32_t limit =
        config.max_depth != 0
            ? config.max_depth
            : std::min(kKdMaxDepth, uint32_t(8 + 1.3 * std::log2(double(triangles.size())) + 0.5));
    tree.stats.depth_limit = limit;
    std::vector<uint32_t> all(triangles.size());
    for (uint32_t i = 0; i < all.size(); ++i)
        all[i] = i;
    const std::unique_ptr<BuildNode> root =
        Builder(triangles, limit, config.max_references_per_triangle,
                config.general_planes ? kBspPlaneDirections : 3, name)
            .build(tree.bounds, std::move(all), 0, 0);
    tree.references.reserve(references_of(*root));
    flatten(*root, tree);
    fill_stats(tree);
    return tree;
}

}  // namespace tpsim::scene
