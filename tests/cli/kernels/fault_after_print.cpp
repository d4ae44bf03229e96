// Prints, then writes into the read-only scene: every engine must show what the kernel printed
// before the fault's line, since a student debugging with trax_printf needs it most then. Only
// thread 0 prints and faults, so what it printed before the fault is the same on every engine;
// the twin reports this fault by name (a crash by a signal would lose its output).
#include "trax.hpp"

void trax_main() {
    if (trax_thread_id() != 0) return;
    trax_printf("camera at word %d\n", trax_camera());
    trax_printf("writing into it");
    storef(0.0f, trax_camera(), 0);
}
