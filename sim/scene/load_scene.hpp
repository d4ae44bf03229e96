// Scene front end: TOML scene files (docs/scenes.md) and bare mesh files.
#pragma once
#include <filesystem>
#include <span>

#include "sim/core/error.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/scene.hpp"

namespace tpsim::scene {

/// Every problem with a scene or mesh file, as one line: "file:line:column: what, allowed range".
class SceneError : public Error {
public:
    using Error::Error;
};

/// A `.toml` path is read as a scene file; anything assimp reads is loaded as a bare mesh with
/// an automatic camera, light and material.
Scene load_scene(const std::filesystem::path& path);

Scene load_scene_file(const std::filesystem::path& toml_path);
Scene scene_from_mesh(const std::filesystem::path& mesh_path);

/// Bounds of all vertices; requires at least one triangle.
Aabb bounds_of(std::span<const Triangle> triangles);

/// A camera that sees the whole bounding sphere of `bounds` at the given image aspect
/// (width / height), looking from the front (+z), a little right and above, y up.
Camera frame_bounds(const Aabb& bounds, float aspect);

/// A light above and behind the camera, bright enough that the irradiance at the centre of
/// `bounds` is 1 (with falloff, I / d^2; without, I).
PointLight default_light(const Camera& camera, const Aabb& bounds, bool light_falloff);

}  // namespace tpsim::scene
