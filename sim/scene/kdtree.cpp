#include "sim/scene/kdtree.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>
#include <oneapi/tbb/parallel_invoke.h>
#include <oneapi/tbb/scalable_allocator.h>

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

/// A box cut by planes n.x = split of one orientation, for every split the builder tries on it.
/// The orientations' components are 0 or +-1, so each half's bounding box has a closed form:
/// the half below reaches along an axis a with n_a = +1 from lo_a to lo_a + (split - m), m the
/// least n.x over the box (from hi_a down to hi_a - (split - m) where n_a = -1), and the half
/// above likewise from the greatest n.x. Each half is exact for an axis; for a diagonal, it is
/// rounded outwards.
class BoxCut {
public:
    BoxCut(const Aabb& box, uint32_t direction)
        : box_(box), direction_(direction),
          extent_(glm::max(glm::dvec3(box.hi) - glm::dvec3(box.lo), glm::dvec3(0))),
          area_(surface(extent_)) {
        std::tie(least_, greatest_) = project(direction, box);
    }

    /// The part below the plane (n.x <= split) and the part above.
    std::pair<Aabb, Aabb> halves(float split) const {
        Aabb below = box_, above = box_;
        if (direction_ < 3) {
            below.hi[int(direction_)] = split;
            above.lo[int(direction_)] = split;
            return {below, above};
        }
        const auto& n = trax::layout::kBspDirection[direction_];
        const glm::dvec3 lo(box_.lo), hi(box_.hi);
        glm::dvec3 below_lo = lo, below_hi = hi, above_lo = lo, above_hi = hi;
        const double reach_below = double(split) - least_, reach_above = greatest_ - double(split);
        for (int a = 0; a < 3; ++a) {
            if (n[a] > 0) {
                below_hi[a] = lo[a] + reach_below;
                above_lo[a] = hi[a] - reach_above;
            } else if (n[a] < 0) {
                below_lo[a] = hi[a] - reach_below;
                above_hi[a] = lo[a] + reach_above;
            }
        }
        // Nothing on a side (a plane the heuristic does not choose) leaves that side the box.
        return {reach_below >= 0 ? rounded_out(below_lo, below_hi) : box_,
                reach_above >= 0 ? rounded_out(above_lo, above_hi) : box_};
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
    /// The box from lo to hi rounded outwards to floats, within the cut box.
    Aabb rounded_out(const glm::dvec3& lo, const glm::dvec3& hi) const {
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
    double least_ = 0, greatest_ = 0;  ///< n.x over the box
};

/// Triangle indices. Each level of the build makes new lists for both sides of its planes and
/// frees the parent's: oneTBB's allocator keeps the freed memory for the next lists, where
/// malloc would return large ones to the kernel and fault in zeroed pages again.
using References = std::vector<uint32_t, tbb::scalable_allocator<uint32_t>>;

/// Part of the tree laid out depth-first, as the kernel walks it, with node and reference
/// indices of its own from 0.
struct Subtree {
    std::vector<KdNode> nodes;
    References references;
};

/// The top of the tree, whose halves are built in parallel. A node of at most
/// kParallelReferences references has its whole subtree built on one thread straight into its
/// layout: the millions of nodes below are never allocated one by one.
struct TopNode {
    int axis = -1;  ///< -1: `subtree` holds the node's subtree
    float split = 0;
    std::unique_ptr<TopNode> below, above;
    Subtree subtree;
};

class Builder {
public:
    Builder(std::span<const Triangle> triangles, uint32_t depth_limit, double max_per_triangle,
            uint32_t directions, const char* name)
        : name_(name), depth_limit_(depth_limit),
          max_references_(uint64_t(max_per_triangle * double(triangles.size()))),
          max_per_triangle_(max_per_triangle), directions_(directions), triangles_(triangles),
          ranges_(triangles.size() * directions) {
        for (size_t i = 0; i < triangles.size(); ++i)
            for (uint32_t k = 0; k < directions; ++k) {
                const auto [lo, hi] = exact_range(uint32_t(i), k);
                ranges_[i * directions + k] = {float(lo), float(hi)};
            }
    }

    std::unique_ptr<TopNode> build(const Aabb& box, References refs, uint32_t depth,
                                   uint32_t bad_cuts) const {
        auto out = std::make_unique<TopNode>();
        if (refs.size() <= kParallelReferences) {
            build(box, std::move(refs), depth, bad_cuts, out->subtree);
            check_references(references_ += out->subtree.references.size());
            return out;
        }
        Cut cut = choose_cut(box, refs, depth, bad_cuts);
        if (cut.axis < 0) {
            check_references(references_ += refs.size());
            out->subtree.nodes.push_back({.first = 0, .count = uint32_t(refs.size())});
            out->subtree.references = std::move(refs);
            return out;
        }
        out->axis = cut.axis;
        out->split = cut.split;
        const uint32_t below_cuts = bad_cuts + cut.bad;
        tbb::parallel_invoke(
            [&] { out->below = build(cut.below_box, std::move(cut.below), depth + 1, below_cuts); },
            [&] {
                out->above = build(cut.above_box, std::move(cut.above), depth + 1, below_cuts);
            });
        return out;
    }

private:
    /// Triangle t's range of n.x for orientation k, in double (exact for the axes).
    std::pair<double, double> exact_range(uint32_t t, uint32_t k) const {
        const Triangle& tri = triangles_[t];
        const double a = project(k, tri.v0), b = project(k, tri.v1), c = project(k, tri.v2);
        return {std::min({a, b, c}), std::max({a, b, c})};
    }

    /// Refuses the build as soon as the leaves hold too many references, before they fill the
    /// memory.
    void check_references(uint64_t total) const {
        if (total > max_references_)
            throw std::invalid_argument(fmt::format(
                "{}: more than {} leaf references, {:g} per triangle, the limit: the scene's "
                "triangles reach across many leaves; use a BVH (--accel bvh2), which references "
                "each triangle once",
                name_, max_references_, max_per_triangle_));
    }

    /// A node's choice: a leaf (axis -1), or a plane and what lies on each side of it.
    struct Cut {
        int axis = -1;
        float split = 0;
        bool bad = false;
        References below, above;
        Aabb below_box, above_box;
    };

    /// Builds `refs`' subtree on this thread at the end of `out`.
    void build(const Aabb& box, References refs, uint32_t depth, uint32_t bad_cuts,
               Subtree& out) const {
        const size_t index = out.nodes.size();
        out.nodes.emplace_back();
        Cut cut = choose_cut(box, refs, depth, bad_cuts);
        if (cut.axis < 0) {
            KdNode& leaf = out.nodes[index];
            leaf.first = uint32_t(out.references.size());
            leaf.count = uint32_t(refs.size());
            out.references.insert(out.references.end(), refs.begin(), refs.end());
            // The subtree's references join the total when it is done (one thread's
            // additions to a shared count would stall the other's).
            check_references(references_.load(std::memory_order_relaxed) + out.references.size());
            return;
        }
        const uint32_t below_cuts = bad_cuts + cut.bad;
        build(cut.below_box, std::move(cut.below), depth + 1, below_cuts, out);
        const auto right = uint32_t(out.nodes.size());
        build(cut.above_box, std::move(cut.above), depth + 1, below_cuts, out);
        KdNode& interior = out.nodes[index];
        interior.axis = uint32_t(cut.axis);
        interior.split = cut.split;
        interior.right_child = right;
    }

    /// The heuristic's plane for the node of `refs` and its sides (freeing `refs`), or a leaf
    /// (leaving `refs` as they are).
    Cut choose_cut(const Aabb& box, References& refs, uint32_t depth, uint32_t bad_cuts) const {
        const auto [axis, split, binned_below, binned_above] = choose_split(box, refs, depth);
        Cut out;
        const BoxCut box_cut(box, uint32_t(std::max(axis, 0)));
        if (axis >= 0) {
            const auto k = uint32_t(axis);
            const glm::vec3 extent = box.hi - box.lo;
            const auto [lo, hi] = project(k, box);
            const float width = k < 3 ? extent[axis] : float(hi - lo);
            const float margin = width * kKdMargin + std::abs(split) * 0x1p-20f;
            // The margin adds the few triangles near the plane to the binned counts.
            out.below.reserve(binned_below + binned_below / 16 + 16);
            out.above.reserve(binned_above + binned_above / 16 + 16);
            // Rounding to the nearest float keeps order, so the rounded range decides against
            // a float bound unless it equals the bound; the exact range decides that tie.
            const float below_bound = split + margin, above_bound = split - margin;
            for (uint32_t r : refs) {
                const Range& range = ranges_[r * directions_ + k];
                if (range.lo < below_bound ||
                    (range.lo == below_bound && exact_range(r, k).first <= double(below_bound)))
                    out.below.push_back(r);
                if (range.hi > above_bound ||
                    (range.hi == above_bound && exact_range(r, k).second >= double(above_bound)))
                    out.above.push_back(r);
            }
        }
        const size_t nl = out.below.size(), nr = out.above.size();
        // A BSP split that leaves one side with every triangle and still gives the other some is
        // a bad cut (one that cuts off empty space is not); past kMaxBadCuts on a path the node
        // stays a leaf (the kd-tree builds without this limit).
        out.bad = directions_ > 3 && nl != 0 && nr != 0 && (nl == refs.size() || nr == refs.size());
        // The margin puts triangles on or near the plane on both sides, which the binned cost
        // did not count: a split that then costs more than the leaf (or moves nothing) is none.
        if (axis < 0 || (out.bad && bad_cuts == kMaxBadCuts) ||
            split_cost(box_cut, axis, split, nl, nr) >= kIntersectionCost * double(refs.size()))
            return {};
        refs = {};
        std::tie(out.below_box, out.above_box) = box_cut.halves(split);
        out.axis = axis;
        out.split = split;
        return out;
    }

    /// A plane the heuristic chose (axis -1: a leaf costs less), and the triangles its bins
    /// put on each side.
    struct Split {
        int axis = -1;
        float split = 0;
        uint32_t left = 0, right = 0;
    };

    /// One orientation's bins over a node: bin b holds n.x in [lo + b w, lo + (b + 1) w),
    /// w = extent / kBins, by the quotient (x - lo) / extent * kBins.
    struct Bins {
        double lo, hi, extent, scale;  ///< scale: kBins / extent
        std::array<uint32_t, kBins> starts, ends;

        int bin(float x) const {
            // A product is cheaper than the quotient and rounds to the same bin unless the two
            // fall either side of a bin edge: a product within 1e-6 of one takes the quotient.
            const double t = (double(x) - lo) * scale, whole = std::floor(t);
            const double b = t - whole > 1e-6 && t - whole < 1 - 1e-6
                                 ? whole
                                 : std::floor((double(x) - lo) / extent * kBins);
            return int(std::clamp(b, 0.0, double(kBins - 1)));
        }
    };

    /// The SAH's best plane over kBins bins per orientation.
    Split choose_split(const Aabb& box, const References& refs, uint32_t depth) const {
        const double n = double(refs.size());
        if (refs.size() <= 1 || depth >= depth_limit_) return {};
        const double box_area = area(box.lo, box.hi);
        if (box_area <= 0) return {};
        // Every orientation's bins in one pass over the references, which touches each
        // triangle's ranges once. Most nodes are small: only the bins used are cleared.
        std::array<Bins, kBspPlaneDirections> bins;
        std::array<uint32_t, kBspPlaneDirections> binned;
        uint32_t orientations = 0;
        for (uint32_t k = 0; k < directions_; ++k) {
            Bins& b = bins[orientations];
            std::tie(b.lo, b.hi) = project(k, box);
            b.extent = b.hi - b.lo;
            if (!(b.extent > 0)) continue;
            b.scale = kBins / b.extent;
            b.starts.fill(0);
            b.ends.fill(0);
            binned[orientations++] = k;
        }
        for (uint32_t r : refs) {
            const Range* range = &ranges_[r * directions_];
            for (uint32_t o = 0; o < orientations; ++o) {
                Bins& b = bins[o];
                const Range& x = range[binned[o]];
                ++b.starts[size_t(b.bin(x.lo))];
                ++b.ends[size_t(b.bin(x.hi))];
            }
        }
        double best_cost = kIntersectionCost * n;
        Split best;
        for (uint32_t o = 0; o < orientations; ++o) {
            const uint32_t k = binned[o];
            const int axis = int(k);
            const Bins& b = bins[o];
            const double lo = b.lo, hi = b.hi, extent = b.extent;
            const BoxCut cut(box, k);
            // Plane b lies between bins b - 1 and b: the triangles starting before it reach
            // left, those ending at or after it reach right.
            std::array<uint32_t, kBins> right_count;  // [1, kBins)
            uint32_t sum = 0;
            for (int p = kBins - 1; p >= 1; --p) {
                sum += b.ends[size_t(p)];
                right_count[size_t(p)] = sum;
            }
            const auto split_at = [&](int p) { return float(lo + extent * p / kBins); };
            // A diagonal plane's price clips the box, so most are bounded first: the half below
            // only grows with the split and the half above only shrinks, so the areas at the
            // priced planes around p bound p's from below (a little less, for the rounding).
            // A plane whose bound is not below the best so far cannot become the best: the
            // choice is the one pricing every plane gives.
            std::array<std::pair<double, double>, kBins> priced{};  // (0, 0): no bound
            if (k >= 3)
                for (int p = 1; p < kBins + kPricedEvery - 1; p += kPricedEvery) {
                    const int q = std::min(p, kBins - 1);  // ... and the last plane
                    const float split = split_at(q);
                    if (split > lo && split < hi) priced[size_t(q)] = cut.half_areas(split);
                }
            const auto valid = [&](int p) {
                const float split = split_at(p);
                return split > lo && split < hi;
            };
            // Planes p - 1 and p have the same counts when no triangle starts or ends in bin
            // p - 1. Along such a run an axis plane's cost is linear in the split, rising by
            // (nl - nr) times the cross-section's perimeter (in the halves' areas, which round
            // monotonically): with nl > nr only the run's first valid plane can be the best,
            // with nl < nr only its last; with nl == nr every plane is priced.
            const auto same_counts = [&](int p) {  // planes p - 1 and p
                return b.starts[size_t(p - 1)] == 0 && b.ends[size_t(p - 1)] == 0;
            };
            uint32_t left_count = 0;
            for (int p = 1; p < kBins; ++p) {
                left_count += b.starts[size_t(p - 1)];
                const float split = split_at(p);
                if (!(split > lo && split < hi)) continue;
                const uint32_t nl = left_count, nr = right_count[size_t(p)];
                if (k < 3 && ((nl > nr && p > 1 && same_counts(p) && valid(p - 1)) ||
                              (nl < nr && p + 1 < kBins && same_counts(p + 1) && valid(p + 1))))
                    continue;
                if (k >= 3 && (nl == 0 || nr == 0)) continue;  // split_cost: infinite
                double cost;
                if (k >= 3 && (p - 1) % kPricedEvery == 0) {
                    cost = sah_cost(priced[size_t(p)].first, priced[size_t(p)].second, box_area, nl,
                                    nr);
                } else if (k >= 3) {
                    const int below = p - (p - 1) % kPricedEvery;
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
                    best = {axis, split, nl, nr};
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
    std::span<const Triangle> triangles_;
    /// Each triangle's range of n.x rounded to the nearest floats, directions_ per triangle:
    /// the bins take floats, and half the bytes of doubles are half the memory traffic.
    struct Range {
        float lo, hi;
    };
    std::vector<Range> ranges_;
    mutable std::atomic<uint64_t> references_{0};
};

/// The nodes and references of `node`'s tree.
std::pair<size_t, size_t> sizes(const TopNode& node) {
    if (node.axis < 0) return {node.subtree.nodes.size(), node.subtree.references.size()};
    const auto [below_nodes, below_refs] = sizes(*node.below);
    const auto [above_nodes, above_refs] = sizes(*node.above);
    return {1 + below_nodes + above_nodes, below_refs + above_refs};
}

/// Lays `node`'s tree out depth-first at the end of the tree's nodes and references, freeing
/// its subtrees as it goes.
void lay_out(TopNode& node, KdTree& tree) {
    if (node.axis < 0) {
        const auto node_base = uint32_t(tree.nodes.size());
        const auto reference_base = uint32_t(tree.references.size());
        for (KdNode n : node.subtree.nodes) {
            (n.is_leaf() ? n.first : n.right_child) += n.is_leaf() ? reference_base : node_base;
            tree.nodes.push_back(n);
        }
        tree.references.insert(tree.references.end(), node.subtree.references.begin(),
                               node.subtree.references.end());
        node.subtree = {};
        return;
    }
    const size_t index = tree.nodes.size();
    tree.nodes.emplace_back();
    lay_out(*node.below, tree);
    const auto right = uint32_t(tree.nodes.size());
    lay_out(*node.above, tree);
    KdNode& interior = tree.nodes[index];
    interior.axis = uint32_t(node.axis);
    interior.split = node.split;
    interior.right_child = right;
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
    References all(triangles.size());
    for (uint32_t i = 0; i < all.size(); ++i)
        all[i] = i;
    const std::unique_ptr<TopNode> root =
        Builder(triangles, limit, config.max_references_per_triangle,
                config.general_planes ? kBspPlaneDirections : 3, name)
            .build(tree.bounds, std::move(all), 0, 0);
    const auto [nodes, references] = sizes(*root);
    tree.nodes.reserve(nodes);
    tree.references.reserve(references);
    lay_out(*root, tree);
    fill_stats(tree);
    return tree;
}

}  // namespace tpsim::scene
