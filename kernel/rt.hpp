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

/// What intersect() finds: the distance along the (unnormalised) direction, and a bound on how
/// far the point origin + t*dir may lie from the triangle's plane because t was rounded, times
/// the length of the plane normal cross(v1 - v0, v2 - v0) (surface_point() divides it out).
struct TriangleHit {
    float t;
    float plane_error;
};

constexpr float gamma(int n) {
    return float(n) * 0x1p-24f / (1.0f - float(n) * 0x1p-24f);
}

/// A triangle's vertices on a sheared ray's permuted axes: what intersect_vertices() tests.
struct PermutedTriangle {
    float x0, y0, z0, x1, y1, z1, x2, y2, z2;
};

/// Whether the ray meets the triangle `tri` with 0 < t < t_max, and where.
/// Two-sided.
///
/// Inside or outside: the edge functions of Woop, Benthin and Wald's watertight test. The
/// paper's double-precision fallback for edge coefficients that are exactly zero is left out
/// (TRaX has no doubles): such rays count as hits, so a ray through a shared edge or vertex is
/// never lost, at worst reported by both triangles. Degenerate triangles have det == 0 and never
/// hit. Every comparison that accepts is written so that a NaN (from a NaN or infinite ray)
/// rejects.
///
/// Distance: from the plane, t = n.(v0 - o) / n.d with n = cross(v1 - v0, v2 - v0), not the
/// paper's interpolated sheared z, which cancels catastrophically when the triangle is much
/// larger than the hit distance (a 1e5 floor seen from 5 mm lost its hits near the camera).
/// For an axis-aligned plane n has one non-zero component and t is exact. Both dot products
/// carry a conservative rounding bound in the style of pbrt-v4 sec. 6.8 (Pharr, Jakob and
/// Humphreys, 4th ed.): each term's error is at most gamma(7) times (|n_i| plus the error of n_i,
/// itself at most |e1_j e2_k| + |e1_k e2_j| times gamma(3)) times the term's other factor. A hit
/// whose numerator or denominator could have the wrong sign is rejected, so t > 0 is certain:
/// a ray leaving a surface from an origin on the right side of its plane never hits it again.
/// Always inlined into the loops so the ray stays in registers across triangles; callers that
/// ignore the plane error (any-hit rays) do not compute it. intersect() below loads the
/// vertices; a packet (packet.hpp) loads each triangle once for all its rays.
[[gnu::always_inline]] inline bool intersect_vertices(const ShearedRay& r,
                                                      const PermutedTriangle& tri, float t_max,
                                                      TriangleHit& hit) {
    const float x0 = tri.x0, y0 = tri.y0, z0 = tri.z0, x1 = tri.x1, y1 = tri.y1, z1 = tri.z1,
                x2 = tri.x2, y2 = tri.y2, z2 = tri.z2;
    // Vertices relative to the origin, sheared so the ray runs along +z through (0, 0).
    const float a_z = z0 - r.oz, b_z = z1 - r.oz, c_z = z2 - r.oz;
    const float a_x = x0 - r.ox - r.sx * a_z;
    const float a_y = y0 - r.oy - r.sy * a_z;
    const float b_x = x1 - r.ox - r.sx * b_z;
    const float b_y = y1 - r.oy - r.sy * b_z;
    const float c_x = x2 - r.ox - r.sx * c_z;
    const float c_y = y2 - r.oy - r.sy * c_z;

    // Edge functions in the sheared 2D space: all of one sign inside.
    const float u = c_x * b_y - c_y * b_x;
    const float v = a_x * c_y - a_y * c_x;
    const float w = b_x * a_y - b_y * a_x;
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
    if (u + v + w == 0.0f) return false;

    // The plane: normal from the edges (on permuted axes: the same products, so the same
    // numbers up to sign), numerator n.(v0 - o), denominator n.(sx, sy, 1) (the direction
    // divided by its z, so the distance along it is t*dz), and their rounding bounds.
    const float e1x = x1 - x0, e1y = y1 - y0, e1z = z1 - z0;
    const float e2x = x2 - x0, e2y = y2 - y0, e2z = z2 - z0;
    const float px = e1y * e2z, qx = e1z * e2y, py = e1z * e2x, qy = e1x * e2z, pz = e1x * e2y,
                qz = e1y * e2x;
    const float nx = px - qx, ny = py - qy, nz = pz - qz;
    const float ax = x0 - r.ox, ay = y0 - r.oy;
    float num = nx * ax + ny * ay + nz * a_z;
    // n.d / |dz|, exact up to the rounding of sx and sy: (sx, sy, 1) is d / dz.
    float den = nx * r.sx + ny * r.sy + nz;
    if (r.sz < 0.0f) den = -den;
    if (den < 0.0f) {
        num = -num;
        den = -den;
    }
    // t = num / (den * |dz|); behind the origin or beyond t_max (the commonest rejections,
    // e.g. a shadow ray's own triangle) before the bounds, and no division for a miss.
    const float scaled_num = num * trax_abs(r.sz);
    if (!(num > 0.0f && scaled_num < t_max * den)) return false;
    // The signs must be certain. |n_i| + the error of n_i (gamma(3) * (|p_i| + |q_i|)) is at
    // most 2 * (|p_i| + |q_i|); gamma(7): the dot products' rounding, plus one for the
    // subtractions in v0 - o and one for the rounding of sx and sy.
    const float mx = trax_abs(px) + trax_abs(qx), my = trax_abs(py) + trax_abs(qy),
                mz = trax_abs(pz) + trax_abs(qz);
    const float num_error =
        2.0f * gamma(7) * (mx * trax_abs(ax) + my * trax_abs(ay) + mz * trax_abs(a_z));
    const float den_error = 2.0f * gamma(7) * (mx * trax_abs(r.sx) + my * trax_abs(r.sy) + mz);
    if (!(num > num_error && den > den_error)) return false;
    const float inverse_den = 1.0f / den;
    hit.t = scaled_num * inverse_den;
    // t's rounding moves o + t*d off the plane by at most (num_error + t*|dz|*den_error)/|n|
    // plus the rounding of the scaling, the reciprocal and the product.
    hit.plane_error = num_error + num * inverse_den * den_error + gamma(3) * num;
    return true;
}

/// intersect_vertices() for the triangle at address `tri`.
[[gnu::always_inline]] inline bool intersect(const ShearedRay& r, int tri, float t_max,
                                             TriangleHit& hit) {
    // Vertex coordinates on the permuted axes. One address per axis, so the three vertices'
    // coordinates on it are constant offsets from it (one flw each).
    const int x = tri + r.kx, y = tri + r.ky, z = tri + r.kz;
    const PermutedTriangle v{loadf(x, kTriangleV0), loadf(y, kTriangleV0), loadf(z, kTriangleV0),
                             loadf(x, kTriangleV1), loadf(y, kTriangleV1), loadf(z, kTriangleV1),
                             loadf(x, kTriangleV2), loadf(y, kTriangleV2), loadf(z, kTriangleV2)};
    return intersect_vertices(r, v, t_max, hit);
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

/// Closest (or any) hit: image triangle index or -1, its distance and (closest-hit rays only)
/// TriangleHit::plane_error.
struct Hit {
    int triangle = -1;
    float t = 0.0f;
    float plane_error = 0.0f;
};

/// Records a triangle hit found by a traversal; any-hit rays keep no error bound.
template <bool kAnyHit> inline void record(Hit& hit, int triangle, const TriangleHit& found) {
    hit.triangle = triangle;
    hit.t = found.t;
    if (!kAnyHit) hit.plane_error = found.plane_error;
}

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
            TriangleHit found;
            if (intersect(r, triangles + i * kTriangleWords, hit.t, found)) {
                record<kAnyHit>(hit, i, found);
                if (kAnyHit) break;
            }
        }
        return hit;
    }
};

/// The robust slab test of Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013, for a ray given
/// by its origin and reciprocal direction, against a box, within [0, t_far].
/// Returns the entry distance, or a value > t_far for a miss (always a number, never NaN).
/// - The exit distance is scaled by 1 + 2*gamma(3) (gamma(n) = n*eps/(1 - n*eps), eps = 2^-24)
///   so rounding in (bound - origin) * inverse can never make a box that the ray grazes look
///   missed — without it, rays through shared edges leak between neighbouring leaves.
/// - An axis-parallel ray has inverse +-inf; if its origin lies exactly on the box plane,
///   (bound - origin) * inverse is 0 * inf = NaN. The comparisons below are ordered so a NaN
///   distance never replaces the running entry/exit, i.e. such a slab does not clip the ray:
///   the ray lies in the box's face and counts as inside (conservative, no leak).
/// `box` gives the bounds, box.min(axis) and box.max(axis): a node's loads, or a wide node's
/// decoded child box (wide_bvh.hpp).
template <class Box>
[[gnu::always_inline]] inline float slab_entry_of(const Box& box, Vec3 origin, Vec3 inverse,
                                                  float t_far) {
    constexpr float kExitScale = 1.0f + 2.0f * (3.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f));
    float entry = 0.0f, exit = t_far;
    const float axes_o[3] = {origin.x, origin.y, origin.z};
    const float axes_i[3] = {inverse.x, inverse.y, inverse.z};
    for (int axis = 0; axis < 3; ++axis) {
        const float t0 = (box.min(axis) - axes_o[axis]) * axes_i[axis];
        const float t1 = (box.max(axis) - axes_o[axis]) * axes_i[axis];
        const float near = t0 < t1 ? t0 : t1;
        const float far = (t0 < t1 ? t1 : t0) * kExitScale;
        if (near > entry) entry = near;  // NaN compares false: the slab is ignored
        if (far < exit) exit = far;
    }
    return entry <= exit ? entry : t_far + 1.0f + trax_abs(t_far);
}

/// Clips the segment [t_enter, t_leave] of the ray with origin `o` and reciprocal direction
/// `inv` to the box [lo, hi], for structures that clip the ray once and pad their box rather
/// than widen the exit (sim/scene/grid.hpp, kdtree.hpp). A NaN distance (an axis-parallel ray
/// whose origin lies on a face) never clips. Returns whether any of the segment is left.
[[gnu::always_inline]] inline bool clip_to_box(const float* o, const float* inv, const float* lo,
                                               const float* hi, float& t_enter, float& t_leave) {
    for (int axis = 0; axis < 3; ++axis) {
        const float t0 = (lo[axis] - o[axis]) * inv[axis];
        const float t1 = (hi[axis] - o[axis]) * inv[axis];
        const float near = t0 < t1 ? t0 : t1, far = t0 < t1 ? t1 : t0;
        if (near > t_enter) t_enter = near;  // NaN compares false: no clip
        if (far < t_leave) t_leave = far;
    }
    return t_enter <= t_leave;
}

/// The box of the BVH node at word address `node` (scene_layout.hpp BvhNode), loaded as the
/// slab test reads it.
struct NodeBox {
    int node;
    [[gnu::always_inline]] float min(int axis) const { return loadf(node, kNodeMin + axis); }
    [[gnu::always_inline]] float max(int axis) const { return loadf(node, kNodeMax + axis); }
};

[[gnu::always_inline]] inline float slab_entry(int node, Vec3 origin, Vec3 inverse, float t_far) {
    return slab_entry_of(NodeBox{node}, origin, inverse, t_far);
}

/// Stack-based BVH traversal over the image's BVH (scene_layout.hpp BvhNode): nearer child
/// first, far child pushed with its entry distance, popped subtrees beyond the closest hit
/// skipped, any-hit rays stop at the first hit. Stack capacity: kTraversalStackEntries
/// (scene_layout.hpp), which matches the scene builder's depth contract. A full stack is counted,
/// never silent: the far child is then dropped (the hit may be missed) and the host reports the
/// overflow as an error.
///
/// The policy switches off the two things that make the traversal fast, for the course
/// experiments that measure them (docs/course/experiments.md): `nearer_child_first = false`
/// always descends into the left child first; `early_out = false` tests boxes against the ray's
/// full extent instead of the closest hit so far and never skips a popped subtree. The tracer
/// uses the defaults.
struct TraversalPolicy {
    bool nearer_child_first = true;
    bool early_out = true;
};

template <TraversalPolicy kPolicy = TraversalPolicy{}> struct BasicBvhTraversal {
    int nodes, triangles;

    static BasicBvhTraversal from_scene() { return {trax_bvh(), trax_triangles()}; }

    // Inlined into its caller: BvhTraversal::trace below is then the tracer's traversal itself.
    template <bool kAnyHit>
    [[gnu::always_inline]] inline Hit trace(Vec3 origin, Vec3 dir, float t_max,
                                            RayStats& stats) const {
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
        const auto box_limit = [&] { return kPolicy.early_out ? hit.t : t_max; };
        for (;;) {
            const int count = loadi(node, kNodeCount);
            const int first = loadi(node, kNodeFirst);
            if (count == 0) {
                const int left = nodes + first * kBvhNodeWords, right = left + kBvhNodeWords;
                stats.nodes_visited += 2;
                const float limit = box_limit();
                const float t_left = slab_entry(left, origin, inverse, limit);
                const float t_right = slab_entry(right, origin, inverse, limit);
                const bool hit_left = t_left <= limit, hit_right = t_right <= limit;
                if (hit_left && hit_right) {
                    const bool left_first = !kPolicy.nearer_child_first || t_left <= t_right;
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
                    TriangleHit found;
                    if (intersect(r, triangles + i * kTriangleWords, hit.t, found)) {
                        record<kAnyHit>(hit, i, found);
                        if (kAnyHit) return hit;
                    }
                }
            }
            // Pop the next subtree that may still hold a closer hit.
            for (;;) {
                if (depth == 0) return hit;
                --depth;
                if (stack_entry[depth] <= box_limit()) break;
            }
            node = stack_node[depth];
        }
    }
};
/// The tracer's traversal: BasicBvhTraversal with the defaults, as a class of its own so that
/// profiles and debuggers name it BvhTraversal::trace.
struct BvhTraversal {
    int nodes, triangles;

    static BvhTraversal from_scene() { return {trax_bvh(), trax_triangles()}; }

    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        return BasicBvhTraversal<>{nodes, triangles}.template trace<kAnyHit>(origin, dir, t_max,
                                                                             stats);
    }
};

/// A closest hit's surface point p = origin + t*dir and a bound on its distance from the
/// triangle's plane. The offset below follows pbrt-v4 (Pharr, Jakob and Humphreys, "Physically
/// Based Rendering", 4th ed., sec. 6.8 "Managing Rounding Error"), with the point's error taken
/// from this computation rather than from a barycentric reconstruction: pbrt's
/// gamma(7) * sum |b_i v_i| bound grows with the vertices' magnitudes in every direction, so on a
/// 1e5 floor the rebuilt point moved centimetres along the surface and 1 mm objects cast their
/// shadows in the wrong place; o + t*d with the certain plane t of intersect() is accurate to a
/// few ulps of |o| and |t*d| along the surface, and its distance from the plane is bounded.
struct SurfacePoint {
    Vec3 p;
    Vec3 n;              ///< unit face normal, on the side of v0, v1, v2's winding
    float normal_error;  ///< bound on p's distance from the plane
};

inline Vec3 abs(Vec3 a) {
    return {trax_abs(a.x), trax_abs(a.y), trax_abs(a.z)};
}

/// The surface point of `hit`, a closest hit of the ray (origin, dir) on the image triangle at
/// address `tri`. p's components carry at most gamma(2) * (|o_i| + |t*d_i|) of rounding
/// (gamma(3) below also covers the bound's own rounding).
inline SurfacePoint surface_point(int tri, const Hit& hit, Vec3 origin, Vec3 dir) {
    const Vec3 v0 = load_vec3(tri, kTriangleV0);
    const Vec3 n = cross(load_vec3(tri, kTriangleV1) - v0, load_vec3(tri, kTriangleV2) - v0);
    const float inverse_length = 1.0f / trax_sqrt(dot(n, n));
    const Vec3 unit = n * inverse_length;
    const Vec3 along = dir * hit.t;
    const float rounding = gamma(3) * dot(abs(unit), abs(origin) + abs(along));
    // (1 + gamma(3)) covers the rounding of the bound's own division.
    return {origin + along, unit, hit.plane_error * inverse_length * (1.0f + gamma(3)) + rounding};
}

/// The float next to x away from zero along `sign` (> 0: up, < 0: down); x itself when it is
/// already infinite that way. -0 and +0 both step to the smallest subnormal of that sign.
inline float next_float(float x, float sign) {
    if (x == 0.0f) return sign > 0.0f ? 0x1p-149f : -0x1p-149f;
    const bool up = sign > 0.0f;
    if (trax_abs(x) > 0x1.fffffep127f && (x > 0.0f) == up) return x;  // infinity stays
    const int bits = __builtin_bit_cast(int, x);
    return __builtin_bit_cast(float, (x > 0.0f) == up ? bits + 1 : bits - 1);
}

/// The origin of a ray leaving surface point s on the side `toward` points to: pbrt-v4's
/// OffsetRayOrigin (sec. 6.8.6). p lies within normal_error of the triangle's plane, so p moved
/// by that distance along the normal lies on the far side of the plane from every point the
/// exact hit could be; each component is then rounded one more float away from the surface so
/// the rounding of p + offset cannot pull it back.
inline Vec3 offset_origin(const SurfacePoint& s, Vec3 toward) {
    const float d = s.normal_error;
    const Vec3 offset = s.n * (dot(toward, s.n) < 0.0f ? -d : d);
    const Vec3 q = s.p + offset;
    return {offset.x != 0.0f ? next_float(q.x, offset.x) : q.x,
            offset.y != 0.0f ? next_float(q.y, offset.y) : q.y,
            offset.z != 0.0f ? next_float(q.z, offset.z) : q.z};
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

/// The order the pixels are handed out in: work item n (from atomicinc) renders pixel_of(n).
/// Threads that run at the same time take neighbouring items, so the order decides how close
/// together their rays are (the packet idea on a thread-per-ray machine). Scanlines: row by
/// row. Tiles: 8 x 8 blocks, row by row inside each. Morton: the Z-order curve over the
/// smallest power-of-two square holding the image (items outside it render nothing).
enum class PixelOrder { scanlines, tiles, morton };

/// How render_image() works: the tracer uses the defaults; the rest are the course experiments'
/// alternatives (docs/course/experiments.md). `any_hit_shadows = false` makes shadow rays find
/// the closest blocker instead of stopping at the first.
struct RenderPolicy {
    PixelOrder order = PixelOrder::scanlines;
    bool any_hit_shadows = true;
    bool operator==(const RenderPolicy&) const = default;
};

/// Work items to hand out for a width x height image in `order`.
inline int work_items(int width, int height, PixelOrder order) {
    if (order == PixelOrder::scanlines) return width * height;
    if (order == PixelOrder::tiles) return ((width + 7) / 8) * ((height + 7) / 8) * 64;
    int side = 1;
    while (side < width || side < height)
        side *= 2;
    return side * side;
}

/// Every other bit of x, packed: the inverse of interleaving two coordinates.
inline uint32_t even_bits(uint32_t x) {
    x &= 0x55555555u;
    x = (x | (x >> 1)) & 0x33333333u;
    x = (x | (x >> 2)) & 0x0f0f0f0fu;
    x = (x | (x >> 4)) & 0x00ff00ffu;
    return (x | (x >> 8)) & 0x0000ffffu;
}

/// The pixel (y * width + x) work item `item` renders, or -1 when it lies outside the image
/// (never for scanlines, whose items are the pixels).
inline int pixel_of(int item, int width, int height, PixelOrder order) {
    if (order == PixelOrder::scanlines) return item;
    int x, y;
    if (order == PixelOrder::tiles) {
        const int tile = item / 64, tiles_across = (width + 7) / 8;
        x = (tile % tiles_across) * 8 + item % 8;
        y = (tile / tiles_across) * 8 + (item / 8) % 8;
    } else {
        x = static_cast<int>(even_bits(static_cast<uint32_t>(item)));
        y = static_cast<int>(even_bits(static_cast<uint32_t>(item) >> 1));
    }
    return x < width && y < height ? y * width + x : -1;
}

/// The ray from surface point s to `target` (a light), from the origin offset towards the
/// target: any hit on the segment, or the closest when kAnyHit is false.
template <bool kAnyHit, class Accel>
[[gnu::always_inline]] inline Hit trace_segment(const Accel& accel, const SurfacePoint& s,
                                                Vec3 target, RayStats& stats) {
    const Vec3 start = offset_origin(s, target - s.p);
    return accel.template trace<kAnyHit>(start, target - start, 1.0f, stats);
}

/// The shadow ray from surface point s to `target`: any hit on the segment.
template <class Accel>
Hit trace_to(const Accel& accel, const SurfacePoint& s, Vec3 target, RayStats& stats) {
    return trace_segment<true>(accel, s, target, stats);
}

/// trace_to() with the closest hit instead, for the experiment that measures the difference: a
/// function of its own as trace_to() is, so the two kernels make the same calls.
template <class Accel>
Hit trace_closest_to(const Accel& accel, const SurfacePoint& s, Vec3 target, RayStats& stats) {
    return trace_segment<false>(accel, s, target, stats);
}

/// A closest hit ready for Lambert shading: its surface point, the normal facing the ray and the
/// material's albedo.
struct LitPoint {
    SurfacePoint surface;
    Vec3 n;
    Vec3 albedo;
};

[[gnu::always_inline]] inline LitPoint lit_point(const Shading& s, const Hit& hit, Vec3 origin,
                                                 Vec3 dir) {
    const int tri = s.triangles + hit.triangle * kTriangleWords;
    const SurfacePoint surface = surface_point(tri, hit, origin, dir);
    const Vec3 n = dot(surface.n, dir) > 0.0f ? surface.n * -1.0f : surface.n;  // two-sided
    const Vec3 albedo =
        load_vec3(s.materials + loadi(tri, kTriangleMaterial) * kMaterialWords, kMaterialDiffuse);
    return {surface, n, albedo};
}

/// Whether the point light at `position` faces the point, and its weight there: the cosine,
/// over d^2 when the scene asks for falloff.
[[gnu::always_inline]] inline bool light_weight(const Shading& s, const LitPoint& lit,
                                                Vec3 position, float& weight) {
    const Vec3 to_light = position - lit.surface.p;
    const float n_dot_l = dot(lit.n, to_light);
    if (n_dot_l <= 0.0f) return false;
    const float distance2 = dot(to_light, to_light);
    weight = n_dot_l / trax_sqrt(distance2);  // cosine
    if (s.flags & kFeatureLightFalloff) weight = weight / distance2;
    return true;
}

/// Lambert shading of the camera ray (origin, dir): ambient plus every point light facing the
/// surface, with hard shadows (any-hit rays from the offset hit point) and 1/d^2 falloff when
/// the scene asks for them. shade() below is this with the default policy. Its statements are
/// lit_point() and light_weight() written out: calling them moves the tracer's code (clang keeps
/// the struct in memory), and with it the reference statistics.
template <RenderPolicy kPolicy, class Accel>
[[gnu::always_inline]] inline Vec3 shade_with(const Shading& s, const Accel& accel, Vec3 origin,
                                              Vec3 dir, ThreadTotals& totals) {
    RayStats primary;
    const Hit hit = accel.template trace<false>(origin, dir, 3.0e38f, primary);
    totals.add(primary, false);
    if (hit.triangle < 0) return s.background;

    const int tri = s.triangles + hit.triangle * kTriangleWords;
    const SurfacePoint surface = surface_point(tri, hit, origin, dir);
    const Vec3 n = dot(surface.n, dir) > 0.0f ? surface.n * -1.0f : surface.n;  // two-sided
    const Vec3 albedo =
        load_vec3(s.materials + loadi(tri, kTriangleMaterial) * kMaterialWords, kMaterialDiffuse);

    Vec3 light_sum = s.ambient;
    for (int i = 0; i < s.num_lights; ++i) {
        const int light = s.lights + i * kPointLightWords;
        const Vec3 light_position = load_vec3(light, kLightPosition);
        const Vec3 to_light = light_position - surface.p;
        const float n_dot_l = dot(n, to_light);
        if (n_dot_l <= 0.0f) continue;
        const float distance2 = dot(to_light, to_light);
        float weight = n_dot_l / trax_sqrt(distance2);  // cosine
        if (s.flags & kFeatureLightFalloff) weight = weight / distance2;
        if (s.flags & kFeatureShadows) {
            RayStats shadow;
            const Hit blocker = kPolicy.any_hit_shadows
                                    ? trace_to(accel, surface, light_position, shadow)
                                    : trace_closest_to(accel, surface, light_position, shadow);
            totals.add(shadow, true);
            if (blocker.triangle >= 0) continue;
        }
        light_sum = light_sum + load_vec3(light, kLightColor) * weight;
    }
    return albedo * light_sum;
}

template <class Accel>
Vec3 shade(const Shading& s, const Accel& accel, Vec3 origin, Vec3 dir, ThreadTotals& totals) {
    return shade_with<RenderPolicy{}>(s, accel, origin, dir, totals);
}

/// shade_with() for another policy, a function of its own as shade() is for the default: the
/// course experiments' variants then make the tracer's calls (inlining everything into the
/// pixel loop instead saves 2-4 % of the instructions, which would be measured as the policy's).
template <RenderPolicy kPolicy, class Accel>
Vec3 shade_variant(const Shading& s, const Accel& accel, Vec3 origin, Vec3 dir,
                   ThreadTotals& totals) {
    return shade_with<kPolicy>(s, accel, origin, dir, totals);
}

/// Uniform in [0, 1), 24 bits: exactly representable, the same on both sides.
inline float unit_float(uint32_t bits) {
    return static_cast<float>(bits >> 8) * (1.0f / 16777216.0f);
}

/// The camera rays of the image: the scene's pinhole camera (scene_layout.hpp Camera) and the
/// image size, loaded once per thread. Every camera ray starts at `eye` and goes through a point
/// of the image plane.
struct CameraRays {
    Vec3 eye, corner, right, down;
    int width;
    float fwidth, fheight;

    static CameraRays from_scene() {
        const int camera = trax_camera();
        return {load_vec3(camera, kCameraEye),
                load_vec3(camera, kCameraCorner),
                load_vec3(camera, kCameraRight),
                load_vec3(camera, kCameraDown),
                trax_image_width(),
                static_cast<float>(trax_image_width()),
                static_cast<float>(trax_image_height())};
    }

    /// The direction through image point (x, y), in pixels from the top-left corner: pixel
    /// (i, j) covers [i, i + 1) x [j, j + 1), its centre is (i + 0.5, j + 0.5).
    Vec3 through(float x, float y) const {
        return corner + right * (x / fwidth) + down * (y / fheight);
    }

    /// The direction of camera ray `sample` of `samples` through `pixel` (y * width + x): the
    /// pixel centre for one sample, else a jitter hashed from pixel and sample only, so the
    /// image does not depend on which thread renders the pixel.
    [[gnu::always_inline]] Vec3 direction(int pixel, int sample, int samples) const {
        float jx = 0.5f, jy = 0.5f;
        if (samples > 1) {
            const uint32_t key = 2u * static_cast<uint32_t>(pixel * samples + sample);
            jx = unit_float(trax_hash(key));
            jy = unit_float(trax_hash(key + 1u));
        }
        const float x = static_cast<float>(pixel % width), y = static_cast<float>(pixel / width);
        // through(x + jx, y + jy) written out, the same floats: through() makes clang schedule
        // two adds differently and moves the tracer's reference cycles (by 0.02 %).
        return corner + right * ((x + jx) / fwidth) + down * ((y + jy) / fheight);
    }
};

/// The pixel loop of the image kernels: work items handed out with atomicinc(0) in `kOrder`;
/// each pixel gets samples_per_pixel camera rays (CameraRays::direction), each shaded by
/// shade_sample(origin, dir, pixel, sample, totals) and averaged into the framebuffer as linear
/// RGB; the thread's statistics record is written at the end.
template <PixelOrder kOrder, class ShadeSample>
[[gnu::always_inline]] inline void render_pixels(const ShadeSample& shade_sample) {
    const int width = trax_image_width(), height = trax_image_height();
    const int samples = trax_samples_per_pixel();
    const CameraRays camera = CameraRays::from_scene();
    const int framebuffer = trax_framebuffer();
    ThreadTotals totals;

    const int items = work_items(width, height, kOrder);
    for (int item = atomicinc(0); item < items; item = atomicinc(0)) {
        const int pixel = pixel_of(item, width, height, kOrder);
        if constexpr (kOrder != PixelOrder::scanlines)
            if (pixel < 0) continue;
        Vec3 color{0.0f, 0.0f, 0.0f};
        for (int sample = 0; sample < samples; ++sample) {
            const Vec3 dir = camera.direction(pixel, sample, samples);
            color = color + shade_sample(camera.eye, dir, pixel, sample, totals);
        }
        color = color * (1.0f / static_cast<float>(samples));
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
    totals.store();
}

/// The whole render kernel: render_pixels() with shade_with() in the policy's order.
/// render_image() below is this with the default policy.
template <RenderPolicy kPolicy, class Accel>
[[gnu::always_inline]] inline void render_image_with(const Accel& accel) {
    const Shading s = Shading::from_scene();
    render_pixels<kPolicy.order>([&](Vec3 origin, Vec3 dir, int, int, ThreadTotals& totals) {
        if constexpr (kPolicy == RenderPolicy{})
            return shade(s, accel, origin, dir, totals);
        else
            return shade_variant<kPolicy>(s, accel, origin, dir, totals);
    });
}

template <class Accel> void render_image(const Accel& accel) {
    render_image_with<RenderPolicy{}>(accel);
}

}  // namespace trax::rt
