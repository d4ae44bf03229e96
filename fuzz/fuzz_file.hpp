// Writes a fuzz input to a file, for loaders that take a path: in the process's scratch
// directory (tests/scratch.hpp), so parallel fuzzing jobs do not share files.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/scratch.hpp"

namespace tpsim::fuzz {

inline std::filesystem::path write_input(const uint8_t* data, size_t size,
                                         const std::string& name) {
    const std::filesystem::path path = testing::scratch_path(name);
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return path;
}

}  // namespace tpsim::fuzz
