// Every thread adds 1 to one shared counter kTimes, by load and store: without mutual exclusion,
// increments are lost when threads interleave between the load and the store.
#include "trax.hpp"

namespace {

constexpr int kTimes = 5;
constexpr int kCounterSemaphore = 7;

template <bool kLocked> void count() {
    const int counter = trax_framebuffer();
    for (int i = 0; i < kTimes; ++i) {
        if (kLocked) trax_semacquire(kCounterSemaphore);
        const int value = loadi(counter);
        float slow = float(value);  // a little work inside the critical section
        for (int k = 0; k < 4; ++k)
            slow = trax_sqrt(slow * slow + 1.0f);
        storef(slow, counter, 1 + trax_thread_id());
        storei(value + 1, counter);
        if (kLocked) trax_semrelease(kCounterSemaphore);
    }
}

}  // namespace
