// Course experiment "nearer child first" (docs/course/experiments.md): the tracer with the
// traversal always descending into the left child first, whichever is nearer.
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    render_image(BasicBvhTraversal<TraversalPolicy{.nearer_child_first = false}>::from_scene());
}
