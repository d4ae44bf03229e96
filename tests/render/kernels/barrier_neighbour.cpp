// Phase 1: every thread writes its value; the barrier; phase 2: every thread reads its
// neighbour's and writes the sum. Without the barrier a thread reads a neighbour that has not
// written yet. The last thread exits after the first round: the second barrier must let the
// others go on without it (threads that exited do not count).
#include "trax.hpp"

namespace {
constexpr int kRounds = 3;
}

void trax_main() {
    const int id = trax_thread_id();
    const int n = trax_num_threads();
    const int slots = trax_framebuffer();  // n words: the values of this round
    const int results = slots + n;         // n words: the sums
    for (int round = 0; round < kRounds; ++round) {
        storei(id * 10 + round, slots, id);
        trax_barrier();
        const int neighbour = (id + 1) % n;
        storei(loadi(results, id) + loadi(slots, neighbour), results, id);
        if (round == 0 && id == n - 1 && n > 1) return;
        barrier(5);  // simtrax's name: before anyone writes the next round's value
    }
}
