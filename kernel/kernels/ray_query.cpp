// Ray queries for tests through the BVH, with the tracer's traversal (kernel/ray_query.hpp).
#include "ray_query.hpp"

TRAX_USES_BVH;

void trax_main() {
    trax::rt::answer_ray_queries(trax::rt::BvhTraversal::from_scene());
}
