// Scene front end: TOML scene files (docs/scenes.md) and bare mesh files.
#pragma once
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>

#include "sim/core/error.hpp"
#include "sim/scene/accel_settings.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/scene.hpp"

namespace tpsim::scene {

/// Every problem with a scene or mesh file, as one line: "file:line:column: what, allowed range".
class SceneError : public Error {
public:
    using Error::Error;
};

/// The axis a mesh was authored with pointing up. The scene compiler turns it to +y (tpsim's up)
/// by a quarter or half turn, exactly.
enum class UpAxis { pos_x, pos_y, pos_z, neg_x, neg_y, neg_z };

/// "x", "y", "z", "-x", "-y", "-z" (a leading '+' allowed); nullopt for anything else.
std::optional<UpAxis> parse_up_axis(std::string_view text);
inline constexpr const char* kUpAxisNames = "x, y, z, -x, -y, -z";

/// A `.toml` path is read as a scene file; anything assimp reads is loaded as a bare mesh with
/// an automatic camera, light and material, its `mesh_up` axis turned to +y (a scene file names
/// the axis per mesh instead).
Scene load_scene(const std::filesystem::path& path, UpAxis mesh_up = UpAxis::pos_y);

Scene load_scene_file(const std::filesystem::path& toml_path);
Scene scene_from_mesh(const std::filesystem::path& mesh_path, UpAxis up = UpAxis::pos_y);

/// The [accel] table of a scene file, without loading its geometry (Scene::accel holds it
/// once loaded): for choosing the kernel before the scene is loaded. Unset for a bare mesh, or
/// a scene file without one. Throws SceneError as load_scene does.
AccelSettings load_accel_settings(const std::filesystem::path& path);

/// Bounds of all vertices; requires at least one triangle.
Aabb bounds_of(std::span<const Triangle> triangles);

}  // namespace tpsim::scene
