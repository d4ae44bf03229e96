// Every thread prints a few lines, with a barrier between them so that on every engine the
// threads' lines are produced interleaved; the output must still come out in thread order, the
// same on every engine. Covers each conversion and the simtrax names.
#include "trax.hpp"

void trax_main() {
    const int id = trax_thread_id();
    trax_printf("x = %d, %i%%, %u, %x/%X, [%c] %s\n", id, -id, 4000000000u, 255 + id, 0xbeef,
                char('a' + id % 26), "ok");
    trax_barrier();
    trax_printf("f = %f %.3f %.0f %8.2f|%-7.1f|%+.2f %f %f\n", float(id) * 0.1f, -2.0005f, 2.5f,
                3.14159f, 1.25f, 7.0f, 1e30f, 1e-7f);
    trax_barrier();
    trax_printf("pad [%5d] [%-5d] [%05d] [%.3d] [%6s] [%-6s] [%.2s]\n", id, id, -id, id, "ab", "cd",
                "efgh");
    trax_printf("bad %d %f %s\n", 1.5f, id, id);
    trax_printi(id);
    trax_printf(0.5f);
    printf("simtrax printf %d\n", id);
    trax_printf("no newline at the end");
}
