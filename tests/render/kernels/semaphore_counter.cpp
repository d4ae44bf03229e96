// The shared counter with the semaphore around each increment: never an increment lost.
#include "semaphore_counter.hpp"

void trax_main() {
    count<true>();
}
