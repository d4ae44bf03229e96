// Assignment 1, reference solution: the gradient. Red grows from left to right, green from top
// to bottom, blue is a constant 0.25; pixels are handed out with atomicinc(0) so every thread
// works.
#include "trax.hpp"

void trax_main() {
    const int width = trax_image_width(), height = trax_image_height();
    const int framebuffer = trax_framebuffer();
    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const int x = pixel % width, y = pixel / width;
        const int out = framebuffer + pixel * trax::layout::kPixelWords;
        storef((static_cast<float>(x) + 0.5f) / static_cast<float>(width), out, 0);
        storef((static_cast<float>(y) + 0.5f) / static_cast<float>(height), out, 1);
        storef(0.25f, out, 2);
    }
}
