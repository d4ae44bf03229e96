// The scene compiler's last step: lays a Scene (and optionally its BVH) out as the guest memory
// image defined by kernel/scene_layout.hpp, holding only the sections the scene needs.
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "kernel/scene_layout.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/grid.hpp"
#include "sim/scene/kdtree.hpp"
#include "sim/scene/octree.hpp"
#include "sim/scene/scene.hpp"
#include "sim/scene/wide_bvh.hpp"

namespace tpsim::image {

/// One section of the image, for the "memory image by section" report and the chip's
/// traffic by region.
struct SectionSize {
    std::string name;
    uint32_t records = 0;
    uint64_t bytes = 0;
    uint64_t begin = 0;  ///< byte offset from trax::map::kGlobalBase
};

struct MemoryImage {
    /// Global memory from kGlobalBase on: header, sections, zeroed framebuffer.
    std::vector<uint32_t> words;
    trax::layout::SceneHeader header{};
    std::vector<SectionSize> sections;  ///< in address order, header first

    uint64_t bytes() const { return uint64_t(words.size()) * 4; }
    /// The scene part (header through BVH, before the framebuffer): read-only while a kernel
    /// runs.
    uint64_t read_only_bytes() const { return uint64_t(header.framebuffer.addr) * 4; }
};

/// The acceleration structure to lay out with the scene: at most one, the one the kernel
/// traverses (or none, for brute force).
struct Accel {
    const scene::Bvh* bvh = nullptr;
    const scene::WideBvh* wide_bvh = nullptr;
    scene::BvhOrder bvh_order = scene::BvhOrder::breadth_first;  ///< scene::BvhConfig::order
    bool bvh_align_pairs = false;                                ///< scene::BvhConfig::align_pairs
    scene::BvhBoxes bvh_boxes = scene::BvhBoxes::floats;         ///< scene::BvhConfig::boxes
    const scene::Grid* grid = nullptr;
    const scene::KdTree* kdtree = nullptr;
    const scene::Octree* octree = nullptr;
    Accel(std::nullptr_t = nullptr) {}
    Accel(const scene::Bvh* b, scene::BvhOrder order = scene::BvhOrder::breadth_first,
          bool align_pairs = false)
        : bvh(b), bvh_order(order), bvh_align_pairs(align_pairs) {}
    Accel(const scene::WideBvh* b, scene::BvhOrder order, scene::BvhBoxes boxes)
        : wide_bvh(b), bvh_order(order), bvh_boxes(boxes) {}
    Accel(const scene::Grid* g) : grid(g) {}
    Accel(const scene::KdTree* k) : kdtree(k) {}
    Accel(const scene::Octree* o) : octree(o) {}
};

/// The BVH section: the builder's nodes as layout::BvhNode wants them, the root at index 0 and
/// the two children of every interior node side by side, their pairs in `order`; with
/// `align_pairs`, index 1 is left unused (zeroed) so that every pair starts on a 64-byte
/// boundary (the section starts on one). Leaf ranges index the triangles in leaf order.
std::vector<trax::layout::BvhNode> compile_bvh(const scene::Bvh& bvh, scene::BvhOrder order,
                                               bool align_pairs);

/// The wide BVH's nodes (layout::wide_node_words each) in `order`, for a section at word
/// address `addr`: child references are word addresses. Throws tpsim::Error for a leaf the
/// reference format cannot address.
std::vector<uint32_t> compile_wide_bvh(const scene::WideBvh& bvh, scene::BvhOrder order,
                                       scene::BvhBoxes boxes, int32_t addr);

/// Lays the scene out. With a BVH, triangles are stored in leaf order and nodes with sibling
/// pairs adjacent, as the traversal kernel expects; without one, the BVH section is left out.
/// With a grid, the AccelRecord and the grid's cells and references (sections "grid",
/// "grid_cells", "grid_refs"), triangles in scene order. With a wide BVH, the AccelRecord
/// ("bvh_root") and the wide nodes ("bvh_nodes", the binary BVH's region name, so that traffic
/// compares across widths), triangles in leaf order. With a kd-tree, the AccelRecord and its
/// nodes and references ("kdtree", "kdtree_nodes", "kdtree_refs"), triangles in scene order; the
/// same for an octree ("octree", "octree_nodes", "octree_refs") and a BSP tree ("bsp",
/// "bsp_nodes", "bsp_refs").
/// One zeroed ThreadStats record per thread (`threads` of them); `rays` (for the ray_query
/// kernel) and room for as many RayResults. With `extras_seed`, also the SceneExtras record
/// (that run seed, every material's emission, the emissive triangles): only for kernels that
/// read it (their ELF defines trax::layout::kUsesExtrasSymbol). Throws tpsim::Error if the
/// scene does not fit the layout (e.g. more than 2^31 words).
MemoryImage build_memory_image(const scene::Scene& scene, Accel accel, uint32_t threads,
                               std::span<const trax::layout::Ray> rays = {},
                               std::optional<uint32_t> extras_seed = std::nullopt);

/// The kernel's per-thread statistics records summed (ThreadStats; max for the depth).
struct TraversalTotals {
    uint64_t primary_rays = 0, shadow_rays = 0;
    uint64_t nodes_visited = 0, triangles_tested = 0;
    uint32_t max_stack_depth = 0;
    uint64_t stack_overflows = 0;
    uint64_t rays() const { return primary_rays + shadow_rays; }
};
TraversalTotals read_thread_stats(const trax::layout::SceneHeader& header,
                                  const uint32_t* global_words);

/// The ray_query kernel's results, one per ray.
std::vector<trax::layout::RayResult> read_ray_results(const trax::layout::SceneHeader& header,
                                                      const uint32_t* global_words);

/// The framebuffer's linear RGB floats, row 0 at the top, read back from global memory.
std::vector<float> read_framebuffer(const trax::layout::SceneHeader& header,
                                    const uint32_t* global_words);

}  // namespace tpsim::image
