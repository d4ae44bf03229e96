// A first kernel: one camera ray per pixel through the scene's BVH; a pixel whose ray hits gets
// its triangle's colour, brighter the more squarely the ray meets the triangle. Change it, then
// rebuild with `cmake --build build` and render it (README.md). API: docs/kernel-api.md.
#include "rt.hpp"

using namespace trax::layout;
using namespace trax::rt;

TRAX_USES_BVH;  // tpsim builds the scene's BVH for this kernel

void trax_main() {
    const BvhTraversal bvh = BvhTraversal::from_scene();
    const int width = trax_image_width(), height = trax_image_height();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera, kCameraEye);
    const Vec3 corner = load_vec3(camera, kCameraCorner);
    const Vec3 right = load_vec3(camera, kCameraRight);
    const Vec3 down = load_vec3(camera, kCameraDown);

    // Every thread takes the next pixel until none is left.
    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const float u = (static_cast<float>(pixel % width) + 0.5f) / static_cast<float>(width);
        const float v = (static_cast<float>(pixel / width) + 0.5f) / static_cast<float>(height);
        const Vec3 dir = corner + right * u + down * v;
        RayStats stats;
        const Hit hit = bvh.trace<false>(eye, dir, 1e30f, stats);

        Vec3 color = load_vec3(0, kHeaderBackground);
        if (hit.triangle >= 0) {
            const int triangle = trax_triangles() + hit.triangle * kTriangleWords;
            const int material =
                trax_materials() + loadi(triangle, kTriangleMaterial) * kMaterialWords;
            const SurfacePoint surface = surface_point(triangle, hit, eye, dir);
            const float facing = trax_abs(dot(surface.n, dir)) / trax_sqrt(dot(dir, dir));
            color = load_vec3(material, kMaterialDiffuse) * facing;
        }
        const int out = trax_framebuffer() + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
}
