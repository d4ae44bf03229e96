// Accepted: the control case, so a failure of the others means the checker, not the rule, spoke.
// Uses struct copies and a zeroed array, the things that make clang emit memcpy/memset.
#include "trax.hpp"

struct Big {
    float values[24];
};

__attribute__((noinline)) Big fill(float seed) {
    Big b{};
    for (int i = 0; i < 24; i += 5)
        b.values[i] = seed * static_cast<float>(i);
    return b;
}

void trax_main() {
    const Big b = fill(loadf(0, 7));
    Big copy = b;
    storef(copy.values[trax_thread_id() % 24], trax_framebuffer());
}
