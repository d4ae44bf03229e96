// A scene as the host sees it after import: flat triangle soup plus everything around it.
// The scene compiler turns this (and a BVH over it) into the guest memory image.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "sim/scene/accel.hpp"

namespace tpsim::scene {

struct Triangle {
    glm::vec3 v0, v1, v2;
    uint32_t material = 0;  ///< index into Scene::materials
};

struct Material {
    std::string name;
    glm::vec3 diffuse{0.8f};
    glm::vec3 emission{0.f};  ///< emitted radiance, linear RGB (an area light when not 0)
};

struct PointLight {
    glm::vec3 position{0.f};
    glm::vec3 color{1.f};  ///< radiant intensity per channel, in the scene frame's units
};

/// Right-handed: the image's right axis is normalize(cross(look_at - eye, up)).
struct Camera {
    glm::vec3 eye{0.f, 0.f, 1.f};
    glm::vec3 look_at{0.f};
    glm::vec3 up{0.f, 1.f, 0.f};
    double vertical_fov_degrees = 45.0;  ///< double: 179.9999999999 must not round to 180
};

/// Where the scene's float coordinates lie in the world the scene file describes:
/// world = origin + unit * local. The scene compiler works camera-relative (docs/scenes.md):
/// origin is the camera's eye and unit the power of two that brings the whole scene into
/// [-1, 1], so float precision follows the camera, not the world origin, and every scale gives
/// the same float numbers. With light falloff, light colours are divided by unit^2 to match.
struct Frame {
    glm::dvec3 origin{0.0};
    double unit = 1.0;
    glm::dvec3 to_world(const glm::vec3& local) const { return origin + unit * glm::dvec3(local); }
};

/// What one mesh file or generator contributed, so the caller can print an import summary.
struct SourceSummary {
    std::string source;                 ///< mesh path or "generator <type>"
    uint64_t triangles = 0;             ///< triangles added to Scene::triangles
    uint64_t degenerate_triangles = 0;  ///< of those, with zero area (kept on purpose)
    uint64_t skipped_primitives = 0;    ///< points and lines in the file, not imported
};

struct Scene {
    std::string name;
    std::vector<Triangle> triangles;
    std::vector<Material> materials;  ///< only those some triangle uses
    std::vector<PointLight> lights;
    Camera camera;
    glm::vec3 ambient{0.1f};
    glm::vec3 background{0.f};
    uint32_t width = 256, height = 256;
    uint32_t samples_per_pixel = 1;
    bool shadows = true;                 ///< cast a shadow ray to every light
    bool light_falloff = true;           ///< light intensity falls off with the squared distance
    std::vector<SourceSummary> sources;  ///< in the order they were loaded
    Frame frame;  ///< triangles, camera and lights are in this frame's coordinates
    std::vector<std::string> warnings;  ///< for the user, one line each (without "tpsim: ")
    AccelSettings accel;                ///< the scene file's [accel] table (unset for a bare mesh)
};

}  // namespace tpsim::scene
