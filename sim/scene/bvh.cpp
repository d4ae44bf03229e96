#include "sim/scene/bvh.hpp"

#include "sim/core/huge_pages.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_invoke.h>

namespace tpsim::scene {

namespace {

/// The one definition of a box's surface area (empty boxes have none), inlined in the sweeps.
inline float surface_area(const glm::vec3& lo, const glm::vec3& hi) {
    const glm::vec3 d = glm::max(hi - lo, glm::vec3(0.f));
    return 2.f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

}  // namespace

float Aabb::surface_area() const {
    return scene::surface_area(lo, hi);
}

bool Aabb::contains(const Aabb& inner) const {
    return glm::all(glm::lessThanEqual(lo, inner.lo)) && glm::all(glm::lessThanEqual(inner.hi, hi));
}

const char* to_string(BvhBuilder builder) {
    return builder == BvhBuilder::binned  ? "binned"
           : builder == BvhBuilder::sweep ? "sweep"
                                          : "median";
}

namespace {

/// The names of every value in `all` (to_string), and the value a name names.
template <class Enum, size_t N> std::vector<std::string> names_of(const Enum (&all)[N]) {
    std::vector<std::string> names;
    for (Enum value : all)
        names.emplace_back(to_string(value));
    return names;
}

template <class Enum, size_t N>
std::optional<Enum> find_by_name(const Enum (&all)[N], std::string_view name) {
    for (Enum value : all)
        if (name == to_string(value)) return value;
    return std::nullopt;
}

}  // namespace

std::vector<std::string> bvh_builder_names() {
    return names_of(kBvhBuilders);
}

std::optional<BvhBuilder> find_bvh_builder(std::string_view name) {
    return find_by_name(kBvhBuilders, name);
}

const char* to_string(BvhOrder order) {
    return order == BvhOrder::breadth_first ? "breadth-first"
           : order == BvhOrder::depth_first ? "depth-first"
                                            : "van-emde-boas";
}

std::vector<std::string> bvh_order_names() {
    return names_of(kBvhOrders);
}

std::optional<BvhOrder> find_bvh_order(std::string_view name) {
    return find_by_name(kBvhOrders, name);
}

const char* to_string(BvhBoxes boxes) {
    return boxes == BvhBoxes::floats ? "float" : "quantized";
}

std::vector<std::string> bvh_boxes_names() {
    return names_of(kBvhBoxes);
}

std::optional<BvhBoxes> find_bvh_boxes(std::string_view name) {
    return find_by_name(kBvhBoxes, name);
}

namespace {

/// A box that starts empty and grows; converted to Aabb only once it holds something.
struct Box {
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};
    void grow(const Box& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    void grow(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    float area() const { return surface_area(lo, hi); }
};

/// Most triangles a subtree can hold when its leaves may sit at most `levels` below its root.
uint64_t subtree_capacity(uint32_t max_leaf_size, uint32_t levels) {
    return levels >= 40 ? std::numeric_limits<uint64_t>::max() / 2
                        : uint64_t{max_leaf_size} << levels;
}

/// A candidate object split. cost = A(left) * n_left + A(right) * n_right, i.e. the SAH without
/// the node's own term. `position` is where it cuts: the sweep builder's count of triangles that
/// go left, the binned builder's count of bins that go left.
struct Split {
    int axis = -1;
    uint32_t position = 0;
    uint32_t left_count = 0;
    double cost = std::numeric_limits<double>::infinity();
    bool valid() const { return axis >= 0; }
};

/// Lower cost wins; on a tie (e.g. many identical boxes) the more balanced split, which keeps
/// such trees shallow; then the earlier candidate, so the result never depends on anything else.
bool better(const Split& candidate, const Split& incumbent, uint32_t count) {
    if (candidate.cost != incumbent.cost) return candidate.cost < incumbent.cost;
    const auto imbalance = [&](const Split& s) {
        return std::abs(2 * int64_t(s.left_count) - int64_t(count));
    };
    return imbalance(candidate) < imbalance(incumbent);
}

/// Shared by both builders: per-triangle boxes and centroids, node emission and the
/// leaf-or-split decision, which is where the SAH and the depth limit meet.
class BuilderBase {
public:
    BuilderBase(std::span<const Triangle> triangles, const BvhConfig& config) : config_(config) {
        boxes_.resize(triangles.size());
        centroids_.resize(triangles.size());
        tbb::parallel_for(size_t{0}, triangles.size(), [&](size_t i) {
            const Triangle& t = triangles[i];
            Box b;
            b.grow(t.v0);
            b.grow(t.v1);
            b.grow(t.v2);
            boxes_[i] = b;
            centroids_[i] = (b.lo + b.hi) * 0.5f;
        });
    }

protected:
    struct NodeChoice {
        bool make_leaf = false;
        Split split;
    };

    /// `best` ignores the depth limit, `feasible` honours it (both sides fit below the limit).
    NodeChoice decide(uint32_t count, float node_area, uint32_t levels_left, const Split& best,
                      const Split& feasible) {
        const bool fits_leaf = count <= config_.max_leaf_size;
        if (levels_left == 0) {
            if (best.valid() && best.cost + node_area < double(count) * node_area)
                ++depth_limited_nodes_;
            return {true, {}};
        }
        if (fits_leaf &&
            (!feasible.valid() || double(count) * node_area <= node_area + feasible.cost))
            return {true, {}};
        if (best.valid() && (!feasible.valid() || feasible.cost > best.cost))
            ++depth_limited_nodes_;
        return {false, feasible};
    }

    uint32_t emit_node(const Box& bounds) {
        nodes_.push_back(BvhNode{Aabb{bounds.lo, bounds.hi}, 0, 0, 0});
        return uint32_t(nodes_.size() - 1);
    }

    /// Most triangles each child may take; 0 at the depth limit, where no split is feasible.
    uint64_t child_capacity(uint32_t levels_left) const {
        return levels_left == 0 ? 0 : subtree_capacity(config_.max_leaf_size, levels_left - 1);
    }

    const BvhConfig& config_;
    // Per triangle, and with the sorted lists below what a large build's page faults are for.
    core::HugeVector<Box> boxes_;
    core::HugeVector<glm::vec3> centroids_;
    std::vector<BvhNode> nodes_;
    BvhStats stats_;
    /// Counted from several threads by the sweep builder; copied into the stats at the end.
    std::atomic<uint32_t> depth_limited_nodes_{0};
};

/// Half the range [begin, end) of `order` to each side of the object median by centroid on the
/// widest centroid axis (index tie-break: deterministic); returns the middle.
uint32_t partition_at_median(std::vector<uint32_t>& order, std::span<const glm::vec3> centroids,
                             uint32_t begin, uint32_t end, const Box& centroid_bounds) {
    const glm::vec3 extent = centroid_bounds.hi - centroid_bounds.lo;
    const int axis =
        extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const uint32_t middle = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                     [&](uint32_t a, uint32_t b) {
                         const float ca = centroids[a][axis], cb = centroids[b][axis];
                         return ca < cb || (ca == cb && a < b);
                     });
    return middle;
}

/// Exact SAH over object splits (the full sweep): the triangles of every node are kept sorted by
/// centroid on each axis (three lists, presorted once, partitioned stably per node), and every
/// split position on every axis is evaluated: O(n log n) presort + O(n) per tree level.
///
/// What makes it fast, as in the well-known full-sweep builders: the lists hold the triangles'
/// boxes themselves, so the sweeps and partitions stream through memory instead of gathering
/// boxes by index; the presort is a radix sort; the node's three axes are swept in parallel
/// and the two subtrees are built in parallel above a size cutoff (in oneTBB's current arena,
/// the default one unless the caller chose another, so a process-wide tbb::global_control
/// limits the threads).
///
/// Same tree for any thread count: each node depends only on its range of the lists, the split
/// chosen is the first best candidate in (axis, position) order however the axes are swept,
/// and the nodes, made in whatever order the threads get to them, are laid out depth-first
/// at the end.
class SweepBuilder : BuilderBase {
public:
    SweepBuilder(std::span<const Triangle> triangles, const BvhConfig& config)
        : BuilderBase(triangles, config) {
        const size_t n = triangles.size();
        tbb::parallel_invoke([&] { presort(0); }, [&] { presort(1); }, [&] { presort(2); });
        boxes_ = {};
        centroids_ = {};
        for (auto& areas : right_area_)
            areas.resize(n);
        goes_right_.resize(n);
        scratch_.resize(n);
        // A binary tree with at most n leaves has at most 2n - 1 nodes.
        build_nodes_ = core::make_huge_array<BuildNode>(2 * n - 1);
    }

    Bvh build() {
        const uint32_t n = uint32_t(refs_[0].size());
        build_node(0, 0, n, config_.traversal_stack_entries);
        Bvh bvh;
        bvh.nodes.reserve(next_node_);
        lay_out(bvh.nodes, 0);
        bvh.triangle_order.resize(n);
        for (uint32_t i = 0; i < n; ++i)
            bvh.triangle_order[i] = refs_[0][i].triangle();
        bvh.stats = std::move(stats_);
        bvh.stats.depth_limited_nodes = depth_limited_nodes_;
        return bvh;
    }

private:
    /// Four floats in one SIMD register (a GCC/Clang vector type): one min or max grows a box.
    using Float4 = float __attribute__((vector_size(16)));
    /// A triangle's box in a sorted list: lanes 0-2 of lo and hi; the triangle's index is kept
    /// as bits in hi's lane 3, whose grown value nothing reads.
    struct Ref {
        Float4 lo, hi;
        uint32_t triangle() const { return std::bit_cast<uint32_t>(hi[3]); }
    };
    /// A growing box of Refs, exactly as Box grows (the same min and max, lane by lane).
    struct Box4 {
        Float4 lo = Float4{} + std::numeric_limits<float>::infinity();
        Float4 hi = Float4{} - std::numeric_limits<float>::infinity();
        void grow(const Float4& other_lo, const Float4& other_hi) {
            lo = other_lo < lo ? other_lo : lo;
            hi = hi < other_hi ? other_hi : hi;
        }
        void grow(const Ref& r) { grow(r.lo, r.hi); }
        void grow(const Box4& b) { grow(b.lo, b.hi); }
        glm::vec3 low() const { return {lo[0], lo[1], lo[2]}; }
        glm::vec3 high() const { return {hi[0], hi[1], hi[2]}; }
        float area() const { return surface_area(low(), high()); }
    };
    /// A node as built: an interior node's children are build_nodes_[first] and [first + 1].
    /// Trivial, so the pool's unused part is never touched.
    struct BuildNode {
        glm::vec3 lo, hi;
        uint32_t first;  ///< leaf: first entry of the range; interior: the left child
        uint32_t count;  ///< leaf: triangles; 0 for interior nodes
    };
    /// Nodes with fewer triangles build both subtrees on one thread, and sweep their axes one
    /// after the other: below these, handing work to another thread costs more than it saves.
    static constexpr uint32_t kParallelSubtrees = 4096;
    static constexpr uint32_t kParallelAxes = 65536;

    /// Sorts refs_[axis] by centroid, ties by triangle index: a stable LSD radix sort (three
    /// 11-bit digits) of keys that order like the floats, started in index order.
    void presort(int axis) {
        const uint32_t n = uint32_t(centroids_.size());
        core::HugeVector<uint64_t> keys(n), sorted(n);  // key << 32 | triangle
        for (uint32_t i = 0; i < n; ++i) {
            // + 0.f turns -0 into +0, which compares equal to it; then negative floats get
            // their bits flipped, positive ones the sign bit set, so the integers order alike.
            const uint32_t bits = std::bit_cast<uint32_t>(centroids_[i][axis] + 0.f);
            const uint32_t key = bits & 0x80000000u ? ~bits : bits | 0x80000000u;
            keys[i] = uint64_t(key) << 32 | i;
        }
        for (int shift = 32; shift < 64; shift += 11) {
            std::array<uint32_t, 2048> start{};
            for (uint64_t k : keys)
                ++start[(k >> shift) & 2047];
            uint32_t sum = 0;
            for (uint32_t& s : start)
                sum += std::exchange(s, sum);
            for (uint64_t k : keys)
                sorted[start[(k >> shift) & 2047]++] = k;
            keys.swap(sorted);
        }
        auto& refs = refs_[axis];
        refs.resize(n);
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t t = uint32_t(keys[i]);
            const Box& b = boxes_[t];
            refs[i] = Ref{Float4{b.lo.x, b.lo.y, b.lo.z, 0.f},
                          Float4{b.hi.x, b.hi.y, b.hi.z, std::bit_cast<float>(t)}};
        }
    }

    void build_node(uint32_t index, uint32_t begin, uint32_t end, uint32_t levels_left) {
        const uint32_t count = end - begin;
        Box4 bounds;
        Split best, feasible;
        if (count > 1)
            find_splits(begin, end, child_capacity(levels_left), bounds, best, feasible);
        else
            bounds.grow(refs_[0][begin]);
        BuildNode& node = build_nodes_[index];
        node = BuildNode{bounds.low(), bounds.high(), 0, 0};
        const NodeChoice choice = decide(count, bounds.area(), levels_left, best, feasible);
        if (choice.make_leaf) {
            node.first = begin;
            node.count = count;
            return;
        }
        partition(begin, end, choice.split);
        const uint32_t middle = begin + choice.split.left_count;
        const uint32_t left = next_node_.fetch_add(2, std::memory_order_relaxed);
        node.first = left;
        const auto build_left = [&] { build_node(left, begin, middle, levels_left - 1); };
        const auto build_right = [&] { build_node(left + 1, middle, end, levels_left - 1); };
        if (count >= kParallelSubtrees) {
            tbb::parallel_invoke(build_left, build_right);
        } else {
            build_left();
            build_right();
        }
    }

    /// Also sets `bounds` to the range's bounds, grown in list order on axis 0 as the previous
    /// builder grew them (where -0 and +0 meet, the order decides which one a bound keeps).
    void find_splits(uint32_t begin, uint32_t end, uint64_t child_cap, Box4& bounds, Split& best,
                     Split& feasible) {
        std::array<Split, 3> axis_best, axis_feasible;
        const auto sweep = [&](int axis) {
            const Box4 prefix =
                sweep_axis(axis, begin, end, child_cap, axis_best[axis], axis_feasible[axis]);
            if (axis == 0) {
                bounds = prefix;
                bounds.grow(refs_[0][end - 1]);
            }
        };
        if (end - begin >= kParallelAxes) {
            tbb::parallel_invoke([&] { sweep(0); }, [&] { sweep(1); }, [&] { sweep(2); });
        } else {
            for (int axis = 0; axis < 3; ++axis)
                sweep(axis);
        }
        // In axis order, as one sweep over all three would pick.
        for (int axis = 0; axis < 3; ++axis) {
            if (better(axis_best[axis], best, end - begin)) best = axis_best[axis];
            if (better(axis_feasible[axis], feasible, end - begin)) feasible = axis_feasible[axis];
        }
    }

    /// Returns the bounds of all but the range's last box, grown in list order.
    Box4 sweep_axis(int axis, uint32_t begin, uint32_t end, uint64_t child_cap, Split& best,
                    Split& feasible) {
        const uint32_t count = end - begin;
        const Ref* refs = refs_[axis].data();
        float* right_area = right_area_[axis].data();  // [i]: area of the range's suffix from i
        Box4 right;
        for (uint32_t i = end - 1; i > begin; --i) {
            right.grow(refs[i]);
            right_area[i] = right.area();
        }
        // Every split is feasible when either side may take all but one triangle.
        const bool all_feasible = child_cap >= count - 1;
        Box4 left;
        for (uint32_t i = begin; i + 1 < end; ++i) {
            left.grow(refs[i]);
            const uint32_t left_count = i + 1 - begin, right_count = count - left_count;
            const Split candidate{axis, left_count, left_count,
                                  double(left.area()) * left_count +
                                      double(right_area[i + 1]) * right_count};
            if (better(candidate, best, count)) best = candidate;
            if (!all_feasible && left_count <= child_cap && right_count <= child_cap &&
                better(candidate, feasible, count))
                feasible = candidate;
        }
        if (all_feasible) feasible = best;
        return left;
    }

    /// Splits the range on the chosen axis and carries the split over to the other two sorted
    /// lists with a stable partition, so they stay sorted.
    void partition(uint32_t begin, uint32_t end, const Split& split) {
        const uint32_t middle = begin + split.position;
        const Ref* chosen = refs_[split.axis].data();
        for (uint32_t i = begin; i < end; ++i)
            goes_right_[chosen[i].triangle()] = i >= middle;
        for (int axis = 0; axis < 3; ++axis) {
            if (axis == split.axis) continue;
            Ref* refs = refs_[axis].data();
            Ref* right = scratch_.data() + begin;  // this range's part: subtrees never overlap
            uint32_t left = begin, right_count = 0;
            for (uint32_t i = begin; i < end; ++i) {
                if (goes_right_[refs[i].triangle()])
                    right[right_count++] = refs[i];
                else
                    refs[left++] = refs[i];
            }
            std::copy(right, right + right_count, refs + left);
        }
    }

    /// Appends the subtree of build_nodes_[index] depth-first: left child right after its parent.
    void lay_out(std::vector<BvhNode>& nodes, uint32_t index) const {
        const BuildNode& node = build_nodes_[index];
        const uint32_t out = uint32_t(nodes.size());
        nodes.push_back(BvhNode{Aabb{node.lo, node.hi}, 0, 0, 0});
        if (node.count != 0) {
            nodes[out].first_triangle = node.first;
            nodes[out].triangle_count = node.count;
            return;
        }
        lay_out(nodes, node.first);
        nodes[out].right_child = uint32_t(nodes.size());
        lay_out(nodes, node.first + 1);
    }

    std::array<core::HugeVector<Ref>, 3> refs_;
    std::array<core::HugeVector<float>, 3> right_area_;
    core::HugeVector<uint8_t> goes_right_;  // per triangle, for the partition of its node
    core::HugeVector<Ref> scratch_;
    core::HugeArray<BuildNode> build_nodes_;
    std::atomic<uint32_t> next_node_{1};  // build_nodes_[0] is the root
};

/// Binned SAH after Wald 2007: centroids are binned into `bins` equal slots per axis and only
/// the bin boundaries are evaluated: O(n) per tree level, no sorting.
class BinnedBuilder : BuilderBase {
public:
    BinnedBuilder(std::span<const Triangle> triangles, const BvhConfig& config)
        : BuilderBase(triangles, config), bins_(config.bins) {
        sweep_.bins.resize(bins_);
        sweep_.right_area.resize(bins_);
        sweep_.right_count.resize(bins_);
        order_.resize(triangles.size());
        for (uint32_t i = 0; i < order_.size(); ++i)
            order_[i] = i;
    }

    Bvh build() {
        nodes_.reserve(2 * order_.size());
        build_node(0, uint32_t(order_.size()), config_.traversal_stack_entries);
        stats_.depth_limited_nodes = depth_limited_nodes_;
        return Bvh{std::move(nodes_), std::move(order_), std::move(stats_)};
    }

private:
    struct Bin {
        Box bounds;
        uint32_t count = 0;
    };
    struct BinSweep {
        std::vector<Bin> bins;
        std::vector<float> right_area;      // [b]: area of bins b.. together
        std::vector<uint32_t> right_count;  // [b]: triangles in bins b..
    };

    void build_node(uint32_t begin, uint32_t end, uint32_t levels_left) {
        const uint32_t count = end - begin;
        Box bounds, centroid_bounds;
        for (uint32_t i = begin; i < end; ++i) {
            bounds.grow(boxes_[order_[i]]);
            centroid_bounds.grow(centroids_[order_[i]]);
        }
        const uint32_t index = emit_node(bounds);

        Split best, feasible;
        if (count > 1)
            find_splits(begin, end, centroid_bounds, child_capacity(levels_left), best, feasible);
        NodeChoice choice = decide(count, bounds.area(), levels_left, best, feasible);
        if (!choice.make_leaf && !choice.split.valid() && count <= config_.max_leaf_size)
            choice.make_leaf = true;
        if (choice.make_leaf) {
            nodes_[index].first_triangle = begin;
            nodes_[index].triangle_count = count;
            return;
        }
        const uint32_t middle =
            choice.split.valid()
                ? partition_by_bin(begin, end, centroid_bounds, choice.split)
                : partition_at_median(order_, centroids_, begin, end, centroid_bounds);
        build_node(begin, middle, levels_left - 1);
        nodes_[index].right_child = uint32_t(nodes_.size());
        build_node(middle, end, levels_left - 1);
    }

    /// Bins per unit length on an axis, or 0 when the centroids cannot be binned along it.
    float bin_scale(int axis, const Box& centroid_bounds) const {
        const float scale = float(bins_) / (centroid_bounds.hi[axis] - centroid_bounds.lo[axis]);
        return centroid_bounds.hi[axis] > centroid_bounds.lo[axis] && std::isfinite(scale) ? scale
                                                                                           : 0.f;
    }

    uint32_t bin_of(uint32_t triangle, int axis, const Box& centroid_bounds, float scale) const {
        const float slot = (centroids_[triangle][axis] - centroid_bounds.lo[axis]) * scale;
        return uint32_t(std::clamp(slot, 0.f, float(bins_ - 1)));
    }

    void find_splits(uint32_t begin, uint32_t end, const Box& centroid_bounds, uint64_t child_cap,
                     Split& best, Split& feasible) {
        const uint32_t count = end - begin;
        auto& [bins, right_area, right_count] = sweep_;
        for (int axis = 0; axis < 3; ++axis) {
            const float scale = bin_scale(axis, centroid_bounds);
            if (scale == 0.f) continue;
            std::fill(bins.begin(), bins.end(), Bin{});
            for (uint32_t i = begin; i < end; ++i) {
                Bin& bin = bins[bin_of(order_[i], axis, centroid_bounds, scale)];
                bin.bounds.grow(boxes_[order_[i]]);
                ++bin.count;
            }
            Box right;
            uint32_t right_n = 0;
            for (uint32_t b = bins_ - 1; b > 0; --b) {
                right.grow(bins[b].bounds);
                right_n += bins[b].count;
                right_area[b] = right.area();
                right_count[b] = right_n;
            }
            Box left;
            uint32_t left_n = 0;
            for (uint32_t b = 0; b + 1 < bins_; ++b) {
                left.grow(bins[b].bounds);
                left_n += bins[b].count;
                const uint32_t right_n_here = right_count[b + 1];
                if (left_n == 0 || right_n_here == 0) continue;
                const Split candidate{axis, b + 1, left_n,
                                      double(left.area()) * left_n +
                                          double(right_area[b + 1]) * right_n_here};
                if (better(candidate, best, count)) best = candidate;
                if (left_n <= child_cap && right_n_here <= child_cap &&
                    better(candidate, feasible, count))
                    feasible = candidate;
            }
        }
    }

    uint32_t partition_by_bin(uint32_t begin, uint32_t end, const Box& centroid_bounds,
                              const Split& split) {
        const float scale = bin_scale(split.axis, centroid_bounds);
        // std::partition is not stable but is a pure function of its input: still deterministic.
        const auto middle =
            std::partition(order_.begin() + begin, order_.begin() + end, [&](uint32_t t) {
                return bin_of(t, split.axis, centroid_bounds, scale) < split.position;
            });
        return uint32_t(middle - order_.begin());
    }

    uint32_t bins_;
    std::vector<uint32_t> order_;
    BinSweep sweep_;  // reused by every node
};

/// The median split, no SAH: every node with more than max_leaf_size triangles is halved at the
/// object median. Halving keeps the depth at ceil(log2(n / max_leaf_size)), inside the stack
/// contract whenever validate() accepted the soup.
class MedianBuilder : BuilderBase {
public:
    MedianBuilder(std::span<const Triangle> triangles, const BvhConfig& config)
        : BuilderBase(triangles, config) {
        order_.resize(triangles.size());
        for (uint32_t i = 0; i < order_.size(); ++i)
            order_[i] = i;
    }

    Bvh build() {
        nodes_.reserve(2 * order_.size());
        build_node(0, uint32_t(order_.size()));
        return Bvh{std::move(nodes_), std::move(order_), std::move(stats_)};
    }

private:
    void build_node(uint32_t begin, uint32_t end) {
        Box bounds, centroid_bounds;
        for (uint32_t i = begin; i < end; ++i) {
            bounds.grow(boxes_[order_[i]]);
            centroid_bounds.grow(centroids_[order_[i]]);
        }
        const uint32_t index = emit_node(bounds);
        if (end - begin <= config_.max_leaf_size) {
            nodes_[index].first_triangle = begin;
            nodes_[index].triangle_count = end - begin;
            return;
        }
        const uint32_t middle =
            partition_at_median(order_, centroids_, begin, end, centroid_bounds);
        build_node(begin, middle);
        nodes_[index].right_child = uint32_t(nodes_.size());
        build_node(middle, end);
    }

    std::vector<uint32_t> order_;
};

/// Beyond this, box surface areas overflow float and the SAH becomes inf/inf.
constexpr float kMaxCoordinate = 1e18f;

void validate(std::span<const Triangle> triangles, const BvhConfig& config) {
    if (config.max_leaf_size < 1 || config.max_leaf_size > 8)
        throw std::invalid_argument(
            fmt::format("BVH: max_leaf_size must be in 1..8, got {}", config.max_leaf_size));
    if (config.bins < 2 || config.bins > 256)
        throw std::invalid_argument(
            fmt::format("BVH: bins must be in 2..256, got {}", config.bins));
    if (triangles.empty())
        throw std::invalid_argument("BVH: the scene has no triangles; add a mesh or generator");
    if (triangles.size() > (size_t{1} << 31))
        throw std::invalid_argument(
            fmt::format("BVH: {} triangles exceed the 2^31 limit", triangles.size()));
    const uint64_t capacity =
        subtree_capacity(config.max_leaf_size, config.traversal_stack_entries);
    if (triangles.size() > capacity)
        throw std::invalid_argument(fmt::format("BVH: {} triangles cannot fit in leaves of {} at "
                                                "depth <= {}; raise traversal_stack_entries",
                                                triangles.size(), config.max_leaf_size,
                                                config.traversal_stack_entries));
    for (size_t i = 0; i < triangles.size(); ++i) {
        const Triangle& t = triangles[i];
        for (const glm::vec3& v : {t.v0, t.v1, t.v2})
            if (!glm::all(glm::lessThanEqual(glm::abs(v), glm::vec3(kMaxCoordinate))))
                throw std::invalid_argument(
                    fmt::format("BVH: triangle {} has vertex ({}, {}, {}); coordinates must be "
                                "finite and within +-{:g}",
                                i, v.x, v.y, v.z, kMaxCoordinate));
    }
}

void fill_shape_stats(const Bvh& bvh, uint32_t max_leaf_size, BvhStats& stats) {
    stats.nodes = uint32_t(bvh.nodes.size());
    stats.leaves = 0;
    stats.max_depth = 0;
    stats.leaf_size_histogram.assign(max_leaf_size + 1, 0);
    std::vector<std::pair<uint32_t, uint32_t>> pending{{0, 0}};  // (node, depth)
    while (!pending.empty()) {
        const auto [index, depth] = pending.back();
        pending.pop_back();
        const BvhNode& node = bvh.nodes[index];
        if (node.is_leaf()) {
            ++stats.leaves;
            stats.max_depth = std::max(stats.max_depth, depth);
            ++stats.leaf_size_histogram[node.triangle_count];
        } else {
            pending.push_back({node.right_child, depth + 1});
            pending.push_back({index + 1, depth + 1});
        }
    }
    stats.sah_cost = sah_cost(bvh);
}

}  // namespace

double sah_cost(const Bvh& bvh) {
    const double root_area = bvh.nodes.at(0).bounds.surface_area();
    // A root without area (all triangles on one line or point) makes every ratio 0/0; take its
    // limit, 1, so the cost still counts nodes and triangle tests.
    const auto ratio = [&](const BvhNode& node) {
        return root_area > 0.0 ? double(node.bounds.surface_area()) / root_area : 1.0;
    };
    double sum = 0.0;
    for (const BvhNode& node : bvh.nodes)
        sum += ratio(node) * (node.is_leaf() ? double(node.triangle_count) : 1.0);
    return sum;
}

Bvh build_bvh(std::span<const Triangle> triangles, const BvhConfig& config) {
    validate(triangles, config);
    const auto start = std::chrono::steady_clock::now();
    Bvh bvh = config.builder == BvhBuilder::sweep    ? SweepBuilder(triangles, config).build()
              : config.builder == BvhBuilder::binned ? BinnedBuilder(triangles, config).build()
                                                     : MedianBuilder(triangles, config).build();
    bvh.stats.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fill_shape_stats(bvh, config.max_leaf_size, bvh.stats);
    return bvh;
}

}  // namespace tpsim::scene
