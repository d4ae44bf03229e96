// Helpers shared by the scene tests: scratch files and small geometry.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "sim/scene/scene.hpp"

#include "tests/scratch.hpp"

namespace tpsim::scene::testing {

inline std::filesystem::path write_file(const std::string& name, const std::string& contents) {
    const auto path = tpsim::testing::scratch_path(name);
    std::ofstream(path, std::ios::binary) << contents;
    return path;
}

/// `count` random triangles in [-10, 10]^3, each within `size` of its centre on every axis.
inline std::vector<Triangle> soup(uint32_t count, uint32_t seed, float size) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> position(-10.f, 10.f), offset(-size, size);
    std::vector<Triangle> triangles;
    for (uint32_t i = 0; i < count; ++i) {
        const glm::vec3 c(position(rng), position(rng), position(rng));
        const auto corner = [&] { return c + glm::vec3(offset(rng), offset(rng), offset(rng)); };
        triangles.push_back({corner(), corner(), corner(), 0});
    }
    return triangles;
}

/// FNV-1a over 32-bit words, byte by byte: the scene tests' digests of built structures (equal
/// digests mean the same structure).
class Fnv {
public:
    void add(uint32_t word) {
        for (int byte = 0; byte < 4; ++byte) {
            hash_ ^= (word >> (8 * byte)) & 0xff;
            hash_ *= 1099511628211ull;
        }
    }
    uint64_t hash() const { return hash_; }

private:
    uint64_t hash_ = 14695981039346656037ull;
};

}  // namespace tpsim::scene::testing
