// Ray queries for tests through the octree (kernel/octree.hpp, kernel/ray_query.hpp): the
// robustness oracle checks its hits against the BVH's and Embree's.
#include "octree.hpp"
#include "ray_query.hpp"

TRAX_USES_OCTREE;

void trax_main() {
    trax::rt::answer_ray_queries(trax::rt::OctreeTraversal::from_scene());
}
