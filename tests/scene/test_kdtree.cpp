// The kd-tree builder: every triangle is in every leaf its box reaches, the nodes are the
// depth-first tree the kernel walks, the build is the same on any number of threads, and the
// limits are enforced with a clear message; the same for the BSP tree it builds with general
// planes.
#include <algorithm>
#include <bit>
#include <tuple>
#include <vector>

#include <catch2/catch.hpp>
#include <oneapi/tbb/global_control.h>

#include "sim/scene/kdtree.hpp"
#include "sim/scene/load_scene.hpp"
#include "tests/scene/scene_test_util.hpp"

using namespace tpsim::scene;
using tpsim::scene::testing::soup;

namespace {

/// Walks the tree with each node's cell; calls leaf(cell, node) for every leaf.
template <class Leaf> void walk(const KdTree& tree, Leaf leaf) {
    struct Item {
        uint32_t node;
        Aabb cell;
        uint32_t depth;
    };
    std::vector<Item> pending{{0, tree.bounds, 0}};
    while (!pending.empty()) {
        const Item item = pending.back();
        pending.pop_back();
        const KdNode& node = tree.nodes.at(item.node);
        if (node.is_leaf()) {
            leaf(item.cell, node, item.depth);
            continue;
        }
        REQUIRE(node.axis < 3);
        REQUIRE(node.right_child > item.node + 1);
        CHECK(node.split > item.cell.lo[node.axis]);
        CHECK(node.split < item.cell.hi[node.axis]);
        Aabb below = item.cell, above = item.cell;
        below.hi[node.axis] = node.split;
        above.lo[node.axis] = node.split;
        pending.push_back({node.right_child, above, item.depth + 1});
        pending.push_back({item.node + 1, below, item.depth + 1});
    }
}

}  // namespace

TEST_CASE("Every triangle is in every kd-tree leaf its bounding box reaches", "[kdtree]") {
    const float size = GENERATE(0.3f, 3.f);
    const auto triangles = soup(800, 5, size);
    const KdTree tree = build_kdtree(triangles);
    for (const Triangle& t : triangles)
        for (const glm::vec3& v : {t.v0, t.v1, t.v2})
            CHECK(glm::all(glm::lessThan(tree.bounds.lo, v) && glm::lessThan(v, tree.bounds.hi)));
    uint32_t leaves = 0, empty = 0, deepest = 0;
    uint64_t references = 0;
    walk(tree, [&](const Aabb& cell, const KdNode& leaf, uint32_t depth) {
        ++leaves;
        empty += leaf.count == 0;
        references += leaf.count;
        deepest = std::max(deepest, depth);
        REQUIRE(leaf.first + leaf.count <= tree.references.size());
        const auto begin = tree.references.begin() + leaf.first;
        const std::vector<uint32_t> listed(begin, begin + leaf.count);
        for (uint32_t i = 0; i < triangles.size(); ++i) {
            const Triangle& t = triangles[i];
            const glm::vec3 lo = glm::min(t.v0, glm::min(t.v1, t.v2));
            const glm::vec3 hi = glm::max(t.v0, glm::max(t.v1, t.v2));
            // The box reaches into the cell (touching a face counts: the margin takes it).
            if (glm::all(glm::lessThanEqual(lo, cell.hi) && glm::lessThanEqual(cell.lo, hi)))
                CHECK(std::count(listed.begin(), listed.end(), i) == 1);
        }
    });
    const KdTreeStats& s = tree.stats;
    CHECK(s.nodes == tree.nodes.size());
    CHECK(s.leaves == leaves);
    CHECK(s.nodes == 2 * leaves - 1);
    CHECK(s.empty_leaves == empty);
    CHECK(s.references == references);
    CHECK(s.references == tree.references.size());
    CHECK(s.references >= triangles.size());
    CHECK(s.max_depth == deepest);
    CHECK(s.max_depth <= s.depth_limit);
    CHECK(s.depth_limit == uint32_t(8 + 1.3 * std::log2(800.0) + 0.5));
    CHECK(s.nodes > 100);  // the SAH split the soup
}

TEST_CASE("The kd-tree is the same on one thread and on many", "[kdtree]") {
    const auto triangles = soup(20000, 9, 0.5f);
    const KdTree many = build_kdtree(triangles);
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const KdTree single = build_kdtree(triangles);
    REQUIRE(single.nodes.size() == many.nodes.size());
    for (size_t i = 0; i < many.nodes.size(); ++i) {
        const KdNode &a = many.nodes[i], &b = single.nodes[i];
        CHECK((a.axis == b.axis && a.split == b.split && a.right_child == b.right_child &&
               a.first == b.first && a.count == b.count));
    }
    CHECK(single.references == many.references);
}

/// FNV-1a over every field of every node, then the references: equal digests mean the same tree.
uint64_t digest(const KdTree& tree) {
    testing::Fnv fnv;
    const auto add = [&](uint32_t word) { fnv.add(word); };
    for (const KdNode& node : tree.nodes) {
        add(node.axis);
        add(std::bit_cast<uint32_t>(node.split));
        add(node.right_child);
        add(node.first);
        add(node.count);
    }
    for (uint32_t r : tree.references)
        add(r);
    return fnv.hash();
}

TEST_CASE("The kd-tree and the BSP tree of pinned inputs are the trees they were", "[kdtree]") {
    // A change to the builder that moves these digests moves every kd-tree and BSP figure in
    // docs/accel.md: a speed-up must keep them.
    const auto bunny = load_scene(TPSIM_SCENES_DIR "/bunny.toml").triangles;
    CHECK(digest(build_kdtree(bunny)) == 0x7b14d9b606529b47ull);
    CHECK(digest(build_kdtree(soup(20000, 9, 0.5f))) == 0x3ef964ff1ad43e0full);
    KdTreeConfig bsp;
    bsp.general_planes = true;
    CHECK(digest(build_kdtree(soup(6000, 3, 0.5f), bsp)) == 0xe0f3727f4c6436a9ull);
}

TEST_CASE("kd-tree limits: depth, references per triangle, bad input", "[kdtree]") {
    const auto triangles = soup(500, 2, 4.f);
    KdTreeConfig shallow;
    shallow.max_depth = 3;
    CHECK(build_kdtree(triangles, shallow).stats.max_depth <= 3);
    KdTreeConfig deep;
    deep.max_depth = kKdMaxDepth + 1;
    CHECK_THROWS_WITH(build_kdtree(triangles, deep), "kd-tree: max_depth must be in 1..40, got 41");
    KdTreeConfig tight;
    tight.max_references_per_triangle = 1.5;
    CHECK_THROWS_WITH(build_kdtree(triangles, tight),
                      Catch::StartsWith("kd-tree: more than 750 leaf references, 1.5 per "
                                        "triangle, the limit"));
    CHECK_THROWS_WITH(build_kdtree({}), "kd-tree: the scene has no triangles");
    std::vector<Triangle> far = {{{0, 0, 0}, {1, 0, 0}, {0, 1e19f, 0}, 0}};
    CHECK_THROWS_WITH(build_kdtree(far), "kd-tree: a vertex is beyond +-1e18 (or NaN)");
}

TEST_CASE("Every triangle is in every BSP leaf its projections reach, planes of all 13 "
          "orientations",
          "[kdtree][bsp]") {
    const auto triangles = soup(600, 7, 1.5f);
    KdTreeConfig config;
    config.general_planes = true;
    const KdTree tree = build_kdtree(triangles, config);
    REQUIRE(tree.general_planes);
    // n.x over a triangle, as the builder projects it.
    const auto range = [](const Triangle& t, uint32_t k) {
        const auto& n = trax::layout::kBspDirection[k];
        double lo = 1e300, hi = -1e300;
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
            const double p = double(n[0]) * v.x + double(n[1]) * v.y + double(n[2]) * v.z;
            lo = std::min(lo, p);
            hi = std::max(hi, p);
        }
        return std::pair{lo, hi};
    };
    // Each leaf with the half-spaces on its path: (orientation, plane, above).
    struct Item {
        uint32_t node;
        std::vector<std::tuple<uint32_t, float, bool>> path;
    };
    std::vector<Item> pending{{0, {}}};
    uint32_t leaves = 0, diagonal = 0;
    while (!pending.empty()) {
        Item item = std::move(pending.back());
        pending.pop_back();
        const KdNode& node = tree.nodes.at(item.node);
        if (!node.is_leaf()) {
            REQUIRE(node.axis < kBspPlaneDirections);
            diagonal += node.axis >= 3;
            Item below{item.node + 1, item.path}, above{node.right_child, item.path};
            below.path.emplace_back(node.axis, node.split, false);
            above.path.emplace_back(node.axis, node.split, true);
            pending.push_back(std::move(above));
            pending.push_back(std::move(below));
            continue;
        }
        ++leaves;
        const auto begin = tree.references.begin() + node.first;
        const std::vector<uint32_t> listed(begin, begin + node.count);
        for (uint32_t i = 0; i < triangles.size(); ++i) {
            bool reaches = true;
            for (const auto& [k, split, up] : item.path) {
                const auto [lo, hi] = range(triangles[i], k);
                reaches = reaches && (up ? hi >= split : lo <= split);
            }
            if (reaches) CHECK(std::count(listed.begin(), listed.end(), i) == 1);
        }
    }
    const KdTreeStats& s = tree.stats;
    CHECK(s.leaves == leaves);
    CHECK(s.nodes == 2 * leaves - 1);
    CHECK(s.diagonal_planes == diagonal);
    CHECK(s.diagonal_planes > 0);  // the diagonals are used, not only the axes
    CHECK(s.references >= triangles.size());
    // The axes-only build of the same soup uses none.
    CHECK(build_kdtree(triangles).stats.diagonal_planes == 0);
}

TEST_CASE("The BSP tree is the same on one thread and on many", "[kdtree][bsp]") {
    const auto triangles = soup(6000, 3, 0.5f);
    KdTreeConfig config;
    config.general_planes = true;
    const KdTree many = build_kdtree(triangles, config);
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const KdTree single = build_kdtree(triangles, config);
    REQUIRE(single.nodes.size() == many.nodes.size());
    for (size_t i = 0; i < many.nodes.size(); ++i) {
        const KdNode &a = many.nodes[i], &b = single.nodes[i];
        CHECK((a.axis == b.axis && a.split == b.split && a.right_child == b.right_child &&
               a.first == b.first && a.count == b.count));
    }
    CHECK(single.references == many.references);
    KdTreeConfig tight = config;
    tight.max_references_per_triangle = 1.01;
    CHECK_THROWS_WITH(build_kdtree(triangles, tight), Catch::StartsWith("BSP tree: more than"));
}
