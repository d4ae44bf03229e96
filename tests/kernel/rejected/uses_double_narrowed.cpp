// Rejected at compile time: p * 0.5 is int x double, computed in double and then narrowed to
// float; -Werror=implicit-float-conversion catches it (no float is promoted, so
// -Werror=double-promotion alone would let it through).
#include "trax.hpp"

void trax_main() {
    const int p = loadi(0, 2);
    float x = p * 0.5;
    storef(x, trax_framebuffer());
}
