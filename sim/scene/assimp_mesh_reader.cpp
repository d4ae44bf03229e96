// The mesh module (libtpsim_assimp.so): parses mesh files with assimp. Loaded on first use by
// import_mesh (mesh_import.cpp), which reads and checks the file before handing it over.
#include <cmath>
#include <sstream>

#include <assimp/BaseImporter.h>
#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/scene/mesh_reader.hpp"

namespace tpsim::scene {
namespace {

bool is_degenerate(const Triangle& t) {
    const glm::vec3 n = glm::cross(t.v1 - t.v0, t.v2 - t.v0);
    return n.x == 0.f && n.y == 0.f && n.z == 0.f;
}

bool is_finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Material convert_material(const aiMaterial& source, const std::string& where) {
    Material material;
    aiString name;
    if (source.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) material.name = name.C_Str();
    aiColor3D diffuse;
    if (source.Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == AI_SUCCESS)
        material.diffuse = {diffuse.r, diffuse.g, diffuse.b};
    // An OBJ's .mtl `Ke`: the radiance the material emits, straight to the kernel as float.
    aiColor3D emission;
    if (source.Get(AI_MATKEY_COLOR_EMISSIVE, emission) == AI_SUCCESS) {
        material.emission = {emission.r, emission.g, emission.b};
        if (!is_finite(material.emission) || material.emission.x < 0.f ||
            material.emission.y < 0.f || material.emission.z < 0.f)
            throw Error(fmt::format("{}: material '{}' emits ({}, {}, {}) (.mtl Ke): each "
                                    "channel must be a finite number >= 0 within float range",
                                    where, material.name, emission.r, emission.g, emission.b));
    }
    return material;
}

/// Every file assimp opens is read through tpsim's input check (`read_named`) into memory, so a
/// FIFO, a device or a huge file named inside a mesh (an OBJ's mtllib, a glTF buffer's uri)
/// cannot block the import or exhaust memory. The first refusal is kept and reported once the
/// import returns, even when assimp would carry on without the file. The mesh file itself, already
/// read and checked by import_mesh, is served from those bytes rather than read again.
class CheckedIOSystem : public Assimp::DefaultIOSystem {
public:
    CheckedIOSystem(std::string mesh, const std::string& mesh_bytes,
                    const ReadNamedFile& read_named)
        : mesh_(std::move(mesh)), mesh_bytes_(mesh_bytes), read_named_(read_named) {}

    // DefaultIOSystem::Exists opens the file, which blocks on a FIFO; stat does not.
    bool Exists(const char* file) const override {
        std::error_code error;
        return std::filesystem::exists(file, error);
    }

    Assimp::IOStream* Open(const char* file, const char* mode) override {
        // A missing file is assimp's to handle: an OBJ without its .mtl gets a default material.
        if (!Exists(file)) return nullptr;
        std::string named_file;
        try {
            if (std::string_view(mode).find_first_of("wa+") != std::string_view::npos)
                throw Error(fmt::format("{}: the importer tried to write '{}'", mesh_, file));
            if (file != mesh_) named_file = read_named_(file);
        } catch (const Error& e) {
            if (refusal_.empty()) refusal_ = e.what();
            return nullptr;
        }
        const std::string& bytes = file == mesh_ ? mesh_bytes_ : named_file;
        auto* copy = new uint8_t[bytes.size()];
        std::copy(bytes.begin(), bytes.end(), copy);
        return new Assimp::MemoryIOStream(copy, bytes.size(), /*own=*/true);  // Close deletes it
    }

    const std::string& refusal() const { return refusal_; }

private:
    std::string mesh_;
    const std::string& mesh_bytes_;
    const ReadNamedFile& read_named_;
    std::string refusal_;
};

/// Assimp offers a file that the reader for its extension declines to every other reader, so a
/// damaged .obj could end up in one tpsim does not offer (the SMD reader hangs on 22 bytes, the
/// ASE reader imports random bytes). Only the readers for `extension` stay registered.
void keep_only_readers_for(Assimp::Importer& importer, const std::string& extension) {
    const std::string wanted = extension.substr(1);  // without the dot
    for (size_t i = importer.GetImporterCount(); i-- > 0;) {
        std::istringstream extensions(importer.GetImporterInfo(i)->mFileExtensions);
        std::string e;
        bool reads = false;
        while (extensions >> e)
            reads = reads || e == wanted;
        if (reads) continue;
        Assimp::BaseImporter* reader = importer.GetImporter(i);
        importer.UnregisterLoader(reader);
        delete reader;  // unregistering hands the reader back
    }
}

class AssimpMeshReader final : public MeshReader {
public:
    ImportedMesh read(const std::string& where, const std::string& extension,
                      const std::string& bytes, const ReadNamedFile& read_named) const override {
        Assimp::Importer importer;
        keep_only_readers_for(importer, extension);
        auto* io = new CheckedIOSystem(where, bytes, read_named);
        importer.SetIOHandler(io);  // the importer owns it from here
        // ValidateDataStructure runs first so a malformed file is an error, not an ai_assert abort
        // in a later step (Debian's assimp keeps its asserts; e.g. an OFF file with a missing face
        // list). PreTransformVertices bakes node transforms in. FindDegenerates is deliberately
        // absent: degenerate triangles stay in as a robustness test for the kernels.
        const aiScene* file =
            importer.ReadFile(where, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                         aiProcess_PreTransformVertices);
        if (!io->refusal().empty()) throw Error(io->refusal());
        if (file == nullptr) {
            const std::string why = importer.GetErrorString();
            if (why.find("contains no faces") != std::string::npos)
                throw Error(fmt::format("{}: the mesh has no faces (a point cloud?); tpsim renders "
                                        "triangles",
                                        where));
            if (why.find("No suitable reader found") != std::string::npos)
                throw Error(
                    fmt::format("{}: not a {} file that assimp can read (damaged, or another "
                                "format under that extension)",
                                where, extension));
            throw Error(fmt::format("{}: cannot read mesh: {}", where, why));
        }

        ImportedMesh mesh;
        mesh.summary.source = where;
        for (unsigned m = 0; m < file->mNumMaterials; ++m)
            mesh.materials.push_back(convert_material(*file->mMaterials[m], where));
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
                        throw Error(fmt::format("{}: face {} of mesh {} refers to vertex {} of {}",
                                                where, f, m, face.mIndices[k], part.mNumVertices));
                    const aiVector3D& p = part.mVertices[face.mIndices[k]];
                    corners[k] = {p.x, p.y, p.z};
                    if (!is_finite(corners[k]))
                        throw Error(fmt::format("{}: face {} of mesh {} has a non-finite vertex",
                                                where, f, m));
                }
                const Triangle triangle{corners[0], corners[1], corners[2], material};
                if (is_degenerate(triangle)) ++mesh.summary.degenerate_triangles;
                mesh.triangles.push_back(triangle);
            }
        }
        mesh.summary.triangles = mesh.triangles.size();
        if (mesh.triangles.empty())
            throw Error(
                fmt::format("{}: the file holds no triangles ({} meshes, {} points/lines); is it "
                            "empty or in another format than its extension says?",
                            where, file->mNumMeshes, mesh.summary.skipped_primitives));
        return mesh;
    }
};

}  // namespace
}  // namespace tpsim::scene

extern "C" const void* tpsim_mesh_reader() {
    static const tpsim::scene::AssimpMeshReader reader;
    return &reader;
}
