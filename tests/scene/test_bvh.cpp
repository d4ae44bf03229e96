#include <bit>
#include <cmath>
#include <deque>
#include <filesystem>
#include <limits>
#include <random>

#include <catch2/catch.hpp>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/task_arena.h>

#include "sim/image/memory_image.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/scene/procedural.hpp"
#include "tests/scene/scene_test_util.hpp"

using namespace tpsim::scene;

namespace {

/// Checks every structural promise build_bvh makes, independently of how it was built.
void check_invariants(const Bvh& bvh, const std::vector<Triangle>& triangles,
                      const BvhConfig& config) {
    const uint32_t n = uint32_t(triangles.size());
    REQUIRE(bvh.triangle_order.size() == n);
    REQUIRE(!bvh.nodes.empty());
    std::vector<int> seen(n, 0);
    std::vector<int> covered(n, 0);  // positions of triangle_order covered by leaves
    uint32_t leaves = 0, max_depth = 0;
    std::vector<std::pair<uint32_t, uint32_t>> pending{{0, 0}};
    size_t visited = 0;
    while (!pending.empty()) {
        const auto [index, depth] = pending.back();
        pending.pop_back();
        ++visited;
        REQUIRE(index < bvh.nodes.size());
        const BvhNode& node = bvh.nodes[index];
        for (int k = 0; k < 3; ++k) {
            REQUIRE(std::isfinite(node.bounds.lo[k]));
            REQUIRE(std::isfinite(node.bounds.hi[k]));
            REQUIRE(node.bounds.lo[k] <= node.bounds.hi[k]);
        }
        if (node.is_leaf()) {
            ++leaves;
            max_depth = std::max(max_depth, depth);
            REQUIRE(node.triangle_count <= config.max_leaf_size);
            REQUIRE(uint64_t(node.first_triangle) + node.triangle_count <= n);
            for (uint32_t i = node.first_triangle; i < node.first_triangle + node.triangle_count;
                 ++i) {
                ++covered[i];
                const uint32_t t = bvh.triangle_order[i];
                REQUIRE(t < n);
                ++seen[t];
                for (const glm::vec3& v : {triangles[t].v0, triangles[t].v1, triangles[t].v2})
                    REQUIRE(node.bounds.contains(Aabb{v, v}));
            }
        } else {
            const uint32_t left = index + 1, right = node.right_child;
            REQUIRE(right > left);
            REQUIRE(right < bvh.nodes.size());
            REQUIRE(node.bounds.contains(bvh.nodes[left].bounds));
            REQUIRE(node.bounds.contains(bvh.nodes[right].bounds));
            pending.push_back({right, depth + 1});
            pending.push_back({left, depth + 1});
        }
    }
    CHECK(visited == bvh.nodes.size());  // every node reachable exactly once
    CHECK(std::count(seen.begin(), seen.end(), 1) == n);
    CHECK(std::count(covered.begin(), covered.end(), 1) == n);
    CHECK(max_depth <= config.traversal_stack_entries);
    CHECK(bvh.stats.max_depth == max_depth);
    CHECK(bvh.stats.leaves == leaves);
    CHECK(bvh.stats.nodes == 2 * leaves - 1);  // a full binary tree
    uint32_t histogram_leaves = 0;
    for (uint32_t c : bvh.stats.leaf_size_histogram)
        histogram_leaves += c;
    CHECK(histogram_leaves == leaves);
    CHECK(std::isfinite(bvh.stats.sah_cost));
}

std::vector<Triangle> random_soup(uint32_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> position(-10.f, 10.f), offset(-0.5f, 0.5f);
    std::vector<Triangle> triangles;
    for (uint32_t i = 0; i < count; ++i) {
        const glm::vec3 c(position(rng), position(rng), position(rng));
        triangles.push_back({c + glm::vec3(offset(rng), offset(rng), offset(rng)),
                             c + glm::vec3(offset(rng), offset(rng), offset(rng)),
                             c + glm::vec3(offset(rng), offset(rng), offset(rng)), 0});
    }
    return triangles;
}

/// Corners drawn from {-1, -0, +0, 0.5, 1}: node bounds where -0 and +0 meet keep whichever the
/// build order meets first, so a builder that grows boxes in another order changes their bits.
std::vector<Triangle> signed_zero_soup(uint32_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    const float values[] = {-1.f, -0.f, 0.f, 0.5f, 1.f};
    std::uniform_int_distribution<int> pick(0, 4);
    std::vector<Triangle> triangles;
    for (uint32_t i = 0; i < count; ++i) {
        glm::vec3 v[3];
        for (glm::vec3& corner : v)
            corner = {values[pick(rng)], values[pick(rng)], values[pick(rng)]};
        triangles.push_back({v[0], v[1], v[2], 0});
    }
    return triangles;
}

/// Triangle i spans [r^i, r^(i+1)] along x: each is a fixed fraction of everything to its
/// right, so greedy SAH peels one triangle per level and wants a tree as deep as the input.
std::vector<Triangle> geometric_strip(uint32_t count) {
    std::vector<Triangle> triangles;
    double x = 1.0;
    const double ratio = 1.00002;
    for (uint32_t i = 0; i < count; ++i) {
        const double next = x * ratio;
        triangles.push_back(
            {{float(x), 0.f, 0.f}, {float(next), 0.f, 0.f}, {float(x), float(next - x), 0.f}, 0});
        x = next;
    }
    return triangles;
}

const BvhBuilder kBuilders[] = {BvhBuilder::sweep, BvhBuilder::binned};

/// FNV-1a over every field of every node, then the triangle order: equal digests mean the same
/// memory image of the tree.
uint64_t digest(const Bvh& bvh) {
    testing::Fnv fnv;
    const auto add = [&](uint32_t word) { fnv.add(word); };
    for (const BvhNode& node : bvh.nodes) {
        for (int k = 0; k < 3; ++k) {
            add(std::bit_cast<uint32_t>(node.bounds.lo[k]));
            add(std::bit_cast<uint32_t>(node.bounds.hi[k]));
        }
        add(node.right_child);
        add(node.first_triangle);
        add(node.triangle_count);
    }
    for (uint32_t t : bvh.triangle_order)
        add(t);
    return fnv.hash();
}

/// The sweep builder's tree of `triangles` built on `threads` host threads (more than the host
/// has cores, too: the arena has that many slots and the limit lets that many run).
Bvh build_on_threads(const std::vector<Triangle>& triangles, int threads) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    tbb::task_arena arena(threads);
    return arena.execute([&] {
        REQUIRE(tbb::this_task_arena::max_concurrency() == threads);
        return build_bvh(triangles, {.builder = BvhBuilder::sweep});
    });
}

}  // namespace

TEST_CASE("A hand-computed two-triangle tree has the expected SAH cost", "[bvh]") {
    // Each triangle's box is a unit cube (area 6); together they span [0,10]x[0,1]x[0,1] (area 42).
    // Leaf: 2 * 42 = 84; split: 42 + 6 + 6 = 54 -> split, cost (42 + 6 + 6) / 42.
    const std::vector<Triangle> triangles{{{0, 0, 0}, {1, 1, 0}, {1, 0, 1}, 0},
                                          {{9, 0, 0}, {10, 1, 0}, {10, 0, 1}, 0}};
    for (BvhBuilder builder : kBuilders) {
        const Bvh bvh = build_bvh(triangles, {.builder = builder});
        CHECK(bvh.stats.nodes == 3);
        CHECK(bvh.stats.sah_cost == Approx(54.0 / 42.0));
    }
}

TEST_CASE("Overlapping triangles stay in one leaf when splitting does not pay", "[bvh]") {
    // Same box twice: leaf 2A against split A + A + A.
    const Triangle t{{0, 0, 0}, {1, 1, 0}, {1, 0, 1}, 0};
    for (BvhBuilder builder : kBuilders) {
        const Bvh bvh = build_bvh(std::vector<Triangle>{t, t}, {.builder = builder});
        CHECK(bvh.stats.nodes == 1);
        CHECK(bvh.stats.sah_cost == Approx(2.0));
    }
}

TEST_CASE("Random soups give valid trees for every builder and leaf size", "[bvh]") {
    const auto triangles = random_soup(5000, 42);
    for (BvhBuilder builder : kBuilders)
        for (uint32_t leaf : {1u, 2u, 4u, 8u}) {
            INFO(to_string(builder) << " leaf " << leaf);
            const BvhConfig config{.builder = builder, .max_leaf_size = leaf};
            const Bvh bvh = build_bvh(triangles, config);
            check_invariants(bvh, triangles, config);
            CHECK(bvh.stats.sah_cost == Approx(sah_cost(bvh)));
            CHECK(bvh.stats.depth_limited_nodes == 0);
        }
}

TEST_CASE("Builds are deterministic", "[bvh]") {
    const auto triangles = random_soup(20000, 7);
    for (BvhBuilder builder : kBuilders) {
        const Bvh a = build_bvh(triangles, {.builder = builder});
        const Bvh b = build_bvh(triangles, {.builder = builder});
        REQUIRE(a.triangle_order == b.triangle_order);
        REQUIRE(a.nodes.size() == b.nodes.size());
        for (size_t i = 0; i < a.nodes.size(); ++i) {
            REQUIRE(a.nodes[i].bounds.lo == b.nodes[i].bounds.lo);
            REQUIRE(a.nodes[i].bounds.hi == b.nodes[i].bounds.hi);
            REQUIRE(a.nodes[i].right_child == b.nodes[i].right_child);
            REQUIRE(a.nodes[i].first_triangle == b.nodes[i].first_triangle);
            REQUIRE(a.nodes[i].triangle_count == b.nodes[i].triangle_count);
        }
    }
}

TEST_CASE("The sweep builder gives the same tree on 1, 2, 3 and 8 threads", "[bvh]") {
    // Big enough that the axes are swept in parallel and subtrees built in parallel; the
    // strip's depth limit makes the feasible split differ from the best one.
    for (const auto& triangles :
         {random_soup(150000, 11), geometric_strip(20000), signed_zero_soup(3000, 5)}) {
        const Bvh one = build_on_threads(triangles, 1);
        check_invariants(one, triangles, {});
        for (int threads : {2, 3, 8}) {
            const Bvh many = build_on_threads(triangles, threads);
            CHECK(digest(many) == digest(one));
            CHECK(many.stats.nodes == one.stats.nodes);
            CHECK(many.stats.max_depth == one.stats.max_depth);
            CHECK(many.stats.sah_cost == one.stats.sah_cost);
            CHECK(many.stats.depth_limited_nodes == one.stats.depth_limited_nodes);
            CHECK(many.stats.leaf_size_histogram == one.stats.leaf_size_histogram);
        }
    }
}

TEST_CASE("The sweep builder's trees are pinned: any change moves the reference figures", "[bvh]") {
    // Digests of the trees the single-threaded builder of 2026-11 made (before the parallel,
    // streaming one): its tree decides every cycle count in the README. A new digest here means
    // a new tree; say so and update the figures.
    CHECK(digest(build_bvh(random_soup(150000, 11))) == 0xef37273e464691a7ull);
    CHECK(digest(build_bvh(geometric_strip(20000))) == 0xd90c9ac967f87702ull);
    CHECK(digest(build_bvh(signed_zero_soup(3000, 5))) == 0x6ad949ba707ca8f7ull);
    CHECK(digest(build_bvh(load_scene(TPSIM_SCENES_DIR "/cornell.toml").triangles)) ==
          0xb7ee23433d63882bull);
    const std::filesystem::path bunny = TPSIM_SCENES_DIR "/bunny.toml";
    if (std::filesystem::exists("/usr/share/glmark2/models/bunny.obj"))
        CHECK(digest(build_bvh(load_scene(bunny).triangles)) == 0xdbd157326eb537deull);
}

TEST_CASE("The depth limit holds on a 2^20-triangle geometric strip", "[bvh][slow]") {
    const auto triangles = geometric_strip(1u << 20);
    for (BvhBuilder builder : kBuilders) {
        INFO(to_string(builder));
        const BvhConfig config{.builder = builder};
        const Bvh bvh = build_bvh(triangles, config);
        check_invariants(bvh, triangles, config);
        // 17 entries hold exactly 8 * 2^17 = 2^20 triangles: only full leaves in a perfectly
        // balanced tree fit, far from what the SAH wants, so the limit must take over.
        const BvhConfig tight{.builder = builder, .traversal_stack_entries = 17};
        const Bvh limited = build_bvh(triangles, tight);
        check_invariants(limited, triangles, tight);
        CHECK(limited.stats.depth_limited_nodes > 0);
        CHECK(limited.stats.leaf_size_histogram[8] == limited.stats.leaves);
    }
}

TEST_CASE("A tiny stack forces a shallow tree and says so", "[bvh]") {
    // 1000 triangles, leaves of 8 and depth <= 7: at most 8 * 2^7 = 1024 triangles fit, so
    // the limit must shape the tree.
    const auto triangles = geometric_strip(1000);
    for (BvhBuilder builder : kBuilders) {
        INFO(to_string(builder));
        const BvhConfig config{.builder = builder, .traversal_stack_entries = 7};
        const Bvh bvh = build_bvh(triangles, config);
        check_invariants(bvh, triangles, config);
        CHECK(bvh.stats.depth_limited_nodes > 0);
    }
    const BvhConfig too_small{.traversal_stack_entries = 6};
    CHECK_THROWS_WITH(build_bvh(triangles, too_small), Catch::Contains("traversal_stack_entries"));
}

TEST_CASE("Identical and degenerate triangles build valid trees", "[bvh]") {
    std::vector<Triangle> triangles(1000, Triangle{{1, 2, 3}, {4, 5, 6}, {7, 8, 10}, 0});
    std::vector<Triangle> points(300, Triangle{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, 0});
    std::vector<Triangle> lines;
    for (int i = 0; i < 300; ++i)
        lines.push_back({{float(i), 0, 0}, {float(i + 1), 0, 0}, {float(i), 0, 0}, 0});
    for (const auto* soup : {&triangles, &points, &lines})
        for (BvhBuilder builder : kBuilders) {
            const BvhConfig config{.builder = builder};
            const Bvh bvh = build_bvh(*soup, config);
            check_invariants(bvh, *soup, config);
            CHECK(bvh.stats.max_depth <= 10);  // ties split in half: log2(1000 / 8) ~ 7
        }
}

TEST_CASE("The SAH cost does not depend on scale or position", "[bvh]") {
    std::vector<Triangle> sphere;
    generate_sphere({{0, 0, 0}, 1.f, 48, 24}, 0, sphere);
    const double reference = build_bvh(sphere).stats.sah_cost;
    for (float scale : {1e-4f, 1e4f})
        for (float shift : {0.f, 1e5f}) {
            INFO("scale " << scale << " shift " << shift);
            std::vector<Triangle> moved = sphere;
            for (Triangle& t : moved)
                for (glm::vec3* v : {&t.v0, &t.v1, &t.v2})
                    *v = *v * scale + glm::vec3(shift);
            for (BvhBuilder builder : kBuilders) {
                const BvhConfig config{.builder = builder};
                const Bvh bvh = build_bvh(moved, config);
                check_invariants(bvh, moved, config);
                // At 1e-4 scale and 1e5 offset float spacing (~0.008) exceeds the sphere: it
                // collapses to a point, so only the well-conditioned cases must match.
                if (shift == 0.f || scale >= 1.f)
                    CHECK(bvh.stats.sah_cost == Approx(reference).epsilon(0.05));
            }
        }
}

TEST_CASE("Bad input and bad configs are rejected with a clear message", "[bvh]") {
    const std::vector<Triangle> one{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0}};
    CHECK_THROWS_WITH(build_bvh(std::vector<Triangle>{}), Catch::Contains("no triangles"));
    CHECK_THROWS_WITH(build_bvh(one, {.max_leaf_size = 0}),
                      Catch::Contains("max_leaf_size must be in 1..8"));
    CHECK_THROWS_WITH(build_bvh(one, {.max_leaf_size = 9}),
                      Catch::Contains("max_leaf_size must be in 1..8"));
    CHECK_THROWS_WITH(build_bvh(one, {.bins = 1}), Catch::Contains("bins"));
    std::vector<Triangle> bad = one;
    bad[0].v1.y = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH(build_bvh(bad), Catch::Contains("triangle 0"));
    bad[0].v1.y = 1e30f;
    CHECK_THROWS_WITH(build_bvh(bad), Catch::Contains("within"));
}

TEST_CASE("Bunny: sweep SAH cost <= 32.5", "[bvh][bunny]") {
    const std::filesystem::path bunny = "/usr/share/glmark2/models/bunny.obj";
    if (!std::filesystem::exists(bunny)) {
        WARN("SKIPPED: " << bunny << " missing; install glmark2-data (scripts/setup does)");
        return;
    }
    const Scene scene = load_scene(bunny);
    REQUIRE(scene.triangles.size() == 69666);
    for (BvhBuilder builder : kBuilders) {
        const BvhConfig config{.builder = builder};
        const Bvh bvh = build_bvh(scene.triangles, config);
        check_invariants(bvh, scene.triangles, config);
        // Best public binary builders reach 31.5-31.9 with this cost model; binned may trail.
        CHECK(bvh.stats.sah_cost <= (builder == BvhBuilder::sweep ? 32.5 : 33.5));
        CHECK(bvh.stats.sah_cost > 20.0);  // far below the state of the art would mean a wrong cost
    }
}

TEST_CASE("The median builder halves every node: valid, balanced, no better than the SAH",
          "[bvh]") {
    const auto triangles = random_soup(5000, 42);
    for (uint32_t leaf : {1u, 2u, 4u, 8u}) {
        INFO("leaf " << leaf);
        const BvhConfig config{.builder = BvhBuilder::median, .max_leaf_size = leaf};
        const Bvh bvh = build_bvh(triangles, config);
        check_invariants(bvh, triangles, config);
        CHECK(bvh.stats.sah_cost == Approx(sah_cost(bvh)));
        // Halving 5000 until at most `leaf` remain: ceil(log2(ceil(5000 / leaf))) levels.
        const auto expected_depth = uint32_t(std::ceil(std::log2(std::ceil(5000.0 / leaf))));
        CHECK(bvh.stats.max_depth == expected_depth);
        CHECK(bvh.stats.sah_cost > build_bvh(triangles, {.max_leaf_size = leaf}).stats.sah_cost);
        const Bvh again = build_bvh(triangles, config);
        CHECK(again.triangle_order == bvh.triangle_order);
    }
    // Always within the depth limit, even where the SAH builders must be forced: 1000
    // triangles, leaves of 8, depth <= 7.
    const auto strip = geometric_strip(1000);
    const BvhConfig tight{.builder = BvhBuilder::median, .traversal_stack_entries = 7};
    const Bvh shallow = build_bvh(strip, tight);
    check_invariants(shallow, strip, tight);
    CHECK(shallow.stats.depth_limited_nodes == 0);
    CHECK(std::string(to_string(BvhBuilder::median)) == "median");
}

namespace {

using tpsim::image::compile_bvh;
using ImageNode = trax::layout::BvhNode;

/// Interior image nodes (their `first`, the index of their pair) in breadth-first (FIFO) or
/// depth-first (pre-order, left first) order of the image tree.
std::vector<int32_t> pairs_in_walk(const std::vector<ImageNode>& nodes, bool breadth_first) {
    std::vector<int32_t> out;
    std::deque<int32_t> pending{0};
    while (!pending.empty()) {
        const int32_t n = breadth_first ? pending.front() : pending.back();
        breadth_first ? pending.pop_front() : pending.pop_back();
        if (nodes[size_t(n)].count != 0) continue;
        const int32_t first = nodes[size_t(n)].first;
        out.push_back(first);
        if (breadth_first) {
            pending.push_back(first);
            pending.push_back(first + 1);
        } else {
            pending.push_back(first + 1);
            pending.push_back(first);
        }
    }
    return out;
}

/// The image tree is the builder's tree: the same boxes and leaf ranges, node for node, every
/// image node but the padding reached once; pairs line-aligned when asked.
void check_same_tree(const Bvh& bvh, const std::vector<ImageNode>& nodes, bool align_pairs) {
    REQUIRE(nodes.size() == bvh.nodes.size() + (align_pairs ? 1 : 0));
    std::vector<int> reached(nodes.size(), 0);
    std::vector<std::pair<uint32_t, int32_t>> pending{{0, 0}};  // builder node, image node
    while (!pending.empty()) {
        const auto [b, i] = pending.back();
        pending.pop_back();
        REQUIRE(size_t(i) < nodes.size());
        ++reached[size_t(i)];
        const BvhNode& built = bvh.nodes[b];
        const ImageNode& laid = nodes[size_t(i)];
        for (int k = 0; k < 3; ++k) {
            REQUIRE(laid.bounds_min[k] == built.bounds.lo[k]);
            REQUIRE(laid.bounds_max[k] == built.bounds.hi[k]);
        }
        if (built.is_leaf()) {
            REQUIRE(laid.count == int32_t(built.triangle_count));
            REQUIRE(laid.first == int32_t(built.first_triangle));
        } else {
            REQUIRE(laid.count == 0);
            if (align_pairs) REQUIRE(laid.first % 2 == 0);  // 32-byte nodes: a 64-byte line
            pending.push_back({b + 1, laid.first});
            pending.push_back({built.right_child, laid.first + 1});
        }
    }
    for (size_t i = 0; i < nodes.size(); ++i) {
        INFO("image node " << i);
        CHECK(reached[i] == (align_pairs && i == 1 ? 0 : 1));
    }
}

/// Depth of each pair (by its index in memory) in the tree of pairs, the root's pair at 0.
std::vector<uint32_t> pair_depths(const std::vector<ImageNode>& nodes, int32_t first_pair) {
    std::vector<uint32_t> depth(nodes.size() / 2 + 1, 0);
    std::vector<std::pair<int32_t, uint32_t>> pending{{0, 0}};
    while (!pending.empty()) {
        const auto [n, d] = pending.back();
        pending.pop_back();
        if (nodes[size_t(n)].count != 0) continue;
        const int32_t first = nodes[size_t(n)].first;
        depth[size_t((first - first_pair) / 2)] = d;
        pending.push_back({first, d + 1});
        pending.push_back({first + 1, d + 1});
    }
    return depth;
}

}  // namespace

TEST_CASE("Every node order lays out the builder's tree, pairs in the order it names",
          "[bvh][layout]") {
    // A random soup (bushy) and a geometric strip (a deep, lopsided tree).
    const auto soup = random_soup(5000, 42);
    const auto strip = geometric_strip(3000);
    for (const auto* triangles : {&soup, &strip}) {
        const Bvh bvh = build_bvh(*triangles);
        REQUIRE(bvh.stats.max_depth >= 8);
        for (BvhOrder order : kBvhOrders)
            for (bool align : {false, true}) {
                INFO(to_string(order)
                     << (align ? ", aligned" : "") << ", " << triangles->size() << " triangles");
                const std::vector<ImageNode> nodes = compile_bvh(bvh, order, align);
                check_same_tree(bvh, nodes, align);
                const int32_t first_pair = align ? 2 : 1;
                const uint32_t pairs = uint32_t(nodes.size() - size_t(first_pair)) / 2;
                std::vector<int32_t> consecutive(pairs);
                for (uint32_t j = 0; j < pairs; ++j)
                    consecutive[j] = first_pair + 2 * int32_t(j);
                if (order == BvhOrder::breadth_first)
                    CHECK(pairs_in_walk(nodes, true) == consecutive);
                if (order == BvhOrder::depth_first)
                    CHECK(pairs_in_walk(nodes, false) == consecutive);
                if (order == BvhOrder::van_emde_boas) {
                    // The top half of the tree of pairs comes first, and is not the breadth-
                    // or depth-first order.
                    const std::vector<uint32_t> depth = pair_depths(nodes, first_pair);
                    const uint32_t height =
                        *std::max_element(depth.begin(), depth.begin() + pairs) + 1;
                    const uint32_t top = height / 2;
                    const auto in_top = uint32_t(std::count_if(
                        depth.begin(), depth.begin() + pairs, [&](uint32_t d) { return d < top; }));
                    for (uint32_t j = 0; j < pairs; ++j) {
                        INFO("pair " << j);
                        REQUIRE((depth[j] < top) == (j < in_top));
                    }
                    CHECK(pairs_in_walk(nodes, true) != consecutive);
                    CHECK(pairs_in_walk(nodes, false) != consecutive);
                }
            }
    }
    for (BvhOrder order : kBvhOrders)
        CHECK(find_bvh_order(to_string(order)) == order);
    CHECK(!find_bvh_order("depth_first").has_value());
}

TEST_CASE("A tree that is one leaf lays out as one node in every order", "[bvh][layout]") {
    const auto one = random_soup(1, 1);
    const Bvh bvh = build_bvh(one);
    REQUIRE(bvh.nodes.size() == 1);
    for (BvhOrder order : kBvhOrders)
        for (bool align : {false, true}) {
            const std::vector<ImageNode> nodes = compile_bvh(bvh, order, align);
            REQUIRE(nodes.size() == 1);
            CHECK(nodes[0].count == 1);
        }
}
