// The tracer of tracer.cpp over the uniform grid instead of the BVH: the same camera rays,
// shading and shadow rays, each ray walked cell by cell with the 3D-DDA of kernel/grid.hpp.
// Compare it with tracer by traffic: `tpsim compare` of the two runs.
#include "grid.hpp"

TRAX_USES_GRID;

void trax_main() {
    trax::rt::render_image(trax::rt::GridTraversal::from_scene());
}
