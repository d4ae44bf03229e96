// A second, independent path tracer for assignment 5, written differently from
// course/solutions/5-path-tracing.cpp on purpose, and the same tracer with one deliberate mistake
// each, so the checker is seen to accept a correct tracer that is not the reference and to reject
// plausible wrong ones. Unlike the reference it has no next-event estimation (a path gathers
// light only when it hits an emitter's front, so it is much noisier for the same samples), draws
// cosine-weighted directions as the normal plus a uniform unit vector (Shirley's "Ray Tracing in
// One Weekend"; the reference lifts a disk sample), seeds once per pixel and draws every sample
// from that one sequence, and starts Russian roulette later with a different survival rule.
// Each paths_*.cpp picks one variant.
#pragma once
#include "rt.hpp"

namespace paths {

using namespace trax::rt;

enum class Variant {
    correct,
    direct_only,    ///< stops after one bounce: only light that reaches a surface directly
    no_cosine,      ///< uniform directions weighted by BRDF / pdf = 2 albedo, without the cosine
    emission_back,  ///< counts emission on the side the emitter's normal points away from
};

constexpr int kRouletteAfter = 4;  ///< bounces before Russian roulette may end a path
/// The reference's limit too (its converged image is the checker's reference), so this tracer
/// estimates the same sum; roulette ends nearly every path long before it.
constexpr int kMaxBounces = 16;

/// A uniform direction: a point uniform in the unit ball (by rejection) pushed onto the sphere.
inline Vec3 unit_vector() {
    for (;;) {
        const Vec3 v{2.0f * trax_rand() - 1.0f, 2.0f * trax_rand() - 1.0f,
                     2.0f * trax_rand() - 1.0f};
        const float length2 = dot(v, v);
        if (length2 > 1.0e-6f && length2 <= 1.0f) return v * (1.0f / trax_sqrt(length2));
    }
}

inline Vec3 normalized(Vec3 v) {
    return v * (1.0f / trax_sqrt(dot(v, v)));
}

template <Variant kVariant>
Vec3 radiance(const BvhTraversal& bvh, const Shading& s, Vec3 origin, Vec3 dir,
              ThreadTotals& totals) {
    Vec3 sum{0.0f, 0.0f, 0.0f};
    Vec3 weight{1.0f, 1.0f, 1.0f};
    const int bounces = kVariant == Variant::direct_only ? 2 : kMaxBounces;
    for (int bounce = 0; bounce < bounces; ++bounce) {
        RayStats ray;
        const Hit hit = bvh.trace<false>(origin, dir, 3.0e38f, ray);
        totals.add(ray, false);
        if (hit.triangle < 0) return sum + weight * s.background;
        const int tri = s.triangles + hit.triangle * kTriangleWords;
        const int material = loadi(tri, kTriangleMaterial);
        const SurfacePoint surface = surface_point(tri, hit, origin, dir);
        const bool front = dot(surface.n, dir) < 0.0f;
        if (front != (kVariant == Variant::emission_back))
            sum = sum + weight * load_vec3(trax_emission(material), kEmissionRadiance);
        const Vec3 n = front ? surface.n : surface.n * -1.0f;
        const Vec3 albedo = load_vec3(s.materials + material * kMaterialWords, kMaterialDiffuse);
        if (kVariant == Variant::no_cosine) {
            dir = unit_vector();
            if (dot(dir, n) < 0.0f) dir = dir * -1.0f;
            weight = weight * albedo * 2.0f;
        } else {
            // n + a uniform unit vector has density cos / pi around n: the BRDF's 1 / pi and the
            // cosine cancel against it, leaving the albedo.
            Vec3 d = n + unit_vector();
            if (dot(d, d) < 1.0e-8f) d = n;  // the unit vector was almost exactly -n
            dir = normalized(d);
            weight = weight * albedo;
        }
        if (bounce >= kRouletteAfter) {
            const float survive = trax_min(1.0f, (weight.x + weight.y + weight.z) * (1.0f / 3.0f));
            if (trax_rand() >= survive) break;
            weight = weight * (1.0f / survive);
        }
        origin = offset_origin(surface, dir);
    }
    return sum;
}

template <Variant kVariant> void render() {
    const BvhTraversal bvh = BvhTraversal::from_scene();
    const Shading s = Shading::from_scene();
    const int width = trax_image_width(), height = trax_image_height();
    const int samples = trax_samples_per_pixel();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera, kCameraEye), corner = load_vec3(camera, kCameraCorner);
    const Vec3 right = load_vec3(camera, kCameraRight), down = load_vec3(camera, kCameraDown);
    ThreadTotals totals;
    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        trax_srand(trax_hash(uint32_t(pixel) * 2654435761u, trax_run_seed() + 1u));
        const float x = static_cast<float>(pixel % width), y = static_cast<float>(pixel / width);
        Vec3 sum{0.0f, 0.0f, 0.0f};
        for (int i = 0; i < samples; ++i) {
            const float jy = trax_rand(), jx = trax_rand();
            const Vec3 dir =
                corner + right * ((x + jx) / float(width)) + down * ((y + jy) / float(height));
            sum = sum + radiance<kVariant>(bvh, s, eye, dir, totals);
        }
        const Vec3 c = sum * (1.0f / float(samples));
        const int out = trax_framebuffer() + pixel * kPixelWords;
        storef(c.x, out, 0);
        storef(c.y, out, 1);
        storef(c.z, out, 2);
    }
    totals.store();
}

}  // namespace paths
