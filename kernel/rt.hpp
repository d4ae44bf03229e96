// The ray-tracing core shared by every kernel (primary_brute, tracer, ray_query): vectors, the
// watertight ray/triangle test, the robust slab test, the secondary-ray origin offset, brute-force
// and BVH traversal with statistics, Lambert shading and the pixel loop. One copy, so the kernels
// differ only in how they find hits and the native twin computes exactly what the guest does.
// See docs/kernel-api.md and docs/robustness.md.
#pragma once
#include "trax.hpp"

namespace trax::rt {

using namespace trax::layout;

struct Vec3 {
    float x, y, z;
};
inline Vec3 operator+(Vec3 a, Vec3 b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(Vec3 a, Vec3 b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator*(Vec3 a, float s) {
    return {a.x * s, a.y * s, a.z * s};
}
inline Vec3 operator*(Vec3 a, Vec3 b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline float dot(Vec3 a, Vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vec3 load_vec3(int addr, int offset) {
    return {loadf(addr, offset), loadf(addr, offset + 1), loadf(addr, offset + 2)};
}
inline float component(Vec3 v, int axis) {
    return axis == 0 ? v.x : axis == 1 ? v.y : v.z;
}
inline bool is_nan(float x) {
    return x != x;
}

/// A ray prepared for the watertight test of Woop, Benthin and Wald, "Watertight Ray/Triangle
/// Intersection", JCGT 2(1), 2013: axes permuted so the direction's largest component is z, and
/// a shear that maps the direction to +z. The origin is kept per permuted axis so a triangle
/// vertex coordinate is one loadf(triangle, vertex + axis) away.
struct ShearedRay {
    int kx, ky, kz;
    float ox, oy, oz;
    float sx, sy, sz;
};

inline ShearedRay shear(Vec3 origin, Vec3 dir) {
    ShearedRay r;
    const float ax = trax_abs(dir.x), ay = trax_abs(dir.y), az = trax_abs(dir.z);
    r.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    r.kx = r.kz == 2 ? 0 : r.kz + 1;
    r.ky = r.kx == 2 ? 0 : r.kx + 1;
    const float dz = component(dir, r.kz);
    if (dz < 0.0f) {  // keep the winding: swap x and y when the ray looks down -z
        const int k = r.kx;
        r.kx = r.ky;
        r.ky = k;
    }
    r.sx = component(dir, r.kx) / dz;
    r.sy = component(dir, r.ky) / dz;
    r.sz = 1.0f / dz;
    r.ox = component(origin, r.kx);
    r.oy = component(origin, r.ky);
    r.oz = component(origin, r.kz);
    return r;
}

/// Hit distance along the (unnormalised) direction, if the ray meets the triangle at address
/// `tri` with t_min < t < t_max. Two-sided. The paper's double-precision fallback for edge
/// coefficients that are exactly zero is left out (TRaX has no doubles): such rays count as
/// hits, so a ray through a shared edge or vertex is never lost, at worst reported by both
/// triangles. Degenerate triangles have det == 0 and never hit. Every comparison that accepts
/// is written so that a NaN (from a NaN or infinite ray) rejects.
/// Always inlined into the loops so the ray stays in registers across triangles.
[[gnu::always_inline]] inline bool intersect(const ShearedRay& r, int tri, float t_min, float t_max,
                                             float& t) {
    // Vertices relative to the origin, sheared and scaled. One address per permuted axis, so
    // the three vertices' coordinates on it are constant offsets from it (one flw each).
    const int x = tri + r.kx, y = tri + r.ky, z = tri + r.kz;
    const float a_z = loadf(z, kTriangleV0) - r.oz;
    const float b_z = loadf(z, kTriangleV1) - r.oz;
    const float c_z = loadf(z, kTriangleV2) - r.oz;
    const float a_x = loadf(x, kTriangleV0) - r.ox - r.sx * a_z;
    const float a_y = loadf(y, kTriangleV0) - r.oy - r.sy * a_z;
    const float b_x = loadf(x, kTriangleV1) - r.ox - r.sx * b_z;
    const float b_y = loadf(y, kTriangleV1) - r.oy - r.sy * b_z;
    const float c_x = loadf(x, kTriangleV2) - r.ox - r.sx * c_z;
    const float c_y = loadf(y, kTriangleV2) - r.oy - r.sy * c_z;

    // Scaled barycentrics: edge functions in the sheared 2D space.
    const float u = c_x * b_y - c_y * b_x;
    const float v = a_x * c_y - a_y * c_x;
    const float w = b_x * a_y - b_y * a_x;
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
    const float det = u + v + w;
    if (det == 0.0f) return false;

    // Scaled distance; compare before dividing so misses cost no division.
    const float scaled_t = r.sz * (u * a_z + v * b_z + w * c_z);
    const bool inside = det > 0.0f ? (scaled_t > t_min * det && scaled_t < t_max * det)
                                   : (scaled_t < t_min * det && scaled_t > t_max * det);
    if (!inside) return false;
    t = scaled_t / det;
    return true;
}

/// Moves a surface point off its surface along the normal so a ray leaving it does not hit its
/// own triangle: Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
/// Ray Tracing Gems ch. 6, 2019. Components far from zero move a fixed number of ulps (integer
/// arithmetic on the float bits); components near zero, where ulps are tiny, move by a float step.
///
/// Scale-free variant: the paper calls a component "near the origin" when |p| < 1/32 and moves
/// it by n/65536, which assumes a scene of size ~1. But a hit point's rounding error is set by
/// its LARGEST coordinate (the vertices and the origin it was computed from are that large), so
/// on a 500-unit Cornell box the point (250, 0, 300) on the floor got a 1.5e-5 offset in y,
/// below the ~3e-5 error of the hit: shadow acne. Here "near" is relative to the largest
/// magnitude m of the point (|p_i| < m/32) and the float step is m * n_i/65536 — about 128 ulps
/// of m, the same size as the 256-ulp integer step at m/2..m. Scaling the scene by any power of
/// two scales every offset by it, so the test is the same at 1e-4 and 1e4.
inline float offset_coordinate(float p, float n, float magnitude) {
    constexpr float kNearFraction = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
    if (trax_abs(p) < magnitude * kNearFraction) return p + kFloatScale * magnitude * n;
    const int ulps = static_cast<int>(kIntScale * n);
    return __builtin_bit_cast(float, __builtin_bit_cast(int, p) + (p < 0.0f ? -ulps : ulps));
}
inline Vec3 offset_origin(Vec3 p, Vec3 n) {
    const float m = trax_max(trax_abs(p.x), trax_max(trax_abs(p.y), trax_abs(p.z)));
    return {offset_coordinate(p.x, n.x, m), offset_coordinate(p.y, n.y, m),
            offset_coordinate(p.z, n.z, m)};
}

/// Counts of one ray's traversal.
struct RayStats {
    uint32_t nodes_visited = 0;  ///< BVH node boxes tested (the root's included)
    uint32_t triangles_tested = 0;
    uint32_t max_stack_depth = 0;
    uint32_t stack_overflows = 0;
};

/// A thread's running totals (ThreadStats in scene_layout.hpp), kept in registers and written
/// to the thread's record once, by store().
struct ThreadTotals {
    uint32_t primary_rays = 0, shadow_rays = 0;
    uint64_t nodes_visited = 0, triangles_tested = 0;
    uint32_t max_stack_depth = 0, stack_overflows = 0;

    void add(const RayStats& ray, bool shadow) {
        if (shadow)
            ++shadow_rays;
        else
            ++primary_rays;
        nodes_visited += ray.nodes_visited;
        triangles_tested += ray.triangles_tested;
        if (ray.max_stack_depth > max_stack_depth) max_stack_depth = ray.max_stack_depth;
        stack_overflows += ray.stack_overflows;
    }
    /// Writes this thread's ThreadStats record, if the image has one for it.
    void store() const {
        const int thread = trax_thread_id();
        if (thread >= loadi(0, kHeaderThreadStats + 1)) return;
        const int out = loadi(0, kHeaderThreadStats) + thread * kThreadStatsWords;
        storei(static_cast<int>(primary_rays), out, kStatsPrimaryRays);
        storei(static_cast<int>(shadow_rays), out, kStatsShadowRays);
        storei(static_cast<int>(nodes_visited), out, kStatsNodesVisited);
        storei(static_cast<int>(nodes_visited >> 32), out, kStatsNodesVisited + 1);
        storei(static_cast<int>(triangles_tested), out, kStatsTrianglesTested);
        storei(static_cast<int>(triangles_tested >> 32), out, kStatsTrianglesTested + 1);
        storei(static_cast<int>(max_stack_depth), out, kStatsMaxStackDepth);
        storei(static_cast<int>(stack_overflows), out, kStatsStackOverflows);
    }
};

/// Closest (or any) hit: image triangle index or -1, and its distance.
struct Hit {
    int triangle = -1;
    float t = 0.0f;
};

/// A NaN anywhere in the ray, a zero direction or a t_max that is not > 0 (NaN included) means
/// "no ray": it hits nothing and costs no traversal. Infinite components are valid inputs; the
/// tests below turn them into misses without NaN results.
inline bool valid_ray(Vec3 o, Vec3 d, float t_max) {
    return !(is_nan(o.x) || is_nan(o.y) || is_nan(o.z) || is_nan(d.x) || is_nan(d.y) ||
             is_nan(d.z)) &&
           (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f) && t_max > 0.0f;
}

/// Every triangle, in order: the reference for the BVH.
struct BruteForce {
    int triangles, num_triangles;

    static BruteForce from_scene() { return {trax_triangles(), trax_num_triangles()}; }

    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        if (!valid_ray(origin, dir, t_max)) return hit;
        const ShearedRay r = shear(origin, dir);
        for (int i = 0; i < num_triangles; ++i) {
            ++stats.triangles_tested;
            float t;
            if (intersect(r, triangles + i * kTriangleWords, 0.0f, hit.t, t)) {
                hit.t = t;
                hit.triangle = i;
                if (kAnyHit) break;
            }
        }
        return hit;
    }
};

/// The robust slab test of Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013, for a ray given
/// by its origin and reciprocal direction, against the box at `node`, within [0, t_far].
/// Returns the entry distance, or a value > t_far for a miss (always a number, never NaN).
/// - The exit distance is scaled by 1 + 2*gamma(3) (gamma(n) = n*eps/(1 - n*eps), eps = 2^-24)
///   so rounding in (bound - origin) * inverse can never make a box that the ray grazes look
///   missed — without it, rays through shared edges leak between neighbouring leaves.
/// - An axis-parallel ray has inverse +-inf; if its origin lies exactly on the box plane,
///   (bound - origin) * inverse is 0 * inf = NaN. The comparisons below are ordered so a NaN
///   distance never replaces the running entry/exit, i.e. such a slab does not clip the ray:
///   the ray lies in the box's face and counts as inside (conservative, no leak).
[[gnu::always_inline]] inline float slab_entry(int node, Vec3 origin, Vec3 inverse, float t_far) {
    constexpr float kExitScale = 1.0f + 2.0f * (3.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f));
    float entry = 0.0f, exit = t_far;
    const float axes_o[3] = {origin.x, origin.y, origin.z};
    const float axes_i[3] = {inverse.x, inverse.y, inverse.z};
    for (int axis = 0; axis < 3; ++axis) {
        const float t0 = (loadf(node, kNodeMin + axis) - axes_o[axis]) * axes_i[axis];
        const float t1 = (loadf(node, kNodeMax + axis) - axes_o[axis]) * axes_i[axis];
        const float near = t0 < t1 ? t0 : t1;
        const float far = (t0 < t1 ? t1 : t0) * kExitScale;
        if (near > entry) entry = near;  // NaN compares false: the slab is ignored
        if (far < exit) exit = far;
    }
    return entry <= exit ? entry : t_far + 1.0f + trax_abs(t_far);
}

/// Stack-based BVH traversal over the image's BVH (scene_layout.hpp BvhNode): nearer child
/// first, far child pushed with its entry distance, popped subtrees beyond the closest hit
/// skipped, any-hit rays stop at the first hit. Stack capacity: kTraversalStackEntries
/// (scene_layout.hpp), which matches the scene builder's depth contract. A full stack is counted,
/// never silent: the far child is then dropped (the hit may be missed) and the host reports the
/// overflow as an error.
struct BvhTraversal {
    int nodes, triangles;

    static BvhTraversal from_scene() { return {trax_bvh(), trax_triangles()}; }

    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        if (!valid_ray(origin, dir, t_max)) return hit;
        const ShearedRay r = shear(origin, dir);
        const Vec3 inverse{1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        int stack_node[kTraversalStackEntries];
        float stack_entry[kTraversalStackEntries];
        int depth = 0;

        int node = nodes;
        ++stats.nodes_visited;
        if (!(slab_entry(node, origin, inverse, hit.t) <= hit.t)) return hit;
        for (;;) {
            const int count = loadi(node, kNodeCount);
            const int first = loadi(node, kNodeFirst);
            if (count == 0) {
                const int left = nodes + first * kBvhNodeWords, right = left + kBvhNodeWords;
                stats.nodes_visited += 2;
                const float t_left = slab_entry(left, origin, inverse, hit.t);
                const float t_right = slab_entry(right, origin, inverse, hit.t);
                const bool hit_left = t_left <= hit.t, hit_right = t_right <= hit.t;
                if (hit_left && hit_right) {
                    const bool left_first = t_left <= t_right;
                    node = left_first ? left : right;
                    if (depth == kTraversalStackEntries) {
                        ++stats.stack_overflows;
                    } else {
                        stack_node[depth] = left_first ? right : left;
                        stack_entry[depth] = left_first ? t_right : t_left;
                        ++depth;
                        if (uint32_t(depth) > stats.max_stack_depth) stats.max_stack_depth = depth;
                    }
                    continue;
                }
                if (hit_left || hit_right) {
                    node = hit_left ? left : right;
                    continue;
                }
            } else {
                for (int i = first; i < first + count; ++i) {
                    ++stats.triangles_tested;
                    float t;
                    if (intersect(r, triangles + i * kTriangleWords, 0.0f, hit.t, t)) {
                        hit.t = t;
                        hit.triangle = i;
                        if (kAnyHit) return hit;
                    }
                }
            }
            // Pop the next subtree that may still hold a closer hit.
            for (;;) {
                if (depth == 0) return hit;
                --depth;
                if (stack_entry[depth] <= hit.t) break;
            }
            node = stack_node[depth];
        }
    }
};

/// The face normal of the image triangle `tri` (address), unit length, facing against `dir`
/// (two-sided surfaces).
inline Vec3 facing_normal(int tri, Vec3 dir) {
    const Vec3 v0 = load_vec3(tri, kTriangleV0);
    Vec3 n = cross(load_vec3(tri, kTriangleV1) - v0, load_vec3(tri, kTriangleV2) - v0);
    n = n * (1.0f / trax_sqrt(dot(n, n)));
    return dot(n, dir) > 0.0f ? n * -1.0f : n;
}

/// What shading reads from the scene header, loaded once per thread.
struct Shading {
    int triangles;
    int lights, num_lights;
    int materials;
    uint32_t flags;
    Vec3 ambient, background;

    static Shading from_scene() {
        Shading s;
        s.triangles = trax_triangles();
        s.lights = trax_lights();
        s.num_lights = trax_num_lights();
        s.materials = trax_materials();
        s.flags = static_cast<uint32_t>(trax_scene_flags());
        s.ambient = load_vec3(trax_ambient(), 0);
        s.background = load_vec3(trax_background(), 0);
        return s;
    }
};

/// Lambert shading of the camera ray (origin, dir): ambient plus every point light facing the
/// surface, with hard shadows (any-hit rays from the offset hit point) and 1/d^2 falloff when
/// the scene asks for them.
template <class Accel>
Vec3 shade(const Shading& s, const Accel& accel, Vec3 origin, Vec3 dir, ThreadTotals& totals) {
    RayStats primary;
    const Hit hit = accel.template trace<false>(origin, dir, 3.0e38f, primary);
    totals.add(primary, false);
    if (hit.triangle < 0) return s.background;

    const int tri = s.triangles + hit.triangle * kTriangleWords;
    const Vec3 n = facing_normal(tri, dir);
    const Vec3 p = origin + dir * hit.t;
    const Vec3 albedo =
        load_vec3(s.materials + loadi(tri, kTriangleMaterial) * kMaterialWords, kMaterialDiffuse);

    Vec3 light_sum = s.ambient;
    for (int i = 0; i < s.num_lights; ++i) {
        const int light = s.lights + i * kPointLightWords;
        const Vec3 to_light = load_vec3(light, kLightPosition) - p;
        const float n_dot_l = dot(n, to_light);
        if (n_dot_l <= 0.0f) continue;
        const float distance2 = dot(to_light, to_light);
        float weight = n_dot_l / trax_sqrt(distance2);  // cosine
        if (s.flags & kFeatureLightFalloff) weight = weight / distance2;
        if (s.flags & kFeatureShadows) {
            const Vec3 start = offset_origin(p, n);
            RayStats shadow;
            const Hit blocker = accel.template trace<true>(
                start, load_vec3(light, kLightPosition) - start, 1.0f, shadow);
            totals.add(shadow, true);
            if (blocker.triangle >= 0) continue;
        }
        light_sum = light_sum + load_vec3(light, kLightColor) * weight;
    }
    return albedo * light_sum;
}

/// Integer hash (Wellons' "lowbias32"): decorrelated jitter that depends only on its input.
inline uint32_t hash(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}
/// Uniform in [0, 1), 24 bits: exactly representable, the same on both sides.
inline float unit_float(uint32_t bits) {
    return static_cast<float>(bits >> 8) * (1.0f / 16777216.0f);
}

/// The whole render kernel: pixels handed out with atomicinc(0); each gets samples_per_pixel
/// camera rays (pixel centre for one sample, hashed jitter for more), shaded and averaged into
/// the framebuffer as linear RGB; the thread's statistics record is written at the end.
template <class Accel> void render_image(const Accel& accel) {
    const Shading s = Shading::from_scene();
    const int width = trax_image_width(), height = trax_image_height();
    const int samples = trax_samples_per_pixel();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera, kCameraEye);
    const Vec3 corner = load_vec3(camera, kCameraCorner);
    const Vec3 right = load_vec3(camera, kCameraRight);
    const Vec3 down = load_vec3(camera, kCameraDown);
    const int framebuffer = trax_framebuffer();
    const float fwidth = static_cast<float>(width), fheight = static_cast<float>(height);
    ThreadTotals totals;

    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const float x = static_cast<float>(pixel % width), y = static_cast<float>(pixel / width);
        Vec3 color{0.0f, 0.0f, 0.0f};
        for (int sample = 0; sample < samples; ++sample) {
            float jx = 0.5f, jy = 0.5f;
            if (samples > 1) {
                const uint32_t key = 2u * static_cast<uint32_t>(pixel * samples + sample);
                jx = unit_float(hash(key));
                jy = unit_float(hash(key + 1u));
            }
            const Vec3 dir = corner + right * ((x + jx) / fwidth) + down * ((y + jy) / fheight);
            color = color + shade(s, accel, eye, dir, totals);
        }
        color = color * (1.0f / static_cast<float>(samples));
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
    totals.store();
}

}  // namespace trax::rt
