// Assignment 4, reference solution: the BVH traversal of bvh_traversal.hpp (explicit stack,
// nearer child first, early-out; assignment 6's solution shares it) with rt.hpp's slab test.
// The triangle test, shading and the pixel loop are kernel/rt.hpp's too (assignment 3 is
// behind us).
#include "bvh_traversal.hpp"

TRAX_USES_BVH;

void trax_main() {
    trax::rt::render_image(SolutionBvh<trax::rt::slab_entry>::from_scene());
}
