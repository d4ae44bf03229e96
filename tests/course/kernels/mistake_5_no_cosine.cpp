// Assignment 5 by paths.hpp's tracer: the cosine left out of the bounce weight.
#include "paths.hpp"

TRAX_USES_BVH;

void trax_main() {
    paths::render<paths::Variant::no_cosine>();
}
