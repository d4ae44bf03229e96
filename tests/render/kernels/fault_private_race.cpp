// fault_race's twin whose fault is in an instruction other threads cannot see: the thread that
// takes item 40 stores into its stack's overflow guard. The cycle loop may run a TM's private
// steps ahead of the order (cycle, TM); the fault must still be reported in its place in that
// order, after the same printed items, on any number of host threads (test_parallel.cpp).
#include "trax.hpp"

void trax_main() {
    for (int item = atomicinc(1); item < 200; item = atomicinc(1)) {
        trax_printf("%d ", item);
        float x = float(item);
        for (int k = 0; k < item % 7; ++k)
            x = trax_sqrt(x * x + 1.0f);
        if (item == 40) storef(x, 0x7f00'0000);  // the local store's overflow guard
        storef(x, trax_framebuffer(), item % 16);
    }
}
