// Mesh files through assimp (OBJ, PLY, OFF, STL, 3DS, glTF, ...), flattened to a triangle soup.
#pragma once
#include <filesystem>
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
/// skipped and counted. Throws std::runtime_error for a missing, unreadable, malformed or
/// triangle-free file, or a non-finite vertex.
ImportedMesh import_mesh(const std::filesystem::path& path);

/// True if assimp can read files with this path's extension.
bool is_mesh_file(const std::filesystem::path& path);

}  // namespace tpsim::scene
