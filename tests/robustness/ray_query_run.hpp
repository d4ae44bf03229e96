// The harness both robustness tests share: every acceleration structure (and box format) built
// for a mesh, and its ray_query kernel (ray_query through the BVH, ray_query_wide through the
// wide BVHs, ray_query_grid through the uniform grid, ray_query_kdtree through the kd-tree,
// ray_query_octree through the octree, ray_query_bsp through the BSP tree, ray_query_packet in
// packets through the BVH) over a batch of rays, on the functional simulator and on the native
// twin, whose results must agree bit for bit.
#pragma once
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "sim/image/memory_image.hpp"
#include "sim/render/render.hpp"
#include "sim/scene/accel.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/wide_bvh.hpp"

namespace tpsim::test {

/// One structure as a test builds it: its kind, for a wide BVH its box format, and for the
/// binary BVH whether packets of rays traverse it (ray_query_packet).
struct AccelVariant {
    scene::AccelStructure structure;
    scene::BvhBoxes boxes = scene::BvhBoxes::floats;
    bool packets = false;
};

inline std::string to_string(AccelVariant v) {
    std::string name(scene::to_string(v.structure));
    if (scene::wide_bvh_width(v.structure) != 0) name += std::string(" ") + to_string(v.boxes);
    if (v.packets) name += " packets";
    return name;
}

/// Every structure tpsim builds, every wide BVH in both box formats, the binary BVH also in
/// packets.
inline constexpr AccelVariant kAccelVariants[] = {
    {scene::AccelStructure::bvh2},   {scene::AccelStructure::bvh2, scene::BvhBoxes::floats, true},
    {scene::AccelStructure::bvh4},   {scene::AccelStructure::bvh4, scene::BvhBoxes::quantized},
    {scene::AccelStructure::bvh8},   {scene::AccelStructure::bvh8, scene::BvhBoxes::quantized},
    {scene::AccelStructure::grid},   {scene::AccelStructure::kdtree},
    {scene::AccelStructure::octree}, {scene::AccelStructure::bsp},
};

/// A structure built for a mesh as render() builds it (the BVH with the kernels' depth limit).
struct BuiltAccel {
    AccelVariant variant;
    std::optional<scene::Bvh> bvh;
    std::optional<scene::WideBvh> wide;
    std::optional<scene::Grid> grid;
    std::optional<scene::KdTree> kdtree;
    std::optional<scene::Octree> octree;

    BuiltAccel(const std::vector<scene::Triangle>& mesh, AccelVariant v) : variant(v) {
        if (v.structure == scene::AccelStructure::grid) {
            grid = scene::build_grid(mesh);
            return;
        }
        if (v.structure == scene::AccelStructure::kdtree ||
            v.structure == scene::AccelStructure::bsp) {
            scene::KdTreeConfig config;
            config.general_planes = v.structure == scene::AccelStructure::bsp;
            kdtree = scene::build_kdtree(mesh, config);
            return;
        }
        if (v.structure == scene::AccelStructure::octree) {
            octree = scene::build_octree(mesh);
            return;
        }
        scene::BvhConfig config;
        config.traversal_stack_entries = trax::layout::kTraversalStackEntries;
        bvh = scene::build_bvh(mesh, config);
        if (const uint32_t width = scene::wide_bvh_width(v.structure); width != 0) {
            wide = scene::collapse_bvh(*bvh, width);
            bvh.reset();
        }
    }
    image::Accel accel() const {
        if (grid) return &*grid;
        if (kdtree) return &*kdtree;
        if (octree) return &*octree;
        if (wide) return {&*wide, scene::BvhOrder::breadth_first, variant.boxes};
        return &*bvh;
    }
    /// The scene triangle behind an image triangle index (a BVH's are in leaf order).
    uint32_t scene_triangle(int32_t image_index) const {
        return bvh    ? bvh->triangle_order[size_t(image_index)]
               : wide ? wide->triangle_order[size_t(image_index)]
                      : uint32_t(image_index);
    }
    /// Most nodes (boxes, cells) one ray can visit: every box once; a straight line crosses
    /// at most res_x + res_y + res_z - 2 cells.
    uint64_t most_nodes() const {
        if (bvh) return bvh->nodes.size();
        if (wide) return 1 + uint64_t(wide->nodes.size()) * wide->stats.width;
        if (kdtree) return kdtree->nodes.size();
        if (octree) return octree->nodes.size();
        return uint64_t(grid->stats.resolution[0]) + grid->stats.resolution[1] +
               grid->stats.resolution[2] - 2;
    }
    const char* kernel() const {
        return grid     ? "ray_query_grid.elf"
               : wide   ? "ray_query_wide.elf"
               : kdtree ? (kdtree->general_planes ? "ray_query_bsp.elf" : "ray_query_kdtree.elf")
               : octree ? "ray_query_octree.elf"
               : variant.packets ? "ray_query_packet.elf"
                                 : "ray_query.elf";
    }
};

struct RayQueryRun {
    std::vector<trax::layout::RayResult> results;  ///< one per ray, identical on both engines
    std::array<image::TraversalTotals, 2> totals;  ///< per engine: functional, then native
    image::MemoryImage image;                      ///< the functional run's memory image
};

/// Runs the ray_query kernel of `built` (TPSIM_KERNEL_DIR) over `rays` through that structure
/// of `triangles` on 1 TM x 4 TPs with an instruction budget per thread (a ray that hung the
/// traversal fails the run), on both engines; REQUIREs one result per ray and bit-identical
/// results.
inline RayQueryRun run_ray_query(const std::vector<scene::Triangle>& triangles,
                                 const BuiltAccel& built,
                                 const std::vector<trax::layout::Ray>& rays, uint64_t budget) {
    scene::Scene s;
    s.triangles = triangles;
    s.materials.resize(1);
    s.width = s.height = 1;
    timing::ChipConfig chip;
    chip.chip.num_tms = 1;
    chip.chip.tps_per_tm = 4;
    const auto kernel =
        render::Kernel::load(std::filesystem::path(TPSIM_KERNEL_DIR) / built.kernel());

    RayQueryRun run;
    std::vector<trax::layout::RayResult> per_engine[2];
    const render::Engine engines[2] = {render::Engine::functional, render::Engine::native};
    for (int e = 0; e < 2; ++e) {
        image::MemoryImage img = image::build_memory_image(s, built.accel(), 4, rays);
        render::run_kernel(kernel, engines[e], img, chip, budget);
        per_engine[e] = image::read_ray_results(img.header, img.words.data());
        run.totals[e] = image::read_thread_stats(img.header, img.words.data());
        if (e == 0) run.image = std::move(img);
    }
    REQUIRE(per_engine[0].size() == rays.size());
    REQUIRE(per_engine[1].size() == rays.size());
    size_t differing = 0;
    for (size_t i = 0; i < rays.size(); ++i)
        differing +=
            std::memcmp(&per_engine[0][i], &per_engine[1][i], sizeof(trax::layout::RayResult)) != 0;
    INFO(differing << " of " << rays.size() << " results differ between simulator and twin");
    REQUIRE(differing == 0);
    run.results = std::move(per_engine[0]);
    return run;
}

}  // namespace tpsim::test
