// Assignment 4, reference solution: the BVH. A closest-hit ray walks the tree with an explicit
// stack, visits the nearer child first, pushes the farther one with its entry distance, and
// skips every popped subtree that starts beyond the closest hit found so far; a shadow ray
// (any hit) stops at its first hit. The triangle test, the slab test, shading and the pixel
// loop are kernel/rt.hpp's (assignment 3 is behind us).
#include "rt.hpp"

TRAX_USES_BVH;

using namespace trax::rt;

struct Bvh {
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
                // Interior: test both children's boxes, go into the nearer, keep the farther.
                const int left = nodes + first * kBvhNodeWords, right = left + kBvhNodeWords;
                stats.nodes_visited += 2;
                const float t_left = slab_entry(left, origin, inverse, hit.t);
                const float t_right = slab_entry(right, origin, inverse, hit.t);
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

void trax_main() {
    render_image(Bvh{trax_bvh(), trax_triangles()});
}
