// Assignment 5: path tracing with area lights. Starter kernel.
//
// As it stands it renders only the light that the camera sees directly: the Cornell box's
// ceiling light, everything else black. Your job is the rest of the light transport, in
// trace_path() below. Every surface is Lambertian (BRDF = albedo / pi); light comes only from
// emissive triangles (a material with an `emission`; .mtl `Ke`). The API (docs/kernel-api.md):
//   trax_rand()                 uniform float in [0, 1), per thread (already seeded per pixel)
//   trax_emission(material)     word address of the radiance (3 floats) a material emits
//   trax_emitters(), trax_num_emitters()
//                               the emissive triangles: one Emitter record each, with fields
//                               kEmitterTriangle (index into the triangles), kEmitterArea,
//                               kEmitterProbability (of picking it) and kEmitterCdf
//   BvhTraversal::trace<false>  closest hit; trace<true>: any hit (a shadow ray)
//   surface_point(), offset_origin()   the hit point and a safe origin for the next ray
#include "rt.hpp"

TRAX_USES_BVH;

namespace {

using namespace trax::rt;

/// Radiance arriving at the camera along (origin, dir).
Vec3 trace_path(const BvhTraversal& bvh, const Shading& s, Vec3 origin, Vec3 dir,
                ThreadTotals& totals) {
    Vec3 radiance{0.0f, 0.0f, 0.0f};
    RayStats ray;
    const Hit hit = bvh.trace<false>(origin, dir, 3.0e38f, ray);
    totals.add(ray, false);
    if (hit.triangle < 0) return s.background;
    const int tri = s.triangles + hit.triangle * kTriangleWords;
    const int material = loadi(tri, kTriangleMaterial);
    const SurfacePoint surface = surface_point(tri, hit, origin, dir);
    // Light the camera sees directly: emitters emit on their front side, where their normal
    // (v1 - v0) x (v2 - v0) points.
    if (dot(surface.n, dir) < 0.0f)
        radiance = load_vec3(trax_emission(material), kEmissionRadiance);

    // TODO 1, direct light (next-event estimation): pick one emitter (u = trax_rand(), the
    //   first i with u < its kEmitterCdf), a uniform point on its triangle (b1 = 1 - sqrt(r1),
    //   b2 = r2 * sqrt(r1)), and cast a shadow ray to it from offset_origin(surface, ...) that
    //   stops just short of the light. If nothing blocks it, add
    //     (albedo / pi) * emission * cos_surface * cos_light / distance^2 / pdf,
    //   where pdf = kEmitterProbability / kEmitterArea (per unit area on the light).
    //   The emitter's front must face the surface point. The albedo is
    //   load_vec3(s.materials + material * kMaterialWords, kMaterialDiffuse).
    //
    // TODO 2, indirect light: turn this function into a loop over bounces. Keep a throughput
    //   (starting at 1, 1, 1); at each hit add throughput * (direct light of TODO 1), then pick
    //   a cosine-weighted direction around the normal (density cos / pi: the throughput is
    //   then simply multiplied by the albedo) and trace on. Add the emission of a hit only for
    //   the camera ray: TODO 1 already counted the light a bounce ray would find.
    //
    // TODO 3, Russian roulette: after a few bounces, continue a path only with probability
    //   q = max(throughput) (at most 0.95) and divide the throughput by q when it continues.
    return radiance;
}

}  // namespace

void trax_main() {
    const BvhTraversal bvh = BvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    const uint32_t seed = trax_run_seed();
    const int width = trax_image_width(), height = trax_image_height();
    const int samples = trax_samples_per_pixel();
    const CameraRays camera = CameraRays::from_scene();
    const int framebuffer = trax_framebuffer();
    ThreadTotals totals;

    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const float x = static_cast<float>(pixel % width), y = static_cast<float>(pixel / width);
        Vec3 color{0.0f, 0.0f, 0.0f};
        for (int sample = 0; sample < samples; ++sample) {
            // Seeded per pixel and sample: the image does not depend on which thread renders
            // which pixel, and the simulator and the native twin agree bit for bit.
            trax_srand(trax_hash(trax_hash(uint32_t(pixel), uint32_t(sample)), seed));
            const float jx = trax_rand(), jy = trax_rand();
            const Vec3 dir = camera.through(x + jx, y + jy);
            color = color + trace_path(bvh, s, camera.eye, dir, totals);
        }
        color = color * (1.0f / static_cast<float>(samples));
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
    totals.store();
}
