// Helpers shared by the sim-core tests: paths of the cross-compiled guest programs.
#pragma once
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace tpsim::test {

inline std::string guest_program(const std::string& name) {
    return std::string(TPSIM_TEST_PROGRAMS) + "/" + name + ".elf";
}

inline std::string guest_source(const std::string& file) {
    return std::string(TPSIM_TEST_SOURCES) + "/" + file;
}

inline std::vector<uint8_t> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The 1-based line of the first line of `file` containing `marker` (0 if none).
inline uint32_t line_of(const std::string& file, const std::string& marker) {
    std::ifstream in(guest_source(file));
    std::string line;
    for (uint32_t number = 1; std::getline(in, line); ++number)
        if (line.find(marker) != std::string::npos) return number;
    return 0;
}

}  // namespace tpsim::test
