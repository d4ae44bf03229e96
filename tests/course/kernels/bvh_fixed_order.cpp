// The reference traversal with the children in fixed order, left first (bvh_variants.hpp).
#include "bvh_variants.hpp"

void trax_main() {
    variants::render<false, true>();
}
