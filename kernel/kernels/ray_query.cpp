// Ray queries for tests: reads the image's rays section, traces each ray through the BVH with
// the tracer's traversal (kernel/rt.hpp) and writes one RayResult per ray: the hit triangle
// (image index, -1 for none), its distance and the ray's traversal counts.
// Rays are handed out with atomicinc(0), so any thread count gives the same results.
#include "rt.hpp"

TRAX_USES_BVH;

using namespace trax::rt;

void trax_main() {
    const BvhTraversal bvh = BvhTraversal::from_scene();
    const int rays = loadi(0, kHeaderRays), num_rays = loadi(0, kHeaderRays + 1);
    const int results = loadi(0, kHeaderRayResults);
    ThreadTotals totals;
    for (int i = atomicinc(0); i < num_rays; i = atomicinc(0)) {
        const int ray = rays + i * kRayWords;
        Vec3 origin = load_vec3(ray, kRayOrigin);
        const Vec3 dir = load_vec3(ray, kRayDirection);
        const float t_max = loadf(ray, kRayTMax);
        const int mode = loadi(ray, kRayMode);
        if (mode & kRayFromSurface) {
            const int tri = bvh.triangles + loadi(ray, kRaySurfaceTriangle) * kTriangleWords;
            // The normal facing against -dir, i.e. towards the side the ray leaves to.
            origin = offset_origin(origin, facing_normal(tri, dir * -1.0f));
        }
        RayStats stats;
        const bool any_hit = mode & kRayAnyHit;
        const Hit hit = any_hit ? bvh.trace<true>(origin, dir, t_max, stats)
                                : bvh.trace<false>(origin, dir, t_max, stats);
        totals.add(stats, any_hit);
        const int out = results + i * kRayResultWords;
        storei(hit.triangle, out, kResultTriangle);
        storef(hit.t, out, kResultT);
        storei(static_cast<int>(stats.nodes_visited), out, kResultNodesVisited);
        storei(static_cast<int>(stats.triangles_tested), out, kResultTrianglesTested);
        storei(static_cast<int>(stats.max_stack_depth), out, kResultMaxStackDepth);
        storei(static_cast<int>(stats.stack_overflows), out, kResultStackOverflows);
    }
    totals.store();
}
