// Course experiment "grid early stop" (docs/course/experiments.md) and assignment 7's budget
// test: tracer_grid with the walk going on to the grid's far side after the closest hit, instead
// of stopping at the first cell whose exit lies beyond it.
#include "grid.hpp"

TRAX_USES_GRID;

void trax_main() {
    trax::rt::render_image(trax::rt::BasicGridTraversal<false>::from_scene());
}
