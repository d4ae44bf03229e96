// Fuzzes the scene-file loader (sim/scene/load_scene.cpp) with the input as a scene's TOML. The
// meshes a scene names are looked up beside it, in the harness's scratch directory.
#include <cstdint>
#include <string>

#include "fuzz/fuzz_file.hpp"
#include "sim/core/error.hpp"
#include "sim/scene/load_scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // A mesh for scenes to name, as the crafted bad scenes do.
    static const bool mesh_written = [] {
        const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        tpsim::fuzz::write_input(reinterpret_cast<const uint8_t*>(triangle.data()), triangle.size(),
                                 "tri.obj");
        return true;
    }();
    (void)mesh_written;
    try {
        tpsim::scene::load_scene(tpsim::fuzz::write_input(data, size, "scene.toml"));
    } catch (const tpsim::Error&) {
    }
    return 0;
}
