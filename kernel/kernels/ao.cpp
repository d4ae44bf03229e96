// Ambient occlusion with single rays (kernel/occlusion.hpp): each camera ray's hit sends four
// diffuse rays through the BVH, one thread per pixel. The reference for ao_packet, which traces
// the same rays in packets of four.
#include "occlusion.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    const BvhTraversal bvh = BvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    const float reach = occlusion_distance();
    render_pixels<PixelOrder::scanlines>(
        [&](Vec3 origin, Vec3 dir, int pixel, int sample, ThreadTotals& totals) {
            return shade_occlusion(s, bvh, reach, origin, dir, pixel, sample, totals);
        });
}
