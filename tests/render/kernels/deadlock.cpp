// Thread 0 takes the semaphore and keeps it; after the first barrier (so thread 0 surely holds
// it) the others wait for it while thread 0 waits at the second barrier: nobody can go on,
// which must be a fault naming them, not a hang.
#include "trax.hpp"

void trax_main() {
    const int id = trax_thread_id();
    if (id == 0) trax_semacq(3);
    trax_barrier();
    if (id != 0) {
        trax_semacq(3);
        trax_semrel(3);
    }
    trax_barrier();
}
