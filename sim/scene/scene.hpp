// A scene as the host sees it after import: flat triangle soup plus everything around it.
// The scene compiler turns this (and a BVH over it) into the guest memory image.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace tpsim::scene {

struct Triangle {
    glm::vec3 v0, v1, v2;
    uint32_t material = 0;  ///< index into Scene::materials
};

struct Material {
    std::string name;
    glm::vec3 diffuse{0.8f};
};

struct PointLight {
    glm::vec3 position{0.f};
    glm::vec3 color{1.f};  ///< radiant intensity per channel
};

struct Camera {
    glm::vec3 eye{0.f, 0.f, 1.f};
    glm::vec3 look_at{0.f};
    glm::vec3 up{0.f, 1.f, 0.f};
    float vertical_fov_degrees = 45.f;
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
};

}  // namespace tpsim::scene
