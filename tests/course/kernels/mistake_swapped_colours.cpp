// Brute-force shading with one mistake: swapped colours (mistakes.hpp).
#include "mistakes.hpp"

void trax_main() {
    mistakes::render<mistakes::Mistake::swapped_colours>();
}
