// The reference solutions' BVH traversal (assignments 4 and 6): a closest-hit ray walks the tree
// with an explicit stack, visits the nearer child first, pushes the farther one with its entry
// distance, and skips every popped subtree that starts beyond the closest hit found so far; a
// shadow ray (any hit) stops at its first hit. The box test is a parameter: assignment 4 uses
// rt.hpp's slab_entry, assignment 6 a leaner one.
#pragma once
#include "rt.hpp"

/// Where the ray (origin, 1 / direction) enters the box of `node` within [0, t_far], or a value
/// beyond t_far for a miss (rt.hpp's slab_entry is one).
using BoxEntry = float (*)(int node, trax::rt::Vec3 origin, trax::rt::Vec3 inverse, float t_far);

template <BoxEntry kBoxEntry> struct SolutionBvh {
    int nodes, triangles;

    static SolutionBvh from_scene() { return {trax_bvh(), trax_triangles()}; }

    template <bool kAnyHit>
    trax::rt::Hit trace(trax::rt::Vec3 origin, trax::rt::Vec3 dir, float t_max,
                        trax::rt::RayStats& stats) const {
        using namespace trax::rt;
        Hit hit;
        hit.t = t_max;
        const ShearedRay ray = shear(origin, dir);
        const Vec3 inverse{1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        int stack[kTraversalStackEntries];
        float entry[kTraversalStackEntries];
        int depth = 0;
        int node = nodes;
        ++stats.nodes_visited;
        if (kBoxEntry(node, origin, inverse, hit.t) > hit.t) return hit;
        for (;;) {
            const int first = loadi(node, kNodeFirst), count = loadi(node, kNodeCount);
            if (count == 0) {
                // Interior: test both children's boxes, go into the nearer, keep the farther.
                const int left = nodes + first * kBvhNodeWords, right = left + kBvhNodeWords;
                stats.nodes_visited += 2;
                const float t_left = kBoxEntry(left, origin, inverse, hit.t);
                const float t_right = kBoxEntry(right, origin, inverse, hit.t);
                const bool in_left = t_left <= hit.t, in_right = t_right <= hit.t;
                if (in_left && in_right) {
                    const bool left_nearer = t_left <= t_right;
                    node = left_nearer ? left : right;
                    stack[depth] = left_nearer ? right : left;
                    entry[depth] = left_nearer ? t_right : t_left;
                    ++depth;
                    continue;
                }
                if (in_left || in_right) {
                    node = in_left ? left : right;
                    continue;
                }
            } else {
                for (int i = first; i < first + count; ++i) {
                    ++stats.triangles_tested;
                    TriangleHit found;
                    if (intersect(ray, triangles + i * kTriangleWords, hit.t, found)) {
                        hit.triangle = i;
                        hit.t = found.t;
                        hit.plane_error = found.plane_error;
                        if (kAnyHit) return hit;
                    }
                }
            }
            // Early-out: a subtree whose box starts beyond the closest hit cannot hold a closer
            // one.
            do {
                if (depth == 0) return hit;
                --depth;
            } while (entry[depth] > hit.t);
            node = stack[depth];
        }
    }
};
