// Rejected: sinf is a C library function; TRaX kernels have no C library.
#include "trax.hpp"

extern "C" float sinf(float);

float wave(float x) {
    return sinf(x);
}

void trax_main() {
    storef(wave(loadf(0, 7)), trax_framebuffer());
}
