// Ambient occlusion in packets (kernel/packet.hpp, kernel/occlusion.hpp): a 2 x 2 block of pixels
// per thread; the camera rays go through the BVH as one packet, then each of the four occlusion
// rays of every hit as one packet of the block's rays. The same rays and image as ao: the
// difference is what packets do to incoherent rays.
#include "occlusion.hpp"
#include "packet.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    const PacketBvhTraversal bvh = PacketBvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    const float reach = occlusion_distance();
    render_packets([&](const RayPacket& camera_rays, const int(&pixels)[kPacketRays], int sample,
                       Vec3(&colors)[kPacketRays], ThreadTotals& totals) {
        Hit hits[kPacketRays];
        RayStats stats[kPacketRays];
        bvh.trace<false>(camera_rays, hits, stats);
        LitPoint lit[kPacketRays];
        int escaped[kPacketRays] = {};
        uint32_t lit_rays = 0;
        for (int i = 0; i < kPacketRays; ++i) {
            if (pixels[i] < 0) continue;
            totals.add(stats[i], false);
            if (hits[i].triangle < 0) {
                colors[i] = s.background;
                continue;
            }
            lit[i] = lit_point(s, hits[i], camera_rays.origin[i], camera_rays.dir[i]);
            lit_rays |= 1u << i;
        }
        if (lit_rays == 0) return;
        for (int ray = 0; ray < kOcclusionRays; ++ray) {
            RayPacket occlusion_rays;
            for (int i = 0; i < kPacketRays; ++i) {
                if (!(lit_rays >> i & 1u)) continue;
                const Vec3 d = occlusion_direction(lit[i].n, pixels[i], sample, ray);
                occlusion_rays.set(i, offset_origin(lit[i].surface, d), d, reach);
            }
            Hit blockers[kPacketRays];
            RayStats occlusion_stats[kPacketRays];
            bvh.trace<true>(occlusion_rays, blockers, occlusion_stats);
            for (int i = 0; i < kPacketRays; ++i) {
                if (!(lit_rays >> i & 1u)) continue;
                totals.add(occlusion_stats[i], true);
                if (blockers[i].triangle < 0) ++escaped[i];
            }
        }
        for (int i = 0; i < kPacketRays; ++i)
            if (lit_rays >> i & 1u) colors[i] = occluded_color(lit[i], escaped[i]);
    });
}
