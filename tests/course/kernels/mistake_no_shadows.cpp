// Brute-force shading with one mistake: no shadows (mistakes.hpp).
#include "mistakes.hpp"

void trax_main() {
    mistakes::render<mistakes::Mistake::no_shadows>();
}
