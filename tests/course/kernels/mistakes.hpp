// Kernels with one deliberate mistake each, for the checker's tests: rt.hpp's brute-force
// shading (right everywhere else) with the shadows left out, the image upside down, or red and
// blue exchanged. Each mistake_*.cpp picks one.
#pragma once
#include "rt.hpp"

namespace mistakes {

using namespace trax::rt;

enum class Mistake { no_shadows, flipped, swapped_colours };

template <Mistake kMistake> void render() {
    const BruteForce accel = BruteForce::from_scene();
    Shading s = Shading::from_scene();
    if (kMistake == Mistake::no_shadows) s.flags &= ~uint32_t(kFeatureShadows);
    const int width = trax_image_width(), height = trax_image_height();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera, kCameraEye), corner = load_vec3(camera, kCameraCorner);
    const Vec3 right = load_vec3(camera, kCameraRight), down = load_vec3(camera, kCameraDown);
    ThreadTotals totals;
    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const int x = pixel % width, y = pixel / width;
        const Vec3 dir = corner + right * ((static_cast<float>(x) + 0.5f) / float(width)) +
                         down * ((static_cast<float>(y) + 0.5f) / float(height));
        const Vec3 c = shade(s, accel, eye, dir, totals);
        const int row = kMistake == Mistake::flipped ? height - 1 - y : y;
        const int out = trax_framebuffer() + (row * width + x) * kPixelWords;
        const bool swap = kMistake == Mistake::swapped_colours;
        storef(swap ? c.z : c.x, out, 0);
        storef(c.y, out, 1);
        storef(swap ? c.x : c.z, out, 2);
    }
    totals.store();
}

}  // namespace mistakes
