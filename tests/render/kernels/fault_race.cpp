// Threads take items with atomicinc and print each; the thread that takes item 40 then runs an
// illegal instruction, a fault in an instruction private to it. Which
// items are printed before the fault follows the order of every atomic, print and fault in the
// run, which must not depend on how many host threads simulate the chip (test_parallel.cpp).
#include "trax.hpp"

void trax_main() {
    for (int item = atomicinc(1); item < 200; item = atomicinc(1)) {
        trax_printf("%d ", item);
        float x = float(item);
        for (int k = 0; k < item % 7; ++k)
            x = trax_sqrt(x * x + 1.0f);
        if (item == 40) asm volatile(".word 0");  // not an instruction
        storef(x, trax_framebuffer(), item % 16);
    }
}
