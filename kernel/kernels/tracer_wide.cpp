// The tracer of tracer.cpp over a wide BVH (4 or 8 children per node, float or quantized boxes,
// whichever render --accel bvh4|bvh8 and --bvh-boxes built): the same camera rays, shading and
// shadow rays, each ray walked with kernel/wide_bvh.hpp. Compare it with tracer by traffic:
// `tpsim compare` of the two runs.
#include "wide_bvh.hpp"

TRAX_USES_WIDE_BVH;

void trax_main() {
    trax::rt::with_wide_bvh([](const auto& bvh) { trax::rt::render_image(bvh); });
}
