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
    const int width = trax_image_width(), height = trax_image_height();
    const int most = trax_samples_per_pixel();
    const int first = most < kFirstSamples ? most : kFirstSamples;
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera, kCameraEye);
    const Vec3 corner = load_vec3(camera, kCameraCorner);
    const Vec3 right = load_vec3(camera, kCameraRight);
    const Vec3 down = load_vec3(camera, kCameraDown);
    const int framebuffer = trax_framebuffer();
    const float fwidth = static_cast<float>(width), fheight = static_cast<float>(height);
    ThreadTotals totals;

    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const float x = static_cast<float>(pixel % width), y = static_cast<float>(pixel / width);
        const auto sample = [&](int i) {
            const uint32_t key = 2u * static_cast<uint32_t>(pixel * most + i);
            const float jx = unit_float(hash(key)), jy = unit_float(hash(key + 1u));
            const Vec3 dir = corner + right * ((x + jx) / fwidth) + down * ((y + jy) / fheight);
            return shade(s, accel, eye, dir, totals);
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
