// Reports what a BVH walk with a 4-entry stack reports on a deeper BVH: its stack filled at 4
// entries and an entry was dropped. (Only the report matters here, not the walk itself.)
#include "rt.hpp"

TRAX_USES_BVH;

void trax_main() {
    trax::rt::RayStats ray;
    ray.max_stack_depth = 4;
    ray.stack_overflows = 1;
    trax::rt::ThreadTotals totals;
    totals.add(ray, false);
    totals.store();
}
