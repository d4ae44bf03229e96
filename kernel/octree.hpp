// Octree traversal (scene_layout.hpp AccelRecord, kAccelOctree) over the tree tpsim builds for
// kernels that declare TRAX_USES_OCTREE. At each cell the ray's segment is cut where it crosses
// the cell's three centre planes: the octants it passes through, in order along the ray
// (Revelles, Ureña and Lastra, "An Efficient Parametric Algorithm for Octree Traversal", WSCG
// 2000, with the crossings sorted instead of their state machine), the first walked and the
// others pushed with their parts of the segment. Each plane is classified as the kd-tree's
// (kernel/kdtree.hpp), with the same rounding guard in the builder. A drop-in for BvhTraversal:
// the same trace(), the same watertight triangle test, so the image is the BVH tracer's.
#pragma once
#include "rt.hpp"

namespace trax::rt {

struct OctreeTraversal {
    int triangles, nodes, refs;
    Vec3 lo, hi;

    static OctreeTraversal from_scene() {
        const int record = loadi(0, kHeaderAccel);
        return {trax_triangles(), loadi(record, kAccelNodes), loadi(record, kAccelRefs),
                load_vec3(record, kAccelBoundsMin), load_vec3(record, kAccelBoundsMax)};
    }

    /// The closest (or any) hit with 0 < t < t_max. A leaf's triangles are tested against the
    /// closest hit so far; the walk ends once that hit lies before the leaf's exit. A triangle
    /// in several leaves is tested in each (no mailbox). RayStats::nodes_visited counts the
    /// cells visited, leaves included; empty octants are skipped unvisited.
    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        if (!valid_ray(origin, dir, t_max)) return hit;
        const float o[3] = {origin.x, origin.y, origin.z};
        const float d[3] = {dir.x, dir.y, dir.z};
        const float inv[3] = {1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        const float box_lo[3] = {lo.x, lo.y, lo.z}, box_hi[3] = {hi.x, hi.y, hi.z};
        float t_near = 0.0f, t_far = t_max;
        if (!clip_to_box(o, inv, box_lo, box_hi, t_near, t_far)) return hit;
        const ShearedRay r = shear(origin, dir);
        int stack_node[kOctreeStackEntries];
        float stack_near[kOctreeStackEntries], stack_far[kOctreeStackEntries];
        int depth = 0;
        int node = 0;
        for (;;) {
            ++stats.nodes_visited;
            const int address = nodes + node * kOctreeNodeWords;
            const int shape = loadi(address, kOctreeShape);
            if (shape >= 0) {
                // The octant the segment starts in, and the planes it crosses, sorted by t.
                int octant = 0, crossings = 0;
                float t_cross[3];
                int cross_axis[3];
                for (int axis = 0; axis < 3; ++axis) {
                    const float centre = loadf(address, axis);
                    const float t_split = (centre - o[axis]) * inv[axis];
                    const bool below = o[axis] < centre || (o[axis] == centre && d[axis] <= 0.0f);
                    const bool starts_above =
                        (!(t_split > 0.0f) || t_split > t_far || !(t_split < t_near)) ? !below
                                                                                      : below;
                    if (starts_above) octant |= 1 << axis;
                    if (!(t_split > 0.0f) || t_split > t_far || t_split < t_near) continue;
                    int k = crossings++;
                    for (; k > 0 && t_cross[k - 1] > t_split; --k) {
                        t_cross[k] = t_cross[k - 1];
                        cross_axis[k] = cross_axis[k - 1];
                    }
                    t_cross[k] = t_split;
                    cross_axis[k] = axis;
                }
                const int first_child = shape >> 8, occupied = shape & 0xff;
                // The octants after the first, pushed last first, each with its segment.
                int octants[4];
                octants[0] = octant;
                for (int k = 0; k < crossings; ++k)
                    octants[k + 1] = octants[k] ^ (1 << cross_axis[k]);
                for (int k = crossings; k >= 1; --k) {
                    if (!(occupied >> octants[k] & 1)) continue;
                    if (depth == kOctreeStackEntries) {
                        ++stats.stack_overflows;
                        continue;
                    }
                    stack_node[depth] = first_child + octants[k];
                    stack_near[depth] = t_cross[k - 1];
                    stack_far[depth] = k < crossings ? t_cross[k] : t_far;
                    ++depth;
                    if (uint32_t(depth) > stats.max_stack_depth) stats.max_stack_depth = depth;
                }
                if (occupied >> octant & 1) {
                    node = first_child + octant;
                    if (crossings > 0) t_far = t_cross[0];
                    continue;
                }
            } else {
                const int first_ref = loadi(address, kOctreeFirst);
                const int end = first_ref + loadi(address, kOctreeCount);
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
            }
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

}  // namespace trax::rt
