// Ray queries for tests through the wide BVH (kernel/wide_bvh.hpp, kernel/ray_query.hpp): the
// robustness oracle checks its hits against the binary BVH's and Embree's.
#include "ray_query.hpp"
#include "wide_bvh.hpp"

TRAX_USES_WIDE_BVH;

void trax_main() {
    trax::rt::with_wide_bvh([](const auto& bvh) { trax::rt::answer_ray_queries(bvh); });
}
