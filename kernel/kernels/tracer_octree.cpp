// The tracer of tracer.cpp over the octree instead of the BVH: the same camera rays, shading
// and shadow rays, each ray walked cell by cell with kernel/octree.hpp. Compare it with tracer
// by traffic: `tpsim compare` of the two runs.
#include "octree.hpp"

TRAX_USES_OCTREE;

void trax_main() {
    trax::rt::render_image(trax::rt::OctreeTraversal::from_scene());
}
