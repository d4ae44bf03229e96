// The tracer of tracer.cpp over the kd-tree instead of the BVH: the same camera rays, shading
// and shadow rays, each ray walked leaf by leaf with kernel/kdtree.hpp. Compare it with tracer
// by traffic: `tpsim compare` of the two runs.
#include "kdtree.hpp"

TRAX_USES_KDTREE;

void trax_main() {
    trax::rt::render_image(trax::rt::KdTreeTraversal::from_scene());
}
