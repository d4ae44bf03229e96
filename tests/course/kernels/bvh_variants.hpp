// BVH traversals that drop one of assignment 4's ideas, for the checker's budget tests: children
// in fixed order (left first) instead of nearer first, or no early-out (boxes are tested against
// the whole ray, not cut at the closest hit, and every pushed subtree is visited). Otherwise the
// reference traversal.
#pragma once
#include "rt.hpp"

TRAX_USES_BVH;

namespace variants {

using namespace trax::rt;

template <bool kNearerFirst, bool kEarlyOut> struct Bvh {
    int nodes, triangles;

    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        const ShearedRay ray = shear(origin, dir);
        const Vec3 inverse{1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        int stack[kTraversalStackEntries];
        float entry[kTraversalStackEntries];
        int depth = 0;
        int node = nodes;
        ++stats.nodes_visited;
        if (slab_entry(node, origin, inverse, hit.t) > hit.t) return hit;
        for (;;) {
            const int first = loadi(node, kNodeFirst), count = loadi(node, kNodeCount);
            if (count == 0) {
                const int left = nodes + first * kBvhNodeWords, right = left + kBvhNodeWords;
                stats.nodes_visited += 2;
                const float t_far = kEarlyOut ? hit.t : t_max;
                const float t_left = slab_entry(left, origin, inverse, t_far);
                const float t_right = slab_entry(right, origin, inverse, t_far);
                const bool in_left = t_left <= t_far, in_right = t_right <= t_far;
                if (in_left && in_right) {
                    const bool left_first = !kNearerFirst || t_left <= t_right;
                    node = left_first ? left : right;
                    stack[depth] = left_first ? right : left;
                    entry[depth] = left_first ? t_right : t_left;
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
            do {
                if (depth == 0) return hit;
                --depth;
            } while (kEarlyOut && entry[depth] > hit.t);
            node = stack[depth];
        }
    }
};

template <bool kNearerFirst, bool kEarlyOut> void render() {
    render_image(Bvh<kNearerFirst, kEarlyOut>{trax_bvh(), trax_triangles()});
}

}  // namespace variants
