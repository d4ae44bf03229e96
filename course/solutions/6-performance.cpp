// Assignment 6, reference solution: assignment 4's traversal (bvh_traversal.hpp) with two
// changes, each measured (docs/course/6-performance.md):
// - a leaner slab test: rt.hpp's slab_entry widens every axis's exit distance by its rounding
//   bound; widening only the smallest exit gives the same result (rounding is monotonic, so
//   min(a * s, b * s) = min(a, b) * s for s > 0) with 3 multiplies per box instead of 6;
// - pixels in 8 x 8 tiles instead of scanlines, so rays running at the same time on a TM read
//   the same BVH nodes and triangles and the L1 keeps serving them.
#include "bvh_traversal.hpp"

TRAX_USES_BVH;

using namespace trax::rt;

/// rt.hpp's slab_entry (Ize 2013, robust), with the exit bound widened once at the end.
[[gnu::always_inline]] inline float box_entry(int node, Vec3 origin, Vec3 inverse, float t_far) {
    constexpr float kExitScale = 1.0f + 2.0f * (3.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f));
    float entry = 0.0f, exit = 3.0e38f;
    const float o[3] = {origin.x, origin.y, origin.z};
    const float inv[3] = {inverse.x, inverse.y, inverse.z};
    for (int axis = 0; axis < 3; ++axis) {
        const float t0 = (loadf(node, kNodeMin + axis) - o[axis]) * inv[axis];
        const float t1 = (loadf(node, kNodeMax + axis) - o[axis]) * inv[axis];
        const float near = t0 < t1 ? t0 : t1;
        const float far = t0 < t1 ? t1 : t0;
        if (near > entry) entry = near;  // NaN compares false: the slab is ignored
        if (far < exit) exit = far;
    }
    exit = exit * kExitScale;
    if (t_far < exit) exit = t_far;
    return entry <= exit ? entry : t_far + 1.0f + trax_abs(t_far);
}

constexpr int kTile = 8;

void trax_main() {
    const SolutionBvh<box_entry> bvh = SolutionBvh<box_entry>::from_scene();
    const Shading s = Shading::from_scene();
    const int width = trax_image_width(), height = trax_image_height();
    const CameraRays camera = CameraRays::from_scene();
    const int framebuffer = trax_framebuffer();
    const int tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
    const int work = tiles_x * tiles_y * kTile * kTile;
    ThreadTotals totals;
    for (int i = atomicinc(0); i < work; i = atomicinc(0)) {
        const int tile = i / (kTile * kTile), in_tile = i % (kTile * kTile);
        const int x = tile % tiles_x * kTile + in_tile % kTile;
        const int y = tile / tiles_x * kTile + in_tile / kTile;
        if (x >= width || y >= height) continue;  // the edge tiles of an odd-sized image
        const Vec3 dir = camera.through(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
        const Vec3 c = shade(s, bvh, camera.eye, dir, totals);
        const int out = framebuffer + (y * width + x) * kPixelWords;
        storef(c.x, out, 0);
        storef(c.y, out, 1);
        storef(c.z, out, 2);
    }
    totals.store();
}
