// The smallest useful kernel: every thread leaves its ids in the framebuffer, so a test can see
// that each thread ran once with the right identity. Pixel t holds (thread id, TM id, index in
// TM) of thread t as integers; threads beyond the pixel count write nothing.
#include "trax.hpp"

void trax_main() {
    const int id = trax_thread_id();
    if (id >= trax_image_width() * trax_image_height()) return;
    const int pixel = trax_framebuffer() + id * trax::layout::kPixelWords;
    storei(id, pixel, 0);
    storei(trax_tm_id(), pixel, 1);
    storei(trax_tp_id(), pixel, 2);
}
