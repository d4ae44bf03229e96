// A second, independent solution of assignment 5 (paths.hpp): a correct path tracer without
// next-event estimation.
#include "paths.hpp"

TRAX_USES_BVH;

void trax_main() {
    paths::render<paths::Variant::correct>();
}
