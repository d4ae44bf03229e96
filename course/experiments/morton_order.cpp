// Course experiment "coherence" (docs/course/experiments.md): the tracer handing pixels out along
// the Morton (Z-order) curve instead of scanlines.
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    render_image_with<RenderPolicy{.order = PixelOrder::morton}>(BvhTraversal::from_scene());
}
