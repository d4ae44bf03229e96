// Recurses far deeper than any local store holds: the run must stop with a stack-overflow fault.
#include "trax.hpp"

namespace {
int depth(int n) {
    volatile int frame[16];  // a real stack frame per call, so the recursion cannot be folded
    frame[0] = n;
    return n == 0 ? 0 : depth(n - 1) + frame[0];
}
}  // namespace

void trax_main() {
    storei(depth(1 << 20), trax_framebuffer(), 0);
}
