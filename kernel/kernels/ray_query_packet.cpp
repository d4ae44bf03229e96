// Ray queries for tests in packets (kernel/packet.hpp): what ray_query answers, four consecutive
// rays of the rays section per work item traced as packets: one packet of the rays whose first
// trace finds the closest hit, one of the any-hit rays, then the kRayFromSurface queries' rays
// from their surface points, closest and any-hit again apart. The robustness oracle checks the
// results against the single-ray BVH's and Embree's.
#include "packet.hpp"

TRAX_USES_BVH;

namespace {

using namespace trax::rt;

/// Traces `closest` and `any` as two packets into `hits` and `stats`: ray i is any's when bit i
/// of `any_rays` is set, closest's otherwise.
void trace_both(const PacketBvhTraversal& bvh, const RayPacket& closest, const RayPacket& any,
                uint32_t any_rays, Hit (&hits)[kPacketRays], RayStats (&stats)[kPacketRays]) {
    Hit any_hits[kPacketRays];
    RayStats any_stats[kPacketRays];
    bvh.trace<false>(closest, hits, stats);
    bvh.trace<true>(any, any_hits, any_stats);
    for (int i = 0; i < kPacketRays; ++i) {
        if (!(any_rays >> i & 1u)) continue;
        hits[i] = any_hits[i];
        stats[i] = any_stats[i];
    }
}

}  // namespace

void trax_main() {
    const PacketBvhTraversal bvh = PacketBvhTraversal::from_scene();
    const int rays = loadi(0, kHeaderRays), num_rays = loadi(0, kHeaderRays + 1);
    const int results = loadi(0, kHeaderRayResults);
    ThreadTotals totals;
    const int groups = (num_rays + kPacketRays - 1) / kPacketRays;
    for (int group = atomicinc(0); group < groups; group = atomicinc(0)) {
        const int base = group * kPacketRays;
        const int count = num_rays - base < kPacketRays ? num_rays - base : kPacketRays;
        int mode[kPacketRays];
        Vec3 origin[kPacketRays], dir[kPacketRays];
        RayPacket closest, any;
        uint32_t any_rays = 0;
        for (int i = 0; i < count; ++i) {
            const int ray = rays + (base + i) * kRayWords;
            origin[i] = load_vec3(ray, kRayOrigin);
            dir[i] = load_vec3(ray, kRayDirection);
            mode[i] = loadi(ray, kRayMode);
            const bool first_any = (mode[i] & kRayAnyHit) && !(mode[i] & kRayFromSurface);
            (first_any ? any : closest).set(i, origin[i], dir[i], loadf(ray, kRayTMax));
            (first_any ? closest : any).t_max[i] = 0.0f;
            if (first_any) any_rays |= 1u << i;
        }
        for (int i = count; i < kPacketRays; ++i)
            closest.t_max[i] = any.t_max[i] = 0.0f;
        Hit first[kPacketRays];
        RayStats stats[kPacketRays];
        trace_both(bvh, closest, any, any_rays, first, stats);

        // The second rays of the surface queries: from the closest hit towards the target.
        RayPacket second_closest, second_any;
        for (int i = 0; i < kPacketRays; ++i)
            second_closest.t_max[i] = second_any.t_max[i] = 0.0f;
        uint32_t second_rays = 0, second_any_rays = 0;
        for (int i = 0; i < count; ++i) {
            const bool any_hit = mode[i] & kRayAnyHit;
            totals.add(stats[i], any_hit && !(mode[i] & kRayFromSurface));
            if (!(mode[i] & kRayFromSurface) || first[i].triangle < 0) continue;
            const SurfacePoint s = surface_point(bvh.triangles + first[i].triangle * kTriangleWords,
                                                 first[i], origin[i], dir[i]);
            const Vec3 target = load_vec3(rays + (base + i) * kRayWords, kRayTarget);
            const Vec3 start = offset_origin(s, target - s.p);
            (any_hit ? second_any : second_closest).set(i, start, target - start, 1.0f);
            second_rays |= 1u << i;
            if (any_hit) second_any_rays |= 1u << i;
        }
        Hit second[kPacketRays];
        RayStats second_stats[kPacketRays];
        trace_both(bvh, second_closest, second_any, second_any_rays, second, second_stats);

        for (int i = 0; i < count; ++i) {
            Hit hit = first[i], surface;
            surface.triangle = -1;
            if (mode[i] & kRayFromSurface) {
                surface = first[i];
                hit = Hit{};
                if (second_rays >> i & 1u) {
                    hit = second[i];
                    totals.add(second_stats[i], mode[i] & kRayAnyHit);
                    stats[i].nodes_visited += second_stats[i].nodes_visited;
                    stats[i].triangles_tested += second_stats[i].triangles_tested;
                    if (second_stats[i].max_stack_depth > stats[i].max_stack_depth)
                        stats[i].max_stack_depth = second_stats[i].max_stack_depth;
                    stats[i].stack_overflows += second_stats[i].stack_overflows;
                }
            }
            const int out = results + (base + i) * kRayResultWords;
            storei(hit.triangle, out, kResultTriangle);
            storef(hit.t, out, kResultT);
            storei(surface.triangle, out, kResultSurfaceTriangle);
            storef(surface.t, out, kResultSurfaceT);
            storei(static_cast<int>(stats[i].nodes_visited), out, kResultNodesVisited);
            storei(static_cast<int>(stats[i].triangles_tested), out, kResultTrianglesTested);
            storei(static_cast<int>(stats[i].max_stack_depth), out, kResultMaxStackDepth);
            storei(static_cast<int>(stats[i].stack_overflows), out, kResultStackOverflows);
        }
    }
    totals.store();
}
