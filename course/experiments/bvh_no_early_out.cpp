// Course experiment "early-out" (docs/course/experiments.md): the tracer with boxes tested against
// the ray's full extent and every pushed subtree visited, however far beyond the closest hit it
// starts.
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    render_image(BasicBvhTraversal<TraversalPolicy{.early_out = false}>::from_scene());
}
