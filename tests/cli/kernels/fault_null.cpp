// Loads through a null pointer: the run must stop with an unmapped-access fault.
#include "trax.hpp"

void trax_main() {
    int* pointer = nullptr;
    asm volatile("" : "+r"(pointer));  // hide the null from the optimiser
    storei(*pointer, trax_framebuffer(), 0);
}
