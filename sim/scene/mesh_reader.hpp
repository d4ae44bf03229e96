// The interface of the mesh module: what tpsim asks of assimp, loaded on first use
// (sim/core/module.hpp) so that commands without a mesh never load assimp.
#pragma once
#include <functional>
#include <string>

#include "sim/scene/mesh_import.hpp"

namespace tpsim::scene {

inline constexpr char kMeshReaderModule[] = "libtpsim_assimp.so";
inline constexpr char kMeshReaderEntry[] = "tpsim_mesh_reader";

/// Reads a file the mesh names (a material library, a buffer); throws tpsim::Error to refuse it.
using ReadNamedFile = std::function<std::string(const std::string& file)>;

class MeshReader {
public:
    /// Converts `bytes`, the mesh file `where` with the (lower-case) `extension`, already read
    /// and checked, to a triangle soup (see import_mesh). Throws tpsim::Error.
    virtual ImportedMesh read(const std::string& where, const std::string& extension,
                              const std::string& bytes, const ReadNamedFile& read_named) const = 0;

protected:
    ~MeshReader() = default;
};

}  // namespace tpsim::scene
