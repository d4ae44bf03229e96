// Loads a word from an address that is not a multiple of 4: the run must stop with a
// misaligned-access fault.
#include "trax.hpp"

void trax_main() {
    unsigned address = 0x1000'0002;  // two bytes into global memory
    asm volatile("" : "+r"(address));
    storei(*reinterpret_cast<int*>(address), trax_framebuffer(), 0);
}
