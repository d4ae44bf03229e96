// Helpers shared by the emitter, random-number and path-tracing tests.
#pragma once
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "sim/render/render.hpp"
#include "tests/scratch.hpp"

namespace tpsim::pathtrace_test {

inline render::RenderOptions options_for(const std::filesystem::path& scene, const char* kernel,
                                         render::Engine engine) {
    render::RenderOptions o;
    o.scene = scene;
    o.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / kernel;
    o.engine = engine;
    o.chip.chip.num_tms = 1;  // 32 threads: quick
    o.chip.chip.tps_per_tm = 32;
    return o;
}

inline std::filesystem::path cornell() {
    return std::filesystem::path(TPSIM_SOURCE_DIR) / "scenes" / "cornell.toml";
}

/// A scene file in the test's scratch directory.
inline std::filesystem::path write_scene(const std::string& name, const std::string& contents) {
    const std::filesystem::path path = testing::scratch_path(name);
    std::ofstream(path, std::ios::binary) << contents;
    return path;
}

/// Index of the first float whose bits differ, or -1.
inline long first_difference(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) return long(i);
    return -1;
}

}  // namespace tpsim::pathtrace_test
