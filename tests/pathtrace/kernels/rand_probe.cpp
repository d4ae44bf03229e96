// For the trax_rand() tests: thread t of T fills pixels t, t + T, t + 2T ... of the framebuffer
// with three trax_rand() numbers each (static assignment, so a test knows who drew what).
// The scene's samples_per_pixel picks what seeds them:
//   1: nothing (each thread's default seeding: thread id and run seed);
//   2: trax_srand(42) once per thread (every thread draws the same sequence);
//   3: trax_srand(pixel) per pixel (the image does not depend on the thread layout).
#include "trax.hpp"

void trax_main() {
    const int mode = trax_samples_per_pixel();
    const int pixels = trax_image_width() * trax_image_height();
    const int framebuffer = trax_framebuffer();
    if (mode == 2) trax_srand(42);
    for (int pixel = trax_thread_id(); pixel < pixels; pixel += trax_num_threads()) {
        if (mode == 3) trax_srand(uint32_t(pixel));
        for (int c = 0; c < 3; ++c)
            storef(trax_rand(), framebuffer + pixel * trax::layout::kPixelWords, c);
    }
}
