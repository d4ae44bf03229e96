// Fuzzes mesh import (sim/scene/mesh_import.cpp and the assimp readers behind it). The first
// byte picks the format, the rest is the file.
#include <cstdint>
#include <iterator>
#include <string>

#include "fuzz/fuzz_file.hpp"
#include "sim/core/error.hpp"
#include "sim/scene/mesh_import.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const char* const extensions[] = {".obj", ".ply", ".off", ".stl", ".gltf", ".glb"};
    if (size == 0) return 0;
    const std::string name = std::string("mesh") + extensions[data[0] % std::size(extensions)];
    try {
        tpsim::scene::import_mesh(tpsim::fuzz::write_input(data + 1, size - 1, name));
    } catch (const tpsim::Error&) {
    }
    return 0;
}
