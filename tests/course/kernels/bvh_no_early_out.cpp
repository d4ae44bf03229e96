// The reference traversal without the early-out (bvh_variants.hpp).
#include "bvh_variants.hpp"

void trax_main() {
    variants::render<true, false>();
}
