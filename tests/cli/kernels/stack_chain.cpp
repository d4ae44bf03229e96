// Calls of fixed frames, nested three deep on one branch and one deep on the other: the stack
// bound is the deeper chain's frames summed, and thread 0 takes exactly that chain, so `tpsim
// exec --local-store BOUND` runs and BOUND - 16 faults (the bound is exact, not just safe).
#include "trax.hpp"

namespace {
/// A frame of `words` ints that the compiler must keep whole: every word written, then read.
template <int words> __attribute__((always_inline)) inline int use_frame(int n) {
    volatile int frame[words];
    for (int i = 0; i < words; ++i)
        frame[i] = i + n;
    int sum = 0;
    for (int i = 0; i < words; ++i)
        sum += frame[i];
    return sum;
}
__attribute__((noinline)) int leaf(int n) {
    return use_frame<100>(n);
}
__attribute__((noinline)) int middle(int n) {
    return use_frame<200>(n) + leaf(n + 1);
}
__attribute__((noinline)) int outer(int n) {
    return use_frame<50>(n) + middle(n + 2);
}
__attribute__((noinline)) int shallow(int n) {
    return use_frame<20>(n);
}
}  // namespace

void trax_main() {
    const int id = trax_thread_id();
    volatile int result = id == 0 ? outer(id) : shallow(id);
    (void)result;
}
