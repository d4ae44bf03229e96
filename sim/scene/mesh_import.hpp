// Mesh files through assimp (OBJ, PLY, OFF, STL, glTF), flattened to a triangle soup.
#pragma once
#include <filesystem>
#include <string_view>
#include <vector>

#include "sim/scene/scene.hpp"

namespace tpsim::scene {

struct ImportedMesh {
    std::vector<Triangle> triangles;  ///< Triangle::material indexes `materials` below
    std::vector<Material> materials;  ///< as named in the file (assimp's default if none)
    SourceSummary summary;
};

/// Loads every triangle of every mesh in the file, node transforms applied. Polygons are
/// triangulated; degenerate (zero-area) triangles are kept and counted; points and lines are
/// skipped and counted. Throws tpsim::Error for a missing, unreadable, oversized, malformed or
/// triangle-free file, a format tpsim does not offer, or a non-finite vertex; every file the
/// mesh names (materials, buffers) is read under the same checks.
ImportedMesh import_mesh(const std::filesystem::path& path);

/// True if the path's extension is a mesh format tpsim reads.
bool is_mesh_file(const std::filesystem::path& path);

/// The mesh formats tpsim reads, for messages: ".obj, .ply, .off, .stl, .gltf or .glb".
std::string_view mesh_format_list();

}  // namespace tpsim::scene
