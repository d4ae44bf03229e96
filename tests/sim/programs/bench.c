// Compute-heavy loop for measuring the functional core: integer hashing plus FP arithmetic.
// Global word 0 holds the iteration count (set by the host); each thread stores its result in
// global word [1 + mhartid] so nothing is optimized away.
#include "guest.h"

#define GLOBAL ((volatile unsigned*)0x10000000)

int main(void) {
    unsigned id;
    __asm__ volatile("csrr %0, mhartid" : "=r"(id));
    const unsigned iterations = GLOBAL[0];
    unsigned hash = id;
    float x = (float)id * 0.001f, y = 1.0f, sum = 0.0f;
    for (unsigned i = 0; i < iterations; ++i) {
        hash = hash * 1664525u + 1013904223u;
        x = x * 0.999f + (float)(hash >> 24) * 0.001f;
        sum += x * y;
        y = y * 0.5f + 0.75f;
    }
    union { float f; unsigned u; } bits = {sum};
    GLOBAL[1 + id] = bits.u ^ hash;
    return 0;
}
