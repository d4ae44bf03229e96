// Assignment 5 by paths.hpp's tracer: emission counted on the emitters' back side.
#include "paths.hpp"

TRAX_USES_BVH;

void trax_main() {
    paths::render<paths::Variant::emission_back>();
}
