// Assignment 1: your first kernel, an image gradient (docs/course/1-gradient.md).
//
// Every hardware thread runs trax_main() once. The framebuffer holds 3 floats per pixel (red,
// green, blue, linear), row 0 at the top: pixel (x, y) starts at word
//     trax_framebuffer() + (y * trax_image_width() + x) * 3.
//
// As given, thread 0 alone paints every pixel the same blue. Make it the gradient:
#include "trax.hpp"

void trax_main() {
    // TODO 2: let every thread work: take pixels with `atomicinc(0)` (it returns 0, 1, 2, ...
    // over all threads, each value once) instead of this early return.
    if (trax_thread_id() != 0) return;

    const int width = trax_image_width(), height = trax_image_height();
    const int framebuffer = trax_framebuffer();
    for (int pixel = 0; pixel < width * height; ++pixel) {
        const int out = framebuffer + pixel * 3;
        // TODO 1: red = (x + 0.5) / width and green = (y + 0.5) / height of this pixel.
        storef(0.0f, out, 0);
        storef(0.0f, out, 1);
        storef(0.25f, out, 2);
    }
}
