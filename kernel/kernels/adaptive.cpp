// Adaptive super-sampling: the tracer's shading (kernel/rt.hpp) with the samples spent where the
// image needs them. Three passes over the pixels, a barrier between them:
//   1. every pixel takes `first_samples` camera rays and stores their mean; a pixel whose rays
//      differ in brightness (Rec. 709 luma of linear RGB) by more than `threshold` is marked;
//   2. an unmarked pixel whose mean differs from a 4-neighbour's by more than `threshold` is
//      marked too: an edge or a shadow boundary that all of its first rays missed (unless
//      `neighbours` is 0);
//   3. every marked pixel takes the rest of the scene's samples_per_pixel.
// Flat regions get `first_samples`, edges the full count (`tpsim converge` measures what that
// saves; docs/error-vs-time.md). The mark is the sign bit of the pixel's red value in the
// framebuffer (the tracer's colours are never negative), so the passes need no other memory.
// Deterministic and the same on every engine: a sample's position depends only on the pixel and
// the sample index, exactly as in the tracer (so with threshold < 0, which refines every pixel,
// the image is the tracer's at the same samples per pixel), and each pass reads only what the
// pass before it wrote (pass 2 reads magnitudes and changes only signs). Pass 1 hands out
// pixels with global register 0, which the heat map and the progress line follow; passes 2
// and 3 use registers 1 and 2.
#include "rt.hpp"

TRAX_USES_BVH;

/// Largest brightness difference (linear luma; about 10 steps of an 8-bit display near
/// mid-grey) between a pixel's first rays, or between its mean and a neighbour's, before the
/// pixel takes all its samples. Below 0: every pixel does.
TRAX_PARAM(float, threshold, 0.05f);
/// Rays every pixel takes first (at least 1, at most samples_per_pixel).
TRAX_PARAM(int, first_samples, 4);
/// 0 leaves pass 2 out: only pixels whose own first rays differ are refined.
TRAX_PARAM(int, neighbours, 1);

namespace {

using namespace trax::rt;

constexpr uint32_t kMark = 0x80000000u;

float luma(Vec3 c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

/// A pixel as the framebuffer holds it between the passes: the mean so far, and the mark.
struct Stored {
    Vec3 mean;
    bool marked;
};

Stored load_pixel(int framebuffer, int pixel) {
    const int at = framebuffer + pixel * kPixelWords;
    const uint32_t red = static_cast<uint32_t>(loadi(at, 0));
    return {{__builtin_bit_cast(float, red & ~kMark), loadf(at, 1), loadf(at, 2)},
            (red & kMark) != 0};
}

void store_pixel(int framebuffer, int pixel, Vec3 color, bool marked) {
    const int at = framebuffer + pixel * kPixelWords;
    storei(static_cast<int>(__builtin_bit_cast(uint32_t, color.x) | (marked ? kMark : 0u)), at, 0);
    storef(color.y, at, 1);
    storef(color.z, at, 2);
}

}  // namespace

void trax_main() {
    const BvhTraversal accel = BvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    const CameraRays camera = CameraRays::from_scene();
    const int width = camera.width, height = trax_image_height(), pixels = width * height;
    const int most = trax_samples_per_pixel();
    const int first = first_samples < 1 ? 1 : first_samples > most ? most : first_samples;
    const float limit = threshold;
    const int framebuffer = trax_framebuffer();
    ThreadTotals totals;
    const auto sample = [&](int pixel, int i) {
        return shade(s, accel, camera.eye, camera.direction(pixel, i, most), totals);
    };

    for (int pixel = atomicinc(0); pixel < pixels; pixel = atomicinc(0)) {
        Vec3 sum{0.0f, 0.0f, 0.0f};
        float darkest = 3.0e38f, brightest = -3.0e38f;
        for (int i = 0; i < first; ++i) {
            const Vec3 c = sample(pixel, i);
            sum = sum + c;
            darkest = trax_min(darkest, luma(c));
            brightest = trax_max(brightest, luma(c));
        }
        store_pixel(framebuffer, pixel, sum * (1.0f / static_cast<float>(first)),
                    first < most && brightest - darkest > limit);
    }

    // The conditions are the same on every thread, so all of them meet at the barriers.
    if (first < most && neighbours != 0) {
        trax_barrier();
        for (int pixel = atomicinc(1); pixel < pixels; pixel = atomicinc(1)) {
            const Stored own = load_pixel(framebuffer, pixel);
            if (own.marked) continue;
            const float own_luma = luma(own.mean);
            const auto differs = [&](int other) {
                return trax_abs(luma(load_pixel(framebuffer, other).mean) - own_luma) > limit;
            };
            const int x = pixel % width, y = pixel / width;
            if ((x > 0 && differs(pixel - 1)) || (x + 1 < width && differs(pixel + 1)) ||
                (y > 0 && differs(pixel - width)) || (y + 1 < height && differs(pixel + width)))
                store_pixel(framebuffer, pixel, own.mean, true);
        }
    }
    if (first < most) {
        trax_barrier();
        for (int pixel = atomicinc(2); pixel < pixels; pixel = atomicinc(2)) {
            const Stored own = load_pixel(framebuffer, pixel);
            if (!own.marked) continue;
            Vec3 sum = own.mean * static_cast<float>(first);
            for (int i = first; i < most; ++i)
                sum = sum + sample(pixel, i);
            store_pixel(framebuffer, pixel, sum * (1.0f / static_cast<float>(most)), false);
        }
    }
    totals.store();
}
