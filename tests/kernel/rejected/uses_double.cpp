// Rejected: double arithmetic needs soft-float helpers (__muldf3 ...) on RV32IMF.
#include "trax.hpp"

static double scale(double x) {
    return x * 3.25;
}

void trax_main() {
    storef(static_cast<float>(scale(loadi(0, 2))), trax_framebuffer());
}
