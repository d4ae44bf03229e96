// Rejected at compile time: 0.5 is a double literal, so the float is promoted to double.
#include "trax.hpp"

void trax_main() {
    storef(static_cast<float>(loadf(0, 7) * 0.5), trax_framebuffer());
}
