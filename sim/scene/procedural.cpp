#include "sim/scene/procedural.hpp"

#include <cmath>
#include <numbers>

namespace tpsim::scene {

namespace {

/// splitmix32-style integer hash of a lattice point to [0, 1).
float lattice_value(int32_t x, int32_t z, uint32_t seed) {
    uint32_t h = uint32_t(x) * 0x9E3779B1u ^ uint32_t(z) * 0x85EBCA77u ^ seed * 0xC2B2AE3Du;
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return float(h >> 8) * (1.f / 16777216.f);
}

float smooth(float t) {
    return t * t * (3.f - 2.f * t);
}

/// Value noise in [0, 1): hashed lattice values blended with a smoothstep.
float value_noise(float x, float z, uint32_t seed) {
    const float fx = std::floor(x), fz = std::floor(z);
    const int32_t ix = int32_t(fx), iz = int32_t(fz);
    const float tx = smooth(x - fx), tz = smooth(z - fz);
    const float a = lattice_value(ix, iz, seed), b = lattice_value(ix + 1, iz, seed);
    const float c = lattice_value(ix, iz + 1, seed), d = lattice_value(ix + 1, iz + 1, seed);
    const float top = a + (b - a) * tx, bottom = c + (d - c) * tx;
    return top + (bottom - top) * tz;
}

}  // namespace

void generate_sphere(const SphereParams& p, uint32_t material, std::vector<Triangle>& out) {
    const auto point = [&](uint32_t ring, uint32_t segment) {
        const float theta = std::numbers::pi_v<float> * float(ring) / float(p.rings);
        const float phi =
            2.f * std::numbers::pi_v<float> * float(segment % p.segments) / float(p.segments);
        return p.center + p.radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                               std::sin(theta) * std::sin(phi));
    };
    for (uint32_t ring = 0; ring < p.rings; ++ring)
        for (uint32_t s = 0; s < p.segments; ++s) {
            const glm::vec3 a = point(ring, s), b = point(ring, s + 1);
            const glm::vec3 c = point(ring + 1, s), d = point(ring + 1, s + 1);
            // The pole rows collapse to a point, so they get one triangle per segment, not two.
            // Counter-clockwise seen from outside: the normal (v1 - v0) x (v2 - v0) points out,
            // the side an emissive sphere emits from.
            if (ring != 0) out.push_back({a, b, d, material});
            if (ring + 1 != p.rings) out.push_back({a, d, c, material});
        }
}

float terrain_height(const TerrainParams& p, float x, float z) {
    // Four octaves, the coarsest with about 8 features across the terrain.
    const float base_frequency = 8.f / std::max(p.size.x, p.size.y);
    float sum = 0.f, amplitude = 0.5f, frequency = base_frequency;
    for (uint32_t octave = 0; octave < 4; ++octave) {
        sum += amplitude * value_noise(x * frequency, z * frequency, p.seed + octave);
        amplitude *= 0.5f;
        frequency *= 2.f;
    }
    // sum is in [0, 0.9375); centre it on center.y.
    return p.center.y + p.height * (sum - 0.46875f);
}

void generate_terrain(const TerrainParams& p, uint32_t material, std::vector<Triangle>& out) {
    const glm::vec2 origin = glm::vec2(p.center.x, p.center.z) - 0.5f * p.size;
    const auto vertex = [&](uint32_t i, uint32_t j) {
        const float x = origin.x + p.size.x * float(i) / float(p.cells.x);
        const float z = origin.y + p.size.y * float(j) / float(p.cells.y);
        return glm::vec3(x, terrain_height(p, x, z), z);
    };
    out.reserve(out.size() + size_t{2} * p.cells.x * p.cells.y);
    for (uint32_t j = 0; j < p.cells.y; ++j)
        for (uint32_t i = 0; i < p.cells.x; ++i) {
            const glm::vec3 a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i, j + 1),
                            d = vertex(i + 1, j + 1);
            out.push_back({a, c, b, material});
            out.push_back({b, c, d, material});
        }
}

void generate_sphere_grid(const SphereGridParams& p, uint32_t material,
                          std::vector<Triangle>& out) {
    out.reserve(out.size() +
                size_t{2} * p.count.x * p.count.y * p.sphere.segments * (p.sphere.rings - 1));
    const glm::vec2 first =
        glm::vec2(p.center.x, p.center.z) - 0.5f * p.spacing * glm::vec2(p.count - 1u);
    for (uint32_t j = 0; j < p.count.y; ++j)
        for (uint32_t i = 0; i < p.count.x; ++i) {
            SphereParams sphere = p.sphere;
            sphere.center = {first.x + p.spacing * float(i), p.center.y,
                             first.y + p.spacing * float(j)};
            generate_sphere(sphere, material, out);
        }
}

}  // namespace tpsim::scene
