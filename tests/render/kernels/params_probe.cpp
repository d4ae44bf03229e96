// Run-time parameters as every engine sees them: thread 0 writes `gain` (as a float) and `count`
// to framebuffer words 0 and 1, and `gain * count` to word 2. `unused` is never read: the link
// script keeps it, so it can still be set.
#include "trax.hpp"

TRAX_PARAM(float, gain, 0.5f);
TRAX_PARAM(int, count, 3);
TRAX_PARAM(int, unused, 7);

void trax_main() {
    if (trax_thread_id() != 0) return;
    const int out = trax_framebuffer();
    storef(gain, out, 0);
    storei(count, out, 1);
    storef(gain * static_cast<float>(count), out, 2);
}
