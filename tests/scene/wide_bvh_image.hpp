// A wide BVH read back from a memory image by the format scene_layout.hpp documents (an
// independent reading of it, for the tests): every node reachable from the root, in the order
// a depth-first walk meets them, each child's box as the kernel decodes it and its reference.
#pragma once
#include <cstdint>
#include <cstring>
#include <vector>

#include <glm/glm.hpp>

#include "sim/image/memory_image.hpp"

namespace tpsim::test {

struct ImageWideChild {
    glm::vec3 lo, hi;
    uint32_t ref;
    bool is_leaf() const { return (ref & trax::layout::kWideLeafBit) != 0; }
    uint32_t first() const { return (ref & 0x7fffffffu) >> 4; }
    uint32_t count() const { return ref & 15u; }
};

struct ImageWideNode {
    int32_t addr;
    std::vector<ImageWideChild> children;
};

inline float word_float(const uint32_t* words, int32_t addr) {
    float f;
    std::memcpy(&f, words + addr, 4);
    return f;
}

/// The wide BVH of `image`, which must hold one (AccelRecord kind kAccelWideBvh).
inline std::vector<ImageWideNode> read_wide_bvh(const image::MemoryImage& image) {
    namespace layout = trax::layout;
    const uint32_t* w = image.words.data();
    const int32_t record = image.header.accel;
    const auto width = int32_t(w[record + layout::kAccelWidth]);
    const bool quantized = w[record + layout::kAccelQuantized] != 0;
    std::vector<ImageWideNode> nodes;
    std::vector<int32_t> pending{int32_t(w[record + layout::kAccelNodes])};
    while (!pending.empty()) {
        const int32_t addr = pending.back();
        pending.pop_back();
        ImageWideNode node{addr, {}};
        const uint32_t* n = w + addr;
        const auto* bytes =
            reinterpret_cast<const uint8_t*>(n) + layout::wide_quantized_boxes_byte(width);
        for (int32_t c = 0; c < width; ++c) {
            const uint32_t ref = n[quantized ? layout::kWideQuantizedRefs + c : 6 * width + c];
            if (ref == 0) break;
            ImageWideChild child{};
            child.ref = ref;
            for (int a = 0; a < 3; ++a) {
                if (quantized) {
                    const float origin = word_float(n, a);
                    const uint32_t scale_bits = ((n[3] >> (8 * a)) & 255u) << 23;
                    float scale;
                    std::memcpy(&scale, &scale_bits, 4);
                    child.lo[a] = origin + float(bytes[a * width + c]) * scale;
                    child.hi[a] = origin + float(bytes[(3 + a) * width + c]) * scale;
                } else {
                    child.lo[a] = word_float(n, 6 * c + a);
                    child.hi[a] = word_float(n, 6 * c + 3 + a);
                }
            }
            node.children.push_back(child);
        }
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
            if (!c->is_leaf()) pending.push_back(int32_t(c->ref));
        nodes.push_back(std::move(node));
    }
    return nodes;
}

}  // namespace tpsim::test
