// Rejected at compile time: kernels are built with -fno-exceptions.
#include "trax.hpp"

void trax_main() {
    if (trax_thread_id() < 0) throw 1;
}
