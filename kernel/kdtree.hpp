// kd-tree traversal (scene_layout.hpp AccelRecord, kAccelKdTree) over the tree tpsim builds
// for kernels that declare TRAX_USES_KDTREE: the ray's segment inside the tree's box is cut at
// each plane it crosses, the near side walked first and the far side pushed with its part of
// the segment (Havran's thesis, "Heuristic Ray Shooting Algorithms", 2000, the recursive
// traversal made iterative). A drop-in for BvhTraversal: the same trace(), the same watertight
// triangle test, so the image is the BVH tracer's. The BSP tree (kAccelBsp, TRAX_USES_BSP) is
// walked the same way, its planes n.x = split of the kBspDirections orientations: the ray's
// n.o and n.d are computed once for each.
#pragma once
#include "rt.hpp"

namespace trax::rt {

/// n.v for every plane orientation of a BSP tree, in kBspDirection's order.
inline void along_bsp_directions(Vec3 v, float (&out)[kBspDirections]) {
    const float values[kBspDirections] = {v.x,
                                          v.y,
                                          v.z,
                                          v.x + v.y,
                                          v.x - v.y,
                                          v.x + v.z,
                                          v.x - v.z,
                                          v.y + v.z,
                                          v.y - v.z,
                                          v.x + v.y + v.z,
                                          v.x + v.y - v.z,
                                          v.x - v.y + v.z,
                                          -v.x + v.y + v.z};
    for (int k = 0; k < kBspDirections; ++k)
        out[k] = values[k];
}

/// The walk of a kd-tree (kGeneralPlanes false) or a BSP tree (true): KdTreeTraversal and
/// BspTraversal below.
template <bool kGeneralPlanes> struct BasicKdTraversal {
    static constexpr int kDirections = kGeneralPlanes ? kBspDirections : 3;
    static constexpr uint32_t kShapeBits = kGeneralPlanes ? kBspShapeBits : 2;
    static constexpr uint32_t kLeafShape = kGeneralPlanes ? kBspLeaf : kKdLeaf;

    int triangles, nodes, refs;
    Vec3 lo, hi;

    static BasicKdTraversal from_scene() {
        const int record = loadi(0, kHeaderAccel);
        return {trax_triangles(), loadi(record, kAccelNodes), loadi(record, kAccelRefs),
                load_vec3(record, kAccelBoundsMin), load_vec3(record, kAccelBoundsMax)};
    }

    /// The closest (or any) hit with 0 < t < t_max. A leaf's triangles are tested against the
    /// closest hit so far; the walk ends once that hit lies before the leaf's exit, since every
    /// leaf after it lies beyond. A triangle in several leaves is tested in each (no mailbox).
    /// The plane distances' rounding is covered by the builder listing each triangle on both
    /// sides of a plane it comes within a margin of (sim/scene/kdtree.hpp).
    /// RayStats::nodes_visited counts the nodes visited, leaves included.
    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        if (!valid_ray(origin, dir, t_max)) return hit;
        // The ray's n.o, n.d and 1 / n.d for every plane orientation, the axes first.
        float o[kDirections] = {origin.x, origin.y, origin.z};
        float d[kDirections] = {dir.x, dir.y, dir.z};
        float inv[kDirections] = {1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        const float box_lo[3] = {lo.x, lo.y, lo.z}, box_hi[3] = {hi.x, hi.y, hi.z};
        // The segment inside the box, [t_near, t_far].
        float t_near = 0.0f, t_far = t_max;
        if (!clip_to_box(o, inv, box_lo, box_hi, t_near, t_far)) return hit;
        if constexpr (kGeneralPlanes) {
            along_bsp_directions(origin, o);
            along_bsp_directions(dir, d);
            for (int k = 3; k < kDirections; ++k)
                inv[k] = 1.0f / d[k];
        }
        const ShearedRay r = shear(origin, dir);
        int stack_node[kKdStackEntries];
        float stack_near[kKdStackEntries], stack_far[kKdStackEntries];
        int depth = 0;
        int node = 0;
        for (;;) {
            ++stats.nodes_visited;
            const int address = nodes + node * kKdNodeWords;
            const uint32_t shape = static_cast<uint32_t>(loadi(address, 1));
            const uint32_t axis = shape & kLeafShape;
            if (axis != kLeafShape) {
                const float split = loadf(address, 0);
                const int left = node + 1, right = static_cast<int>(shape >> kShapeBits);
                const float t_split = (split - o[axis]) * inv[axis];
                // The side the ray starts on; a ray in the plane goes on along it, in either
                // side (the builder lists the plane's triangles in both).
                const bool below = o[axis] < split || (o[axis] == split && d[axis] <= 0.0f);
                const int first = below ? left : right, second = below ? right : left;
                if (!(t_split > 0.0f) || t_split > t_far) {
                    node = first;  // the plane lies behind the ray or past the segment
                } else if (t_split < t_near) {
                    node = second;  // the segment starts past the plane
                } else {
                    if (depth == kKdStackEntries) {
                        ++stats.stack_overflows;
                    } else {
                        stack_node[depth] = second;
                        stack_near[depth] = t_split;
                        stack_far[depth] = t_far;
                        ++depth;
                        if (uint32_t(depth) > stats.max_stack_depth) stats.max_stack_depth = depth;
                    }
                    node = first;
                    t_far = t_split;
                }
                continue;
            }
            const int first_ref = loadi(address, 0);
            const int end = first_ref + static_cast<int>(shape >> kShapeBits);
            for (int i = first_ref; i < end; ++i) {
                const int triangle = loadi(refs + i, 0);
                ++stats.triangles_tested;
                TriangleHit found;
                if (intersect(r, triangles + triangle * kTriangleWords, hit.t, found)) {
                    record<kAnyHit>(hit, triangle, found);
                    if (kAnyHit) return hit;
                }
            }
            // Done when the closest hit lies in this leaf: the rest of the segment is beyond.
            if (hit.t <= t_far) return hit;
            for (;;) {
                if (depth == 0) return hit;
                --depth;
                if (stack_near[depth] <= hit.t) break;
            }
            node = stack_node[depth];
            t_near = stack_near[depth];
            t_far = stack_far[depth];
        }
    }
};

/// The kd-tree's walk and the BSP tree's (profiles name them BasicKdTraversal<false> and <true>).
using KdTreeTraversal = BasicKdTraversal<false>;
using BspTraversal = BasicKdTraversal<true>;

}  // namespace trax::rt
