// Unbounded recursion: must fault as a stack overflow inside recurse().
#include "guest.h"

__attribute__((noinline)) int recurse(volatile int n) {  // RECURSE_LINE
    volatile int locals[8];
    locals[n & 7] = n;
    return recurse(n + 1) + locals[0];
}

int main(void) { return recurse(0); }
