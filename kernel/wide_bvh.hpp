// Wide-BVH traversal: 4 or 8 children per node (scene_layout.hpp AccelRecord, kAccelWideBvh),
// with float or quantized child boxes, over the tree tpsim collapses from the binary SAH BVH for
// kernels that declare TRAX_USES_WIDE_BVH. A drop-in for BvhTraversal: the same trace(), slab
// test and watertight triangle test, so the image is the binary BVH tracer's.
#pragma once
#include "rt.hpp"

namespace trax::rt {

/// Child c's float box in the node at word address `node`.
template <int kWidth> struct FloatChildBox {
    int node, child;
    [[gnu::always_inline]] float min(int axis) const { return loadf(node, 6 * child + axis); }
    [[gnu::always_inline]] float max(int axis) const { return loadf(node, 6 * child + 3 + axis); }
};

/// Child c's quantized box: the node's origin plus the child's 8-bit offsets times the axis's
/// power-of-two scale. The host rounded the offsets outwards with this very arithmetic, so the
/// box contains the child's float box.
template <int kWidth> struct QuantizedChildBox {
    int node, child;
    const float* origin;
    const float* scale;
    [[gnu::always_inline]] float bound(int vector, int axis) const {
        const uint32_t q =
            loadbyte(node, wide_quantized_boxes_byte(kWidth) + vector * kWidth + child);
        return origin[axis] + static_cast<float>(q) * scale[axis];
    }
    [[gnu::always_inline]] float min(int axis) const { return bound(axis, axis); }
    [[gnu::always_inline]] float max(int axis) const { return bound(3 + axis, axis); }
};

template <int kWidth, bool kQuantized> struct WideBvhTraversal {
    int root, triangles;
    Vec3 lo, hi;

    static WideBvhTraversal from_scene() {
        const int record = loadi(0, kHeaderAccel);
        return {loadi(record, kAccelNodes), trax_triangles(), load_vec3(record, kAccelBoundsMin),
                load_vec3(record, kAccelBoundsMax)};
    }

    /// The closest (or any) hit with 0 < t < t_max. At each node every child's box is tested;
    /// the ray goes on into the nearest child it hits and pushes the others, farthest first,
    /// with their entry distances; popped entries beyond the closest hit so far are skipped.
    /// RayStats::nodes_visited counts the boxes tested (the root's included), as for the binary
    /// BVH. A full stack is counted, never silent, as there.
    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        if (!valid_ray(origin, dir, t_max)) return hit;
        const ShearedRay r = shear(origin, dir);
        const Vec3 inverse{1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        ++stats.nodes_visited;
        if (!(slab_entry_of(RootBox{lo, hi}, origin, inverse, hit.t) <= hit.t)) return hit;
        int stack_ref[kWideStackEntries];
        float stack_entry[kWideStackEntries];
        int depth = 0;
        int ref = root;
        for (;;) {
            if (ref > 0) {
                // The children hit, nearest first.
                int near_ref[kWidth];
                float near_t[kWidth];
                int hits = 0;
                const float limit = hit.t;
                float origin_q[3], scale_q[3];
                if (kQuantized) {
                    const uint32_t exponents = static_cast<uint32_t>(loadi(ref, 3));
                    for (int axis = 0; axis < 3; ++axis) {
                        origin_q[axis] = loadf(ref, axis);
                        scale_q[axis] =
                            __builtin_bit_cast(float, ((exponents >> (8 * axis)) & 255u) << 23);
                    }
                }
                for (int c = 0; c < kWidth; ++c) {
                    const int child =
                        loadi(ref, (kQuantized ? kWideQuantizedRefs : 6 * kWidth) + c);
                    if (child == 0) break;
                    ++stats.nodes_visited;
                    float t;
                    if (kQuantized)
                        t = slab_entry_of(QuantizedChildBox<kWidth>{ref, c, origin_q, scale_q},
                                          origin, inverse, limit);
                    else
                        t = slab_entry_of(FloatChildBox<kWidth>{ref, c}, origin, inverse, limit);
                    if (!(t <= limit)) continue;
                    int j = hits++;
                    for (; j > 0 && t < near_t[j - 1]; --j) {
                        near_t[j] = near_t[j - 1];
                        near_ref[j] = near_ref[j - 1];
                    }
                    near_t[j] = t;
                    near_ref[j] = child;
                }
                if (hits > 0) {
                    for (int j = hits - 1; j > 0; --j) {
                        if (depth == kWideStackEntries) {
                            ++stats.stack_overflows;
                            continue;
                        }
                        stack_ref[depth] = near_ref[j];
                        stack_entry[depth] = near_t[j];
                        ++depth;
                    }
                    if (uint32_t(depth) > stats.max_stack_depth) stats.max_stack_depth = depth;
                    ref = near_ref[0];
                    continue;
                }
            } else {
                const int count = ref & 15;
                const int first = (ref & 0x7fffffff) >> 4;
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
                if (stack_entry[depth] <= hit.t) break;
            }
            ref = stack_ref[depth];
        }
    }

private:
    struct RootBox {
        Vec3 lo, hi;
        [[gnu::always_inline]] float min(int axis) const {
            return axis == 0 ? lo.x : axis == 1 ? lo.y : lo.z;
        }
        [[gnu::always_inline]] float max(int axis) const {
            return axis == 0 ? hi.x : axis == 1 ? hi.y : hi.z;
        }
    };
};

/// Runs `body` with the traversal for the wide BVH the image holds (its AccelRecord's width and
/// box format), so one kernel serves --accel bvh4 and bvh8 in both formats.
template <class Body> void with_wide_bvh(Body body) {
    const int record = loadi(0, kHeaderAccel);
    const bool quantized = loadi(record, kAccelQuantized) != 0;
    if (loadi(record, kAccelWidth) == 8) {
        if (quantized)
            body(WideBvhTraversal<8, true>::from_scene());
        else
            body(WideBvhTraversal<8, false>::from_scene());
    } else {
        if (quantized)
            body(WideBvhTraversal<4, true>::from_scene());
        else
            body(WideBvhTraversal<4, false>::from_scene());
    }
}

}  // namespace trax::rt
