#include "sim/scene/mesh_import.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
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

bool is_finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Material convert_material(const aiMaterial& source) {
    Material material;
    aiString name;
    if (source.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) material.name = name.C_Str();
    aiColor3D diffuse;
    if (source.Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == AI_SUCCESS)
        material.diffuse = {diffuse.r, diffuse.g, diffuse.b};
    return material;
}

/// Size in bytes of a PLY scalar type, 0 if unknown.
size_t ply_type_size(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
        type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

/// Assimp 5.2's PLY reader loops forever on a truncated header and aborts (ai_assert) on a
/// truncated body, so PLY files are walked here first: the header must end, and the body must
/// hold every element it declares.
void check_ply_complete(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::string where = path.string();
    const auto fail = [&](const std::string& why) {
        throw std::runtime_error(
            fmt::format("{}: malformed or truncated PLY file: {}", where, why));
    };
    struct Property {
        size_t size = 0, count_size = 0;  // count_size != 0: a list
    };
    struct Element {
        uint64_t count = 0;
        std::vector<Property> properties;
    };
    std::vector<Element> elements;
    std::string line, format;
    bool ended = false;
    while (!ended && std::getline(in, line)) {
        std::istringstream words(line);
        std::string word;
        words >> word;
        if (word == "format")
            words >> format;
        else if (word == "element") {
            elements.emplace_back();
            std::string name;
            if (!(words >> name >> elements.back().count)) fail("bad element line '" + line + "'");
        } else if (word == "property") {
            if (elements.empty()) fail("property before any element");
            std::string type, count_type, item_type;
            words >> type;
            Property property;
            if (type == "list") {
                words >> count_type >> item_type;
                property = {ply_type_size(item_type), ply_type_size(count_type)};
                if (property.count_size == 0) fail("bad list property '" + line + "'");
            } else {
                property.size = ply_type_size(type);
            }
            if (property.size == 0) fail("unknown property type in '" + line + "'");
            elements.back().properties.push_back(property);
        } else if (word == "end_header") {
            ended = true;
        }
    }
    if (!ended) fail("no end_header");
    const bool ascii = format == "ascii";
    if (!ascii && format != "binary_little_endian" && format != "binary_big_endian")
        fail("unknown format '" + format + "'");
    if (ascii) {
        std::string token;
        for (const Element& element : elements)
            for (uint64_t i = 0; i < element.count; ++i)
                for (const Property& property : element.properties) {
                    uint64_t items = 1;
                    if (property.count_size != 0 && !(in >> items)) fail("body ends early");
                    for (uint64_t k = 0; k < items; ++k)
                        if (!(in >> token)) fail("body ends early");
                }
        return;
    }
    const std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const bool big_endian = format == "binary_big_endian";
    uint64_t at = 0;
    for (const Element& element : elements)
        for (uint64_t i = 0; i < element.count; ++i)
            for (const Property& property : element.properties) {
                uint64_t items = 1;
                if (property.count_size != 0) {
                    if (at + property.count_size > body.size()) fail("body ends early");
                    items = 0;
                    for (size_t b = 0; b < property.count_size; ++b) {
                        const size_t byte = big_endian ? property.count_size - 1 - b : b;
                        items |= uint64_t(static_cast<unsigned char>(body[at + byte])) << (8 * b);
                    }
                    at += property.count_size;
                }
                at += items * property.size;
                if (at > body.size()) fail("body ends early");
            }
}

}  // namespace

bool is_mesh_file(const std::filesystem::path& path) {
    return Assimp::Importer().IsExtensionSupported(path.extension().string());
}

ImportedMesh import_mesh(const std::filesystem::path& path) {
    const std::string where = path.string();
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
        throw std::runtime_error(
            fmt::format("{}: mesh file not found (paths in scene files are relative to the "
                        "scene file)",
                        where));
    if (!is_mesh_file(path))
        throw std::runtime_error(
            fmt::format("{}: '{}' is not a mesh format assimp reads (try .obj, .ply, .off)", where,
                        path.extension().string()));

    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (extension == ".ply") check_ply_complete(path);

    Assimp::Importer importer;
    // ValidateDataStructure runs first so a malformed file is an error, not an ai_assert abort in
    // a later step (Debian's assimp keeps its asserts; e.g. an OFF file with a missing face list).
    // PreTransformVertices bakes node transforms in. FindDegenerates is deliberately absent:
    // degenerate triangles stay in as a robustness test for the kernels.
    const aiScene* file =
        importer.ReadFile(where, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                     aiProcess_PreTransformVertices);
    if (file == nullptr)
        throw std::runtime_error(
            fmt::format("{}: cannot read mesh: {}", where, importer.GetErrorString()));

    ImportedMesh mesh;
    mesh.summary.source = where;
    for (unsigned m = 0; m < file->mNumMaterials; ++m)
        mesh.materials.push_back(convert_material(*file->mMaterials[m]));
    if (mesh.materials.empty()) mesh.materials.push_back(Material{"default", glm::vec3(0.8f)});

    for (unsigned m = 0; m < file->mNumMeshes; ++m) {
        const aiMesh& part = *file->mMeshes[m];
        const uint32_t material =
            part.mMaterialIndex < mesh.materials.size() ? part.mMaterialIndex : 0;
        for (unsigned f = 0; f < part.mNumFaces; ++f) {
            const aiFace& face = part.mFaces[f];
            if (face.mNumIndices != 3) {
                ++mesh.summary.skipped_primitives;
                continue;
            }
            glm::vec3 corners[3];
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= part.mNumVertices)
                    throw std::runtime_error(
                        fmt::format("{}: face {} of mesh {} refers to vertex {} of {}", where, f, m,
                                    face.mIndices[k], part.mNumVertices));
                const aiVector3D& p = part.mVertices[face.mIndices[k]];
                corners[k] = {p.x, p.y, p.z};
                if (!is_finite(corners[k]))
                    throw std::runtime_error(
                        fmt::format("{}: face {} of mesh {} has a non-finite vertex", where, f, m));
            }
            const Triangle triangle{corners[0], corners[1], corners[2], material};
            if (is_degenerate(triangle)) ++mesh.summary.degenerate_triangles;
            mesh.triangles.push_back(triangle);
        }
    }
    mesh.summary.triangles = mesh.triangles.size();
    if (mesh.triangles.empty())
        throw std::runtime_error(
            fmt::format("{}: the file holds no triangles ({} meshes, {} points/lines); is it "
                        "empty or in another format than its extension says?",
                        where, file->mNumMeshes, mesh.summary.skipped_primitives));
    return mesh;
}

}  // namespace tpsim::scene
