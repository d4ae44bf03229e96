// Brute-force shading with one mistake: flipped (mistakes.hpp).
#include "mistakes.hpp"

void trax_main() {
    mistakes::render<mistakes::Mistake::flipped>();
}
