// Assignment 5, reference solution: a diffuse path tracer with area lights. Every surface is
// Lambertian (albedo / pi); light comes only from emissive triangles (materials with an
// emission, e.g. the Cornell box's ceiling quad). Each camera path:
//   * adds the emission of what the camera ray hits directly (a light seen in the image);
//   * at every hit, samples one point on one emitter (next-event estimation: pick an emitter
//     by its power, a uniform point on it) and adds its light if a shadow ray reaches it;
//   * bounces in a cosine-weighted direction, so the throughput is just multiplied by the
//     albedo; after kMinBounces, Russian roulette ends paths that carry little light.
// Emission found by a bounce ray is not added: next-event estimation already counted it.
// Point lights are not used (a path tracer cannot hit a point). Random numbers: trax_rand(),
// reseeded for every pixel and sample so the image does not depend on which thread renders
// which pixel; the simulator and the native twin give the same bits.
#include "rt.hpp"

TRAX_USES_BVH;

namespace {

using namespace trax::rt;

constexpr float kPi = 3.14159265f;
constexpr int kMinBounces = 3;   ///< bounces before Russian roulette may end a path
constexpr int kMaxBounces = 16;  ///< a hard limit, in case the albedos are near 1

Vec3 normalize(Vec3 v) {
    return v * (1.0f / trax_sqrt(dot(v, v)));
}

/// Cosine-weighted direction around the unit normal n (density cos / pi): a uniform point in
/// the unit disk (by rejection: no sin/cos needed) lifted onto the hemisphere (Malley's method),
/// in the orthonormal basis of Duff et al., "Building an Orthonormal Basis, Revisited" (2017).
Vec3 cosine_direction(Vec3 n) {
    float x, y;
    do {
        x = 2.0f * trax_rand() - 1.0f;
        y = 2.0f * trax_rand() - 1.0f;
    } while (x * x + y * y >= 1.0f);
    const float z = trax_sqrt(trax_max(0.0f, 1.0f - x * x - y * y));
    const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    const Vec3 t{1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    const Vec3 s{b, sign + n.y * n.y * a, -n.y};
    return t * x + s * y + n * z;
}

/// A point light sampling chose: where, what it emits towards the shaded point, and the density
/// of choosing it (per unit area).
struct LightSample {
    Vec3 p;
    Vec3 n;  ///< unit normal of the emitter, on its emitting (front) side
    Vec3 radiance;
    float pdf_area;
};

LightSample sample_emitter(int emitters, int num_emitters, int triangles) {
    const float u = trax_rand();
    int i = 0;
    while (i + 1 < num_emitters && u >= loadf(emitters + i * kEmitterWords, kEmitterCdf))
        ++i;
    const int emitter = emitters + i * kEmitterWords;
    const int tri = triangles + loadi(emitter, kEmitterTriangle) * kTriangleWords;
    const Vec3 v0 = load_vec3(tri, kTriangleV0);
    const Vec3 e1 = load_vec3(tri, kTriangleV1) - v0, e2 = load_vec3(tri, kTriangleV2) - v0;
    // Uniform on the triangle: b1 = 1 - sqrt(r1), b2 = r2 sqrt(r1) (pbrt's square-root map).
    const float root = trax_sqrt(trax_rand());
    const float r2 = trax_rand();
    LightSample light;
    light.p = v0 + e1 * (1.0f - root) + e2 * (r2 * root);
    light.n = normalize(cross(e1, e2));
    light.radiance = load_vec3(trax_emission(loadi(tri, kTriangleMaterial)), kEmissionRadiance);
    light.pdf_area = loadf(emitter, kEmitterProbability) / loadf(emitter, kEmitterArea);
    return light;
}

/// Radiance arriving at the camera along (origin, dir).
Vec3 trace_path(const BvhTraversal& bvh, const Shading& s, int emitters, int num_emitters,
                Vec3 origin, Vec3 dir, ThreadTotals& totals) {
    Vec3 radiance{0.0f, 0.0f, 0.0f};
    Vec3 throughput{1.0f, 1.0f, 1.0f};
    for (int bounce = 0; bounce < kMaxBounces; ++bounce) {
        RayStats ray;
        const Hit hit = bvh.trace<false>(origin, dir, 3.0e38f, ray);
        totals.add(ray, false);
        if (hit.triangle < 0) {
            if (bounce == 0) radiance = s.background;
            break;
        }
        const int tri = s.triangles + hit.triangle * kTriangleWords;
        const int material = loadi(tri, kTriangleMaterial);
        const SurfacePoint surface = surface_point(tri, hit, origin, dir);
        if (bounce == 0 && dot(surface.n, dir) < 0.0f)  // an emitter's front faces the camera
            radiance = load_vec3(trax_emission(material), kEmissionRadiance);
        const Vec3 n = dot(surface.n, dir) > 0.0f ? surface.n * -1.0f : surface.n;  // two-sided
        const Vec3 albedo = load_vec3(s.materials + material * kMaterialWords, kMaterialDiffuse);

        if (num_emitters > 0) {  // next-event estimation
            const LightSample light = sample_emitter(emitters, num_emitters, s.triangles);
            const Vec3 to_light = light.p - surface.p;
            const float distance2 = dot(to_light, to_light);
            const float cos_surface = dot(n, to_light);
            const float cos_light = -dot(light.n, to_light);  // emitters emit on their front
            if (cos_surface > 0.0f && cos_light > 0.0f) {
                // Stop just short of the emitter, which would otherwise block its own light.
                const Vec3 start = offset_origin(surface, to_light);
                RayStats shadow;
                const Hit blocker = bvh.trace<true>(start, light.p - start, 0.9999f, shadow);
                totals.add(shadow, true);
                if (blocker.triangle < 0) {
                    // (albedo / pi) L cos_surface cos_light / d^2 / pdf, the cosines unnormalised.
                    const float weight =
                        cos_surface * cos_light / (distance2 * distance2 * kPi * light.pdf_area);
                    radiance = radiance + throughput * albedo * light.radiance * weight;
                }
            }
        }

        throughput = throughput * albedo;  // cosine sampling cancels cos / pi against the BRDF
        if (bounce + 1 >= kMinBounces) {
            const float keep =
                trax_min(0.95f, trax_max(throughput.x, trax_max(throughput.y, throughput.z)));
            if (trax_rand() >= keep) break;
            throughput = throughput * (1.0f / keep);
        }
        dir = cosine_direction(n);
        origin = offset_origin(surface, dir);
    }
    return radiance;
}

}  // namespace

void trax_main() {
    const BvhTraversal bvh = BvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    const int emitters = trax_emitters(), num_emitters = trax_num_emitters();
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
            // The pixel's own numbers, whichever thread renders it.
            trax_srand(trax_hash(trax_hash(uint32_t(pixel), uint32_t(sample)), seed));
            const float jx = trax_rand(), jy = trax_rand();
            const Vec3 dir = camera.through(x + jx, y + jy);
            color = color + trace_path(bvh, s, emitters, num_emitters, camera.eye, dir, totals);
        }
        color = color * (1.0f / static_cast<float>(samples));
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
    totals.store();
}
