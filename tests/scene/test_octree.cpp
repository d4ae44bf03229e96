// The octree builder: every triangle is in every leaf its box reaches, cells are cut at their
// centres into the octants the kernel expects, empty octants are marked, the build is the same
// on any number of threads, and the limits are enforced with a clear message.
#include <algorithm>
#include <bit>
#include <vector>

#include <catch2/catch.hpp>
#include <oneapi/tbb/global_control.h>

#include "sim/scene/load_scene.hpp"
#include "sim/scene/octree.hpp"
#include "tests/scene/scene_test_util.hpp"

using namespace tpsim::scene;
using tpsim::scene::testing::soup;

namespace {

struct Walked {
    uint32_t interior = 0, leaves = 0, deepest = 0;
    uint64_t references = 0;
};

/// Walks the tree with each node's cell, checking the layout; calls leaf(cell, node) for every
/// leaf and empty(cell) for every empty octant.
template <class Leaf, class Empty> Walked walk(const Octree& tree, Leaf leaf, Empty empty) {
    struct Item {
        uint32_t node;
        Aabb cell;
        uint32_t depth;
    };
    Walked w;
    std::vector<Item> pending{{0, tree.bounds, 0}};
    while (!pending.empty()) {
        const Item item = pending.back();
        pending.pop_back();
        const OctreeNode& node = tree.nodes.at(item.node);
        w.deepest = std::max(w.deepest, item.depth);
        if (node.leaf) {
            ++w.leaves;
            w.references += node.count;
            leaf(item.cell, node);
            continue;
        }
        ++w.interior;
        REQUIRE(node.first_child % 8 == 0);  // a group of siblings: two 64-byte lines
        REQUIRE(node.first_child > item.node);
        REQUIRE(node.first_child + 8 <= tree.nodes.size());
        for (int axis = 0; axis < 3; ++axis)
            CHECK(node.centre[size_t(axis)] ==
                  item.cell.lo[axis] + (item.cell.hi[axis] - item.cell.lo[axis]) * 0.5f);
        for (uint32_t c = 0; c < 8; ++c) {
            Aabb cell = item.cell;
            for (int axis = 0; axis < 3; ++axis)
                (c >> axis & 1 ? cell.lo : cell.hi)[axis] = node.centre[size_t(axis)];
            if (node.occupied >> c & 1)
                pending.push_back({node.first_child + c, cell, item.depth + 1});
            else
                empty(cell);
        }
    }
    return w;
}

bool reaches(const Triangle& t, const Aabb& cell) {
    const glm::vec3 lo = glm::min(t.v0, glm::min(t.v1, t.v2));
    const glm::vec3 hi = glm::max(t.v0, glm::max(t.v1, t.v2));
    return glm::all(glm::lessThanEqual(lo, cell.hi) && glm::lessThanEqual(cell.lo, hi));
}

}  // namespace

TEST_CASE("Every triangle is in every octree leaf its bounding box reaches", "[octree]") {
    const float size = GENERATE(0.3f, 3.f);
    const auto triangles = soup(800, 5, size);
    const Octree tree = build_octree(triangles);
    for (const Triangle& t : triangles)
        for (const glm::vec3& v : {t.v0, t.v1, t.v2})
            CHECK(glm::all(glm::lessThan(tree.bounds.lo, v) && glm::lessThan(v, tree.bounds.hi)));
    uint32_t max_leaf = 0;
    const Walked w = walk(
        tree,
        [&](const Aabb& cell, const OctreeNode& leaf) {
            max_leaf = std::max(max_leaf, leaf.count);
            CHECK(leaf.count > 0);
            REQUIRE(leaf.first + leaf.count <= tree.references.size());
            const auto begin = tree.references.begin() + leaf.first;
            const std::vector<uint32_t> listed(begin, begin + leaf.count);
            for (uint32_t i = 0; i < triangles.size(); ++i)
                if (reaches(triangles[i], cell))
                    CHECK(std::count(listed.begin(), listed.end(), i) == 1);
        },
        // An octant marked empty holds no triangle, not even one touching its faces.
        [&](const Aabb& cell) {
            for (const Triangle& t : triangles)
                CHECK_FALSE(reaches(t, cell));
        });
    const OctreeStats& s = tree.stats;
    CHECK(s.nodes == tree.nodes.size());
    CHECK(s.nodes == 8 * (s.interior + 1));  // the root's group and one per interior cell
    CHECK(s.interior == w.interior);
    CHECK(s.leaves == w.leaves);
    CHECK(s.references == w.references);
    CHECK(s.references == tree.references.size());
    CHECK(s.references >= triangles.size());
    CHECK(s.max_leaf_triangles == max_leaf);
    CHECK(s.max_depth == w.deepest);
    CHECK(s.max_depth <= s.depth_limit);
    CHECK(s.depth_limit == kOctreeMaxDepth);
    CHECK(s.interior > 20);  // the soup was cut
}

TEST_CASE("The octree is the same on one thread and on many", "[octree]") {
    const auto triangles = soup(20000, 9, 0.5f);
    const Octree many = build_octree(triangles);
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const Octree single = build_octree(triangles);
    REQUIRE(single.nodes.size() == many.nodes.size());
    for (size_t i = 0; i < many.nodes.size(); ++i) {
        const OctreeNode &a = many.nodes[i], &b = single.nodes[i];
        CHECK((a.leaf == b.leaf && a.centre == b.centre && a.first_child == b.first_child &&
               a.occupied == b.occupied && a.first == b.first && a.count == b.count));
    }
    CHECK(single.references == many.references);
}

/// FNV-1a over every field of every node, the references and the statistics: equal digests mean
/// the same tree.
uint64_t digest(const Octree& tree) {
    testing::Fnv fnv;
    const auto add = [&](uint32_t word) { fnv.add(word); };
    for (const OctreeNode& node : tree.nodes) {
        add(node.leaf);
        for (float c : node.centre)
            add(std::bit_cast<uint32_t>(c));
        add(node.first_child);
        add(node.occupied);
        add(node.first);
        add(node.count);
    }
    for (uint32_t r : tree.references)
        add(r);
    const OctreeStats& s = tree.stats;
    for (uint64_t field : {uint64_t(s.nodes), uint64_t(s.interior), uint64_t(s.leaves),
                           uint64_t(s.max_depth), s.references, uint64_t(s.max_leaf_triangles)})
        add(uint32_t(field));
    return fnv.hash();
}

TEST_CASE("The octrees of pinned inputs are the trees they were", "[octree]") {
    // A change to the builder that moves these digests moves every octree figure in
    // docs/accel.md: a speed-up must keep them.
    CHECK(digest(build_octree(load_scene(TPSIM_SCENES_DIR "/bunny.toml").triangles)) ==
          0xa217fe0add4fc8cfull);
    CHECK(digest(build_octree(soup(20000, 9, 0.5f))) == 0x401cf2515ad983fbull);
}

TEST_CASE("octree limits: depth, references per triangle, bad input", "[octree]") {
    const auto triangles = soup(500, 2, 4.f);
    OctreeConfig shallow;
    shallow.max_depth = 2;
    CHECK(build_octree(triangles, shallow).stats.max_depth <= 2);
    OctreeConfig deep;
    deep.max_depth = kOctreeMaxDepth + 1;
    CHECK_THROWS_WITH(build_octree(triangles, deep), "octree: max_depth must be in 1..16, got 17");
    // Long thin triangles along the three axes through one point reach every cell they cross;
    // with no depth limit but the kernels', their references pass 64 per triangle.
    std::vector<Triangle> needles;
    for (int i = 0; i < 2000; ++i) {
        const float y = float(i) * 1e-3f;
        needles.push_back({{-100, y, 0}, {100, y, 0}, {100, y + 1e-4f, 0}, 0});
        needles.push_back({{0, -100, y}, {0, 100, y}, {0, 100, y + 1e-4f}, 0});
    }
    CHECK_THROWS_WITH(build_octree(needles),
                      Catch::StartsWith("octree: more than 256000 leaf references, 64 per "
                                        "triangle, the limit"));
    CHECK_THROWS_WITH(build_octree({}), "octree: the scene has no triangles");
    std::vector<Triangle> far = {{{0, 0, 0}, {1, 0, 0}, {0, 1e19f, 0}, 0}};
    CHECK_THROWS_WITH(build_octree(far), "octree: a vertex is beyond +-1e18 (or NaN)");
}
