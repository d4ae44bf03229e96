// Shadow-ray decisions against two independent oracles (docs/robustness.md, "Shadow rays and
// hit-point error"): for every pixel of a varied corpus, the ray_query kernel traces the camera
// ray to its closest hit and the shadow ray from that hit to each light, exactly as shading
// does (kRayFromSurface | kRayAnyHit), on the functional simulator and the native twin (which
// must agree bit for bit). A double-precision brute force over the image's own float triangles
// decides what is certain, Embree 3 in robust mode confirms those decisions, and the kernel
// must match every certain one: no holes, no false shadows, no leaks.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <embree3/rtcore.h>

#include "sim/image/memory_image.hpp"
#include "sim/render/render.hpp"
#include "sim/scene/accel.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/grid.hpp"
#include "sim/scene/mesh_import.hpp"
#include "sim/scene/procedural.hpp"
#include "tests/robustness/ray_query_run.hpp"

using namespace tpsim;
namespace layout = trax::layout;

namespace {

using Mesh = std::vector<scene::Triangle>;
using dvec3 = glm::dvec3;

// ---------------------------------------------------------------- the corpus

void add_quad(Mesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    m.push_back({a, b, c});
    m.push_back({a, c, d});
}

/// A box with half extents `half`, rotated by `rotation` (columns: the box's axes) about its
/// centre: each face one quad.
void add_box(Mesh& m, glm::vec3 center, glm::vec3 half, const glm::mat3& rotation) {
    const auto corner = [&](int i) {
        const glm::vec3 s((i & 1) ? 1.f : -1.f, (i & 2) ? 1.f : -1.f, (i & 4) ? 1.f : -1.f);
        return center + rotation * (s * half);
    };
    const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces)
        add_quad(m, corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3]));
}

/// A closed cylinder along `axis` (unit) with `segments` sides: a finely tessellated CAD part.
void add_cylinder(Mesh& m, glm::vec3 base, glm::vec3 axis, float radius, float height,
                  int segments) {
    const glm::vec3 u = glm::normalize(glm::cross(axis, glm::vec3(0.3f, 0.9f, 0.1f)));
    const glm::vec3 v = glm::cross(axis, u), top = base + axis * height;
    for (int i = 0; i < segments; ++i) {
        const float a0 = 6.2831853f * float(i) / float(segments),
                    a1 = 6.2831853f * float(i + 1) / float(segments);
        const glm::vec3 r0 = (u * std::cos(a0) + v * std::sin(a0)) * radius,
                        r1 = (u * std::cos(a1) + v * std::sin(a1)) * radius;
        add_quad(m, base + r0, base + r1, top + r1, top + r0);
        m.push_back({base, base + r1, base + r0});
        m.push_back({top, top + r0, top + r1});
    }
}

glm::mat3 rotation(float yaw, float pitch) {
    const float cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
    const glm::mat3 ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy), rx(1, 0, 0, 0, cp, sp, 0, -sp, cp);
    return ry * rx;
}

Mesh transformed(Mesh mesh, float scale, glm::vec3 offset) {
    for (scene::Triangle& t : mesh)
        for (glm::vec3* p : {&t.v0, &t.v1, &t.v2})
            *p = *p * scale + offset;
    return mesh;
}

/// A mesh file, scaled and moved so its bounding box is centred on `center` with the largest
/// side `size`.
Mesh imported(const std::filesystem::path& path, float size, glm::vec3 center) {
    Mesh mesh = scene::import_mesh(path).triangles;
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const scene::Triangle& t : mesh)
        for (const glm::vec3& p : {t.v0, t.v1, t.v2}) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    const glm::vec3 extent = hi - lo;
    const float scale = size / std::max(extent.x, std::max(extent.y, extent.z));
    for (scene::Triangle& t : mesh)
        for (glm::vec3* p : {&t.v0, &t.v1, &t.v2})
            *p = (*p - (lo + hi) * 0.5f) * scale + center;
    return mesh;
}

std::string number(float x) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", double(x));
    return text;
}

struct Case {
    std::string name;
    Mesh mesh;
    glm::vec3 eye, look_at;
    float fov_degrees;
    std::vector<glm::vec3> lights;
    int pixels = 40;  ///< the camera rays form a pixels x pixels image
};

/// A 1 mm cube resting on a square floor of side `floor` at y = 0, seen from 5 mm away.
Case small_on_floor(float floor) {
    Case c{"1 mm cube on a floor of " + number(floor), {}, {}, {}, 50.0f, {}, 48};
    // Centred off the cube so the quad's diagonal passes floor/sqrt(8) away from it.
    const float h = floor / 2, x = floor / 4, z = -floor / 4;
    add_quad(c.mesh, {x - h, 0, z - h}, {x - h, 0, z + h}, {x + h, 0, z + h}, {x + h, 0, z - h});
    add_box(c.mesh, {0, 0.0005f, 0}, glm::vec3(0.0005f), rotation(0.5f, 0.0f));
    c.eye = {0.003f, 0.0025f, 0.004f};
    c.look_at = {0, 0.0003f, 0};
    c.lights = {{-0.004f, 0.006f, 0.002f}, {0.01f, 0.002f, -0.01f}};
    return c;
}

std::vector<Case> corpus() {
    std::vector<Case> cases;
    {  // Thin sheets: two parallel 2 x 2 plates 1e-4 apart, tilted; lights on both sides.
        Case c{"thin sheets", {}, {0, 0.4f, 3}, {0, 0, 0}, 45, {{1, 3, 1}, {-1, -2, -1}}};
        const glm::mat3 r = rotation(0.3f, 0.7f);
        for (float gap : {0.0f, 1e-4f})
            add_quad(c.mesh, r * glm::vec3(-1, gap, -1), r * glm::vec3(-1, gap, 1),
                     r * glm::vec3(1, gap, 1), r * glm::vec3(1, gap, -1));
        cases.push_back(c);
    }
    for (float scale : {1e-3f, 1.0f, 1e3f}) {
        // CAD-like: a plate 2 x 1 x 0.002 and a 512-sided cylinder, at three scales.
        Mesh m;
        add_box(m, {0, 0, 0}, {1, 0.001f, 0.5f}, rotation(0.4f, 0.2f));
        add_cylinder(m, {0.2f, -0.6f, 0.1f}, glm::normalize(glm::vec3(0.1f, 1, 0.2f)), 0.15f, 1.2f,
                     512);
        cases.push_back({"CAD plate and cylinder at scale " + number(scale),
                         transformed(m, scale, glm::vec3(0)),
                         glm::vec3(0.5f, 1.5f, 3.0f) * scale,
                         glm::vec3(0),
                         40,
                         {glm::vec3(2, 3, 1) * scale, glm::vec3(-2, 0.5f, 2) * scale}});
    }
    {  // A scan: the Stanford bunny, on a floor.
        Case c{"bunny on a floor",
               imported("/usr/share/glmark2/models/bunny.obj", 2, {0, 1, 0}),
               {1.5f, 1.8f, 3.2f},
               {0, 0.8f, 0},
               40,
               {{2, 4, 2}, {-3, 1.5f, 1}}};
        add_quad(c.mesh, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4});
        cases.push_back(c);
    }
    for (const char* model : {"STL/Spider_binary.stl", "OFF/Wuson.off"}) {
        const std::filesystem::path path =
            std::filesystem::path("/usr/share/assimp/models") / model;
        cases.push_back({model,
                         imported(path, 2, {0, 0, 0}),
                         {0.8f, 1.2f, 2.6f},
                         {0, 0, 0},
                         45,
                         {{2, 3, 2}, {-2, 1, -1}}});
    }
    for (float floor : {1.0f, 1e3f, 1e5f, 1e6f})
        cases.push_back(small_on_floor(floor));
    {  // Far from the origin: a 2-unit sphere and a plate translated to 1e4.
        const glm::vec3 at(1e4f, 1e4f, -1e4f);
        Mesh m;
        scene::generate_sphere({at, 1.0f, 48, 24}, 0, m);
        add_box(m, at + glm::vec3(0, -1.05f, 0), {3, 0.05f, 3}, rotation(0.0f, 0.0f));
        cases.push_back({"sphere and plate at 1e4",
                         m,
                         at + glm::vec3(1.5f, 2.0f, 3.5f),
                         at,
                         45,
                         {at + glm::vec3(2, 4, 1), at + glm::vec3(-3, 0.5f, -2)}});
    }
    return cases;
}

// ---------------------------------------------------------------- the double oracle

struct DTri {
    dvec3 v0, v1, v2;
};

/// Where a line o + t*d crosses a triangle's plane: t, and the signed distance of that point to
/// the nearest edge (> 0 inside), both exact up to double rounding of float inputs.
struct Crossing {
    bool parallel = true;
    double t = 0, edge_distance = 0;
    double b0 = 0, b1 = 0, b2 = 0;  ///< barycentric weights of v0, v1, v2 at the point
    dvec3 point{0};
};

Crossing cross(const DTri& tri, dvec3 o, dvec3 d) {
    Crossing c;
    const dvec3 n = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
    const double nd = glm::dot(n, d), area2 = glm::length(n);
    if (nd == 0 || area2 == 0) return c;
    c.parallel = false;
    c.t = glm::dot(n, tri.v0 - o) / nd;
    c.point = o + d * c.t;
    // Barycentric b_i times the height of vertex i over the opposite edge is the distance of
    // the point to that edge.
    const dvec3 v[3] = {tri.v0, tri.v1, tri.v2};
    double* weights[3] = {&c.b0, &c.b1, &c.b2};
    c.edge_distance = 1e300;
    for (int i = 0; i < 3; ++i) {
        const dvec3 a = v[(i + 1) % 3], b = v[(i + 2) % 3];
        *weights[i] = glm::dot(glm::cross(b - a, c.point - a), n) / (area2 * area2);
        c.edge_distance = std::min(c.edge_distance, *weights[i] * area2 / glm::length(b - a));
    }
    return c;
}

double max_abs(dvec3 p) {
    return std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z)));
}

/// 2^-20 (16 float ulps) of the largest magnitude among points: how far float rounding of
/// computations on them can move a decision.
double ulps20(std::initializer_list<dvec3> points) {
    double m = 0;
    for (const dvec3& p : points)
        m += max_abs(p);
    return 0x1p-20 * m;
}

/// A crossing nearer than this to a triangle's edge is one floats cannot decide: 16 ulps of the
/// vertices' coordinates relative to the ray's origin (what the kernel's edge test works on),
/// plus `origin_ulps` ulps of the origin itself (the rounding of a computed shadow-ray origin).
double edge_band(dvec3 o, const DTri& tri, double origin_ulps) {
    return 0x1p-20 * std::max({max_abs(tri.v0 - o), max_abs(tri.v1 - o), max_abs(tri.v2 - o)}) +
           origin_ulps * 0x1p-24 * max_abs(o);
}

enum class Truth { hit, miss, ambiguous };

/// Closest certain hit of the ray (o, d), t > 0: the triangle, or -1 for a certain miss, or -2
/// when a triangle floats cannot decide lies in front of (or is) the first certain hit.
struct PrimaryTruth {
    int triangle = -1;
    double t = 0;
};

PrimaryTruth primary_truth(const std::vector<DTri>& tris, dvec3 o, dvec3 d) {
    PrimaryTruth best{-1, 1e300};
    double nearest_ambiguous = 1e300;
    const double length = glm::length(d);
    for (size_t i = 0; i < tris.size(); ++i) {
        const Crossing c = cross(tris[i], o, d);
        if (c.parallel || c.t <= 0) continue;
        const double band = edge_band(o, tris[i], 0);
        if (c.edge_distance > band && c.t * length > ulps20({o, c.point})) {
            if (c.t < best.t) best = {int(i), c.t};
        } else if (c.edge_distance > -band) {
            nearest_ambiguous = std::min(nearest_ambiguous, c.t);
        }
    }
    if (nearest_ambiguous < 1e300 && nearest_ambiguous <= best.t * (1 + 1e-9)) best.triangle = -2;
    return best;
}

/// The segment from the exact hit point p on triangle `self` to the light: blocked if a
/// triangle certainly crosses it beyond the band at both ends; ambiguous if a crossing lies in
/// the bands or near a triangle's edge.
Truth shadow_truth(const std::vector<DTri>& tris, int self, dvec3 p, dvec3 light, double band_t) {
    const dvec3 d = light - p;
    bool ambiguous = false;
    for (size_t i = 0; i < tris.size(); ++i) {
        if (int(i) == self) continue;
        const Crossing c = cross(tris[i], p, d);
        if (c.parallel || c.t <= -band_t || c.t >= 1 + band_t) continue;
        const double band = edge_band(p, tris[i], 8);
        if (c.edge_distance < -band) continue;
        if (c.edge_distance > band && c.t > band_t && c.t < 1 - band_t) return Truth::hit;
        ambiguous = true;
    }
    return ambiguous ? Truth::ambiguous : Truth::miss;
}

// ---------------------------------------------------------------- Embree, the second opinion

struct Embree {
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = nullptr;

    explicit Embree(const std::vector<DTri>& tris) {
        scene = rtcNewScene(device);
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, tris.size() * 3));
        auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, tris.size()));
        for (size_t i = 0; i < tris.size(); ++i) {
            const dvec3 v[3] = {tris[i].v0, tris[i].v1, tris[i].v2};
            for (int k = 0; k < 3; ++k) {
                for (int axis = 0; axis < 3; ++axis)
                    vertices[9 * i + 3 * k + axis] = float(v[k][axis]);  // exact: float inputs
                indices[3 * i + k] = unsigned(3 * i + k);
            }
        }
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene);
    }
    ~Embree() {
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }

    static RTCRay ray(dvec3 o, dvec3 d, double t_near, double t_far) {
        RTCRay r{};
        r.org_x = float(o.x), r.org_y = float(o.y), r.org_z = float(o.z);
        r.dir_x = float(d.x), r.dir_y = float(d.y), r.dir_z = float(d.z);
        r.tnear = float(t_near), r.tfar = float(t_far), r.mask = ~0u;
        return r;
    }
    /// Closest hit's triangle, or -1.
    int closest(dvec3 o, dvec3 d) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh{};
        rh.ray = ray(o, d, 0, 1e30);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &context, &rh);
        return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? -1 : int(rh.hit.primID);
    }
    bool occluded(dvec3 o, dvec3 d, double t_near, double t_far) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay r = ray(o, d, t_near, t_far);
        rtcOccluded1(scene, &context, &r);
        return r.tfar < 0;
    }
};

// ---------------------------------------------------------------- the run

struct Tally {
    size_t primary = 0, primary_ambiguous = 0, holes = 0, wrong_first_hit = 0, phantom_hits = 0;
    size_t shadow = 0, shadow_ambiguous = 0, false_shadows = 0, leaks = 0;
    size_t embree_disagreements = 0;
    void add(const Tally& o) {
        primary += o.primary, primary_ambiguous += o.primary_ambiguous, holes += o.holes;
        wrong_first_hit += o.wrong_first_hit, phantom_hits += o.phantom_hits;
        shadow += o.shadow, shadow_ambiguous += o.shadow_ambiguous;
        false_shadows += o.false_shadows, leaks += o.leaks;
        embree_disagreements += o.embree_disagreements;
    }
};

/// The camera rays of a pinhole camera, row by row, as floats.
std::vector<std::pair<glm::vec3, glm::vec3>> camera_rays(const Case& c) {
    const glm::vec3 forward = glm::normalize(c.look_at - c.eye);
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0, 1, 0)));
    const glm::vec3 down = glm::cross(forward, right);
    const float half = std::tan(c.fov_degrees * 3.14159265f / 360.0f);
    std::vector<std::pair<glm::vec3, glm::vec3>> rays;
    for (int y = 0; y < c.pixels; ++y)
        for (int x = 0; x < c.pixels; ++x) {
            const float sx = (2.0f * (float(x) + 0.5f) / float(c.pixels) - 1.0f) * half;
            const float sy = (2.0f * (float(y) + 0.5f) / float(c.pixels) - 1.0f) * half;
            rays.emplace_back(c.eye, forward + right * sx + down * sy);
        }
    return rays;
}

/// Runs the case's queries on both engines (bit-identical results required) and returns the
/// results and the image's triangles in image order, as doubles.
std::pair<std::vector<layout::RayResult>, std::vector<DTri>>
run_case(const Case& c, const std::vector<layout::Ray>& rays, test::AccelVariant variant) {
    const test::BuiltAccel built(c.mesh, variant);
    const test::RayQueryRun run =
        test::run_ray_query(c.mesh, built, rays, 60000 * uint64_t(rays.size()) + 100000);
    for (const image::TraversalTotals& totals : run.totals)
        CHECK(totals.stack_overflows == 0);
    // The float triangles the kernel saw.
    std::vector<DTri> tris;
    const layout::SectionRef t = run.image.header.triangles;
    for (int32_t i = 0; i < t.count; ++i) {
        layout::Triangle record;
        std::memcpy(&record, run.image.words.data() + t.addr + i * layout::kTriangleWords,
                    sizeof record);
        const auto v = [](const float* p) { return dvec3(p[0], p[1], p[2]); };
        tris.push_back({v(record.v0), v(record.v1), v(record.v2)});
    }
    return {run.results, tris};
}

/// What one structure's kernel decided for a case: per query, did the camera ray hit (and at
/// which distance) and was the shadow ray blocked.
struct Decisions {
    std::vector<bool> surface_hit, blocked;
    std::vector<bool> shadow_ambiguous;  ///< the shadow ray's verdict is within the oracle's band
    std::vector<float> surface_t;
};

Tally check_case(const Case& c, test::AccelVariant variant, Decisions& decisions) {
    const auto camera = camera_rays(c);
    std::vector<layout::Ray> rays;
    for (const auto& [o, d] : camera)
        for (const glm::vec3& light : c.lights)
            rays.push_back({{o.x, o.y, o.z},
                            {d.x, d.y, d.z},
                            3.0e38f,
                            layout::kRayFromSurface | layout::kRayAnyHit,
                            {light.x, light.y, light.z}});
    const auto [results, tris] = run_case(c, rays, variant);
    for (const layout::RayResult& r : results) {
        decisions.surface_hit.push_back(r.surface_triangle >= 0);
        decisions.surface_t.push_back(r.surface_t);
        decisions.blocked.push_back(r.triangle >= 0);
        decisions.shadow_ambiguous.push_back(false);
    }
    const Embree embree(tris);
    Tally tally;
    for (size_t i = 0; i < rays.size(); ++i) {
        const layout::RayResult& r = results[i];
        const dvec3 o(camera[i / c.lights.size()].first), d(camera[i / c.lights.size()].second);
        const dvec3 light(c.lights[i % c.lights.size()]);
        if (i % c.lights.size() == 0) {  // one camera-ray check per pixel
            const PrimaryTruth truth = primary_truth(tris, o, d);
            ++tally.primary;
            if (truth.triangle == -2) {
                ++tally.primary_ambiguous;
            } else if (truth.triangle == -1) {
                tally.phantom_hits += r.surface_triangle >= 0;
                tally.embree_disagreements += embree.closest(o, d) != -1;
            } else {
                // The kernel's triangle must be the oracle's or a tie at the same distance
                // (a shared edge, coplanar faces).
                const auto same_place = [&](int k) {
                    if (k < 0) return false;
                    const Crossing kc = cross(tris[size_t(k)], o, d);
                    const double tie = ulps20({o, kc.point}) + 1e-6 * truth.t * glm::length(d);
                    return !kc.parallel && kc.edge_distance > -edge_band(o, tris[size_t(k)], 0) &&
                           std::abs(kc.t - truth.t) * glm::length(d) <= tie;
                };
                if (r.surface_triangle < 0)
                    ++tally.holes;
                else if (!same_place(r.surface_triangle))
                    ++tally.wrong_first_hit;
                tally.embree_disagreements += !same_place(embree.closest(o, d));
            }
        }
        if (r.surface_triangle < 0) continue;
        // The shadow ray from the exact point where the camera ray meets the kernel's triangle.
        const DTri& self = tris[size_t(r.surface_triangle)];
        const Crossing at = cross(self, o, d);
        if (at.parallel) continue;
        ++tally.shadow;
        // The kernel's shadow-ray origin is within a few ulps of the camera ray's origin and
        // length of the exact point, plus the float resolution of the plane's offset at the
        // eye: an occluder within 16 ulps of those of the start is ambiguous.
        const dvec3 n = glm::normalize(glm::cross(self.v1 - self.v0, self.v2 - self.v0));
        const double reach = ulps20({o, at.point}) +
                             0x1p-20 * std::max({glm::dot(glm::abs(n), glm::abs(self.v0 - o)),
                                                 glm::dot(glm::abs(n), glm::abs(self.v1 - o)),
                                                 glm::dot(glm::abs(n), glm::abs(self.v2 - o))});
        const double band_t = reach / glm::length(light - at.point);
        const Truth shadow = shadow_truth(tris, r.surface_triangle, at.point, light, band_t);
        const bool blocked = r.triangle >= 0;
        if (shadow == Truth::ambiguous) {
            ++tally.shadow_ambiguous;
            decisions.shadow_ambiguous[i] = true;
            continue;
        }
        tally.false_shadows += blocked && shadow == Truth::miss;
        tally.leaks += !blocked && shadow == Truth::hit;
        tally.embree_disagreements += embree.occluded(at.point, light - at.point, band_t,
                                                      1 - band_t) != (shadow == Truth::hit);
    }
    return tally;
}

}  // namespace

TEST_CASE("shadow oracle: no holes, false shadows or leaks on the corpus, against double and "
          "Embree, through the BVHs and the uniform grid",
          "[robustness][oracle]") {
    Tally total;
    // Where another structure's kernel decides otherwise than the binary BVH's: a camera ray's
    // hit or miss, its distance (the same watertight test on the same triangle gives the same
    // bits; a tie between two triangles at one distance may pick either), a shadow ray's
    // verdict. A tie on a shared edge may pick the other triangle, whose normal offsets the
    // shadow ray's origin otherwise: so shadow verdicts may differ, but only where the oracle
    // calls them ambiguous (an occluder within a few ulps of the start).
    // Each width and each box format once, and packets (test_robustness runs every combination).
    using scene::AccelStructure;
    const test::AccelVariant variants[] = {{AccelStructure::bvh2},
                                           {AccelStructure::bvh2, scene::BvhBoxes::floats, true},
                                           {AccelStructure::bvh4, scene::BvhBoxes::quantized},
                                           {AccelStructure::bvh8},
                                           {AccelStructure::grid},
                                           {AccelStructure::kdtree},
                                           {AccelStructure::octree},
                                           {AccelStructure::bsp}};
    constexpr size_t kVariants = std::size(variants);
    size_t hit_differs = 0, distance_differs = 0, shadow_differs = 0, clear_shadow_differs = 0,
           queries = 0;
    for (const Case& c : corpus()) {
        INFO(c.name);
        Decisions by_variant[kVariants];
        for (size_t k = 0; k < kVariants; ++k) {
            const std::string name = test::to_string(variants[k]);
            const Tally t = check_case(c, variants[k], by_variant[k]);
            std::printf("%-42s %-14s %5zu tris: primary %5zu (ambiguous %zu, holes %zu, wrong "
                        "%zu, phantom %zu), shadow %5zu (ambiguous %zu, false %zu, leaks %zu), "
                        "embree disagrees %zu\n",
                        c.name.c_str(), name.c_str(), c.mesh.size(), t.primary, t.primary_ambiguous,
                        t.holes, t.wrong_first_hit, t.phantom_hits, t.shadow, t.shadow_ambiguous,
                        t.false_shadows, t.leaks, t.embree_disagreements);
            INFO("through the " << name);
            CHECK(t.holes == 0);
            CHECK(t.wrong_first_hit == 0);
            CHECK(t.phantom_hits == 0);
            CHECK(t.false_shadows == 0);
            CHECK(t.leaks == 0);
            total.add(t);
        }
        const Decisions& bvh = by_variant[0];
        for (size_t k = 1; k < kVariants; ++k) {
            const Decisions& other = by_variant[k];
            REQUIRE(bvh.blocked.size() == other.blocked.size());
            for (size_t i = 0; i < bvh.blocked.size(); ++i) {
                hit_differs += bvh.surface_hit[i] != other.surface_hit[i];
                distance_differs += bvh.surface_hit[i] && other.surface_hit[i] &&
                                    bvh.surface_t[i] != other.surface_t[i];
                shadow_differs += bvh.blocked[i] != other.blocked[i];
                clear_shadow_differs += bvh.blocked[i] != other.blocked[i] &&
                                        !bvh.shadow_ambiguous[i] && !other.shadow_ambiguous[i];
            }
            queries += bvh.blocked.size();
        }
    }
    std::printf("total: %zu camera rays (%zu ambiguous), %zu shadow rays (%zu ambiguous), "
                "embree disagrees %zu\n",
                total.primary, total.primary_ambiguous, total.shadow, total.shadow_ambiguous,
                total.embree_disagreements);
    std::printf("the other structures against the binary BVH over %zu queries: %zu camera-ray "
                "hit/miss, %zu distances, %zu "
                "shadow verdicts differ (%zu outside the oracle's ambiguity band)\n",
                queries, hit_differs, distance_differs, shadow_differs, clear_shadow_differs);
    CHECK(hit_differs == 0);
    CHECK(distance_differs == 0);
    CHECK(clear_shadow_differs == 0);
    // Ambiguity must stay rare, or the test would decide little.
    CHECK(total.primary_ambiguous * 1000 < total.primary);
    CHECK(total.shadow_ambiguous * 50 < total.shadow);
    // Embree is a float tracer: its robust mode is watertight and conservative, so it may
    // report a hit a hair outside an edge (the corpus has two per structure, both on decisions the
    // double oracle and the kernel agree are clear). More would mean the double oracle is wrong.
    CHECK(total.embree_disagreements * 10000 < total.primary + total.shadow);
}
