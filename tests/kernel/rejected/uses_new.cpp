// Rejected: operator new needs a heap.
#include "trax.hpp"

void trax_main() {
    int* counter = new int(trax_thread_id());
    storei(*counter, trax_framebuffer());
}
