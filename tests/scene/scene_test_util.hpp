// Helpers shared by the scene tests: scratch files and small geometry.
#pragma once
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/scratch.hpp"

namespace tpsim::scene::testing {

inline std::filesystem::path write_file(const std::string& name, const std::string& contents) {
    const auto path = tpsim::testing::scratch_path(name);
    std::ofstream(path, std::ios::binary) << contents;
    return path;
}

}  // namespace tpsim::scene::testing
