// Accepted: an int converted to float where the pixel maths needs it, `(x + 0.5f) / width`. A
// float cannot hold every int, but pixel coordinates are far below 2^24: kernels may write it.
#include "trax.hpp"

void trax_main() {
    const int width = trax_image_width(), x = trax_thread_id() % width;
    storef((x + 0.5f) / width, trax_framebuffer());
}
