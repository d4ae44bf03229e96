// Course experiment "any-hit shadow rays" (docs/course/experiments.md): the tracer with shadow rays
// that look for the closest blocker instead of stopping at the first one they find.
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    render_image_with<RenderPolicy{.any_hit_shadows = false}>(BvhTraversal::from_scene());
}
