// Ambient occlusion: the incoherent-ray workload of the packet comparison. Every camera ray's
// closest hit sends kOcclusionRays diffuse rays (cosine-weighted about the normal facing the
// camera) up to kOcclusionReach of the scene's size; the pixel's colour is the albedo times the
// fraction that escape. Neighbouring pixels' occlusion rays start at different points and go in
// unrelated directions, which is what makes them incoherent. The directions are hashed from the
// pixel, sample and ray only, so the single-ray kernel (ao) and the packet kernel (ao_packet)
// trace exactly the same rays. Occlusion rays count as shadow rays in the statistics.
#pragma once
#include "rt.hpp"

namespace trax::rt {

constexpr int kOcclusionRays = 4;         ///< per camera ray that hits
constexpr float kOcclusionReach = 0.25f;  ///< of the diagonal of the scene's box (the BVH root)

/// How far occlusion rays reach: kOcclusionReach times the diagonal of the BVH root's box.
inline float occlusion_distance() {
    const int root = trax_bvh();
    const Vec3 diagonal = load_vec3(root, kNodeMax) - load_vec3(root, kNodeMin);
    return kOcclusionReach * trax_sqrt(dot(diagonal, diagonal));
}

/// Occlusion ray `ray` of camera sample `sample` of `pixel` from a point with unit normal n:
/// cosine-weighted (a uniform point of the unit disk, by rejection on hashed numbers, lifted onto
/// the hemisphere: Malley's method) in the orthonormal basis of Duff et al., "Building an
/// Orthonormal Basis, Revisited", JCGT 6(1), 2017.
inline Vec3 occlusion_direction(Vec3 n, int pixel, int sample, int ray) {
    const uint32_t key = trax_hash(static_cast<uint32_t>(pixel),
                                   static_cast<uint32_t>(sample * kOcclusionRays + ray));
    float x, y;
    uint32_t attempt = 0;
    do {
        x = 2.0f * unit_float(trax_hash(key, 2u * attempt)) - 1.0f;
        y = 2.0f * unit_float(trax_hash(key, 2u * attempt + 1u)) - 1.0f;
        ++attempt;
    } while (x * x + y * y >= 1.0f);
    const float z = trax_sqrt(trax_max(0.0f, 1.0f - x * x - y * y));
    const float sign = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    const Vec3 t{1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    const Vec3 s{b, sign + n.y * n.y * a, -n.y};
    return t * x + s * y + n * z;
}

/// The colour of a hit whose occlusion rays `escaped` of kOcclusionRays did not hit anything.
inline Vec3 occluded_color(const LitPoint& lit, int escaped) {
    return lit.albedo * (static_cast<float>(escaped) * (1.0f / kOcclusionRays));
}

/// The single-ray occlusion of camera ray (origin, dir) of `sample` of `pixel`.
template <class Accel>
Vec3 shade_occlusion(const Shading& s, const Accel& accel, float reach, Vec3 origin, Vec3 dir,
                     int pixel, int sample, ThreadTotals& totals) {
    RayStats primary;
    const Hit hit = accel.template trace<false>(origin, dir, 3.0e38f, primary);
    totals.add(primary, false);
    if (hit.triangle < 0) return s.background;
    const LitPoint lit = lit_point(s, hit, origin, dir);
    int escaped = 0;
    for (int ray = 0; ray < kOcclusionRays; ++ray) {
        const Vec3 d = occlusion_direction(lit.n, pixel, sample, ray);
        RayStats stats;
        const Hit blocker =
            accel.template trace<true>(offset_origin(lit.surface, d), d, reach, stats);
        totals.add(stats, true);
        if (blocker.triangle < 0) ++escaped;
    }
    return occluded_color(lit, escaped);
}

}  // namespace trax::rt
