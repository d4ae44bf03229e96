// Threads take items with atomicinc and print each; the thread that takes item 40 then faults:
// it runs an illegal instruction, or with private_fault=1 stores into its stack's overflow
// guard, a step no other thread can see (which the cycle loop may run ahead of the order
// (cycle, TM), but must report in its place). Which items are printed before the fault follows
// the order of every atomic, print and fault in the run, which must not depend on how many host
// threads simulate the chip (test_parallel.cpp).
#include "trax.hpp"

TRAX_PARAM(int, private_fault, 0);

void trax_main() {
    for (int item = atomicinc(1); item < 200; item = atomicinc(1)) {
        trax_printf("%d ", item);
        float x = float(item);
        for (int k = 0; k < item % 7; ++k)
            x = trax_sqrt(x * x + 1.0f);
        if (item == 40) {
            if (private_fault)
                *reinterpret_cast<volatile float*>(0x7f00'0000) = x;  // the overflow guard
            else
                asm volatile(".word 0");  // not an instruction
        }
        storef(x, trax_framebuffer(), item % 16);
    }
}
