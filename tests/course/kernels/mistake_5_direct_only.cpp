// Assignment 5 by paths.hpp's tracer: one bounce only (direct light, no indirect).
#include "paths.hpp"

TRAX_USES_BVH;

void trax_main() {
    paths::render<paths::Variant::direct_only>();
}
