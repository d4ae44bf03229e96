// Assignment 4: the BVH (docs/course/4-bvh.md).
//
// The shading, the triangle test (rt.hpp's intersect, Woop et al.'s watertight test), the
// slab test (rt.hpp's slab_entry) and the pixel loop (render_image) are given; `trace` is
// yours. As given it tests every triangle for every ray: right, but far too slow for the
// bunny's 69,666 triangles. Make it walk the BVH.
#include "rt.hpp"

// Asks tpsim to build the BVH and put it in memory (trax_bvh(), kBvhNodeWords words a node;
// kernel/scene_layout.hpp's BvhNode says what a node holds).
TRAX_USES_BVH;

using namespace trax::rt;

struct Bvh {
    int nodes, triangles;

    /// The closest hit with 0 < t < t_max (kAnyHit: any hit) of origin + t * dir; counts what
    /// it tests in `stats`.
    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        const ShearedRay ray = shear(origin, dir);
        // TODO 1: start at the root node (`nodes`) instead of looping over every triangle: an
        // interior node (count == 0) has children first and first + 1; a leaf holds triangles
        // [first, first + count). Keep the nodes still to visit on an explicit stack
        // (int stack[kTraversalStackEntries]): kernels have no room for recursion.
        // TODO 2: of two children the ray enters, go into the nearer first (slab_entry gives
        // the entry distance) and push the farther.
        // TODO 3: early-out: skip a popped node whose entry distance is beyond hit.t.
        const int num_triangles = trax_num_triangles();
        for (int i = 0; i < num_triangles; ++i) {
            ++stats.triangles_tested;
            TriangleHit found;
            if (intersect(ray, triangles + i * kTriangleWords, hit.t, found)) {
                hit.triangle = i;
                hit.t = found.t;
                hit.plane_error = found.plane_error;
                if (kAnyHit) return hit;
            }
        }
        return hit;
    }
};

void trax_main() {
    render_image(Bvh{trax_bvh(), trax_triangles()});
}
