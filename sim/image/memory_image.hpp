// The scene compiler's last step: lays a Scene (and optionally its BVH) out as the guest memory
// image defined by kernel/scene_layout.hpp, holding only the sections the scene needs.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "kernel/scene_layout.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/scene.hpp"

namespace tpsim::image {

/// One section of the image, for the "memory image by section" report.
struct SectionSize {
    std::string name;
    uint32_t records = 0;
    uint64_t bytes = 0;
};

struct MemoryImage {
    /// Global memory from kGlobalBase on: header, sections, zeroed framebuffer.
    std::vector<uint32_t> words;
    trax::layout::SceneHeader header{};
    std::vector<SectionSize> sections;  ///< in address order, header first

    uint64_t bytes() const { return uint64_t(words.size()) * 4; }
};

/// Lays the scene out. With a BVH, triangles are stored in leaf order and nodes with sibling
/// pairs adjacent, as the traversal kernel expects; without one, the BVH section is left out.
/// Throws tpsim::Error if the scene does not fit the layout (e.g. more than 2^31 words).
MemoryImage build_memory_image(const scene::Scene& scene, const scene::Bvh* bvh = nullptr);

/// The framebuffer's linear RGB floats, row 0 at the top, read back from global memory.
std::vector<float> read_framebuffer(const trax::layout::SceneHeader& header,
                                    const uint32_t* global_words);

}  // namespace tpsim::image
