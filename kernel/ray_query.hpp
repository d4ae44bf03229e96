// The ray_query kernels' body, for any traversal (BvhTraversal, GridTraversal, ...): reads the
// image's rays section, traces each ray and writes one RayResult per ray: the hit triangle
// (image index, -1 for none), its distance and the ray's traversal counts. A kRayFromSurface
// query is what shading does: the closest hit of a camera ray, then the ray from that surface
// point to a target with the same origin offset (rt.hpp's trace_to for any-hit queries).
// Rays are handed out with atomicinc(0), so any thread count gives the same results.
#pragma once
#include "rt.hpp"

namespace trax::rt {

template <class Accel> void answer_ray_queries(const Accel& accel) {
    const int rays = loadi(0, kHeaderRays), num_rays = loadi(0, kHeaderRays + 1);
    const int results = loadi(0, kHeaderRayResults);
    ThreadTotals totals;
    for (int i = atomicinc(0); i < num_rays; i = atomicinc(0)) {
        const int ray = rays + i * kRayWords;
        const Vec3 origin = load_vec3(ray, kRayOrigin);
        const Vec3 dir = load_vec3(ray, kRayDirection);
        const float t_max = loadf(ray, kRayTMax);
        const int mode = loadi(ray, kRayMode);
        const bool any_hit = mode & kRayAnyHit;
        RayStats stats;
        Hit hit, surface;
        surface.triangle = -1;
        if (mode & kRayFromSurface) {
            surface = accel.template trace<false>(origin, dir, t_max, stats);
            totals.add(stats, false);
            if (surface.triangle >= 0) {
                const SurfacePoint s = surface_point(
                    accel.triangles + surface.triangle * kTriangleWords, surface, origin, dir);
                const Vec3 target = load_vec3(ray, kRayTarget);
                RayStats second;
                if (any_hit) {
                    hit = trace_to(accel, s, target, second);
                } else {
                    const Vec3 start = offset_origin(s, target - s.p);
                    hit = accel.template trace<false>(start, target - start, 1.0f, second);
                }
                totals.add(second, any_hit);
                stats.nodes_visited += second.nodes_visited;
                stats.triangles_tested += second.triangles_tested;
                if (second.max_stack_depth > stats.max_stack_depth)
                    stats.max_stack_depth = second.max_stack_depth;
                stats.stack_overflows += second.stack_overflows;
            }
        } else {
            hit = any_hit ? accel.template trace<true>(origin, dir, t_max, stats)
                          : accel.template trace<false>(origin, dir, t_max, stats);
            totals.add(stats, any_hit);
        }
        const int out = results + i * kRayResultWords;
        storei(hit.triangle, out, kResultTriangle);
        storef(hit.t, out, kResultT);
        storei(surface.triangle, out, kResultSurfaceTriangle);
        storef(surface.t, out, kResultSurfaceT);
        storei(static_cast<int>(stats.nodes_visited), out, kResultNodesVisited);
        storei(static_cast<int>(stats.triangles_tested), out, kResultTrianglesTested);
        storei(static_cast<int>(stats.max_stack_depth), out, kResultMaxStackDepth);
        storei(static_cast<int>(stats.stack_overflows), out, kResultStackOverflows);
    }
    totals.store();
}

}  // namespace trax::rt
