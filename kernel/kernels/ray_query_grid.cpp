// Ray queries for tests through the uniform grid (kernel/grid.hpp, kernel/ray_query.hpp): the
// robustness oracle checks its hits against the BVH's and Embree's.
#include "grid.hpp"
#include "ray_query.hpp"

TRAX_USES_GRID;

void trax_main() {
    trax::rt::answer_ray_queries(trax::rt::GridTraversal::from_scene());
}
