// Deterministic procedural geometry for large test scenes: same parameters, same triangles.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "sim/scene/scene.hpp"

namespace tpsim::scene {

/// Latitude/longitude sphere: 2 * segments * (rings - 1) triangles, no degenerate ones.
struct SphereParams {
    glm::vec3 center{0.f};
    float radius = 1.f;
    uint32_t segments = 32;  ///< around the y axis, >= 3
    uint32_t rings = 16;     ///< from pole to pole, >= 2
};

/// Height field over the xz plane: 2 * cells.x * cells.y triangles. Heights are fractal value
/// noise from an integer hash (no libm), so they are identical on every host.
struct TerrainParams {
    glm::vec3 center{0.f};  ///< the terrain's mean height is center.y
    glm::vec2 size{100.f};  ///< extent along x and z
    glm::uvec2 cells{100};  ///< grid cells along x and z, >= 1
    float height = 5.f;     ///< peak-to-peak amplitude (at most)
    uint32_t seed = 1;
};

/// count.x * count.y spheres on a regular grid in the xz plane, centred on `center`.
struct SphereGridParams {
    glm::vec3 center{0.f};
    glm::uvec2 count{4};
    float spacing = 3.f;  ///< between neighbouring sphere centres
    SphereParams sphere;  ///< its center is ignored
};

void generate_sphere(const SphereParams& params, uint32_t material, std::vector<Triangle>& out);
void generate_terrain(const TerrainParams& params, uint32_t material, std::vector<Triangle>& out);
void generate_sphere_grid(const SphereGridParams& params, uint32_t material,
                          std::vector<Triangle>& out);

/// The terrain's height at (x, z) in world space, for placing things on it.
float terrain_height(const TerrainParams& params, float x, float z);

}  // namespace tpsim::scene
