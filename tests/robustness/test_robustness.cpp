// Stiff and extreme ray-tracing cases (docs/robustness.md), traced by the ray_query kernels
// through every structure (the tracer's BVH traversal, the wide BVHs in both box formats, the
// uniform grid), on the functional simulator AND the native twin: every result must agree bit
// for bit between the two, and meet the geometric expectation, for each structure.
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <utility>

#include <catch2/catch.hpp>

#include "sim/image/memory_image.hpp"
#include "sim/render/render.hpp"
#include "sim/scene/accel.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/grid.hpp"
#include "tests/robustness/ray_query_run.hpp"
#include "tests/scene/wide_bvh_image.hpp"

using namespace tpsim;
using trax::layout::Ray;
using trax::layout::RayResult;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

using Mesh = std::vector<scene::Triangle>;

/// The unit cube [0,1]^3, each face an n x n grid of quads (two triangles each), outward
/// winding. Grid vertices are computed once per face from integers, so shared edges and
/// vertices are bit-identical between neighbouring triangles: the mesh is closed.
Mesh grid_cube(int n) {
    Mesh mesh;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const auto point = [&](int i, int j) {
                glm::vec3 p;
                p[axis] = float(side);
                p[(axis + 1) % 3] = float(i) / float(n);
                p[(axis + 2) % 3] = float(j) / float(n);
                return p;
            };
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    const glm::vec3 a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1),
                                    d = point(i, j + 1);
                    if (side == 1) {
                        mesh.push_back({a, b, c});
                        mesh.push_back({a, c, d});
                    } else {
                        mesh.push_back({a, c, b});
                        mesh.push_back({a, d, c});
                    }
                }
        }
    return mesh;
}

/// Icosahedron subdivided `levels` times, vertices on the unit sphere. Each edge midpoint is
/// created once and shared, so the mesh is closed.
Mesh icosphere(int levels) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (glm::vec3& p : v)
        p = glm::normalize(p);
    std::vector<std::array<uint32_t, 3>> faces = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
        const auto midpoint = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto [it, added] = midpoints.try_emplace({key.first, key.second}, 0);
            if (added) {
                it->second = uint32_t(v.size());
                v.push_back(glm::normalize(v[a] + v[b]));
            }
            return it->second;
        };
        std::vector<std::array<uint32_t, 3>> finer;
        for (const auto& f : faces) {
            const uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]),
                           ca = midpoint(f[2], f[0]);
            finer.push_back({f[0], ab, ca});
            finer.push_back({f[1], bc, ab});
            finer.push_back({f[2], ca, bc});
            finer.push_back({ab, bc, ca});
        }
        faces = std::move(finer);
    }
    Mesh mesh;
    for (const auto& f : faces)
        mesh.push_back({v[f[0]], v[f[1]], v[f[2]]});
    return mesh;
}

Mesh transformed(Mesh mesh, float scale, glm::vec3 offset) {
    for (scene::Triangle& t : mesh)
        for (glm::vec3* p : {&t.v0, &t.v1, &t.v2})
            *p = *p * scale + offset;
    return mesh;
}

Ray make_ray(glm::vec3 origin, glm::vec3 dir, float t_max, int mode = trax::layout::kRayClosestHit,
             glm::vec3 target = glm::vec3(0.0f)) {
    return Ray{{origin.x, origin.y, origin.z},
               {dir.x, dir.y, dir.z},
               t_max,
               mode,
               {target.x, target.y, target.z}};
}

using scene::AccelStructure;
using test::AccelVariant;

/// Each test runs once per structure (and wide-BVH box format).
#define EACH_STRUCTURE                                                                             \
    const AccelVariant variant =                                                                   \
        GENERATE(from_range(std::begin(test::kAccelVariants), std::end(test::kAccelVariants)));    \
    INFO("through the " << test::to_string(variant))

struct Queries {
    explicit Queries(test::BuiltAccel b) : built(std::move(b)) {}
    test::BuiltAccel built;
    std::vector<RayResult> results;  ///< one per ray, identical on both engines
    uint32_t scene_triangle(int32_t image_index) const { return built.scene_triangle(image_index); }
    uint64_t most_nodes() const { return built.most_nodes(); }
};

scene::Bvh bvh_for(const Mesh& mesh) {
    scene::BvhConfig config;
    config.traversal_stack_entries = trax::layout::kTraversalStackEntries;
    return scene::build_bvh(mesh, config);
}

/// Runs the structure's ray_query kernel over `rays` on both engines; REQUIREs that they agree
/// bit for bit.
Queries run_queries(const Mesh& mesh, const std::vector<Ray>& rays, AccelVariant variant) {
    Queries q{test::BuiltAccel(mesh, variant)};
    test::RayQueryRun run =
        test::run_ray_query(mesh, q.built, rays, 20000 * uint64_t(rays.size()) + 100000);
    // A kRayFromSurface query whose first ray hit traces a second one.
    size_t second_rays = 0;
    for (size_t i = 0; i < rays.size(); ++i)
        second_rays +=
            (rays[i].mode & trax::layout::kRayFromSurface) && run.results[i].surface_triangle >= 0;
    for (const image::TraversalTotals& totals : run.totals) {
        CHECK(totals.rays() == rays.size() + second_rays);
        CHECK(totals.stack_overflows == 0);
    }
    q.results = std::move(run.results);
    return q;
}

/// Every distinct vertex and edge midpoint of the mesh.
std::vector<glm::vec3> vertices_and_edge_midpoints(const Mesh& mesh) {
    std::vector<glm::vec3> targets;
    const auto add = [&targets](glm::vec3 p) {
        for (const glm::vec3& q : targets)
            if (q == p) return;
        targets.push_back(p);
    };
    for (const scene::Triangle& t : mesh) {
        add(t.v0);
        add(t.v1);
        add(t.v2);
        add((t.v0 + t.v1) * 0.5f);
        add((t.v1 + t.v2) * 0.5f);
        add((t.v2 + t.v0) * 0.5f);
    }
    return targets;
}

/// Rays from `inside` aimed exactly at every vertex and edge midpoint, closest- and any-hit:
/// a closed mesh must catch every one (zero leaks) at t ~ 1 (the target is on the surface).
void check_no_leaks(const Mesh& mesh, glm::vec3 inside, AccelVariant variant) {
    const std::vector<glm::vec3> targets = vertices_and_edge_midpoints(mesh);
    std::vector<Ray> rays;
    for (const glm::vec3& target : targets) {
        rays.push_back(make_ray(inside, target - inside, kInf));
        rays.push_back(make_ray(inside, target - inside, kInf, trax::layout::kRayAnyHit));
    }
    const Queries q = run_queries(mesh, rays, variant);
    size_t leaks = 0, closest_off = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        const RayResult& r = q.results[i];
        if (r.triangle < 0 || !std::isfinite(r.t)) ++leaks;
        // Closest hit of a ray aimed at a surface point of a convex or star-shaped mesh.
        else if (i % 2 == 0 && std::abs(r.t - 1.0f) > 1e-4f)
            ++closest_off;
    }
    INFO(targets.size() << " targets, " << leaks << " leaks, " << closest_off
                        << " closest hits not at the target");
    CHECK(leaks == 0);
    CHECK(closest_off == 0);
}

}  // namespace

TEST_CASE("robustness: rays at every vertex and edge of closed meshes never leak", "[robustness]") {
    EACH_STRUCTURE;
    const Mesh cube = grid_cube(3), sphere = icosphere(2);
    struct Placement {
        const char* name;
        float scale;
        glm::vec3 offset;
    };
    // 1e5 is translated with a mesh of size 100: float spacing there is 1/128.
    const Placement placements[] = {{"unit", 1.0f, glm::vec3(0.0f)},
                                    {"scaled 1e-4", 1e-4f, glm::vec3(0.0f)},
                                    {"scaled 1e4", 1e4f, glm::vec3(0.0f)},
                                    {"translated 1e5", 100.0f, glm::vec3(1e5f, -1e5f, 1e5f)}};
    for (const Placement& p : placements) {
        SECTION(std::string("grid cube, ") + p.name) {
            // The centre, and an off-centre point: different directions hit different edges.
            check_no_leaks(transformed(cube, p.scale, p.offset),
                           glm::vec3(0.5f) * p.scale + p.offset, variant);
            check_no_leaks(transformed(cube, p.scale, p.offset),
                           glm::vec3(0.3f, 0.55f, 0.7f) * p.scale + p.offset, variant);
        }
        SECTION(std::string("icosphere, ") + p.name) {
            check_no_leaks(transformed(sphere, p.scale, p.offset), p.offset, variant);
            check_no_leaks(transformed(sphere, p.scale, p.offset),
                           glm::vec3(0.2f, -0.3f, 0.1f) * p.scale + p.offset, variant);
        }
    }
}

TEST_CASE("robustness: grazing rays inside a closed cube always hit, at the right distance",
          "[robustness]") {
    EACH_STRUCTURE;
    const Mesh cube = grid_cube(4);
    std::vector<Ray> rays;
    std::vector<float> expected;
    // From just under the top face, almost parallel to it: exits through the side x = 1 at
    // t = 1 - 0.1 (direction x component 1) or clips the top face first.
    for (float rise : {0.0f, 1e-9f, 1e-6f, 1e-3f}) {
        for (float below : {1e-7f, 1e-4f}) {
            const glm::vec3 origin(0.1f, 0.37f, 1.0f - below);
            const glm::vec3 dir(1.0f, 0.0f, rise);
            rays.push_back(make_ray(origin, dir, kInf));
            // The float origin's distance to the top face, exact (Sterbenz).
            const float gap = 1.0f - origin.z;
            expected.push_back(std::min(0.9f, gap / std::max(rise, 1e-30f)));
        }
    }
    const Queries q = run_queries(cube, rays, variant);
    for (size_t i = 0; i < rays.size(); ++i) {
        INFO("ray " << i);
        CHECK(q.results[i].triangle >= 0);
        CHECK(q.results[i].t == Approx(expected[i]).epsilon(1e-4));
    }
}

TEST_CASE("robustness: axis-aligned rays with the origin on BVH box and grid cell planes",
          "[robustness]") {
    EACH_STRUCTURE;
    // A 4x4 grid per face: leaf boxes have planes at multiples of 1/4 inside the cube.
    const Mesh cube = grid_cube(4);
    // The planes the structure's traversal computes distances to: node boxes', cell faces or
    // split planes.
    std::array<std::vector<float>, 3> planes;
    if (variant.structure == AccelStructure::grid) {
        const scene::Grid grid = scene::build_grid(cube);
        for (int axis = 0; axis < 3; ++axis)
            for (uint32_t c = 0; c <= grid.stats.resolution[size_t(axis)]; ++c) {
                // As kernel/grid.hpp computes a cell face.
                const float cell =
                    (grid.hi[axis] - grid.lo[axis]) / float(grid.stats.resolution[size_t(axis)]);
                planes[size_t(axis)].push_back(grid.lo[axis] + float(c) * cell);
            }
    } else if (variant.structure == AccelStructure::kdtree) {
        for (const scene::KdNode& node : scene::build_kdtree(cube).nodes)
            if (!node.is_leaf()) planes[node.axis].push_back(node.split);
    } else if (variant.structure == AccelStructure::bsp) {
        scene::KdTreeConfig bsp;
        bsp.general_planes = true;
        for (const scene::KdNode& node : scene::build_kdtree(cube, bsp).nodes)
            if (!node.is_leaf() && node.axis < 3) planes[node.axis].push_back(node.split);
    } else if (variant.structure == AccelStructure::octree) {
        for (const scene::OctreeNode& node : scene::build_octree(cube).nodes)
            if (!node.leaf)
                for (int axis = 0; axis < 3; ++axis)
                    planes[size_t(axis)].push_back(node.centre[size_t(axis)]);
    } else if (scene::wide_bvh_width(variant.structure) != 0) {
        // The child boxes as the kernel decodes them (quantized ones lie on their own grid).
        const test::BuiltAccel built(cube, variant);
        scene::Scene s;
        s.triangles = cube;
        s.materials.resize(1);
        s.width = s.height = 1;
        for (const test::ImageWideNode& node :
             test::read_wide_bvh(image::build_memory_image(s, built.accel(), 1)))
            for (const test::ImageWideChild& child : node.children)
                for (int axis = 0; axis < 3; ++axis) {
                    planes[size_t(axis)].push_back(child.lo[axis]);
                    planes[size_t(axis)].push_back(child.hi[axis]);
                }
    } else {
        for (const scene::BvhNode& node : bvh_for(cube).nodes)
            for (int axis = 0; axis < 3; ++axis) {
                planes[size_t(axis)].push_back(node.bounds.lo[axis]);
                planes[size_t(axis)].push_back(node.bounds.hi[axis]);
            }
    }
    std::vector<Ray> rays;
    std::vector<float> expected;
    for (int axis = 0; axis < 3; ++axis)
        for (float plane : planes[size_t(axis)]) {
            if (plane <= 0.0f || plane >= 1.0f) continue;  // only planes inside the cube
            for (int dir_axis = 0; dir_axis < 3; ++dir_axis)
                for (float sign : {-1.0f, 1.0f}) {
                    glm::vec3 origin(0.3f, 0.6f, 0.45f);
                    origin[axis] = plane;
                    glm::vec3 dir(0.0f);
                    dir[dir_axis] = sign;
                    rays.push_back(make_ray(origin, dir, kInf));
                    // The unit cube's face along the direction: independent of the mesh.
                    expected.push_back(sign > 0 ? 1.0f - origin[dir_axis] : origin[dir_axis]);
                }
        }
    REQUIRE(!rays.empty());
    const Queries q = run_queries(cube, rays, variant);
    size_t wrong = 0;
    for (size_t i = 0; i < rays.size(); ++i)
        wrong += q.results[i].triangle < 0 || std::abs(q.results[i].t - expected[i]) > 1e-6f;
    INFO(rays.size() << " rays, " << wrong << " missed or at the wrong distance");
    CHECK(wrong == 0);
}

TEST_CASE("robustness: degenerate and zero-area triangles are never hit and give no NaN",
          "[robustness]") {
    EACH_STRUCTURE;
    Mesh mesh = grid_cube(2);
    const size_t first_degenerate = mesh.size();
    const glm::vec3 a(2.0f, 0.5f, 0.5f), b(3.0f, 0.5f, 0.5f), c(2.5f, 0.5f, 0.5f);
    mesh.push_back({a, b, c});  // collinear
    mesh.push_back({a, a, b});  // repeated vertex
    mesh.push_back({c, c, c});  // a point
    mesh.push_back({a, b, a});
    std::vector<Ray> rays;
    const glm::vec3 origins[] = {
        {2.5f, 2.0f, 0.5f}, {2.5f, 0.5f, -1.0f}, {1.5f, 0.5f, 0.5f}, {2.2f, 0.5f, 0.5f}};
    for (const glm::vec3& o : origins)
        for (const glm::vec3& target : {a, b, c, (a + b) * 0.5f}) {
            if (o == target) continue;
            rays.push_back(make_ray(o, target - o, kInf));
            rays.push_back(make_ray(o, target - o, kInf, trax::layout::kRayAnyHit));
        }
    const Queries q = run_queries(mesh, rays, variant);
    for (size_t i = 0; i < rays.size(); ++i) {
        const RayResult& r = q.results[i];
        INFO("ray " << i);
        CHECK(!std::isnan(r.t));
        if (r.triangle >= 0) CHECK(q.scene_triangle(r.triangle) < first_degenerate);
    }
}

TEST_CASE("robustness: NaN and infinite rays terminate without overflow, NaN rays hit nothing",
          "[robustness]") {
    EACH_STRUCTURE;
    const Mesh sphere = icosphere(2);
    const glm::vec3 o(0.1f, 0.2f, 0.3f), d(0.3f, -0.5f, 0.8f);
    std::vector<Ray> rays;
    std::vector<bool> must_miss;
    for (int axis = 0; axis < 3; ++axis)
        for (float bad : {kNaN, kInf, -kInf}) {
            glm::vec3 bad_o = o, bad_d = d;
            bad_o[axis] = bad;
            bad_d[axis] = bad;
            rays.push_back(make_ray(bad_o, d, kInf));
            rays.push_back(make_ray(o, bad_d, kInf));
            rays.push_back(make_ray(bad_o, d, kInf, trax::layout::kRayAnyHit));
            must_miss.insert(must_miss.end(), 3, std::isnan(bad));
        }
    for (float t_max : {kNaN, -kInf, -1.0f, 0.0f}) {
        rays.push_back(make_ray(o, d, t_max));
        must_miss.push_back(true);
    }
    rays.push_back(make_ray(o, glm::vec3(0.0f), kInf));  // no direction
    must_miss.push_back(true);
    rays.push_back(make_ray(glm::vec3(kNaN), glm::vec3(kNaN), kNaN));
    must_miss.push_back(true);

    const Queries q = run_queries(sphere, rays, variant);  // finite instruction budget: no hang
    for (size_t i = 0; i < rays.size(); ++i) {
        const RayResult& r = q.results[i];
        INFO("ray " << i);
        CHECK(r.stack_overflows == 0);
        CHECK(r.nodes_visited <= q.most_nodes());
        if (must_miss[i]) CHECK(r.triangle == -1);
        if (r.triangle >= 0) CHECK(std::isfinite(r.t));
    }
}

TEST_CASE("robustness: rays leaving a surface never hit their own triangle", "[robustness]") {
    EACH_STRUCTURE;
    const float scales[] = {1.0f, 1e-4f, 1e4f, 100.0f};
    const glm::vec3 offsets[] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f),
                                 glm::vec3(1e5f, 1e5f, -1e5f)};
    const glm::vec3 weights[] = {
        {1 / 3.f, 1 / 3.f, 1 / 3.f}, {0.98f, 0.01f, 0.01f}, {0.5f, 0.5f, 0.0f}, {1.0f, 0.0f, 0.0f}};
    for (int k = 0; k < 4; ++k) {
        // Shared vertices and edges included: a vertex (weight 1) lies on several triangles.
        const Mesh mesh = transformed(icosphere(1), scales[k], offsets[k]);
        std::vector<Ray> rays;
        for (const scene::Triangle& tri : mesh) {
            const glm::vec3 n = glm::normalize(glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
            for (const glm::vec3& w : weights) {
                const glm::vec3 p = tri.v0 * w.x + tri.v1 * w.y + tri.v2 * w.z;
                const glm::vec3 tangent = glm::normalize(tri.v1 - tri.v0);
                // A camera ray onto p from outside, then from its hit outward to a light (a
                // shadow ray, also at a grazing angle) and inward through the far side.
                const glm::vec3 eye = p + (n + tangent * 0.3f) * scales[k];
                for (const glm::vec3& to :
                     {n * scales[k], (n * 0.05f + tangent) * scales[k], -n * 4.0f * scales[k]}) {
                    const int mode = trax::layout::kRayFromSurface;
                    rays.push_back(
                        make_ray(eye, p - eye, kInf, mode | trax::layout::kRayAnyHit, p + to));
                    rays.push_back(make_ray(eye, p - eye, kInf, mode, p + to));
                }
            }
        }
        const Queries q = run_queries(mesh, rays, variant);
        size_t surface_misses = 0, self_hits = 0, inward_misses = 0, outward_hits = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
            const RayResult& r = q.results[i];
            surface_misses += r.surface_triangle < 0;
            if (r.triangle >= 0 && r.triangle == r.surface_triangle) ++self_hits;
            const bool inward = (i / 2) % 3 == 2;
            if (inward && r.triangle < 0) ++inward_misses;
            // A convex mesh: nothing lies outside it, along the normal.
            if ((i / 2) % 3 == 0 && r.triangle >= 0) ++outward_hits;
        }
        INFO("scale " << scales[k] << ": " << surface_misses << " camera rays missed, " << self_hits
                      << " self hits, " << inward_misses << " inward misses, " << outward_hits
                      << " outward hits of " << rays.size());
        CHECK(surface_misses == 0);
        CHECK(self_hits == 0);
        CHECK(inward_misses == 0);
        CHECK(outward_hits == 0);
    }
}

TEST_CASE("robustness: a hit point on a large floor at y = 0 does not shadow itself",
          "[robustness]") {
    EACH_STRUCTURE;
    // The Cornell box's floor seen from its camera: with the paper's absolute "near the
    // origin" offset (1/65536) half of these points were shadowed by the floor.
    const glm::vec3 a(0.0f, 0.0f, 0.0f), b(556.0f, 0.0f, 0.0f), c(556.0f, 0.0f, 559.0f),
        d(0.0f, 0.0f, 559.0f);
    const Mesh floor = {{a, b, c}, {a, c, d}};
    const glm::vec3 eye(278.0f, 273.0f, -800.0f);
    std::vector<Ray> rays;
    for (int i = 1; i < 40; ++i)
        for (int j = 1; j < 40; ++j) {
            const glm::vec3 p(556.0f * float(i) / 40.0f, 0.0f, 559.0f * float(j) / 40.0f);
            for (const glm::vec3& light :
                 {glm::vec3(278.0f, 548.0f, 279.5f), glm::vec3(-300.0f, 20.0f, 100.0f)})
                rays.push_back(make_ray(eye, p - eye, kInf,
                                        trax::layout::kRayFromSurface | trax::layout::kRayAnyHit,
                                        light));
        }
    const Queries q = run_queries(floor, rays, variant);
    size_t missed = 0, shadowed = 0;
    for (const RayResult& r : q.results) {
        missed += r.surface_triangle < 0;
        shadowed += r.triangle >= 0;
    }
    INFO(missed << " camera rays missed, " << shadowed << " of " << rays.size()
                << " floor points shadowed by the floor");
    CHECK(missed == 0);
    CHECK(shadowed == 0);
}
