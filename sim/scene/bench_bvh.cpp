// bench_bvh [scene-or-mesh ...]: loads each scene, builds its BVH with both builders and prints
// build time, node count, depth and SAH cost. Defaults to the bunny and the stress scene.
#include <exception>
#include <filesystem>
#include <vector>

#include <fmt/format.h>

#include "sim/scene/bvh.hpp"
#include "sim/scene/load_scene.hpp"

int main(int argc, char** argv) {
    using namespace tpsim::scene;
    std::vector<std::filesystem::path> paths(argv + 1, argv + argc);
    if (paths.empty()) paths = {TPSIM_SCENES_DIR "/bunny.toml", TPSIM_SCENES_DIR "/stress.toml"};
    try {
        fmt::print("{:<14} {:>9} {:<7} {:>9} {:>9} {:>6} {:>8} {:>9} {:>8}\n", "scene", "triangles",
                   "builder", "build_ms", "nodes", "depth", "sah", "leaves", "limited");
        for (const auto& path : paths) {
            const Scene scene = load_scene(path);
            for (BvhBuilder builder : {BvhBuilder::sweep, BvhBuilder::binned}) {
                const Bvh bvh = build_bvh(scene.triangles, BvhConfig{.builder = builder});
                const BvhStats& s = bvh.stats;
                fmt::print("{:<14} {:>9} {:<7} {:>9.1f} {:>9} {:>6} {:>8.3f} {:>9} {:>8}\n",
                           scene.name, scene.triangles.size(), to_string(builder),
                           s.build_seconds * 1e3, s.nodes, s.max_depth, s.sah_cost, s.leaves,
                           s.depth_limited_nodes);
            }
        }
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_bvh: {}\n", e.what());
        return 1;
    }
    return 0;
}
