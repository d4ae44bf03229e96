// The shared counter without the semaphore: the control that shows increments get lost.
#include "semaphore_counter.hpp"

void trax_main() {
    count<false>();
}
