// The tracer of tracer.cpp over the BSP tree (planes of 13 orientations) instead of the BVH: the
// same camera rays, shading and shadow rays, each ray walked leaf by leaf with kernel/kdtree.hpp's
// BspTraversal. Compare it with tracer_kdtree (the same builder with the axes only) by traffic.
#include "kdtree.hpp"

TRAX_USES_BSP;

void trax_main() {
    trax::rt::render_image(trax::rt::BspTraversal::from_scene());
}
