// Assignment 7, reference solution: tpsim's own grid traversal (kernel/grid.hpp, the kernel
// tracer_grid), the 3D-DDA of Amanatides and Woo with the early stop; its comments say why each
// step is written as it is (face distances from the face positions, the entry cell clamped as
// a float).
#include "grid.hpp"

TRAX_USES_GRID;

void trax_main() {
    trax::rt::render_image(trax::rt::GridTraversal::from_scene());
}
