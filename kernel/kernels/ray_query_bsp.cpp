// Ray queries for tests through the BSP tree (kernel/kdtree.hpp, kernel/ray_query.hpp): the
// robustness oracle checks its hits against the BVH's and Embree's.
#include "kdtree.hpp"
#include "ray_query.hpp"

TRAX_USES_BSP;

void trax_main() {
    trax::rt::answer_ray_queries(trax::rt::BspTraversal::from_scene());
}
