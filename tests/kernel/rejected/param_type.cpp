// Rejected at compile time: a run-time parameter is a float or an int (tpsim reads the type from
// the symbol's name, trax_param_<type>_<name>).
#include "trax.hpp"

TRAX_PARAM(unsigned, count, 4u);

void trax_main() {
    storei(static_cast<int>(count), trax_framebuffer());
}
