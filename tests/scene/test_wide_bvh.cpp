// The wide BVHs: the collapse keeps every leaf and box of the binary tree, and the scene
// compiler lays the tree out as scene_layout.hpp documents, in every node order and both box
// formats, with quantized boxes that contain the float ones.
#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <utility>

#include <catch2/catch.hpp>

#include "sim/image/memory_image.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/wide_bvh.hpp"
#include "tests/scene/wide_bvh_image.hpp"

using namespace tpsim;
using namespace tpsim::scene;

namespace {

std::vector<Triangle> soup(uint32_t count, uint32_t seed, float flatten = 1.f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> position(-10.f, 10.f), offset(-0.5f, 0.5f);
    std::vector<Triangle> triangles;
    for (uint32_t i = 0; i < count; ++i) {
        const glm::vec3 c(position(rng), position(rng) * flatten, position(rng));
        const auto corner = [&] {
            return c + glm::vec3(offset(rng), offset(rng) * flatten, offset(rng));
        };
        triangles.push_back({corner(), corner(), corner(), 0});
    }
    return triangles;
}

Bvh binary(const std::vector<Triangle>& triangles) {
    BvhConfig config;
    config.max_leaf_size = 2;  // many leaves, so the collapse has work at every level
    return build_bvh(triangles, config);
}

std::array<float, 6> corners(const Aabb& box) {
    return {box.lo.x, box.lo.y, box.lo.z, box.hi.x, box.hi.y, box.hi.z};
}

/// The binary tree's leaves as (first triangle, count), and its boxes.
void binary_leaves(const Bvh& bvh, std::set<std::pair<uint32_t, uint32_t>>& leaves,
                   std::multiset<std::array<float, 6>>& boxes) {
    for (const BvhNode& node : bvh.nodes) {
        if (node.is_leaf()) leaves.insert({node.first_triangle, node.triangle_count});
        boxes.insert(corners(node.bounds));
    }
}

/// Worst stack by recursion, independently of the builder's walk.
uint32_t worst_stack(const WideBvh& wide, uint32_t node, uint32_t pushed) {
    const WideNode& n = wide.nodes[node];
    uint32_t worst = pushed + n.child_count - 1;
    for (uint32_t c = 0; c < n.child_count; ++c)
        if (!n.children[c].is_leaf())
            worst =
                std::max(worst, worst_stack(wide, n.children[c].node, pushed + n.child_count - 1));
    return worst;
}

scene::Scene scene_of(const std::vector<Triangle>& triangles) {
    scene::Scene s;
    s.triangles = triangles;
    s.materials.resize(1);
    s.width = s.height = 1;
    return s;
}

}  // namespace

TEST_CASE("Collapsing keeps every leaf and box of the binary tree, at most `width` children per "
          "node, opening the largest until only leaves are left",
          "[bvh][wide]") {
    const uint32_t width = GENERATE(4u, 8u);
    const auto triangles = soup(3000, 7);
    const Bvh bvh = binary(triangles);
    const WideBvh wide = collapse_bvh(bvh, width);
    INFO("width " << width);
    CHECK(wide.triangle_order == bvh.triangle_order);
    CHECK(wide.stats.width == width);

    std::set<std::pair<uint32_t, uint32_t>> leaves, wide_leaves;
    std::multiset<std::array<float, 6>> boxes, wide_boxes;
    binary_leaves(bvh, leaves, boxes);
    uint64_t children = 0;
    for (size_t n = 0; n < wide.nodes.size(); ++n) {
        const WideNode& node = wide.nodes[n];
        REQUIRE(node.child_count >= 2);
        REQUIRE(node.child_count <= width);
        children += node.child_count;
        bool all_leaves = true;
        for (uint32_t c = 0; c < node.child_count; ++c) {
            const WideChild& child = node.children[c];
            wide_boxes.insert(corners(child.bounds));
            if (child.is_leaf()) {
                CHECK(wide_leaves.insert({child.first_triangle, child.triangle_count}).second);
            } else {
                all_leaves = false;
                CHECK(child.node > n);  // pre-order: children after their parent
                // The child's box is the union of its own children's.
                const WideNode& below = wide.nodes[child.node];
                Aabb u = below.children[0].bounds;
                for (uint32_t g = 1; g < below.child_count; ++g) {
                    u.lo = glm::min(u.lo, below.children[g].bounds.lo);
                    u.hi = glm::max(u.hi, below.children[g].bounds.hi);
                }
                CHECK(u.lo == child.bounds.lo);
                CHECK(u.hi == child.bounds.hi);
            }
        }
        // A node short of `width` children could not open any: they are all leaves.
        if (node.child_count < width) CHECK(all_leaves);
    }
    CHECK(wide_leaves == leaves);
    // The binary root's box is the record's; every other binary box is one child's, except
    // those of the binary nodes the collapse opened.
    CHECK(wide.bounds.lo == bvh.nodes[0].bounds.lo);
    CHECK(wide.bounds.hi == bvh.nodes[0].bounds.hi);
    for (const auto& box : wide_boxes)
        CHECK(boxes.count(box) >= wide_boxes.count(box));
    CHECK(wide.stats.nodes == wide.nodes.size());
    CHECK(wide.stats.leaves == bvh.stats.leaves);
    CHECK(wide.stats.mean_children == Approx(double(children) / double(wide.nodes.size())));
    CHECK(wide.stats.worst_stack == worst_stack(wide, 0, 0));
    CHECK(wide.stats.max_depth < bvh.stats.max_depth);
    CHECK(wide.nodes.size() < bvh.stats.nodes / (width / 2));
}

TEST_CASE("A one-leaf tree collapses into one node with one leaf child", "[bvh][wide]") {
    const auto triangles = soup(1, 3);
    const WideBvh wide = collapse_bvh(binary(triangles), 8);
    REQUIRE(wide.nodes.size() == 1);
    REQUIRE(wide.nodes[0].child_count == 1);
    CHECK(wide.nodes[0].children[0].triangle_count == 1);
    CHECK(wide.stats.worst_stack == 0);
    for (const BvhBoxes boxes : kBvhBoxes) {
        const auto image = image::build_memory_image(scene_of(triangles),
                                                     {&wide, BvhOrder::depth_first, boxes}, 1);
        const auto nodes = test::read_wide_bvh(image);
        REQUIRE(nodes.size() == 1);
        REQUIRE(nodes[0].children.size() == 1);
        CHECK(nodes[0].children[0].is_leaf());
        CHECK(nodes[0].children[0].first() == 0);
        CHECK(nodes[0].children[0].count() == 1);
    }
}

TEST_CASE("Quantized boxes stay conservative where a child's bound and the node's origin are "
          "too far apart for their difference to be exact",
          "[bvh][wide][layout]") {
    // Node box [-2^56, 2^56] on x: scale 2^50. The small triangle's lo.x = -1e-20 lies just
    // below offset 64 (decoded exactly 0): lo - origin rounds up to 2^56, whose floor is 64.
    const float big = 0x1p56f;
    std::vector<Triangle> triangles = {
        {{-big, 0.f, 0.f}, {-big, 1.f, 0.f}, {-big, 0.f, 1.f}, 0},
        {{big, 0.f, 0.f}, {big, 1.f, 0.f}, {big, 0.f, 1.f}, 0},
        {{-1e-20f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.f, 0.f, 1.f}, 0},
    };
    BvhConfig config;
    config.max_leaf_size = 1;
    const WideBvh wide = collapse_bvh(build_bvh(triangles, config), 4);
    const auto image = image::build_memory_image(
        scene_of(triangles), {&wide, BvhOrder::breadth_first, BvhBoxes::quantized}, 1);
    bool found = false;
    for (const test::ImageWideNode& node : test::read_wide_bvh(image))
        for (const test::ImageWideChild& child : node.children) {
            if (!child.is_leaf()) continue;
            const Triangle& t = triangles[wide.triangle_order[child.first()]];
            const float lo = std::min({t.v0.x, t.v1.x, t.v2.x});
            CHECK(child.lo.x <= lo);
            found = found || lo == -1e-20f;
        }
    CHECK(found);
}

TEST_CASE("Other widths are refused", "[bvh][wide]") {
    const Bvh bvh = binary(soup(10, 1));
    CHECK_THROWS_WITH(collapse_bvh(bvh, 2), "wide BVH: width must be 4 or 8, got 2");
    CHECK_THROWS_WITH(collapse_bvh(bvh, 16), "wide BVH: width must be 4 or 8, got 16");
}

TEST_CASE("The image holds the collapsed tree in every order and box format; quantized boxes "
          "contain the float ones, within one step of the node's grid",
          "[bvh][wide][layout]") {
    const uint32_t width = GENERATE(4u, 8u);
    const BvhOrder order =
        GENERATE(BvhOrder::breadth_first, BvhOrder::depth_first, BvhOrder::van_emde_boas);
    const BvhBoxes boxes = GENERATE(BvhBoxes::floats, BvhBoxes::quantized);
    // Flat in y (extent 0 in some nodes: the exponent's floor) and far from the origin in a
    // second case (the origin's rounding).
    const float flatten = GENERATE(1.f, 0.f);
    INFO("width " << width << ", " << to_string(order) << ", " << to_string(boxes) << ", flatten "
                  << flatten);
    auto triangles = soup(2000, 11, flatten);
    for (Triangle& t : triangles)
        for (glm::vec3* v : {&t.v0, &t.v1, &t.v2})
            *v += glm::vec3(1e5f, 0.f, -3e4f);
    const WideBvh wide = collapse_bvh(binary(triangles), width);
    const auto image = image::build_memory_image(scene_of(triangles), {&wide, order, boxes}, 1);
    const trax::layout::SceneHeader& h = image.header;
    REQUIRE(h.accel != 0);
    const uint32_t* record = image.words.data() + h.accel;
    CHECK(record[trax::layout::kAccelKind] == uint32_t(trax::layout::kAccelWideBvh));
    CHECK(record[trax::layout::kAccelWidth] == width);
    CHECK(record[trax::layout::kAccelQuantized] == (boxes == BvhBoxes::quantized ? 1u : 0u));
    CHECK(h.bvh_nodes.count == 0);
    const int32_t node_words =
        trax::layout::wide_node_words(int32_t(width), boxes == BvhBoxes::quantized);
    CHECK(int32_t(record[trax::layout::kAccelNodes + 1]) ==
          int32_t(wide.nodes.size()) * node_words);

    const std::vector<test::ImageWideNode> nodes = test::read_wide_bvh(image);
    REQUIRE(nodes.size() == wide.nodes.size());
    // Walk both trees depth-first side by side (read_wide_bvh walks the image that way).
    std::vector<uint32_t> pending{0};
    for (const test::ImageWideNode& image_node : nodes) {
        REQUIRE(!pending.empty());
        const WideNode& node = wide.nodes[pending.back()];
        pending.pop_back();
        CHECK((image_node.addr - h.accel) % trax::layout::kSectionAlignWords == 0);
        REQUIRE(image_node.children.size() == node.child_count);
        for (uint32_t c = 0; c < node.child_count; ++c) {
            const WideChild& child = node.children[c];
            const test::ImageWideChild& got = image_node.children[c];
            REQUIRE(got.is_leaf() == child.is_leaf());
            if (child.is_leaf()) {
                CHECK(got.first() == child.first_triangle);
                CHECK(got.count() == child.triangle_count);
            }
            if (boxes == BvhBoxes::floats) {
                CHECK(got.lo == child.bounds.lo);
                CHECK(got.hi == child.bounds.hi);
                continue;
            }
            // Conservative: the decoded box never cuts into the float one ...
            CHECK(glm::all(glm::lessThanEqual(got.lo, child.bounds.lo)));
            CHECK(glm::all(glm::greaterThanEqual(got.hi, child.bounds.hi)));
            // ... and grows it by at most a step (1/255 of the node's extent) plus rounding.
            for (int a = 0; a < 3; ++a) {
                float lo = node.children[0].bounds.lo[a], hi = node.children[0].bounds.hi[a];
                for (uint32_t k = 1; k < node.child_count; ++k) {
                    lo = std::min(lo, node.children[k].bounds.lo[a]);
                    hi = std::max(hi, node.children[k].bounds.hi[a]);
                }
                const double slack = 2.0 * double(hi - lo) / 255 + 4e-7 * std::abs(double(lo));
                CHECK(double(child.bounds.lo[a]) - got.lo[a] <= slack);
                CHECK(double(got.hi[a]) - child.bounds.hi[a] <= slack);
            }
        }
        for (uint32_t c = node.child_count; c-- > 0;)
            if (!node.children[c].is_leaf()) pending.push_back(node.children[c].node);
    }
    // The orders: depth-first puts the walk's nodes at rising addresses, breadth-first the
    // levels, one after the other.
    std::vector<int32_t> addrs;
    for (const test::ImageWideNode& n : nodes)
        addrs.push_back(n.addr);
    CHECK(addrs.front() == int32_t(record[trax::layout::kAccelNodes]));
    if (order == BvhOrder::depth_first) CHECK(std::is_sorted(addrs.begin(), addrs.end()));
    if (order == BvhOrder::breadth_first) {
        std::map<int32_t, uint32_t> depth{{addrs.front(), 0}};
        for (const test::ImageWideNode& n : nodes)
            for (const test::ImageWideChild& c : n.children)
                if (!c.is_leaf()) depth[int32_t(c.ref)] = depth[n.addr] + 1;
        uint32_t previous = 0;
        for (const auto& [addr, d] : depth) {  // by address
            CHECK(d >= previous);
            previous = d;
        }
    }
}
