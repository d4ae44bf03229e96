// Assignment 6: the performance project (docs/course/6-performance.md).
//
// This is tpsim's own BVH tracer (kernel/rt.hpp): its image is right, and its cycles and L1
// misses (chip/l2/reads) are the ones to beat. Copy what you need out of rt.hpp into this file and
// change it: the budgets in course/assignments/6-performance/assignment.toml say by how much.
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    // TODO: make it faster. Measure first (tpsim render --profile, --heatmap, the traffic
    // table), change one thing at a time, and keep the image the same.
    trax::rt::render_image(trax::rt::BvhTraversal::from_scene());
}
