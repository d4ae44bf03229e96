// Course experiment "coherence" (docs/course/experiments.md): the tracer handing pixels out in
// 8 x 8 tiles instead of scanlines.
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    using namespace trax::rt;
    render_image_with<RenderPolicy{.order = PixelOrder::tiles}>(BvhTraversal::from_scene());
}
