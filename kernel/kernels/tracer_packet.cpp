// The tracer of tracer.cpp in packets (kernel/packet.hpp): a 2 x 2 block of pixels per thread,
// its camera rays traced through the BVH as one packet and its shadow rays as one packet per
// light. The same rays and image as tracer; compare the two by traffic and cycles with
// `tpsim compare` to measure what packets do to coherent rays.
#include "packet.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    const PacketBvhTraversal bvh = PacketBvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    render_packets([&](const RayPacket& camera_rays, const int(&pixels)[kPacketRays], int,
                       Vec3(&colors)[kPacketRays], ThreadTotals& totals) {
        shade_lambert(s, bvh, camera_rays, pixels, colors, totals);
    });
}
