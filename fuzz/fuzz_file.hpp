// Writes a fuzz input to a file, for loaders that take a path: one scratch directory per
// process, so parallel fuzzing jobs do not share files.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace tpsim::fuzz {

inline std::filesystem::path write_input(const uint8_t* data, size_t size,
                                         const std::string& name) {
    static const std::filesystem::path directory = [] {
        auto d =
            std::filesystem::temp_directory_path() / ("tpsim-fuzz-" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    const std::filesystem::path path = directory / name;
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return path;
}

}  // namespace tpsim::fuzz
