// Helpers shared by the scene tests: scratch files and small geometry.
#pragma once
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace tpsim::scene::testing {

/// A per-process scratch directory, so parallel ctest runs do not collide.
inline std::filesystem::path scratch_dir() {
    const auto dir =
        std::filesystem::temp_directory_path() / ("tpsim_scene_test_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    return dir;
}

inline std::filesystem::path write_file(const std::string& name, const std::string& contents) {
    const auto path = scratch_dir() / name;
    std::ofstream(path, std::ios::binary) << contents;
    return path;
}

}  // namespace tpsim::scene::testing
