// The harness both robustness tests share: a ray_query kernel (ray_query through the BVH,
// ray_query_grid through the uniform grid) over a batch of rays, on the functional simulator
// and on the native twin, whose results must agree bit for bit.
#pragma once
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <vector>

#include <catch2/catch.hpp>

#include "sim/image/memory_image.hpp"
#include "sim/render/render.hpp"
#include "sim/scene/bvh.hpp"

namespace tpsim::test {

struct RayQueryRun {
    std::vector<trax::layout::RayResult> results;  ///< one per ray, identical on both engines
    std::array<image::TraversalTotals, 2> totals;  ///< per engine: functional, then native
    image::MemoryImage image;                      ///< the functional run's memory image
};

/// Runs the ray_query kernel of `accel` (TPSIM_KERNEL_DIR) over `rays` through that structure
/// of `triangles` on 1 TM x 4 TPs with an instruction budget per thread (a ray that hung the
/// traversal fails the run), on both engines; REQUIREs one result per ray and bit-identical
/// results.
inline RayQueryRun run_ray_query(const std::vector<scene::Triangle>& triangles, image::Accel accel,
                                 const std::vector<trax::layout::Ray>& rays, uint64_t budget) {
    scene::Scene s;
    s.triangles = triangles;
    s.materials.resize(1);
    s.width = s.height = 1;
    timing::ChipConfig chip;
    chip.chip.num_tms = 1;
    chip.chip.tps_per_tm = 4;
    const auto kernel = render::Kernel::load(std::filesystem::path(TPSIM_KERNEL_DIR) /
                                             (accel.grid ? "ray_query_grid.elf" : "ray_query.elf"));

    RayQueryRun run;
    std::vector<trax::layout::RayResult> per_engine[2];
    const render::Engine engines[2] = {render::Engine::functional, render::Engine::native};
    for (int e = 0; e < 2; ++e) {
        image::MemoryImage img = image::build_memory_image(s, accel, 4, rays);
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
