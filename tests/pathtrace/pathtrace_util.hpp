// Helpers shared by the emitter, random-number and path-tracing tests.
#pragma once
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "sim/render/render.hpp"

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

/// A scene file in a per-process scratch directory (parallel ctest runs do not collide).
inline std::filesystem::path write_scene(const std::string& name, const std::string& contents) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("tpsim_pathtrace_test_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary) << contents;
    return dir / name;
}

/// Index of the first float whose bits differ, or -1.
inline long first_difference(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) return long(i);
    return -1;
}

}  // namespace tpsim::pathtrace_test
