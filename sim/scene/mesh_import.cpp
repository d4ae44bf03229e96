#include "mesh_import.hpp"

#include <cmath>
#include <stdexcept>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

namespace tpsim::scene {

namespace {

bool is_degenerate(const Triangle& t) {
    const glm::vec3 n = glm::cross(t.v1 - t.v0, t.v2 - t.v0);
    return n.x == 0.f && n.y == 0.f && n.z == 0.f;
}

bool is_finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

Material convert_material(const aiMaterial& source) {
    Material material;
    aiString name;
    if (source.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) material.name = name.C_Str();
    aiColor3D diffuse;
    if (source.Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == AI_SUCCESS) material.diffuse = {diffuse.r, diffuse.g, diffuse.b};
    return material;
}

}  // namespace

bool is_mesh_file(const std::filesystem::path& path) {
    return Assimp::Importer().IsExtensionSupported(path.extension().string());
}

ImportedMesh import_mesh(const std::filesystem::path& path) {
    const std::string where = path.string();
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
        throw std::runtime_error(fmt::format("{}: mesh file not found (paths in scene files are relative to the "
                                             "scene file)", where));
    if (!is_mesh_file(path))
        throw std::runtime_error(fmt::format("{}: '{}' is not a mesh format assimp reads (try .obj, .ply, .off)",
                                             where, path.extension().string()));

    Assimp::Importer importer;
    // ValidateDataStructure runs first so a malformed file is an error, not an ai_assert abort in
    // a later step (Debian's assimp keeps its asserts; e.g. an OFF file with a missing face list).
    // PreTransformVertices bakes node transforms in. FindDegenerates is deliberately absent:
    // degenerate triangles stay in as a robustness test for the kernels.
    const aiScene* file = importer.ReadFile(
        where, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_PreTransformVertices);
    if (file == nullptr)
        throw std::runtime_error(fmt::format("{}: cannot read mesh: {}", where, importer.GetErrorString()));

    ImportedMesh mesh;
    mesh.summary.source = where;
    for (unsigned m = 0; m < file->mNumMaterials; ++m) mesh.materials.push_back(convert_material(*file->mMaterials[m]));
    if (mesh.materials.empty()) mesh.materials.push_back(Material{"default", glm::vec3(0.8f)});

    for (unsigned m = 0; m < file->mNumMeshes; ++m) {
        const aiMesh& part = *file->mMeshes[m];
        const uint32_t material = part.mMaterialIndex < mesh.materials.size() ? part.mMaterialIndex : 0;
        for (unsigned f = 0; f < part.mNumFaces; ++f) {
            const aiFace& face = part.mFaces[f];
            if (face.mNumIndices != 3) {
                ++mesh.summary.skipped_primitives;
                continue;
            }
            glm::vec3 corners[3];
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= part.mNumVertices)
                    throw std::runtime_error(fmt::format("{}: face {} of mesh {} refers to vertex {} of {}", where, f,
                                                         m, face.mIndices[k], part.mNumVertices));
                const aiVector3D& p = part.mVertices[face.mIndices[k]];
                corners[k] = {p.x, p.y, p.z};
                if (!is_finite(corners[k]))
                    throw std::runtime_error(fmt::format("{}: face {} of mesh {} has a non-finite vertex", where, f, m));
            }
            const Triangle triangle{corners[0], corners[1], corners[2], material};
            if (is_degenerate(triangle)) ++mesh.summary.degenerate_triangles;
            mesh.triangles.push_back(triangle);
        }
    }
    mesh.summary.triangles = mesh.triangles.size();
    if (mesh.triangles.empty())
        throw std::runtime_error(fmt::format("{}: the file holds no triangles ({} meshes, {} points/lines); is it "
                                             "empty or in another format than its extension says?",
                                             where, file->mNumMeshes, mesh.summary.skipped_primitives));
    return mesh;
}

}  // namespace tpsim::scene
