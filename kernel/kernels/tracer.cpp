// The BVH ray tracer: camera rays (jittered when samples_per_pixel > 1), Lambert shading with
// point lights and hard shadows, traced through the scene's BVH with the fixed-capacity stack
// traversal of kernel/rt.hpp (nearer child first, any-hit shadow rays). tpsim's default kernel.
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    trax::rt::render_image(trax::rt::BvhTraversal::from_scene());
}
