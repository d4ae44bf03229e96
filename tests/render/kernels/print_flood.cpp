// Every thread prints far more than the output limit in total: the run keeps the first bytes
// in thread order, the same on every engine, and drops (and counts) the rest.
#include "trax.hpp"

void trax_main() {
    const int id = trax_thread_id();
    for (int line = 0; line < 2000; ++line)
        trax_printf("thread %d line %d: %s\n", id, line,
                    "some text to fill the output quickly .........................");
}
