// Needs more stack than a 4 KiB local store holds, without recursion: every engine refuses it
// before it runs, the native twin included (its host stack would hold it).
#include "trax.hpp"

namespace {
__attribute__((noinline)) int sum_of_squares(int n) {
    volatile int table[2048];  // 8 KiB in this one frame
    for (int i = 0; i < 2048; ++i)
        table[i] = i * n;
    int sum = 0;
    for (int i = 0; i < 2048; i += 64)
        sum += table[i] * table[i];
    return sum;
}
}  // namespace

void trax_main() {
    storei(sum_of_squares(loadi(0, 2)), trax_framebuffer(), 0);
}
