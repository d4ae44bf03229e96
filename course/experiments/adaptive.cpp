// Course experiment "adaptive super-sampling" (docs/course/experiments.md): the tracer's shading
// with the samples spent where they are needed. Every pixel first takes kFirstSamples jittered
// camera rays; only when their brightness differs by more than kThreshold does it take the rest
// of the scene's samples_per_pixel. Edges, shadow boundaries and textures get the full count,
// flat regions a quarter of it. Deterministic: a pixel's sample positions depend only on the
// pixel and the sample index, as in the tracer.
#include "rt.hpp"

TRAX_USES_BVH;

namespace {

using namespace trax::rt;

constexpr int kFirstSamples = 4;
/// Largest brightness difference (in linear RGB, Rec. 709 luma) the first samples may show
/// before the pixel is refined (linear; about 10 steps of an 8-bit display near mid-grey).
constexpr float kThreshold = 0.05f;

float luma(Vec3 c) {
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

}  // namespace

void trax_main() {
    const BvhTraversal accel = BvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    const CameraRays camera = CameraRays::from_scene();
    const int pixels = trax_image_width() * trax_image_height();
    const int most = trax_samples_per_pixel();
    const int first = most < kFirstSamples ? most : kFirstSamples;
    const int framebuffer = trax_framebuffer();
    ThreadTotals totals;

    for (int pixel = atomicinc(0); pixel < pixels; pixel = atomicinc(0)) {
        // Sample i of `most`, at the tracer's sample positions. Inlined into both loops, so
        // each computes the pixel's position once rather than per sample.
        const auto sample = [&](int i) __attribute__((always_inline)) {
            return shade(s, accel, camera.eye, camera.direction(pixel, i, most), totals);
        };
        Vec3 color{0.0f, 0.0f, 0.0f};
        float darkest = 3.0e38f, brightest = -3.0e38f;
        for (int i = 0; i < first; ++i) {
            const Vec3 c = sample(i);
            color = color + c;
            darkest = trax_min(darkest, luma(c));
            brightest = trax_max(brightest, luma(c));
        }
        int taken = first;
        if (brightest - darkest > kThreshold)
            for (; taken < most; ++taken)
                color = color + sample(taken);
        color = color * (1.0f / static_cast<float>(taken));
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
    totals.store();
}
