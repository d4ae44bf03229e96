// Never finishes: only --max-instructions stops it.
#include "trax.hpp"

void trax_main() {
    for (;;)
        asm volatile("");
}
